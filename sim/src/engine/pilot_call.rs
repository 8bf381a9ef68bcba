//! Why a pilot was called, as data: what held the vehicle in the seconds before the call, as the
//! stack believed it (an obstacle it saw, one it lost from view, a mover it yielded to, ground it
//! never saw), and - from ground truth, for the judge only - whether anything was really there.
//! A call is **needless** when no object stood near any point that held the vehicle in the last
//! [`NEEDLESS_WINDOW_S`] seconds, and - when it waited for a mover it believed at its body -
//! none that struck the vehicle stands against it, nor - one it lost there - does any mover
//! stand within [`AT_BODY_WITHIN_M`] of its parts.

use std::collections::VecDeque;

use autonomy::traffic::LostMover;
use autonomy::{DriverStatus, PilotCall};
use nalgebra::Point2;
use serde::Serialize;

use crate::world::World;

/// How far back before a call the points that held the vehicle are judged, seconds.
pub const NEEDLESS_WINDOW_S: f64 = 3.0;

/// How near a point that held the vehicle an object must be for the hold to count as real,
/// metres: a map cell (0.2 m), the estimate's error and a mover's prediction error.
pub const REAL_WITHIN_M: f64 = 1.0;

/// Waiting for a mover it believes at its body, the vehicle is right when a mover stands this
/// near any of its parts, metres, wherever the stack last saw one: what the shipped stack takes
/// for at the body (a box within `hidden_m` plus `at_body_m`, 1 m each, of a circle). A train
/// that stopped 1.7 m from the nose, its tug last seen 3.4 m from where it stands (variant 210
/// of `traffic_jet_speed_profiles.toml`), a van stopped 0.3 m under the wing 8.8 m from where it
/// was lost (variant 189), are there.
pub const AT_BODY_WITHIN_M: f64 = 2.0;

/// What held the vehicle, as the stack believed it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Hold {
    /// An obstacle the sensor hit lately, in the path.
    Obstacle {
        /// When a revolution last hit it, seconds.
        last_seen_s: f64,
    },
    /// An obstacle in the path no revolution has hit for a while (hidden by the airframe, or
    /// only in the offline map).
    LostObstacle {
        /// When a revolution last hit it, if ever, seconds.
        last_seen_s: Option<f64>,
        /// A mover believed at the body though none is seen there, and why (`None`: map cells).
        mover: Option<LostMover>,
    },
    /// A mover predicted to cross the path, yielded to.
    Mover {
        /// Its track id.
        track_id: u32,
    },
    /// Ground the first plan sweeps that no sensor has seen (the start-up rule).
    UnseenGround {
        /// Its area, square metres.
        unseen_m2: f64,
    },
    /// A strike the airframe felt ([`autonomy::Driver::on_strike`]).
    Struck {
        /// When, seconds.
        at_s: f64,
    },
}

impl Hold {
    /// What held the vehicle at `status`, and where; `None` when it was driving.
    pub fn of(status: DriverStatus) -> Option<(Hold, Option<Point2<f64>>)> {
        match status {
            DriverStatus::Driving => None,
            DriverStatus::StoppedFor {
                obstacle,
                last_seen_s,
            } => Some((Hold::Obstacle { last_seen_s }, Some(obstacle))),
            DriverStatus::WaitingForHiddenObstacle {
                obstacle,
                last_seen_s,
                mover,
                ..
            } => Some((Hold::LostObstacle { last_seen_s, mover }, Some(obstacle))),
            DriverStatus::Yielding { track_id, mover_at } => {
                Some((Hold::Mover { track_id }, Some(mover_at)))
            }
            DriverStatus::WaitingForWalkAround { unseen_m2, .. } => {
                Some((Hold::UnseenGround { unseen_m2 }, None))
            }
            DriverStatus::Struck { at_s } => Some((Hold::Struck { at_s }, None)),
        }
    }

    /// A short name for tables: `obstacle`, `lost_obstacle` (map cells), `mover_lost_at_body`,
    /// `mover_lost_coasting`, `mover_lost_standing`, `mover`, `unseen_ground`, `struck`.
    pub fn name(&self) -> &'static str {
        match self {
            Hold::Obstacle { .. } => "obstacle",
            Hold::LostObstacle { mover, .. } => match mover {
                None => "lost_obstacle",
                Some(LostMover::AtBody) => "mover_lost_at_body",
                Some(LostMover::Coasting) => "mover_lost_coasting",
                Some(LostMover::Standing) => "mover_lost_standing",
            },
            Hold::Mover { .. } => "mover",
            Hold::UnseenGround { .. } => "unseen_ground",
            Hold::Struck { .. } => "struck",
        }
    }
}

