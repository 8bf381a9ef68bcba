//! The judge: what the run did, by ground truth, out of the loop. Progress along the route and
//! laps, stops, contacts and who was at fault (the vehicle moving or struck standing), the passes
//! by each run-time obstacle with their outcome and verdict, the clearances, the traffic
//! conflicts with each mover (time to collision, post-encroachment time: `conflict`); it emits
//! the run's events and gives the report's verdicts. It reads the world and the true vehicle
//! state; the stack under test never reads it.
//!
//! A `yield` pass (a mover crossing the route) meets its expectation when nothing touched the
//! mover, the mover crossed the route (its path's point nearest the route) before the vehicle's
//! front reached that point and, where their swept footprints overlap, the mover left the
//! conflict area before the vehicle entered it (PET > 0, mover first), and the vehicle drove on:
//! the pass closed with the vehicle 10 m past the point, or the run ended by time (`timed_out`).
//!
//! A contact is judged when it begins, and again, once, if the vehicle moves while it lasts (a
//! mover that struck the standing vehicle and halted against it, then driven into: at fault).
//! One that begins while the vehicle moves is at fault unless the object, where it touched,
//! overlaps the touching part placed where the vehicle was half a second before
//! (`HELD_ROOM_S`) at least as deeply: then the object came into room the vehicle held - a van
//! into the tail of a jet moving off at 0.3 m/s - and the contact is struck while moving, asked
//! again each step while the vehicle moves (`contacts`).
//!
//! `[expectations] no_contact_at_fault = true`: a contact while the vehicle moved fails the run
//! whatever the obstacles expect; a contact while it stood (struck) counts against neither the
//! run nor a pass (a `yield` pass still needs no contact at all), and the danger distance is
//! then checked only at the steps the vehicle moved.
//!
//! The files, by job: the passes by each obstacle and their verdicts (`passes`), the movers'
//! traffic conflicts and the run's samples for the post-encroachment times (`traffic`), the
//! `yield` rule (`yielding`), the contacts and who was at fault (`contacts`); the [`Judge`]
//! itself here, with progress, laps, stops, clearances and the run's [`Verdict`].

mod contacts;
mod passes;
mod traffic;
mod yielding;

#[cfg(test)]
mod tests;

use autonomy::RoutePath;
use std::collections::VecDeque;

use nalgebra::{Isometry2, Point2};

use super::outcome::{EndReason, Event, JudgedContact, ObstacleReport, Stop};
use crate::scenario::{ExpectedEnd, Scenario};
use crate::world::VehicleState;
use crate::world::{Contact, World};
use passes::{PassWindow, closest_on_route};
use traffic::{Mover, Samples, movers};

/// Half length of the stretch of route searched around the last progress, metres.
const PROGRESS_WINDOW_M: f64 = 30.0;
/// A pass with a lateral offset above this deviated; the planner's offset above it is a deviation.
pub const DEVIATION_M: f64 = 0.5;

/// What the judge found of a step.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepVerdict {
    /// A lap ended at this step.
    pub lap_ended: bool,
    /// Fraction of the whole run done, 0..1.
    pub fraction: f64,
}

/// The judge of one run.
pub struct Judge {
    route: RoutePath,
    laps: u32,
    part_levels: Vec<usize>,
    danger_distance_m: Option<f64>,
    windows: Vec<PassWindow>,
    obstacles: Vec<ObstacleReport>,
    stops: Vec<Stop>,
    /// Whether the vehicle has moved yet: held at the start (the localizer settling, mapping
    /// not begun) is not a stop.
    started: bool,
    lap_times_s: Vec<f64>,
    lap_start_t_s: f64,
    min_clearance_m: Vec<f64>,
    clearance_now_m: Vec<f64>,
    /// True progress: arc length now, where the run started, and the distance driven along.
    s_now: f64,
    s_start: f64,
    s_total: f64,
    deviating: bool,
    contacts_seen: usize,
    /// The (object, part) pairs touching now already judged, and how.
    touching: contacts::Touching,
    /// The vehicle's true poses of the last [`super::outcome::HELD_ROOM_S`] (and the latest
    /// older one).
    recent_poses: VecDeque<(f64, Isometry2<f64>)>,
    events: Vec<(f64, Event)>,
    /// Every contact judged, in the world's order.
    contacts: Vec<JudgedContact>,
    no_contact_at_fault: bool,
    max_stops: Option<usize>,
    wheelbase_m: f64,
    /// How far the vehicle's parts reach ahead of its reference point, metres.
    front_m: f64,
    speed_now_m_s: f64,
    movers: Vec<Mover>,
    samples: Samples,
}

