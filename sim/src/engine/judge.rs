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
//!
//! `[expectations] no_contact_at_fault = true`: a contact while the vehicle moved fails the run
//! whatever the obstacles expect; a contact while it stood (struck) counts against neither the
//! run nor a pass (a `yield` pass still needs no contact at all), and the danger distance is
//! then checked only at the steps the vehicle moved.

use autonomy::RoutePath;
use nalgebra::{Isometry2, Point2, Vector2};

use super::conflict::{self, Body, Encroachment, MoverMotion, Track, VehicleMotion};
use super::outcome::{
    AT_FAULT_SPEED_M_S, EndReason, Event, JudgedContact, ObstacleReport, Pass, PassOutcome, Stop,
};
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
/// The traffic conflicts are judged (and the run sampled for the PET) this often, seconds.
const SAMPLE_S: f64 = 0.1;
/// A mover's time to collision under this starts a conflict (an event), seconds...
const CONFLICT_TTC_S: f64 = 3.0;
/// ... which ends when it rises above this (or the two are no longer on a collision course).
const CONFLICT_CLEAR_S: f64 = 5.0;

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
    /// The smallest clearance at any level at the steps the vehicle moved, metres.
    clearance_moving: f64,
    contacts_before: usize,
    /// The route's point the pass is by (a mover's path's point nearest the route).
    at: Point2<f64>,
    /// When the last pass by it closed (the run's start before the first), seconds.
    since_s: f64,
    /// When the vehicle's front first reached `at` in this window, seconds.
    front_reached_s: Option<f64>,
    /// Its index among the movers, if it moves.
    mover: Option<usize>,
}

/// A run-time obstacle that moves, watched for traffic conflicts.
struct Mover {
    solid_index: usize,
    id: String,
    /// Its footprint.
    body: Body,
    /// The vehicle's parts it can touch (their heights overlap its own).
    vehicle: Body,
    /// Its position at the last step (time, x, y), if present then.
    last: Option<(f64, Point2<f64>)>,
    /// Its velocity, by differencing over the last step, m/s.
    velocity: Vector2<f64>,
    min_ttc_s: Option<f64>,
    /// Whether a TTC under 3 s would start a new conflict.
    armed: bool,
    /// Its pose at each sample (`None`: absent).
    poses: Vec<Option<Isometry2<f64>>>,
}

/// The run sampled every 0.1 s for the post-encroachment times.
#[derive(Default)]
struct Samples {
    t_s: Vec<f64>,
    vehicle: Vec<Isometry2<f64>>,
    /// False where the vehicle was put back at the start of an open route since the last sample.
    joined: Vec<bool>,
    next_t_s: f64,
    jumped: bool,
}

impl Samples {
    /// The samples' index range within `[from_s, to_s]`.
    fn range(&self, from_s: f64, to_s: f64) -> std::ops::Range<usize> {
        let a = self.t_s.partition_point(|t| *t < from_s - 1e-9);
        let b = self.t_s.partition_point(|t| *t <= to_s + 1e-9);
        a..b.max(a)
    }
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
    /// The (object, part) pairs touching now already judged at fault while they touch.
    pushing: Vec<(String, String)>,
    events: Vec<(f64, Event)>,
    /// Every contact judged, in the world's order.
    contacts: Vec<JudgedContact>,
    no_contact_at_fault: bool,
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
            pushing: Vec::new(),
            events: Vec::new(),
            contacts: Vec::new(),
            no_contact_at_fault: scenario.no_contact_at_fault,
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
        self.judge_contacts(state.speed_m_s, world);
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