/// A pilot call, with why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PilotCallReport {
    /// When, seconds.
    pub t_s: f64,
    /// Which rule called: `hidden_obstacle`, `blocked`, `walk_around` or `struck`.
    pub call: &'static str,
    /// What held the vehicle last before the call, as the stack believed it (`None`: it was not
    /// held by anything it could name - blocked while driving slowly).
    pub hold: Option<Hold>,
    /// Where that was, metres.
    pub at_m: Option<[f64; 2]>,
    /// Ground truth, for the judge: the object nearest any point that held the vehicle in the
    /// last [`NEEDLESS_WINDOW_S`] s (for unseen ground: any cell of it), or - waiting for a
    /// mover believed at the body - to the vehicle's parts of one that struck it (or, one lost
    /// there, of any mover), and how far, metres: of those, the one nearest within what counts
    /// for it ([`REAL_WITHIN_M`]; a mover at the body, [`AT_BODY_WITHIN_M`]). For a strike's
    /// call: what struck the airframe, and how far it is now.
    pub nearest_object: Option<(String, f64)>,
    /// Nothing stood within what counts of any of them: the call was needless.
    pub needless: bool,
}

/// The points that held the vehicle, step by step, for the last few seconds.
#[derive(Default)]
pub(super) struct HoldLog {
    held: VecDeque<(f64, Hold, Option<Point2<f64>>)>,
}

impl HoldLog {
    /// Notes the driver's status at `t_s`, forgetting what is older than the window.
    pub(super) fn note(&mut self, t_s: f64, status: DriverStatus) {
        if let Some((hold, at)) = Hold::of(status) {
            self.held.push_back((t_s, hold, at));
        }
        while self
            .held
            .front()
            .is_some_and(|(t, ..)| *t < t_s - NEEDLESS_WINDOW_S)
        {
            self.held.pop_front();
        }
    }

    /// The call at `t_s`, judged against `world` (`unseen`: the start-up rule's unseen cells;
    /// `movers`: the world's objects that move).
    pub(super) fn report(
        &self,
        t_s: f64,
        call: PilotCall,
        world: &World,
        unseen: Option<&[Point2<f64>]>,
        movers: &[usize],
    ) -> PilotCallReport {
        let last = self.held.back();
        if matches!(call, PilotCall::Struck) {
            return struck_report(t_s, last.map(|(_, h, _)| *h), world);
        }
        let mut points: Vec<Point2<f64>> = self.held.iter().filter_map(|(_, _, p)| *p).collect();
        if matches!(call, PilotCall::WalkAround) {
            points.extend(unseen.unwrap_or_default());
        }
        // Waiting for a mover it believes at its body: one that struck the vehicle and stands
        // against it is that mover, wherever the stack last saw it (a person who walked on into
        // the nose out of view).
        let for_a_mover = matches!(
            last,
            Some((_, Hold::LostObstacle { mover: Some(_), .. }, _))
        );
        // ... as is - waiting for one held at its body and lost there - any mover at its body.
        let lost_at_body = matches!(
            last,
            Some((
                _,
                Hold::LostObstacle {
                    mover: Some(LostMover::AtBody),
                    ..
                },
                _
            ))
        );
        let struck = |id: &str| world.contacts().iter().any(|c| c.object == id);
        let at_body = (world.scene().solids.iter().enumerate())
            .filter(|(i, s)| (for_a_mover && struck(&s.id)) || (lost_at_body && movers.contains(i)))
            .filter_map(|(i, _)| {
                let d = world.distances_to(i).into_iter().reduce(f64::min)?;
                let mover_at_body = lost_at_body && movers.contains(&i);
                let within = if mover_at_body {
                    AT_BODY_WITHIN_M
                } else {
                    REAL_WITHIN_M
                };
                Some((i, d, within))
            });
        let nearest = (points.iter())
            .filter_map(|p| world.nearest_object_to(p))
            .map(|(i, d)| (i, d, REAL_WITHIN_M))
            .chain(at_body)
            .min_by(|a, b| (a.1 - a.2).total_cmp(&(b.1 - b.2)));
        PilotCallReport {
            t_s,
            call: call_name(call),
            hold: last.map(|(_, h, _)| *h),
            at_m: last.and_then(|(_, _, p)| p.map(|p| [p.x, p.y])),
            needless: nearest.is_none_or(|(_, d, within)| d > within),
            nearest_object: nearest.map(|(i, d, _)| (world.scene().solids[i].id.clone(), d)),
        }
    }
}

