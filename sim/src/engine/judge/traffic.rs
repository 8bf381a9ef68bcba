//! The traffic conflicts with each mover: its velocity every step, and every 0.1 s a sample of
//! the run (for the post-encroachment times), its time to collision and its conflict events.

use nalgebra::{Isometry2, Point2, Vector2};

use super::Judge;
use crate::engine::conflict::{self, Body, Encroachment, MoverMotion, Track, VehicleMotion};
use crate::engine::outcome::Event;
use crate::scenario::Scenario;
use crate::world::{VehicleState, World};

/// The traffic conflicts are judged (and the run sampled for the PET) this often, seconds.
const SAMPLE_S: f64 = 0.1;
/// A mover's time to collision under this starts a conflict (an event), seconds...
const CONFLICT_TTC_S: f64 = 3.0;
/// ... which ends when it rises above this (or the two are no longer on a collision course).
const CONFLICT_CLEAR_S: f64 = 5.0;

/// A run-time obstacle that moves, watched for traffic conflicts.
pub(super) struct Mover {
    /// Its index among the world's solids.
    pub(super) solid_index: usize,
    /// Its obstacle's id.
    pub(super) id: String,
    /// Its footprint.
    pub(super) body: Body,
    /// The vehicle's parts it can touch (their heights overlap its own).
    pub(super) vehicle: Body,
    /// Its position at the last step (time, x, y), if present then.
    pub(super) last: Option<(f64, Point2<f64>)>,
    /// Its velocity, by differencing over the last step, m/s.
    pub(super) velocity: Vector2<f64>,
    /// Its smallest time to collision so far, seconds (0 once it touched the vehicle).
    pub(super) min_ttc_s: Option<f64>,
    /// Whether it touched the vehicle: its TTC and PET are 0, however soon the run ends after
    /// (a strike ends it: `EndReason::Struck`).
    pub(super) touched: bool,
    /// Whether a TTC under 3 s would start a new conflict.
    pub(super) armed: bool,
    /// Its pose at each sample (`None`: absent).
    pub(super) poses: Vec<Option<Isometry2<f64>>>,
}

/// The run sampled every 0.1 s for the post-encroachment times.
#[derive(Default)]
pub(super) struct Samples {
    /// Each sample's time, seconds.
    pub(super) t_s: Vec<f64>,
    /// The vehicle's pose at each sample.
    pub(super) vehicle: Vec<Isometry2<f64>>,
    /// False where the vehicle was put back at the start of an open route since the last sample.
    pub(super) joined: Vec<bool>,
    /// When the next sample is due, seconds.
    pub(super) next_t_s: f64,
    /// Whether the vehicle was put back at the start since the last sample.
    pub(super) jumped: bool,
}

impl Samples {
    /// The samples' index range within `[from_s, to_s]`.
    pub(super) fn range(&self, from_s: f64, to_s: f64) -> std::ops::Range<usize> {
        let a = self.t_s.partition_point(|t| *t < from_s - 1e-9);
        let b = self.t_s.partition_point(|t| *t <= to_s + 1e-9);
        a..b.max(a)
    }
}

impl Judge {
    /// Every step: the movers' velocities; every 0.1 s: a sample of the run, each mover's time
    /// to collision and its conflict events.
    pub(super) fn watch_traffic(&mut self, t_s: f64, state: &VehicleState, world: &World) {
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
            if world.touches_vehicle(m.solid_index) {
                m.touched = true;
                m.min_ttc_s = Some(0.0);
            }
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

    /// Each mover's smallest TTC and its PET over the whole run, into its report.
    pub(super) fn traffic_figures(&mut self) {
        for (k, w) in self.windows.iter().enumerate() {
            let Some(mover) = w.mover.map(|m| &self.movers[m]) else {
                continue;
            };
            let e = window_encroachment(&self.samples, mover, 0..self.samples.t_s.len());
            let report = &mut self.obstacles[k];
            report.min_ttc_s = mover.min_ttc_s;
            report.pet_s = if mover.touched {
                Some(0.0)
            } else {
                e.map(|e| e.pet_s)
            };
            report.pet_mover_first = e.and_then(|e| e.mover_first);
        }
    }
}

/// The run-time obstacles that move, with their footprints and the vehicle parts each can touch.
pub(super) fn movers(scenario: &Scenario, first_obstacle: usize) -> Vec<Mover> {
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
                touched: false,
                armed: true,
                poses: Vec::new(),
            }
        })
        .collect()
}

/// A mover's post-encroachment time over the samples in `range`.
pub(super) fn window_encroachment(
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
pub(super) fn mover_crossed_s(
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