    /// The contacts begun since the last step and those lasting while the vehicle moves,
    /// judged ([`judge_contacts`]).
    fn judge_contacts(&mut self, speed_m_s: f64, world: &World) {
        let begun = &world.contacts()[self.contacts_seen..];
        self.contacts_seen = world.contacts().len();
        let judged = judge_contacts(&mut self.pushing, begun, &world.touching_now(), speed_m_s);
        for j in judged {
            self.events
                .push((j.contact.time_s, Event::Contact(j.clone())));
            self.contacts.push(j);
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

    /// Obstacle passes: a window from 25 m before to 10 m after each obstacle along the route.
    fn judge_passes(&mut self, t_s: f64, d_now: f64, stopped: bool, world: &World) {
        let length = self.route.length_m();
        let closed = self.route.closed();
        let lap_s =
            (self.s_start + self.s_total).rem_euclid(if closed { length } else { f64::INFINITY });
        let lap = self.lap_times_s.len() as u32 + 1;
        let moving = self.speed_now_m_s.abs() > AT_FAULT_SPEED_M_S;
        let contacts_now = self.contacts.len();
        for k in 0..self.windows.len() {
            let w = &mut self.windows[k];
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
                w.clearance_moving = f64::INFINITY;
                w.contacts_before = contacts_now;
                w.front_reached_s = None;
            }
            if !w.active {
                continue;
            }
            w.offset = w.offset.max(d_now.abs());
            w.stopped |= stopped && rel < 0.0;
            w.present |= world.object_active(w.solid_index);
            if w.front_reached_s.is_none() && rel + self.front_m >= 0.0 {
                w.front_reached_s = Some(t_s);
            }
            for (part, d) in world.distances_to(w.solid_index).into_iter().enumerate() {
                let level = self.part_levels[part];
                w.clearance[level] = w.clearance[level].min(d);
                if moving {
                    w.clearance_moving = w.clearance_moving.min(d);
                }
            }
            if inside {
                continue;
            }
            w.active = false;
            if !w.present {
                // Not in the world during this window (appears later or has gone): no pass.
                w.since_s = t_s;
                continue;
            }
            self.close_window(k, lap, t_s, true);
        }
    }

    /// Closes the pass of window `k` at `t_s`: its outcome and verdict, its event. `drove_on`:
    /// the vehicle left the window ahead (or the run ended by time).
    fn close_window(&mut self, k: usize, lap: u32, t_s: f64, drove_on: bool) {
        let w = &self.windows[k];
        let id = &self.obstacles[k].id;
        let touched: Vec<&JudgedContact> = self.contacts
            [w.contacts_before.min(self.contacts.len())..]
            .iter()
            .filter(|c| c.contact.object == *id)
            .collect();
        let counted = touched
            .iter()
            .any(|c| c.at_fault || !self.no_contact_at_fault);
        let outcome = outcome_of(w, !touched.is_empty());
        let clearance = if self.no_contact_at_fault {
            w.clearance_moving
        } else {
            w.clearance.iter().copied().fold(f64::INFINITY, f64::min)
        };
        let too_close = self
            .danger_distance_m
            .is_some_and(|danger| clearance < danger);
        let mut met = !counted && !too_close && outcome_of(w, counted).meets(w.expect);
        if w.expect == Expectation::Yield {
            let facts = match w.mover.map(|m| &self.movers[m]) {
                Some(mover) => {
                    let range = self.samples.range(w.since_s, t_s);
                    YieldFacts {
                        contact: !touched.is_empty(),
                        encroachment: window_encroachment(&self.samples, mover, range.clone()),
                        mover_crossed_s: mover_crossed_s(&self.samples, mover, range, &w.at),
                        front_reached_s: w.front_reached_s,
                        drove_on,
                    }
                }
                // A static obstacle cannot go first.
                None => YieldFacts {
                    contact: !touched.is_empty(),
                    encroachment: None,
                    mover_crossed_s: None,
                    front_reached_s: w.front_reached_s,
                    drove_on,
                },
            };
            met &= yield_met(&facts);
        }
        let pass = Pass {
            lap,
            outcome,
            min_clearance_m: w.clearance.clone(),
            max_offset_m: w.offset,
            met,
        };
        self.windows[k].since_s = t_s;
        record_pass(&mut self.obstacles[k], &mut self.events, t_s, pass);
    }

    /// Every step: the movers' velocities; every 0.1 s: a sample of the run, each mover's time
    /// to collision and its conflict events.
    fn watch_traffic(&mut self, t_s: f64, state: &VehicleState, world: &World) {
        if self.movers.is_empty() {
            return;
        }
        let sample = t_s + 1e-9 >= self.samples.next_t_s;
        let vm = VehicleMotion {
            pose: state.world_from_vehicle(),
            speed_m_s: state.speed_m_s,
            yaw_rate_rad_s: state.speed_m_s * state.steering_rad.tan() / self.wheelbase_m,
        };
        if sample {
            while self.samples.next_t_s <= t_s + 1e-9 {
                self.samples.next_t_s += SAMPLE_S;
            }
            let joined = !self.samples.t_s.is_empty() && !self.samples.jumped;
            self.samples.jumped = false;
            self.samples.t_s.push(t_s);
            self.samples.vehicle.push(vm.pose);
            self.samples.joined.push(joined);
        }
        for m in &mut self.movers {
            let pose = world
                .scene()
                .solids
                .get(m.solid_index)
                .filter(|_| world.object_active(m.solid_index))
                .map(|s| Isometry2::new(Vector2::new(s.x_m, s.y_m), s.yaw_rad));
            match (pose, m.last) {
                (Some(p), Some((t0, q))) if t_s > t0 => {
                    m.velocity = (p.translation.vector - q.coords) / (t_s - t0);
                }
                (None, _) => m.velocity = Vector2::zeros(),
                _ => {}
            }
            m.last = pose.map(|p| (t_s, Point2::from(p.translation.vector)));
            if !sample {
                continue;
            }
            m.poses.push(pose);
            let Some(pose) = pose else {
                m.armed = true;
                continue;
            };
            let motion = MoverMotion {
                pose,
                velocity_m_s: m.velocity,
            };
            let ttc = conflict::time_to_collision(&m.vehicle, &vm, &m.body, &motion);
            if let Some(t) = ttc {
                m.min_ttc_s = Some(m.min_ttc_s.map_or(t, |x| x.min(t)));
            }
            match ttc {
                Some(t) if t < CONFLICT_TTC_S && m.armed => {
                    m.armed = false;
                    let id = m.id.clone();
                    self.events.push((t_s, Event::Conflict { id, ttc_s: t }));
                }
                Some(t) if t <= CONFLICT_CLEAR_S => {}
                _ => m.armed = true,
            }
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

    /// The run ended (for `end`) while the vehicle stood in front of obstacles (timed out, or
    /// waiting for a hidden one): the passes it was in the middle of close as they stand (a
    /// `yield` pass counts the vehicle as driving on only if the run ended by time).
    pub fn close_open_passes(&mut self, t_s: f64, end: EndReason) {
        let lap = self.lap_times_s.len() as u32 + 1;
        for k in 0..self.windows.len() {
            let w = &mut self.windows[k];
            if !(w.active && w.present) {
                continue;
            }
            w.active = false;
            self.close_window(k, lap, t_s, end == EndReason::TimedOut);
        }
    }

    /// The verdicts: the run ended as `expected` (every lap driven, or waiting for a hidden
    /// obstacle), every obstacle passed as expected on every pass, no contact (with
    /// `no_contact_at_fault`: none while the vehicle moved); each mover's traffic conflicts.
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
            ExpectedEnd::Any => end != EndReason::Interrupted,
            ExpectedEnd::StoppedForGood => {
                matches!(
                    end,
                    EndReason::TimedOut | EndReason::WaitingForHiddenObstacle | EndReason::Blocked
                ) && self.stops.last().is_some_and(|s| s.end_s.is_none())
            }
        };
        let contacts_at_fault = self.contacts.iter().filter(|c| c.at_fault).count();
        let contact_ok = if self.no_contact_at_fault {
            contacts_at_fault == 0
        } else {
            contacts.is_empty()
        };
        Verdict {
            expectations_met: ended_as_expected && every_pass_met && contact_ok,
            laps_completed: self.laps_completed(),
            lap_times_s: self.lap_times_s,
            obstacles: self.obstacles,
            stops: self.stops,
            min_clearance_m: self.min_clearance_m,
            contacts_at_fault,
            contacts_struck: self.contacts.len() - contacts_at_fault,
            contacts: self.contacts,
        }
    }

    /// Each mover's smallest TTC and its PET over the whole run, into its report.
    fn traffic_figures(&mut self) {
        for (k, w) in self.windows.iter().enumerate() {
            let Some(mover) = w.mover.map(|m| &self.movers[m]) else {
                continue;
            };
            let e = window_encroachment(&self.samples, mover, 0..self.samples.t_s.len());
            let report = &mut self.obstacles[k];
            report.min_ttc_s = mover.min_ttc_s;
            report.pet_s = e.map(|e| e.pet_s);
            report.pet_mover_first = e.and_then(|e| e.mover_first);
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
    /// Contacts that began while the vehicle moved.
    pub contacts_at_fault: usize,
    /// Contacts that began while it stood (struck by a mover).
    pub contacts_struck: usize,
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

/// A window's outcome, `collided` or not.
fn outcome_of(w: &PassWindow, collided: bool) -> PassOutcome {
    if collided {
        PassOutcome::Collided
    } else if w.stopped {
        PassOutcome::Stopped
    } else if w.offset > DEVIATION_M {
        PassOutcome::Deviated
    } else {
        PassOutcome::Passed
    }
}

/// The run-time obstacles that move, with their footprints and the vehicle parts each can touch.
fn movers(scenario: &Scenario, first_obstacle: usize) -> Vec<Mover> {
    let parts = &scenario.vehicle.vehicle.parts;
    scenario
        .obstacles
        .iter()
        .enumerate()
        .filter(|(_, o)| o.motion.is_some())
        .map(|(k, o)| {
            let z_lo = o.solid.z_min_m;
            let z_hi = z_lo + o.solid.shape.height_m();
            Mover {
                solid_index: first_obstacle + k,
                id: o.solid.id.clone(),
                body: Body::of_solid(&o.solid),
                vehicle: Body::of_vehicle(parts, z_lo, z_hi),
                last: None,
                velocity: Vector2::zeros(),
                min_ttc_s: None,
                armed: true,
                poses: Vec::new(),
            }
        })
        .collect()
}

/// What a `yield` pass is judged on.
#[derive(Clone, Copy, Debug)]
struct YieldFacts {
    /// Anything touched the mover during the pass.
    contact: bool,
    /// The post-encroachment time since the last pass by it (`None`: no conflict area).
    encroachment: Option<Encroachment>,
    /// When the mover was nearest the route's point (`None`: it never came by).
    mover_crossed_s: Option<f64>,
    /// When the vehicle's front reached the route's point (`None`: it never did).
    front_reached_s: Option<f64>,
    /// The vehicle drove on afterwards (or the run ended by time).
    drove_on: bool,
}

/// The yield rule: no contact, the mover across the route before the vehicle's front got there
/// (and, where they conflict, out of the conflict area before the vehicle entered it), and the
/// vehicle drove on.
fn yield_met(f: &YieldFacts) -> bool {
    let crossed_first = match (f.mover_crossed_s, f.front_reached_s) {
        (Some(mover), Some(front)) => mover < front,
        (Some(_), None) => true,
        (None, _) => false,
    };
    let conflict_first = f
        .encroachment
        .is_none_or(|e| e.mover_first == Some(true) && e.pet_s > 0.0);
    !f.contact && f.drove_on && crossed_first && conflict_first
}

/// A mover's post-encroachment time over the samples in `range`.
fn window_encroachment(
    samples: &Samples,
    mover: &Mover,
    range: std::ops::Range<usize>,
) -> Option<Encroachment> {
    let track = Track {
        t_s: &samples.t_s[range.clone()],
        vehicle: &samples.vehicle[range.clone()],
        joined: &samples.joined[range.clone()],
        mover: &mover.poses[range],
    };
    conflict::post_encroachment(&track, &mover.vehicle, &mover.body)
}

/// When, among the samples in `range`, the mover was nearest `at` - if it came within 1 m plus
/// its largest step between samples (it went through the point, not only towards it).
fn mover_crossed_s(
    samples: &Samples,
    mover: &Mover,
    range: std::ops::Range<usize>,
    at: &Point2<f64>,
) -> Option<f64> {
    let mut best: Option<(f64, f64)> = None;
    let mut largest_step: f64 = 0.0;
    let mut last: Option<Point2<f64>> = None;
    for i in range {
        let Some(pose) = mover.poses[i] else {
            last = None;
            continue;
        };
        let p = Point2::from(pose.translation.vector);
        if let Some(l) = last {
            largest_step = largest_step.max((p - l).norm());
        }
        last = Some(p);
        let d = (p - at).norm();
        if best.is_none_or(|b| d < b.0) {
            best = Some((d, samples.t_s[i]));
        }
    }
    best.filter(|b| b.0 <= 1.0 + largest_step).map(|b| b.1)
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

/// The contacts `begun` since the last step, judged by the vehicle's speed now; and each
/// (object, part) pair `touching` now while the vehicle moves - a mover that struck it standing
/// and halted against it, then driven into - judged at fault, once while it lasts. `pushing`
/// holds the pairs touching and already judged at fault.
fn judge_contacts(
    pushing: &mut Vec<(String, String)>,
    begun: &[Contact],
    touching: &[Contact],
    speed_m_s: f64,
) -> Vec<JudgedContact> {
    let key = |c: &Contact| (c.object.clone(), c.part.clone());
    pushing.retain(|k| touching.iter().any(|c| key(c) == *k));
    let moving = speed_m_s.abs() > AT_FAULT_SPEED_M_S;
    let pushed = touching
        .iter()
        .filter(|c| moving && !begun.iter().any(|b| key(b) == key(c)));
    let mut judged = Vec::new();
    for c in begun.iter().chain(pushed) {
        if pushing.contains(&key(c)) {
            continue;
        }
        let j = JudgedContact::new(c.clone(), speed_m_s);
        if j.at_fault {
            pushing.push(key(c));
        }
        judged.push(j);
    }
    judged
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::ObjectKind;
    use conflict::Hull;

    fn contact(time_s: f64) -> Contact {
        Contact {
            time_s,
            object: "van".into(),
            kind: ObjectKind::Vehicle,
            part: "nose".into(),
        }
    }

    /// A truck strikes the standing jet's wing (struck) and halts against it; the jet then
    /// moves while they touch: at fault, once while it lasts; touching anew later, judged anew.
    #[test]
    fn a_contact_lasting_while_the_vehicle_moves_is_at_fault_once() {
        let c = |t: f64| Contact {
            time_s: t,
            object: "truck".into(),
            kind: ObjectKind::FuelTruck,
            part: "wing_left".into(),
        };
        let mut pushing = Vec::new();
        let j = judge_contacts(&mut pushing, &[c(1.0)], &[c(1.0)], 0.0);
        assert_eq!(j.len(), 1);
        assert!(!j[0].at_fault);
        assert!(judge_contacts(&mut pushing, &[], &[c(2.0)], 0.0).is_empty());
        let j = judge_contacts(&mut pushing, &[], &[c(3.0)], 0.8);
        assert_eq!(j.len(), 1);
        assert!(j[0].at_fault && j[0].contact.time_s == 3.0);
        assert!(judge_contacts(&mut pushing, &[], &[c(3.1)], 0.9).is_empty());
        // Apart, then touching again while moving: a new contact, judged once.
        assert!(judge_contacts(&mut pushing, &[], &[], 0.9).is_empty());
        let j = judge_contacts(&mut pushing, &[c(5.0)], &[c(5.0)], 0.9);
        assert_eq!(j.len(), 1);
        assert!(j[0].at_fault);
        assert!(judge_contacts(&mut pushing, &[], &[c(5.1)], 0.9).is_empty());
    }

    #[test]
    fn a_contact_while_standing_is_struck_and_while_moving_at_fault() {
        let standing = JudgedContact::new(contact(3.0), 0.01);
        assert!(!standing.at_fault);
        let reversing = JudgedContact::new(contact(3.0), -0.5);
        assert!(reversing.at_fault);
        let moving = JudgedContact::new(contact(3.0), 2.0);
        assert!(moving.at_fault);
        // The event and the report carry the contact's fields flat, and the attribution.
        let json = serde_json::to_value(Event::Contact(standing)).unwrap();
        assert_eq!(json["event"], "contact");
        assert_eq!(json["object"], "van");
        assert_eq!(json["at_fault"], false);
        assert_eq!(json["vehicle_speed_m_s"], 0.01);
    }

    /// A crossing sampled every 0.1 s for 30 s: the vehicle (a disc of 1 m) along +x towards
    /// the crossing at x = 0, the mover (a disc of 1 m) along +y through it at 2 m/s, nearest
    /// the route at `mover_at_s`. The vehicle drives at 2 m/s, standing from `stop_s` to
    /// `go_s` at x = `stop_x`, and its front (1 m ahead) reaches x = 0 when it gets to -1 m.
    fn judged_crossing(mover_at_s: f64, stop: Option<(f64, f64)>) -> (YieldFacts, YieldFacts) {
        let mut samples = Samples::default();
        let mut mover = Mover {
            solid_index: 0,
            id: "van".into(),
            body: Body::new(vec![Hull::disc(Point2::origin(), 1.0)]),
            vehicle: Body::new(vec![Hull::disc(Point2::origin(), 1.0)]),
            last: None,
            velocity: Vector2::zeros(),
            min_ttc_s: None,
            armed: true,
            poses: Vec::new(),
        };
        let mut x = -30.0;
        let mut front_reached_s = None;
        for k in 0..=300 {
            let t = 0.1 * k as f64;
            let standing = stop.is_some_and(|(from, to)| (from..to).contains(&t));
            if k > 0 && !standing {
                x += 0.2;
            }
            if front_reached_s.is_none() && x + 1.0 >= 0.0 {
                front_reached_s = Some(t);
            }
            samples.t_s.push(t);
            samples
                .vehicle
                .push(Isometry2::new(Vector2::new(x, 0.0), 0.0));
            samples.joined.push(k > 0);
            mover.poses.push(Some(Isometry2::new(
                Vector2::new(0.0, 2.0 * (t - mover_at_s)),
                0.0,
            )));
        }
        let range = 0..samples.t_s.len();
        let facts = YieldFacts {
            contact: false,
            encroachment: window_encroachment(&samples, &mover, range.clone()),
            mover_crossed_s: mover_crossed_s(&samples, &mover, range, &Point2::origin()),
            front_reached_s,
            drove_on: true,
        };
        (
            facts,
            YieldFacts {
                drove_on: false,
                ..facts
            },
        )
    }

    #[test]
    fn yield_is_met_when_the_mover_goes_first_and_the_vehicle_drives_on() {
        // The vehicle reaches x = -8 at 11 s and stands there until 20 s; the mover crosses
        // at 15 s. Mover first, PET > 0.
        let (facts, stuck) = judged_crossing(15.0, Some((11.0, 20.0)));
        let e = facts.encroachment.expect("their paths cross");
        assert_eq!(e.mover_first, Some(true), "{facts:?}");
        assert!(e.pet_s > 0.0, "{facts:?}");
        assert!(yield_met(&facts), "{facts:?}");
        // Still standing there when the run ended (not by time): not met.
        assert!(!yield_met(&stuck), "{stuck:?}");
        // A contact: not met.
        assert!(!yield_met(&YieldFacts {
            contact: true,
            ..facts
        }));
    }

    #[test]
    fn yield_is_not_met_when_the_vehicle_goes_first() {
        // No stop: the vehicle crosses x = 0 at 15 s, the mover at 20 s.
        let (facts, _) = judged_crossing(20.0, None);
        assert_eq!(facts.encroachment.and_then(|e| e.mover_first), Some(false));
        assert!(!yield_met(&facts), "{facts:?}");
        // Together: not met either.
        let (facts, _) = judged_crossing(15.0, None);
        assert!(!yield_met(&facts), "{facts:?}");
    }
}
