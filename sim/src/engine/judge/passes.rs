//! The passes by each run-time obstacle: a window along the route around it, watched while the
//! vehicle is in it, then closed with its outcome, its verdict and its event.

use autonomy::RoutePath;
use nalgebra::Point2;

use super::traffic::{mover_crossed_s, window_encroachment};
use super::yielding::{YieldFacts, yield_met};
use super::{DEVIATION_M, Judge};
use crate::engine::outcome::{
    AT_FAULT_SPEED_M_S, EndReason, Event, JudgedContact, ObstacleReport, Pass, PassOutcome,
};
use crate::scenario::Expectation;
use crate::world::World;

/// A pass is judged over a window from this far before its obstacle along the route...
const PASS_BEFORE_M: f64 = 25.0;
/// ... to this far after it.
const PASS_AFTER_M: f64 = 10.0;

/// A pass being watched.
pub(super) struct PassWindow {
    /// Its obstacle's index among the world's solids.
    pub(super) solid_index: usize,
    /// Where the obstacle is along the route (arc length), metres.
    pub(super) route_s: f64,
    /// What the obstacle expects of a pass.
    pub(super) expect: Expectation,
    /// Whether the vehicle is in the window now.
    pub(super) active: bool,
    /// The largest lateral offset from the route in the window, metres.
    pub(super) offset: f64,
    /// Whether the vehicle stopped before the obstacle in the window.
    pub(super) stopped: bool,
    /// Whether the obstacle was in the world at some time in the window (one that appears or
    /// disappears may be absent on some laps: no pass then).
    pub(super) present: bool,
    /// The smallest clearance per level in the window, metres.
    pub(super) clearance: Vec<f64>,
    /// The smallest clearance at any level at the steps the vehicle moved, metres.
    pub(super) clearance_moving: f64,
    /// How many contacts had been judged when the window opened.
    pub(super) contacts_before: usize,
    /// The route's point the pass is by (a mover's path's point nearest the route).
    pub(super) at: Point2<f64>,
    /// When the last pass by it closed (the run's start before the first), seconds.
    pub(super) since_s: f64,
    /// When the vehicle's front first reached `at` in this window, seconds.
    pub(super) front_reached_s: Option<f64>,
    /// Its index among the movers, if it moves.
    pub(super) mover: Option<usize>,
}

impl Judge {
    /// Obstacle passes: a window from 25 m before to 10 m after each obstacle along the route.
    pub(super) fn judge_passes(&mut self, t_s: f64, d_now: f64, stopped: bool, world: &World) {
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

/// The point of a path closest to the route (where a crossing vehicle crosses it).
pub(super) fn closest_on_route(route: &RoutePath, path: &[Point2<f64>]) -> Option<Point2<f64>> {
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
