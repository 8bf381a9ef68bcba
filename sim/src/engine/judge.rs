//! The judge: what the run did, by ground truth, out of the loop. Progress along the route and
//! laps, stops, contacts, the passes by each run-time obstacle with their outcome and verdict,
//! the clearances; it emits the run's events and gives the report's verdicts. It reads the world
//! and the true vehicle state; the stack under test never reads it.

use autonomy::RoutePath;
use nalgebra::Point2;

use super::outcome::{EndReason, Event, ObstacleReport, Pass, PassOutcome, Stop};
use crate::scenario::{Expectation, ExpectedEnd, Scenario};
use crate::world::VehicleState;
use crate::world::{Contact, World};

/// Half length of the stretch of route searched around the last progress, metres.
const PROGRESS_WINDOW_M: f64 = 30.0;
/// A pass is judged over a window from this far before its obstacle along the route...
const PASS_BEFORE_M: f64 = 25.0;
/// ... to this far after it.
const PASS_AFTER_M: f64 = 10.0;
/// A pass with a lateral offset above this deviated; the planner's offset above it is a deviation.
pub const DEVIATION_M: f64 = 0.5;

/// A pass being watched.
struct PassWindow {
    solid_index: usize,
    route_s: f64,
    expect: Expectation,
    active: bool,
    offset: f64,
    stopped: bool,
    /// Whether the obstacle was in the world at some time in the window (one that appears or
    /// disappears may be absent on some laps: no pass then).
    present: bool,
    clearance: Vec<f64>,
    contacts_before: usize,
}

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
    events: Vec<(f64, Event)>,
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
                PassWindow {
                    solid_index: first_obstacle + k,
                    route_s: route.project(&at, 0.0, f64::INFINITY).0,
                    expect: o.expect,
                    active: false,
                    offset: 0.0,
                    stopped: false,
                    present: false,
                    clearance: vec![f64::INFINITY; levels],
                    contacts_before: 0,
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
            lap_times_s: Vec::new(),
            lap_start_t_s: 0.0,
            min_clearance_m: vec![f64::INFINITY; levels],
            clearance_now_m: vec![f64::INFINITY; levels],
            s_now: s_start,
            s_start,
            s_total: 0.0,
            deviating: false,
            contacts_seen: 0,
            events: Vec::new(),
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
        for c in &world.contacts()[self.contacts_seen..] {
            self.events.push((c.time_s, Event::Contact(c.clone())));
        }
        self.contacts_seen = world.contacts().len();
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
        match self.stops.last_mut() {
            Some(last) if last.end_s.is_none() && moving => {
                last.end_s = Some(t_s);
                let stopped_s = t_s - last.start_s;
                self.events.push((t_s, Event::Resume { stopped_s }));
            }
            Some(last) if last.end_s.is_none() => {}
            _ if stopped && t_s > 1.0 => {
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

    /// Obstacle passes: a window from 25 m before to 10 m after each obstacle along the route.
    fn judge_passes(&mut self, t_s: f64, d_now: f64, stopped: bool, world: &World) {
        let length = self.route.length_m();
        let closed = self.route.closed();
        let lap_s =
            (self.s_start + self.s_total).rem_euclid(if closed { length } else { f64::INFINITY });
        let lap = self.lap_times_s.len() as u32 + 1;
        for (k, w) in self.windows.iter_mut().enumerate() {
            let rel = if closed {
                (lap_s - w.route_s + length / 2.0).rem_euclid(length) - length / 2.0
            } else {
                lap_s - w.route_s
            };
            let inside = (-PASS_BEFORE_M..=PASS_AFTER_M).contains(&rel);
            if inside && !w.active {
                w.active = true;
                w.offset = 0.0;
                w.stopped = false;
                w.present = false;
                w.clearance.fill(f64::INFINITY);
                w.contacts_before = world.contacts().len();
            }
            if !w.active {
                continue;
            }
            w.offset = w.offset.max(d_now.abs());
            w.stopped |= stopped && rel < 0.0;
            w.present |= world.object_active(w.solid_index);
            for (part, d) in world.distances_to(w.solid_index).into_iter().enumerate() {
                let level = self.part_levels[part];
                w.clearance[level] = w.clearance[level].min(d);
            }
            if inside {
                continue;
            }
            w.active = false;
            if !w.present {
                // Not in the world during this window (appears later or has gone): no pass.
                continue;
            }
            let report = &mut self.obstacles[k];
            let pass = close_pass(w, lap, &report.id, world, self.danger_distance_m);
            record_pass(report, &mut self.events, t_s, pass);
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

    /// The run ended while the vehicle stood in front of obstacles (timed out, or waiting for a
    /// hidden one): the passes it was in the middle of close as they stand.
    pub fn close_open_passes(&mut self, t_s: f64, world: &World) {
        let lap = self.lap_times_s.len() as u32 + 1;
        for (k, w) in self.windows.iter_mut().enumerate() {
            if !(w.active && w.present) {
                continue;
            }
            w.active = false;
            let report = &mut self.obstacles[k];
            let pass = close_pass(w, lap, &report.id, world, self.danger_distance_m);
            record_pass(report, &mut self.events, t_s, pass);
        }
    }

    /// The verdicts: the run ended as `expected` (every lap driven, or waiting for a hidden
    /// obstacle), every obstacle passed as expected on every pass, no contact.
    pub fn verdict(self, end: EndReason, expected: ExpectedEnd, contacts: &[Contact]) -> Verdict {
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
            ExpectedEnd::Any => end != EndReason::Interrupted,
            ExpectedEnd::StoppedForGood => {
                matches!(
                    end,
                    EndReason::TimedOut | EndReason::WaitingForHiddenObstacle
                ) && self.stops.last().is_some_and(|s| s.end_s.is_none())
            }
        };
        Verdict {
            expectations_met: ended_as_expected && every_pass_met && contacts.is_empty(),
            laps_completed: self.laps_completed(),
            lap_times_s: self.lap_times_s,
            obstacles: self.obstacles,
            stops: self.stops,
            min_clearance_m: self.min_clearance_m,
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
}

/// Adds a closed pass to its obstacle's report, and its event.
fn record_pass(report: &mut ObstacleReport, events: &mut Vec<(f64, Event)>, t_s: f64, pass: Pass) {
    events.push((
        t_s,
        Event::Pass {
            id: report.id.clone(),
            outcome: pass.outcome,
            met: pass.met,
        },
    ));
    report.passes.push(pass);
}

/// The pass a window closes with: its outcome and whether it met the expectation.
fn close_pass(
    w: &PassWindow,
    lap: u32,
    id: &str,
    world: &World,
    danger_distance_m: Option<f64>,
) -> Pass {
    let collided = world.contacts()[w.contacts_before..]
        .iter()
        .any(|c| c.object == id);
    let outcome = if collided {
        PassOutcome::Collided
    } else if w.stopped {
        PassOutcome::Stopped
    } else if w.offset > DEVIATION_M {
        PassOutcome::Deviated
    } else {
        PassOutcome::Passed
    };
    let too_close = danger_distance_m.is_some_and(|danger| w.clearance.iter().any(|d| *d < danger));
    Pass {
        lap,
        outcome,
        min_clearance_m: w.clearance.clone(),
        max_offset_m: w.offset,
        met: !collided && !too_close && outcome.meets(w.expect),
    }
}

/// The point of a path closest to the route (where a crossing vehicle crosses it).
fn closest_on_route(route: &RoutePath, path: &[Point2<f64>]) -> Option<Point2<f64>> {
    let mut best: Option<(f64, Point2<f64>)> = None;
    for w in path.windows(2) {
        for k in 0..=50 {
            let p = w[0] + (w[1] - w[0]) * (k as f64 / 50.0);
            let (_, d) = route.project(&p, 0.0, f64::INFINITY);
            if best.is_none_or(|b| d.abs() < b.0) {
                best = Some((d.abs(), p));
            }
        }
    }
    best.map(|b| b.1)
}
