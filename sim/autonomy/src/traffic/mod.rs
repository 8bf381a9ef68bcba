//! Traffic: the movers the tracker follows ([`mapper::TrackState`]), predicted over the planning
//! horizon, and the space-time check of the planned path against them.
//!
//! - **Prediction**: constant velocity from the track's Kalman filter; each mover is a capsule
//!   along its velocity: half its length along the motion (the box of its hits measured along
//!   it, at least half its largest extent) and half its width across, each plus `hidden_m`
//!   (what of it the sensor may not see), widened by `sigmas` standard deviations of its
//!   predicted position, which grow with time. Over a stretch of time it sweeps a longer
//!   capsule, since it moves along its own length, stretched on to where the fastest speed it
//!   was seen at lately would take it (a mover going into a wing's shadow seems to slow as its
//!   visible part shrinks: [`mapper::TrackState::peak_speed_m_s`]). A mover occupies the levels it was hit in: a
//!   baggage cart lower than a wing's level is checked against the gear and fuselage only.
//! - **Space-time check**: the vehicle's arrival time at each pose of the chosen path (from its
//!   speed now, accelerating to the speed it wants), and each circle of a level the mover
//!   occupies against the stretch the mover is predicted to cover from `time_margin_s` before
//!   to `time_margin_s` after the vehicle is there. The first such pose is the conflict.
//! - **Where to stop**: before the conflict zone - the first pose of the path that any position
//!   the mover is predicted to reach within `horizon_s` touches - so a vehicle never stands in
//!   a mover's predicted path when it can stop short of it; when it cannot (too close, too
//!   fast), it drives on if it clears the mover by `committed_margin_s`, and stops before the
//!   conflict itself only if it does not. Wherever it stops - for a mover or for the map - it
//!   stops short of any other mover's predicted path when it can ([`stand_clear`]): a stop for
//!   one must not leave the tail across another's; too late to stop short of the reach of a
//!   mover standing that came there, it stops as short as it can. A mover predicted to pass before the
//!   vehicle arrives (or after it has gone) is no conflict, so it does not stop the vehicle.
//!   While yielding, the margin after grows by `resume_margin_s`, so the vehicle does not creep
//!   off and stop again.
//! - Movers slower than `min_speed_m_s`, or than `sigmas` standard deviations of their speed,
//!   are left to the map (their cells are obstacles there) - but a mover known to move, in
//!   view, down to half that ([`predict_keeping`]: its visible part slows as the airframe hides
//!   the rest of it).
//! - **Caution**: a candidate mover - seen to travel a metre, not yet beyond what revealing a
//!   static object explains - checked the same way caps the speed at `caution_speed_m_s`
//!   instead of stopping the vehicle: slow for what may move, stop for what does. So does a
//!   person-sized object seen only standing within `standing_object_reach_m` of the path
//!   ([`mapper::Tracker::standing_objects`]): it may walk on before it can be predicted.
//! - **A map obstacle closing** (`closing`): the chosen path's first collision with the
//!   map coming nearer along the route faster than `closing_speed_m_s` is something moving the
//!   tracker does not follow; the vehicle closes on it no faster than the caution speed
//!   together and stops short of where it will be by the time the vehicle stands.
//! - **A mover at the body** ([`at_body`]): one seen, or predicted while out of view, whose box
//!   of hits, grown by what of it may be hidden, comes within `at_body_m` of a circle of a level
//!   it occupies is where the map cannot hold it (returns within the map's self-hit margin of
//!   the vehicle are dropped as its own): the vehicle does
//!   not move until it is seen away from the body, and one lost there is waited for as a hidden
//!   obstacle (the pilot is called); so is one predicted out of view whose track drops while
//!   it is predicted to reach the standing vehicle's body within the horizon (a van lost into
//!   the blind zone behind a wing). A person who walked up to the fuselage, a truck that
//!   struck the nose: the vehicle moving on would meet them. Only a mover arrives there: a
//!   track predicted lately that has moved beyond its own extent
//!   ([`moved_beyond_its_extent`]) - not a parked car whose visible part slides.
//!
//! The files, by job: `predict` (the movers' footprints over the horizon), `conflict` (the
//! space-time check of the path, where to stand clear), `body` (movers at or reaching the
//! vehicle's body) - pure functions of tracks and poses - and the rules that keep memory from
//! plan to plan ([`TrafficRules`], in `rules`, `speed_cap`, `closing`, `holds`, `memory` and
//! `parts`): one call a plan ([`TrafficRules::decide`]) turns the plan's inputs into its
//! decision about movers.

mod body;
mod closing;
#[cfg(test)]
mod closing_tests;
mod conflict;
#[cfg(test)]
mod hidden_tests;
mod holds;
mod memory;
#[cfg(test)]
mod memory_tests;
mod parts;
#[cfg(test)]
mod parts_tests;
mod predict;
mod rules;
#[cfg(test)]
mod rules_tests;
mod speed_cap;
#[cfg(test)]
mod tests;

use mapper::TrackState;
use nalgebra::{Isometry2, Point2};
use serde::{Deserialize, Serialize};