impl Judge {
    /// A judge of `scenario` driven for `laps` laps along `route`, from `start` (true pose);
    /// `part_levels` is the level of each vehicle part, `first_obstacle` the index of the first
    /// run-time obstacle among the world's solids.
    pub fn new(
        scenario: &Scenario,
        route: &RoutePath,
        laps: u32,
        part_levels: Vec<usize>,
        levels: usize,
        first_obstacle: usize,
        start: Point2<f64>,
    ) -> Self {
        let parts = &scenario.vehicle.vehicle.parts;
        let movers = movers(scenario, first_obstacle);
        let mut next_mover = 0;
        let windows = scenario
            .obstacles
            .iter()
            .enumerate()
            .map(|(k, o)| {
                let at = o
                    .motion
                    .as_ref()
                    .and_then(|m| closest_on_route(route, &m.path_m))
                    .unwrap_or(Point2::new(o.solid.x_m, o.solid.y_m));
                let mover = o.motion.is_some().then(|| {
                    next_mover += 1;
                    next_mover - 1
                });
                PassWindow {
                    solid_index: first_obstacle + k,
                    route_s: route.project(&at, 0.0, f64::INFINITY).0,
                    expect: o.expect,
                    active: false,
                    offset: 0.0,
                    stopped: false,
                    present: false,
                    clearance: vec![f64::INFINITY; levels],
                    clearance_moving: f64::INFINITY,
                    contacts_before: 0,
                    at,
                    since_s: 0.0,
                    front_reached_s: None,
                    mover,
                }
            })
            .collect();
        let obstacles = scenario
            .obstacles
            .iter()
            .map(|o| ObstacleReport {
                id: o.solid.id.clone(),
                kind: o.solid.kind.name().to_string(),
                expected: o.expect,
                passes: Vec::new(),
                min_ttc_s: None,
                pet_s: None,
                pet_mover_first: None,
            })
            .collect();
        let s_start = route.project(&start, 0.0, f64::INFINITY).0;
        Judge {
            route: route.clone(),
            laps,
            part_levels,
            danger_distance_m: scenario.danger_distance_m,
            windows,
            obstacles,
            stops: Vec::new(),
            started: false,
            lap_times_s: Vec::new(),
            lap_start_t_s: 0.0,
            min_clearance_m: vec![f64::INFINITY; levels],
            clearance_now_m: vec![f64::INFINITY; levels],
            s_now: s_start,
            s_start,
            s_total: 0.0,
            deviating: false,
            contacts_seen: 0,
            touching: contacts::Touching::default(),
            recent_poses: VecDeque::new(),
            events: Vec::new(),
            contacts: Vec::new(),
            no_contact_at_fault: scenario.no_contact_at_fault,
            max_stops: scenario.max_stops,
            wheelbase_m: scenario.vehicle.vehicle.spec.motion.wheelbase_m,
            front_m: parts
                .iter()
                .map(|p| p.footprint().bounds().1.x)
                .fold(0.0, f64::max),
            speed_now_m_s: 0.0,
            movers,
            samples: Samples::default(),
        }
    }

    /// The planner chose a path at `offset_m` from the route: a deviation starts or ends.
    pub fn on_plan(&mut self, t_s: f64, offset_m: f64) {
        if (offset_m.abs() > DEVIATION_M) != self.deviating {
            self.deviating = !self.deviating;
            let event = if self.deviating {
                Event::Deviate { offset_m }
            } else {
                Event::BackOnRoute
            };
            self.events.push((t_s, event));
        }
    }