/// The call's name in reports.
fn call_name(call: PilotCall) -> &'static str {
    match call {
        PilotCall::HiddenObstacle => "hidden_obstacle",
        PilotCall::Blocked => "blocked",
        PilotCall::WalkAround => "walk_around",
        PilotCall::Struck => "struck",
    }
}

/// A strike's call: what struck the airframe first (ground truth, the contact the sensor felt)
/// and how far it is now. Never needless: the sensor feels only real contacts.
fn struck_report(t_s: f64, hold: Option<Hold>, world: &World) -> PilotCallReport {
    let felt = (world.contacts().iter()).find(|c| c.kind.felt_on_contact());
    let nearest = felt.and_then(|c| {
        let i = (world.scene().solids.iter()).position(|s| s.id == c.object)?;
        let d = world.distances_to(i).into_iter().reduce(f64::min)?;
        Some((c.object.clone(), d))
    });
    PilotCallReport {
        t_s,
        call: "struck",
        hold,
        at_m: None,
        needless: false,
        nearest_object: nearest,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use nalgebra::{Isometry2, Vector2};

    const SCENE: &str = r#"
name = "a call held by a strike"
seed = 1
[world]
min_m = [-20.0, -20.0]
max_m = [40.0, 20.0]
[vehicle]
description = "iara_car"
[route]
waypoints_m = [[0.0, 0.0], [30.0, 0.0]]
speed_m_s = 1.0
[[obstacles]]
id = "box"
kind = "box"
x_m = 10.0
y_m = 0.0
size_m = [0.5, 0.5, 0.5]
expect = "stop"
"#;

    /// The call made at 20 s after the holds `held`, with the car's front in the box (`touching`)
    /// or 4 m short of it.
    fn call_after(held: &[DriverStatus], call: PilotCall, touching: bool) -> PilotCallReport {
        let s = Scenario::from_str(SCENE, std::path::Path::new("held.toml")).unwrap();
        let vehicle = &s.vehicle.vehicle;
        let mut world = World::with_obstacles(&s.full_scene(), vehicle, &Isometry2::identity());
        // The car's front is about 3.5 m ahead of its origin; the box's near face at 9.75 m.
        let x = if touching { 6.4 } else { 2.0 };
        world.set_vehicle_pose(&Isometry2::new(Vector2::new(x, 0.0), 0.0), 19.0);
        let mut log = HoldLog::default();
        for (k, status) in held.iter().enumerate() {
            log.note(19.0 + 0.1 * k as f64, *status);
        }
        log.report(20.0, call, &world, None, &[])
    }

    #[test]
    fn a_strikes_call_names_what_struck_and_is_never_needless() {
        let struck = DriverStatus::Struck { at_s: 19.0 };
        let call = call_after(&[struck], PilotCall::Struck, true);
        assert_eq!(call.call, "struck");
        assert!(!call.needless, "{call:?}");
        assert!(matches!(call.hold, Some(Hold::Struck { .. })), "{call:?}");
        let (object, d) = call.nearest_object.clone().expect("what struck it");
        assert_eq!(object, "box");
        assert!(d <= 0.0, "it still touches: {call:?}");
    }

    #[test]
    fn a_call_held_by_a_point_where_nothing_stands_is_needless() {
        // The same car, held by a point 5 m to its side where nothing stands, 4 m short of the
        // box: needless; held by the box's face, not.
        let phantom = DriverStatus::StoppedFor {
            obstacle: Point2::new(5.0, 5.0),
            last_seen_s: 19.0,
        };
        assert!(call_after(&[phantom], PilotCall::Blocked, false).needless);
        let the_box = DriverStatus::StoppedFor {
            obstacle: Point2::new(9.7, 0.0),
            last_seen_s: 19.0,
        };
        assert!(!call_after(&[the_box], PilotCall::Blocked, false).needless);
    }
}