pub use body::{at_body, may_have_walked_to, may_reach_body};
pub use conflict::{
    StandStop, first_conflict, first_conflict_straightforward, first_within_standing_reach,
    passes_standing, stand_clear, stand_clear_why,
};
pub(crate) use predict::reach;
pub use predict::{came_there, moved_beyond_its_extent, predict, predict_keeping, surely_moving};
pub use rules::{BodyHold, LostMover, MoverDecision, MoverInputs, TrafficRules};

/// How the stack predicts movers and checks its path against them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrafficConfig {
    /// Predict movers and yield to them. Default true; false: the map alone (a mover stops the
    /// vehicle only once it stands in the path).
    pub enabled: bool,
    /// How far ahead movers are predicted, seconds. Default 8.
    pub horizon_s: f64,
    /// The vehicle keeps out of where a mover is predicted from this long before it is at a
    /// pose to this long after, seconds. Default 1.5.
    pub time_margin_s: f64,
    /// While yielding - stopped for a mover, or within `conflict_memory_s` of a plan that found
    /// a conflict - the margin after grows by this much, seconds. Default 1.
    pub resume_margin_s: f64,
    /// How long after a conflict was last found the vehicle counts as yielding, seconds.
    /// Default 2.
    pub conflict_memory_s: f64,
    /// The margin of a vehicle too close to stop short of a mover's path: it drives on when it
    /// clears the mover by this much (standing in the path would be worse), seconds. Default 0.5.
    pub committed_margin_s: f64,
    /// A mover's disc is widened by this many standard deviations of its predicted position.
    /// Default 2.
    pub sigmas: f64,
    /// Clearance kept from a predicted mover beyond the radii, metres. Default 0.5.
    pub margin_m: f64,
    /// What may lie of a mover beyond the box of its hits, along and across its motion (the far
    /// side of a van seen from one side, its back seen from the front), metres. Default 1.
    pub hidden_m: f64,
    /// Movers slower than this are left to the map, m/s. Default 0.8 (a static object's visible
    /// part, sliding as it is hidden or revealed, seldom seems faster).
    pub min_speed_m_s: f64,
    /// A tracked mover whose box of hits, grown by what of it may be hidden (`hidden_m` or
    /// more), comes this close to the vehicle's body (beyond a circle's radius, on a level it
    /// occupies) holds the vehicle ([`at_body`]), metres. Default 1 (the map drops returns
    /// within 0.8 m of a circle as the vehicle's own).
    pub at_body_m: f64,
    /// A mover not yet predictable - one the tracker has seen travel a metre but not yet
    /// beyond what revealing a static object's parts explains
    /// ([`mapper::Tracker::candidate_movers`]) - whose motion so far would meet the path caps
    /// the speed at this, m/s, until `conflict_memory_s` after it was last found: by the time
    /// it is confirmed, the vehicle can stop short of it. Default 3 (a long truck crossing at
    /// 1.3 m/s takes 4.4 s to confirm, 35 m at 8 m/s).
    pub caution_speed_m_s: f64,
    /// A mover standing (a known mover not [`surely_moving`]) may walk or drive on without
    /// warning: the vehicle passes within this much of it (beyond `margin_m` and its
    /// footprint) no faster than `caution_speed_m_s` ([`passes_standing`]), does not stop
    /// within it when it can stop short ([`stand_clear`]) and, standing within it, does not
    /// move off, metres. Default 3 (two seconds of a brisk walk; a van from rest at 1.5
    /// m/s^2).
    pub standing_reach_m: f64,
    /// The first obstacle of the map on the path coming nearer along the route faster than
    /// this, fitted over a second and a half of plans, is something moving towards the vehicle
    /// that the tracker does not follow (a towed train seen as a mover only in flashes): the
    /// vehicle closes on it no faster than `caution_speed_m_s` together (a third of it at
    /// least) and stops short of where it will be by the time it stands, m/s. Default 0.8. The
    /// fit must also have fallen 1 m from its first half to its second (a static object met on
    /// a replanned path jitters by the path's pose spacing, 0.5 m), which at 10 plans a second
    /// takes about 1.25 m/s: slower closing is not found.
    pub closing_speed_m_s: f64,
    /// A small object the offline map does not hold, seen only standing, no larger than this
    /// ([`mapper::Tracker::standing_objects`]) and hit above the lowest level - a person
    /// waiting beside the path - may walk on before the tracker can predict it: the vehicle
    /// passes within `standing_object_reach_m` of it no faster than `caution_speed_m_s`,
    /// metres. Default 1 (a person's hits are 0.5-0.9 m across). By footprint and levels alone:
    /// a cone is left out under the Praetor-like jet's 1.1 m level but not under the
    /// A320-like airliner's 0.55 m one; the parking lot's 1.1 m container, seen end-on 0.9-1.0 m
    /// across, is slowed for; a one-level vehicle never slows for one. 0 turns it off.
    pub standing_object_max_m: f64,
    /// How near a small object seen only standing (`standing_object_max_m`) the vehicle's
    /// circles pass at the caution speed at most, beyond its footprint (half its box, grown by
    /// `hidden_m`) and `margin_m`, on a level it occupies, metres. Default 6 (for a person, 8 m
    /// from the centre of their hits beyond a circle's radius).
    pub standing_object_reach_m: f64,
}