    /// Judges the world after a physics step: progress, stops, contacts, passes, clearances and
    /// laps. `speed_command_m_s` is what the stack asked for (a stop is the vehicle standing
    /// with a zero command).
    pub fn after_step(
        &mut self,
        t_s: f64,
        state: &VehicleState,
        speed_command_m_s: f64,
        world: &World,
    ) -> StepVerdict {
        let length = self.route.length_m();
        let (s_now, d_now) = self.route.project(
            &Point2::new(state.x_m, state.y_m),
            self.s_now,
            PROGRESS_WINDOW_M,
        );
        let mut ds = s_now - self.s_now;
        if self.route.closed() {
            ds = (ds + length / 2.0).rem_euclid(length) - length / 2.0;
        }
        self.s_total += ds;
        self.s_now = s_now;
        let stopped = state.speed_m_s.abs() < 0.05 && speed_command_m_s == 0.0;
        self.judge_stops(t_s, state, stopped);
        self.speed_now_m_s = state.speed_m_s;
        let pose = state.world_from_vehicle();
        self.remember_pose(t_s, pose);
        self.judge_contacts(t_s, &pose, state.speed_m_s, world);
        self.watch_traffic(t_s, state, world);
        self.judge_passes(t_s, d_now, stopped, world);
        self.clearance_now_m.fill(f64::INFINITY);
        for (d, level) in world.part_clearances_m().iter().zip(&self.part_levels) {
            self.clearance_now_m[*level] = self.clearance_now_m[*level].min(*d);
        }
        for (m, d) in self.min_clearance_m.iter_mut().zip(&self.clearance_now_m) {
            *m = m.min(*d);
        }
        let done = self.lap_times_s.len() as u32;
        let lap_ended = if self.route.closed() {
            self.s_total >= length * (done + 1) as f64
        } else {
            s_now >= length - 0.5
        };
        if lap_ended {
            self.lap_times_s.push(t_s - self.lap_start_t_s);
            self.events.push((
                t_s,
                Event::Lap {
                    lap: done + 1,
                    time_s: t_s - self.lap_start_t_s,
                },
            ));
            self.lap_start_t_s = t_s;
        }
        let total_m = length * self.laps as f64;
        let fraction = if self.route.closed() {
            self.s_total / total_m
        } else {
            (self.lap_times_s.len() as f64 * length + s_now) / total_m
        };
        StepVerdict {
            lap_ended,
            fraction: fraction.clamp(0.0, 1.0),
        }
    }

    fn judge_stops(&mut self, t_s: f64, state: &VehicleState, stopped: bool) {
        let moving = state.speed_m_s.abs() > 0.3;
        self.started |= moving;
        match self.stops.last_mut() {
            Some(last) if last.end_s.is_none() && moving => {
                last.end_s = Some(t_s);
                let stopped_s = t_s - last.start_s;
                self.events.push((t_s, Event::Resume { stopped_s }));
            }
            Some(last) if last.end_s.is_none() => {}
            _ if stopped && self.started => {
                self.stops.push(Stop {
                    start_s: t_s,
                    end_s: None,
                    route_s_m: self.s_now,
                });
                let route_s_m = self.s_now;
                self.events.push((t_s, Event::Stop { route_s_m }));
            }
            _ => {}
        }
    }

