//! A run's report: the judge's verdicts (contacts with who was at fault, passes, each mover's
//! traffic-conflict figures), the configuration it ran with, why it ended, and where
//! the wall time went.

use serde::Serialize;

use super::outcome::{EndReason, JudgedContact, ObstacleReport, Stop};
use crate::scenario::RunConfig;
use crate::world::Contact;

/// What a run did.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// Scenario name.
    pub scenario: String,
    /// Seed used.
    pub seed: u64,
    /// True when every expectation held and every lap was completed.
    pub expectations_met: bool,
    /// Why the run ended: `completed`, `timed_out`, `interrupted`,
    /// `waiting_for_hidden_obstacle`, `waiting_for_walk_around`, `blocked` or `struck` (the last
    /// four call for a pilot), or an external stack's `stack_timeout` or `stack_failed`.
    pub end: EndReason,
    /// When the run ended waiting for a hidden obstacle: which, and since when.
    pub waiting_for: Option<HiddenObstacle>,
    /// The start-up rule's first check (when the scenario's walk-around is not before the
    /// start): the ground the first plan would sweep that the LiDAR cannot see from the start,
    /// square metres (0: none; the vehicle moved off at once).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_unseen_m2: Option<f64>,
    /// The pilot call that ended the run, with what held the vehicle and whether anything was
    /// really there ([`super::PilotCallReport`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pilot_call: Option<super::PilotCallReport>,
    /// The push-back from the stand, when the route began with one ([`super::PushbackReport`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pushback: Option<super::PushbackReport>,
    /// What the stack outside the process did, when one drove ([`super::run_external`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stack: Option<super::external::StackReport>,
    /// Laps asked for.
    pub laps: u32,
    /// Laps completed.
    pub laps_completed: u32,
    /// Lap times, seconds.
    pub lap_times_s: Vec<f64>,
    /// Ground-truth contacts.
    pub contacts: Vec<Contact>,
    /// The contacts judged, each with the vehicle's true speed then and whether the vehicle was
    /// at fault (moving into it), struck standing, or struck while moving (the object came into
    /// room the vehicle held); a pair driven into while it lasts is judged again, once.
    pub contacts_judged: Vec<JudgedContact>,
    /// Judged at fault: the stack's.
    pub contacts_at_fault: usize,
    /// Judged struck: by a mover, the vehicle standing or moving.
    pub contacts_struck: usize,
    /// Of those, struck while the vehicle moved.
    pub contacts_struck_while_moving: usize,
    /// Per run-time obstacle.
    pub obstacles: Vec<ObstacleReport>,
    /// Stops, once the vehicle has first moved (held at the start while the localizer settles
    /// is not one).
    pub stops: Vec<Stop>,
    /// Smallest ground-truth clearance per level to any object, metres.
    pub min_clearance_m: Vec<f64>,
    /// The static objects the vehicle came within [`CLOSE_STATIC_M`] of (a parked aircraft as
    /// one, its parts' id prefix), nearest first, at most [`CLOSEST_STATIC_COUNT`]: how close the
    /// route comes to the airport's signs, lights and parked wings (ground truth).
    pub closest_static: Vec<StaticClearance>,
    /// The scenario's danger distance, metres (`None`: not stated): a pass closer than this to
    /// its obstacle, at any level, does not meet its expectation.
    pub danger_distance_m: Option<f64>,
    /// Simulated time, seconds.
    pub sim_time_s: f64,
    /// Wall time, seconds.
    pub wall_time_s: f64,
    /// Simulated seconds per wall second.
    pub real_time_factor: f64,
    /// Where the wall time went, seconds: LiDAR, mapping, distance maps, planning, physics.
    pub time_split_s: TimeSplit,
    /// The configuration the run ran with.
    pub config: RunConfig,
    /// What the faults did: lost revolutions, dropped and spurious returns, watchdog stops.
    #[serde(default)]
    pub faults: crate::world::FaultCounts,
    /// The pose estimate against the truth (`None` when the pose source is the truth).
    pub localization: Option<super::pose_error::LocalizationReport>,
    /// The route's speed, lowered: faster, the vehicle could not stop within its longest
    /// horizon or its detection range (`None`: the route's speed was allowed).
    pub speed_lowered: Option<SpeedLowered>,
}