impl Default for TrafficConfig {
    fn default() -> Self {
        TrafficConfig {
            enabled: true,
            horizon_s: 8.0,
            time_margin_s: 1.5,
            resume_margin_s: 1.0,
            conflict_memory_s: 2.0,
            committed_margin_s: 0.5,
            sigmas: 2.0,
            margin_m: 0.5,
            hidden_m: 1.0,
            min_speed_m_s: 0.8,
            at_body_m: 1.0,
            caution_speed_m_s: 3.0,
            standing_reach_m: 3.0,
            closing_speed_m_s: 0.8,
            standing_object_max_m: 1.0,
            standing_object_reach_m: 6.0,
        }
    }
}

impl TrafficConfig {
    /// The first field out of range, as (name, value).
    pub fn invalid_field(&self) -> Option<(&'static str, f64)> {
        let positive = [("horizon_s", self.horizon_s)];
        let non_negative = [
            ("time_margin_s", self.time_margin_s),
            ("resume_margin_s", self.resume_margin_s),
            ("conflict_memory_s", self.conflict_memory_s),
            ("committed_margin_s", self.committed_margin_s),
            ("sigmas", self.sigmas),
            ("margin_m", self.margin_m),
            ("hidden_m", self.hidden_m),
            ("min_speed_m_s", self.min_speed_m_s),
            ("at_body_m", self.at_body_m),
            ("caution_speed_m_s", self.caution_speed_m_s),
            ("standing_reach_m", self.standing_reach_m),
            ("closing_speed_m_s", self.closing_speed_m_s),
            ("standing_object_max_m", self.standing_object_max_m),
            ("standing_object_reach_m", self.standing_object_reach_m),
        ];
        positive
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v > 0.0))
            .or_else(|| {
                non_negative
                    .into_iter()
                    .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
            })
    }
}

/// How the vehicle is expected to move along its path: from `speed_m_s` now towards
/// `target_m_s` at `acceleration_m_s2` (a profile that only speeds up or holds: a slower
/// vehicle arrives later, which the check sees as it slows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedProfile {
    /// Speed now, m/s.
    pub speed_m_s: f64,
    /// Speed it drives up to, m/s.
    pub target_m_s: f64,
    /// Acceleration, m/s^2.
    pub acceleration_m_s2: f64,
}

impl SpeedProfile {
    /// Seconds to cover `s_m` metres (infinite if it never gets there).
    pub fn time_to(&self, s_m: f64) -> f64 {
        let (v0, a) = (self.speed_m_s.max(0.0), self.acceleration_m_s2.max(1e-6));
        let v1 = self.target_m_s.max(v0);
        if v1 <= 1e-9 {
            return if s_m <= 0.0 { 0.0 } else { f64::INFINITY };
        }
        let ramp_m = (v1 * v1 - v0 * v0) / (2.0 * a);
        if s_m <= ramp_m {
            // s = v0 t + a t^2 / 2.
            (-v0 + (v0 * v0 + 2.0 * a * s_m).sqrt()) / a
        } else {
            (v1 - v0) / a + (s_m - ramp_m) / v1
        }
    }
}

/// A mover's predicted footprint at one time: a capsule along its motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PredictedDisc {
    /// Seconds from now.
    pub dt_s: f64,
    /// Centre, metres.
    pub center: Point2<f64>,
    /// Radius across its motion (half width, hidden part and uncertainty), metres.
    pub radius_m: f64,
    /// Half the length of the capsule's axis, along its motion, metres.
    pub half_length_m: f64,
    /// Heading of its motion, radians.
    pub heading_rad: f64,
}

/// A mover the stack predicts: its track and its discs over the horizon.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The track.
    pub track: TrackState,
    /// Its discs every half second over the horizon, from now.
    pub discs: Vec<PredictedDisc>,
}

/// What the space-time check found on the path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conflict {
    /// The mover's track id.
    pub track_id: u32,
    /// Distance along the path to the first pose where the vehicle would meet the mover, metres.
    pub at_m: f64,
    /// Distance along the path to the first pose any predicted position of the mover touches
    /// (the conflict zone's start), metres; at most `at_m`.
    pub zone_m: f64,
    /// When the vehicle would be at the conflict, seconds from now.
    pub in_s: f64,
    /// Where the mover would be then, metres.
    pub mover_at: Point2<f64>,
}

/// The vehicle's path with its timing: what the space-time check checks.
#[derive(Clone, Copy, Debug)]
pub struct TimedPath<'a> {
    /// The poses, `step_m` apart, the first where the vehicle is now.
    pub poses: &'a [Isometry2<f64>],
    /// Their spacing, metres.
    pub step_m: f64,
    /// How the vehicle is expected to move along them.
    pub profile: SpeedProfile,
    /// Now, seconds.
    pub now_s: f64,
    /// The vehicle is already stopped for a mover.
    pub yielding: bool,
}