    /// Drains the events since the last call, each with its time.
    pub fn drain_events(&mut self) -> std::vec::Drain<'_, (f64, Event)> {
        self.events.drain(..)
    }

    /// The vehicle was put back at the start of an open route for its next lap.
    pub fn restart_lap(&mut self) {
        self.s_now = self.s_start;
        self.s_total = 0.0;
        self.samples.jumped = true;
        self.forget_poses();
    }

    /// Smallest ground-truth clearance per level to any object near the vehicle now, metres.
    pub fn clearance_now_m(&self) -> &[f64] {
        &self.clearance_now_m
    }

    /// Laps completed.
    pub fn laps_completed(&self) -> u32 {
        self.lap_times_s.len() as u32
    }

    /// Whether every lap asked for is done.
    pub fn done(&self) -> bool {
        self.laps_completed() >= self.laps
    }

    /// The verdicts: the run ended as `expected` (every lap driven, or waiting for a hidden
    /// obstacle), every obstacle passed as expected on every pass, no contact (with
    /// `no_contact_at_fault`: none while the vehicle moved), no more stops than `max_stops`;
    /// each mover's traffic conflicts.
    pub fn verdict(
        mut self,
        end: EndReason,
        expected: ExpectedEnd,
        contacts: &[Contact],
    ) -> Verdict {
        // Contacts the last step did not judge (none, as the loop runs): judged at the last speed.
        for c in contacts.iter().skip(self.contacts.len()) {
            self.contacts
                .push(JudgedContact::new(c.clone(), self.speed_now_m_s));
        }
        self.traffic_figures();
        // A campaign's `end = "any"` accepts an obstacle never passed (one that appeared after
        // the vehicle went by, or that it waited for until the end).
        let unpassed_ok = expected == ExpectedEnd::Any;
        let every_pass_met = self
            .obstacles
            .iter()
            .all(|r| (unpassed_ok || !r.passes.is_empty()) && r.passes.iter().all(|p| p.met));
        let ended_as_expected = match expected {
            ExpectedEnd::Completed => {
                end == EndReason::Completed && self.laps_completed() == self.laps
            }
            ExpectedEnd::WaitingForHiddenObstacle => end == EndReason::WaitingForHiddenObstacle,
            ExpectedEnd::WaitingForWalkAround => end == EndReason::WaitingForWalkAround,
            ExpectedEnd::Struck => end == EndReason::Struck,
            ExpectedEnd::Any => end != EndReason::Interrupted,
            ExpectedEnd::StoppedForGood => {
                matches!(
                    end,
                    EndReason::TimedOut
                        | EndReason::WaitingForHiddenObstacle
                        | EndReason::Blocked
                        | EndReason::Struck
                ) && (self.stops.last().is_some_and(|s| s.end_s.is_none()) || !self.started)
            }
        };
        let contacts_at_fault = self.contacts.iter().filter(|c| c.at_fault).count();
        let contact_ok = if self.no_contact_at_fault {
            contacts_at_fault == 0
        } else {
            contacts.is_empty()
        };
        let stops_ok = self.max_stops.is_none_or(|m| self.stops.len() <= m);
        Verdict {
            expectations_met: ended_as_expected && every_pass_met && contact_ok && stops_ok,
            laps_completed: self.laps_completed(),
            lap_times_s: self.lap_times_s,
            obstacles: self.obstacles,
            stops: self.stops,
            min_clearance_m: self.min_clearance_m,
            contacts_at_fault,
            contacts_struck: self.contacts.len() - contacts_at_fault,
            contacts_struck_while_moving: self
                .contacts
                .iter()
                .filter(|c| c.struck_while_moving)
                .count(),
            contacts: self.contacts,
        }
    }
}

/// The judge's findings at the end of a run.
pub struct Verdict {
    /// Every expectation held and every lap was completed.
    pub expectations_met: bool,
    /// Laps completed.
    pub laps_completed: u32,
    /// Lap times, seconds.
    pub lap_times_s: Vec<f64>,
    /// Per run-time obstacle.
    pub obstacles: Vec<ObstacleReport>,
    /// Stops.
    pub stops: Vec<Stop>,
    /// Smallest ground-truth clearance per level to any object, metres.
    pub min_clearance_m: Vec<f64>,
    /// Every contact with who was at fault, in the world's order.
    pub contacts: Vec<JudgedContact>,
    /// Contacts at fault: begun while the vehicle moved into them, or driven into while they
    /// lasted.
    pub contacts_at_fault: usize,
    /// The others: struck by a mover while the vehicle stood, or while it moved (the mover
    /// came into room it held).
    pub contacts_struck: usize,
    /// Of those, struck while the vehicle moved.
    pub contacts_struck_while_moving: usize,
}