/// The route's speed, lowered by the stack to what it can stop from within what it checks.
#[derive(Clone, Debug, Serialize)]
pub struct SpeedLowered {
    /// The route's speed, m/s.
    pub route_m_s: f64,
    /// The fastest the stack drove, m/s.
    pub cap_m_s: f64,
    /// What limited it: `horizon` (`autonomy.max_horizon_m`) or `detection_range`
    /// (`autonomy.detection_range_m`).
    pub limit: autonomy::planner::SpeedLimit,
}

/// The obstacle a vehicle waits for without seeing it.
#[derive(Clone, Debug, Serialize)]
pub struct HiddenObstacle {
    /// Its nearest cell to the vehicle's first colliding pose, metres (the estimate's frame).
    pub x_m: f64,
    /// See `x_m`.
    pub y_m: f64,
    /// When a revolution last hit it, seconds (`None`: not since the window held it).
    pub last_seen_s: Option<f64>,
    /// When the wait began, seconds.
    pub since_s: f64,
}

/// Wall time per stage, seconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TimeSplit {
    /// Ray casting.
    pub lidar: f64,
    /// Scan insertion.
    pub mapping: f64,
    /// Distance maps.
    pub distance_maps: f64,
    /// Planner and avoider.
    pub planning: f64,
    /// Motion, ground truth, obstacles.
    pub physics: f64,
    /// The pose source (the particle filter's motion and measurement updates).
    pub localization: f64,
}

/// Progress of a run, for a progress bar.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Simulated time, seconds.
    pub sim_time_s: f64,
    /// Laps completed.
    pub laps_completed: u32,
    /// Fraction of the whole run done, 0..1.
    pub fraction: f64,
}

/// How near a static object must come to be listed in [`RunReport::closest_static`], metres.
pub const CLOSE_STATIC_M: f64 = 5.0;
/// How many [`RunReport::closest_static`] lists at most.
pub const CLOSEST_STATIC_COUNT: usize = 10;

/// A static object and the smallest ground-truth clearance the vehicle kept to it.
#[derive(Clone, Debug, Serialize)]
pub struct StaticClearance {
    /// Its id (a parked aircraft's: before the `/` of its parts' ids).
    pub id: String,
    /// Its kind.
    pub kind: crate::world::ObjectKind,
    /// The smallest clearance over the run, metres.
    pub min_clearance_m: f64,
}

/// The static objects of `scene` the vehicle came within [`CLOSE_STATIC_M`] of, by
/// `clearances_m` (one per solid, as the world keeps them), grouped by id prefix, nearest first.
pub fn closest_static(scene: &crate::world::Scene, clearances_m: &[f64]) -> Vec<StaticClearance> {
    let mut nearest: Vec<StaticClearance> = Vec::new();
    for (solid, &d) in scene.solids.iter().zip(clearances_m) {
        if solid.runtime || d >= CLOSE_STATIC_M {
            continue;
        }
        let id = solid.id.split('/').next().unwrap_or(&solid.id);
        match nearest.iter_mut().find(|c| c.id == id) {
            Some(c) => c.min_clearance_m = c.min_clearance_m.min(d),
            None => nearest.push(StaticClearance {
                id: id.to_string(),
                kind: solid.kind,
                min_clearance_m: d,
            }),
        }
    }
    nearest.sort_by(|a, b| a.min_clearance_m.total_cmp(&b.min_clearance_m));
    nearest.truncate(CLOSEST_STATIC_COUNT);
    nearest
}
