//! What the driver says it is doing about obstacles ([`DriverStatus`]), and when it calls for
//! a pilot ([`PilotCall`]).

use nalgebra::Point2;

use super::Driver;
use crate::online_map::OnlineMap;
use crate::planner::{AutonomyConfig, Plan};
use crate::traffic::{BodyHold, LostMover};

/// What the driver is doing about obstacles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DriverStatus {
    /// Driving (perhaps slowing) with no obstacle stopping it.
    Driving,
    /// Stopped for an obstacle the sensor hit within `hidden_after_s`: it resumes when the
    /// obstacle is seen gone.
    StoppedFor {
        /// The obstacle cell nearest the vehicle's first colliding pose, metres.
        obstacle: Point2<f64>,
        /// When a revolution last hit the obstacle, seconds.
        last_seen_s: f64,
    },
    /// Stopped for an obstacle no revolution has hit for longer than `hidden_after_s` (hidden by
    /// the airframe, or only in the offline map): the sensor cannot see it go, so it will wait
    /// for ever; after `pilot_call_after_s` the run calls for a pilot.
    WaitingForHiddenObstacle {
        /// As in `StoppedFor`.
        obstacle: Point2<f64>,
        /// When a revolution last hit it (`None`: never since the window held it).
        last_seen_s: Option<f64>,
        /// When the wait began, seconds.
        since_s: f64,
        /// A mover none sees that is believed at the body, and why (`None`: the map's cells).
        mover: Option<LostMover>,
    },
    /// Not moved off yet: part of the ground its first plan sweeps is ground its sensors cannot
    /// see from where it stands, and no walk-around has confirmed it (the start-up rule,
    /// [`Driver::await_walk_around`]); after `pilot_call_after_s` the run calls for a pilot.
    WaitingForWalkAround {
        /// That unseen ground, square metres.
        unseen_m2: f64,
        /// When the wait began, seconds.
        since_s: f64,
    },
    /// Stopped short of where a mover is predicted to cross its path: it drives on once the
    /// mover is predicted clear.
    Yielding {
        /// The mover's track id.
        track_id: u32,
        /// Where the mover is predicted to be when the vehicle would meet it, metres.
        mover_at: Point2<f64>,
    },
    /// The airframe felt a strike ([`Driver::on_strike`]): it stands, and once it stands the run
    /// calls for a pilot to inspect it - whatever struck it, it does not move on its own again.
    Struck {
        /// When it felt the strike, seconds.
        at_s: f64,
    },
}

/// Why the driver calls for a pilot (the thesis' pilot intervention).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PilotCall {
    /// It stopped for an obstacle the sensor can no longer see, and cannot see it go.
    HiddenObstacle,
    /// It has stood for obstacles in its path for `blocked_call_after_s`: the way is blocked.
    Blocked,
    /// It has waited at the start for a walk-around of ground its sensors cannot see.
    WalkAround,
    /// It felt a strike and stands: the airframe must be inspected before it moves again.
    Struck,
}

impl Driver {
    /// Why the vehicle is stopped by the chosen candidate's first colliding pose: the obstacle
    /// cells within each circle's radius plus the avoider's margin there (as `config`, the plan's,
    /// widened for the estimate's uncertainty, has it; a metre more if none is), and when a
    /// revolution last hit any of them.
    pub(super) fn stopped_status(
        &self,
        p: &Plan,
        map: &OnlineMap,
        now_s: f64,
        config: &AutonomyConfig,
    ) -> DriverStatus {
        let c = p.chosen();
        let Some(at_m) = c.collision_at_m else {
            return DriverStatus::Driving;
        };
        let k = ((at_m / self.config.step_m).round() as usize).min(c.poses.len().saturating_sub(1));
        let Some(pose) = c.poses.get(k) else {
            return DriverStatus::Driving;
        };
        let m = map.map();
        let margin = f64::from(config.avoider_safety_m) + m.config().resolution_m;
        let (mut nearest, mut last_seen): (Option<(f64, Point2<f64>)>, Option<f64>) = (None, None);
        for extra in [0.0, 1.0] {
            for circle in self.vehicle.collision.circles() {
                let center = pose * Point2::new(circle.x_m, circle.y_m);
                let r = circle.radius_m + margin + extra;
                for cell in m.obstacles_within(circle.level, &center, r) {
                    let at = m.world_cell_center(cell);
                    let d = (at - center).norm();
                    if nearest.is_none_or(|(best, _)| d < best) {
                        nearest = Some((d, at));
                    }
                    if let Some(t) = map.last_hit_s(cell) {
                        last_seen = Some(last_seen.map_or(t, |s: f64| s.max(t)));
                    }
                }
            }
            if nearest.is_some() {
                break;
            }
        }
        let Some((_, obstacle)) = nearest else {
            return DriverStatus::Driving;
        };
        match last_seen {
            Some(t) if now_s - t <= self.config.hidden_after_s => DriverStatus::StoppedFor {
                obstacle,
                last_seen_s: t,
            },
            _ => DriverStatus::WaitingForHiddenObstacle {
                obstacle,
                last_seen_s: last_seen,
                since_s: match self.status {
                    DriverStatus::WaitingForHiddenObstacle { since_s, .. } => since_s,
                    _ => now_s,
                },
                mover: None,
            },
        }
    }

    /// What the driver is doing about obstacles (as of the last plan).
    pub fn status(&self) -> DriverStatus {
        self.status
    }

    /// Whether the driver calls for a pilot at `now_s`, and why: it felt a strike and stands, it
    /// has waited for a hidden obstacle or a walk-around longer than `pilot_call_after_s`, or
    /// stood for obstacles longer than `blocked_call_after_s`. Once struck, only the strike
    /// calls - when the vehicle stands - whatever it waited or stood for before.
    pub fn calls_for_pilot(&self, now_s: f64) -> Option<PilotCall> {
        if self.struck_at_s.is_some() {
            return self.standing().then_some(PilotCall::Struck);
        }
        if matches!(self.status, DriverStatus::WaitingForWalkAround { since_s, .. }
            if now_s - since_s >= self.config.pilot_call_after_s)
        {
            return Some(PilotCall::WalkAround);
        }
        if matches!(self.status, DriverStatus::WaitingForHiddenObstacle { since_s, .. }
            if now_s - since_s >= self.config.pilot_call_after_s)
        {
            return Some(PilotCall::HiddenObstacle);
        }
        self.stopped_since_s
            .filter(|since| now_s - since >= self.config.blocked_call_after_s)
            .map(|_| PilotCall::Blocked)
    }

    /// The status of a vehicle held at its body for a mover at `now_s`: stopped for one seen
    /// lately; waiting for one lost there, as for a hidden obstacle (since it began waiting).
    pub(super) fn body_status(&self, hold: BodyHold, now_s: f64) -> DriverStatus {
        match hold {
            BodyHold::Seen { at, last_seen_s } => DriverStatus::StoppedFor {
                obstacle: at,
                last_seen_s,
            },
            BodyHold::Lost {
                at,
                last_seen_s,
                why,
            } => DriverStatus::WaitingForHiddenObstacle {
                obstacle: at,
                last_seen_s: Some(last_seen_s),
                since_s: match self.status {
                    DriverStatus::WaitingForHiddenObstacle { since_s, .. } => since_s,
                    _ => now_s,
                },
                mover: Some(why),
            },
        }
    }
}
