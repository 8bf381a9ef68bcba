//! The planner, the obstacle avoider, the behaviour and the path follower. They see the route,
//! the distance maps (through the collision checker) and the pose estimate.
//!
//! - **Planner**: candidate paths in the route's Frenet frame, each moving from the current
//!   lateral offset to a target offset over `transition_m` and holding it to `horizon_m`; every
//!   pose is checked with the vehicle's height-tagged circles against the distance map of each
//!   circle's level. A candidate is feasible when no circle comes closer than its radius plus the
//!   avoider's safety distance; among feasible ones the cost is `w_offset |d| + w_change |d -
//!   d_prev|` plus CARMEN's clearance cost `sum (margin - safety_planner)^2` over poses inside the
//!   planner's safety distance.
//! - **Behaviour**: a car deviates around obstacles (the thesis' parking-lot mode); an aircraft
//!   never leaves the centreline (flight safety rule): only offset 0 is a candidate, so an
//!   obstacle in its path makes it stop and wait. Wings pass over whatever is below their level
//!   because their circles read only the map of their level.
//! - **Avoider** (CARMEN `obstacle_avoider`): while the chosen path collides within the stopping
//!   distance of the commanded speed, the speed is scaled by 0.95, down to a stop.
//! - **Follower**: pure pursuit on the chosen path for steering; the speed command is tracked by
//!   the vehicle's acceleration-limited drive.

use mapper::CollisionChecker;
use nalgebra::{Isometry2, Point2, Vector2};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::route::{RoutePath, wrap_angle};

/// What a vehicle does about an obstacle in its way.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Behaviour {
    /// Steer around it (the car in the thesis' parking-lot test).
    Deviate,
    /// Stay on the centreline, stop and wait for it to clear (the aircraft's safety rule).
    StopAndWait,
}

/// Planner, avoider and follower parameters. Defaults from CARMEN where it has them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AutonomyConfig {
    /// Largest lateral offset from the route a candidate may take, metres. Default 3.
    pub max_offset_m: f64,
    /// Spacing of the candidate offsets, metres. Default 0.25.
    pub offset_step_m: f64,
    /// How far ahead candidates are checked at least, metres. Default 30. The horizon grows
    /// with speed to the stopping distance (reaction, braking, buffer) plus a step, up to
    /// `max_horizon_m`.
    pub horizon_m: f64,
    /// The longest horizon, metres: the vehicle never drives faster than it can stop within it
    /// (the route's speed is lowered, and the report says so). Default 60.
    pub max_horizon_m: f64,
    /// Length over which a candidate moves to its offset, metres. Default 12.
    pub transition_m: f64,
    /// Spacing of the checked poses along a candidate, metres. Default 0.5.
    pub step_m: f64,
    /// Clearance the planner's cost asks for beyond each radius, metres (CARMEN 0.6).
    pub planner_safety_m: f32,
    /// Clearance the avoider enforces beyond each radius, metres (CARMEN 0.1-0.2). Default 0.2.
    pub avoider_safety_m: f32,
    /// Cost weight of the offset, per metre. Default 1.
    pub w_offset: f64,
    /// Cost weight of changing the offset, per metre. Default 0.5.
    pub w_change: f64,
    /// Cost weight of the clearance cost. Default 2.
    pub w_clearance: f64,
    /// Reaction time in the stopping distance, seconds. Default 0.5.
    pub reaction_s: f64,
    /// Extra distance kept when stopping, metres. Default 3: a vehicle stopped closer than that
    /// to an obstacle has it in its LiDAR's near blind zone (the lowest beam meets the ground
    /// 2.6 m out from a 1.55 m nose pod) and could not see it leave.
    pub stop_buffer_m: f64,
    /// Pure-pursuit look-ahead: `max(min, gain * speed)`, metres and seconds. Defaults 4 and 1.2.
    pub lookahead_min_m: f64,
    /// See `lookahead_min_m`.
    pub lookahead_gain_s: f64,
    /// A vehicle stopped for an obstacle no revolution has hit for this long waits for a
    /// hidden obstacle, seconds. Default 2.
    pub hidden_after_s: f64,
    /// Waiting for a hidden obstacle this long, the vehicle calls for a pilot (the thesis'
    /// pilot intervention): the run ends, seconds. Default 10.
    pub pilot_call_after_s: f64,
    /// Stopped this long for obstacles (in view or hidden, with no pause), the vehicle calls
    /// for a pilot: its path is blocked (debris on the centreline, a vehicle parked across the
    /// taxiway), and an aircraft never steers round. The run ends, seconds. Default 60: longer
    /// than any wait for a mover to clear.
    pub blocked_call_after_s: f64,
    /// The strike rule ([`crate::Driver::on_strike`]): a vehicle whose airframe felt a strike
    /// stands and calls for a pilot. Default true; false: strikes are ignored (a regression
    /// that checks what the stack does about a mover at its body without it).
    pub stand_when_struck: bool,
    /// The range at which the smallest obstacle the vehicle must avoid is surely mapped, metres
    /// (`taxi-sim small-obstacles` measures it): the avoider never goes faster than it can
    /// stop within it. Default none (no cap): for the IARA car, every obstacle of 0.12 m and up
    /// is mapped 28.8 m ahead or more at up to 8 m/s, farther than it needs at its top speed.
    pub detection_range_m: Option<f64>,
    /// The watchdog: with no fresh LiDAR revolution for this long the vehicle is brought to a
    /// stop (it would be planning blind), and drives on when revolutions return, seconds.
    /// Default 0.3 (three revolutions at 10 Hz).
    pub watchdog_s: f64,
    /// The safety distances (planner's and avoider's) are widened by this many standard
    /// deviations of the estimate's lateral uncertainty at the vehicle's farthest point
    /// (`PoseEstimate::lateral_sigma_at_m`). Default 2.
    pub uncertainty_sigmas: f64,
    /// Movers: prediction and the space-time check (`[autonomy.traffic]`).
    pub traffic: crate::traffic::TrafficConfig,
    /// Above this lateral standard deviation the wanted speed falls linearly ... Default 0.15 m.
    pub uncertainty_slow_m: f64,
    /// ... to a stop at this one, metres. Default 0.5.
    pub uncertainty_stop_m: f64,
}

impl AutonomyConfig {
    /// The configuration for an estimate whose lateral standard deviation at the vehicle's
    /// farthest point is `sigma_m`: the safety distances widened by `uncertainty_sigmas` of it,
    /// and the factor the wanted speed is multiplied by (1 up to `uncertainty_slow_m`, 0 from
    /// `uncertainty_stop_m`).
    pub fn under_uncertainty(&self, sigma_m: f64) -> (AutonomyConfig, f64) {
        if !sigma_m.is_finite() {
            // Nothing known of the pose: hold the vehicle.
            return (self.clone(), 0.0);
        }
        let extra = (self.uncertainty_sigmas * sigma_m) as f32;
        let span = (self.uncertainty_stop_m - self.uncertainty_slow_m).max(1e-9);
        let factor = (1.0 - (sigma_m - self.uncertainty_slow_m) / span).clamp(0.0, 1.0);
        let widened = AutonomyConfig {
            planner_safety_m: self.planner_safety_m + extra,
            avoider_safety_m: self.avoider_safety_m + extra,
            ..self.clone()
        };
        (widened, factor)
    }
}

impl Default for AutonomyConfig {
    fn default() -> Self {
        AutonomyConfig {
            max_offset_m: 3.0,
            offset_step_m: 0.25,
            horizon_m: 30.0,
            max_horizon_m: 60.0,
            transition_m: 12.0,
            step_m: 0.5,
            planner_safety_m: 0.6,
            avoider_safety_m: 0.2,
            w_offset: 1.0,
            w_change: 0.5,
            w_clearance: 2.0,
            reaction_s: 0.5,
            stop_buffer_m: 3.0,
            lookahead_min_m: 4.0,
            lookahead_gain_s: 1.2,
            hidden_after_s: 2.0,
            pilot_call_after_s: 10.0,
            blocked_call_after_s: 60.0,
            stand_when_struck: true,
            detection_range_m: None,
            watchdog_s: 0.3,
            uncertainty_sigmas: 2.0,
            uncertainty_slow_m: 0.15,
            uncertainty_stop_m: 0.5,
            traffic: crate::traffic::TrafficConfig::default(),
        }
    }
}

/// One candidate as the planner saw it (for reports and the replay).
#[derive(Clone, Debug)]
pub struct Candidate {
    /// Target lateral offset, metres.
    pub offset_m: f64,
    /// The poses checked.
    pub poses: Vec<Isometry2<f64>>,
    /// Distance along the candidate to its first colliding pose, if any.
    pub collision_at_m: Option<f64>,
    /// Its cost (infinite when infeasible).
    pub cost: f64,
}

/// The planner's answer.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Every candidate.
    pub candidates: Vec<Candidate>,
    /// Index of the chosen one.
    pub chosen: usize,
    /// True when no candidate is free of collision over the horizon.
    pub blocked: bool,
}

impl Plan {
    /// The chosen candidate.
    pub fn chosen(&self) -> &Candidate {
        &self.candidates[self.chosen]
    }
}

/// Plans from arc length `s0` and lateral offset `d0` on `route`.
pub fn plan(
    checker: &CollisionChecker<'_>,
    route: &RoutePath,
    s0: f64,
    d0: f64,
    previous_offset: f64,
    behaviour: Behaviour,
    cfg: &AutonomyConfig,
) -> Plan {
    let offsets: Vec<f64> = match behaviour {
        Behaviour::StopAndWait => vec![0.0],
        Behaviour::Deviate => {
            let n = (cfg.max_offset_m / cfg.offset_step_m).round() as i64;
            let mut v: Vec<f64> = (-n..=n).map(|k| k as f64 * cfg.offset_step_m).collect();
            v.sort_by(|a, b| a.abs().total_cmp(&b.abs()).then(a.total_cmp(b)));
            v
        }
    };
    let steps = (cfg.horizon_m / cfg.step_m).ceil() as usize;
    // The candidates side by side (collected in order: the same plan as one by one).
    let candidates: Vec<Candidate> = offsets
        .par_iter()
        .map(|&target| {
            let mut poses = Vec::with_capacity(steps + 1);
            let mut collision_at_m = None;
            let mut clearance_cost = 0.0;
            for k in 0..=steps {
                let ds = k as f64 * cfg.step_m;
                let pose = frenet_pose(route, s0 + ds, d0, target, ds, cfg.transition_m);
                let check = checker.check_pose(&pose, cfg.avoider_safety_m);
                if check.colliding && collision_at_m.is_none() {
                    collision_at_m = Some(ds);
                }
                let wanted = cfg.planner_safety_m - cfg.avoider_safety_m;
                if check.margin_m < wanted {
                    clearance_cost += ((wanted - check.margin_m) as f64).powi(2);
                }
                poses.push(pose);
            }
            let cost = if collision_at_m.is_some() {
                f64::INFINITY
            } else {
                cfg.w_offset * target.abs()
                    + cfg.w_change * (target - previous_offset).abs()
                    + cfg.w_clearance * clearance_cost
            };
            Candidate {
                offset_m: target,
                poses,
                collision_at_m,
                cost,
            }
        })
        .collect();
    let best = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| c.cost.is_finite())
        .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost))
        .map(|(i, _)| i);
    match best {
        Some(chosen) => Plan {
            candidates,
            chosen,
            blocked: false,
        },
        None => {
            // Blocked: keep the candidate nearest the route among those that get farthest.
            let chosen = candidates
                .iter()
                .enumerate()
                .max_by(|a, b| {
                    let (ra, rb) = (
                        a.1.collision_at_m.unwrap_or(f64::INFINITY),
                        b.1.collision_at_m.unwrap_or(f64::INFINITY),
                    );
                    ra.total_cmp(&rb)
                        .then(b.1.offset_m.abs().total_cmp(&a.1.offset_m.abs()))
                })
                .map_or(0, |(i, _)| i);
            Plan {
                candidates,
                chosen,
                blocked: true,
            }
        }
    }
}

/// The pose `ds` ahead of `s0` on a path moving from offset `d0` to `target` over `transition_m`.
fn frenet_pose(
    route: &RoutePath,
    s: f64,
    d0: f64,
    target: f64,
    ds: f64,
    transition_m: f64,
) -> Isometry2<f64> {
    let u = (ds / transition_m).clamp(0.0, 1.0);
    // Smoothstep: zero slope at both ends.
    let blend = u * u * (3.0 - 2.0 * u);
    let slope = if ds < transition_m {
        (target - d0) * 6.0 * u * (1.0 - u) / transition_m
    } else {
        0.0
    };
    let d = d0 + (target - d0) * blend;
    let (p, heading) = route.at(s);
    let normal = Vector2::new(-heading.sin(), heading.cos());
    let q = p + normal * d;
    Isometry2::new(q.coords, wrap_angle(heading + slope.atan()))
}

/// Distance to stop from `v` m/s: reaction, braking at `deceleration_m_s2`, the stop buffer.
pub fn stopping_distance_m(v: f64, deceleration_m_s2: f64, cfg: &AutonomyConfig) -> f64 {
    v * cfg.reaction_s + v * v / (2.0 * deceleration_m_s2) + cfg.stop_buffer_m
}

/// The fastest speed from which the vehicle stops within `range_m` (reaction time, braking at
/// `deceleration_m_s2` and the stop buffer included).
fn speed_to_stop_within(range_m: f64, deceleration_m_s2: f64, cfg: &AutonomyConfig) -> f64 {
    // v t + v^2 / 2a + buffer = range, for v >= 0.
    let (a, t) = (deceleration_m_s2, cfg.reaction_s);
    let room = (range_m - cfg.stop_buffer_m).max(0.0);
    a * (-t + (t * t + 2.0 * room / a).sqrt())
}

/// The fastest speed from which the vehicle stops within `cfg.detection_range_m`; infinite
/// without one.
pub fn sight_speed_m_s(deceleration_m_s2: f64, cfg: &AutonomyConfig) -> f64 {
    cfg.detection_range_m.map_or(f64::INFINITY, |r| {
        speed_to_stop_within(r, deceleration_m_s2, cfg)
    })
}

/// Why the vehicle may go no faster than it does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpeedLimit {
    /// It could not stop within the longest horizon (`max_horizon_m`) from faster.
    Horizon,
    /// It could not stop within the detection range (`detection_range_m`) from faster.
    DetectionRange,
}

/// The fastest the vehicle may go, and what limits it: it stops within both the longest horizon
/// and the detection range.
pub fn speed_cap_m_s(deceleration_m_s2: f64, cfg: &AutonomyConfig) -> (f64, SpeedLimit) {
    let horizon = speed_to_stop_within(cfg.max_horizon_m, deceleration_m_s2, cfg);
    let sight = sight_speed_m_s(deceleration_m_s2, cfg);
    if sight < horizon {
        (sight, SpeedLimit::DetectionRange)
    } else {
        (horizon, SpeedLimit::Horizon)
    }
}

/// The horizon checked at `speed_m_s`: the stopping distance plus a step, at least `horizon_m`,
/// at most `max_horizon_m`.
pub fn horizon_for_m(speed_m_s: f64, deceleration_m_s2: f64, cfg: &AutonomyConfig) -> f64 {
    (stopping_distance_m(speed_m_s, deceleration_m_s2, cfg) + cfg.step_m)
        .min(cfg.max_horizon_m)
        .max(cfg.horizon_m)
}

/// The avoider: the speed to command on the chosen candidate (never above [`speed_cap_m_s`]),
/// and how many 0.95 scalings it took.
pub fn avoid(
    candidate: &Candidate,
    wanted_m_s: f64,
    deceleration_m_s2: f64,
    cfg: &AutonomyConfig,
) -> (f64, u32) {
    let wanted_m_s = wanted_m_s.min(speed_cap_m_s(deceleration_m_s2, cfg).0);
    let Some(at) = candidate.collision_at_m else {
        return (wanted_m_s, 0);
    };
    let stopping = |v: f64| stopping_distance_m(v, deceleration_m_s2, cfg);
    let mut v = wanted_m_s;
    let mut scalings = 0;
    while stopping(v) >= at && v > 0.05 && scalings < 500 {
        v *= 0.95;
        scalings += 1;
    }
    if stopping(v) >= at || v <= 0.05 {
        (0.0, scalings)
    } else {
        (v, scalings)
    }
}

/// Pure pursuit: the steering angle that drives `pose` onto the candidate's path.
pub fn pure_pursuit(
    pose: &Isometry2<f64>,
    candidate: &Candidate,
    speed_m_s: f64,
    wheelbase_m: f64,
    cfg: &AutonomyConfig,
) -> f64 {
    let lookahead = cfg
        .lookahead_min_m
        .max(cfg.lookahead_gain_s * speed_m_s.abs());
    let here = Point2::from(pose.translation.vector);
    // The first path pose at least `lookahead` away, ahead of the vehicle.
    let forward = pose.rotation * Vector2::x();
    let target = candidate
        .poses
        .iter()
        .map(|p| Point2::from(p.translation.vector))
        .find(|p| (p - here).norm() >= lookahead && (p - here).dot(&forward) > 0.0)
        .or_else(|| {
            candidate
                .poses
                .last()
                .map(|p| Point2::from(p.translation.vector))
        });
    let Some(target) = target else { return 0.0 };
    let local = pose.inverse() * target;
    let ld2 = local.coords.norm_squared().max(1e-6);
    (2.0 * wheelbase_m * local.y / ld2).atan()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_avoider_slows_then_stops() {
        let cfg = AutonomyConfig::default();
        let free = Candidate {
            offset_m: 0.0,
            poses: vec![],
            collision_at_m: None,
            cost: 0.0,
        };
        assert_eq!(avoid(&free, 5.0, 3.0, &cfg), (5.0, 0));
        let far = Candidate {
            collision_at_m: Some(8.0),
            ..free.clone()
        }; // 5 m/s needs 9.7 m
        let (v, k) = avoid(&far, 5.0, 3.0, &cfg);
        assert!(v > 0.0 && v < 5.0 && k > 0, "{v} {k}");
        let near = Candidate {
            collision_at_m: Some(0.5),
            ..free
        };
        assert_eq!(avoid(&near, 5.0, 3.0, &cfg).0, 0.0);
    }

    /// With a detection range, the avoider goes no faster than it can stop within it - on a
    /// free path too - and exactly that fast: 28.8 m at 3 m/s^2 with 0.5 s and a 3 m buffer.
    #[test]
    fn the_detection_range_caps_the_speed() {
        let cfg = AutonomyConfig {
            detection_range_m: Some(28.8),
            ..AutonomyConfig::default()
        };
        let free = Candidate {
            offset_m: 0.0,
            poses: vec![],
            collision_at_m: None,
            cost: 0.0,
        };
        let (v, _) = avoid(&free, 20.0, 3.0, &cfg);
        let stopping = v * 0.5 + v * v / 6.0 + 3.0;
        assert!(
            (stopping - 28.8).abs() < 1e-9,
            "{v} m/s stops in {stopping} m"
        );
        assert!((11.0..11.5).contains(&v), "{v}");
        assert_eq!(
            avoid(&free, 5.0, 3.0, &cfg).0,
            5.0,
            "slower than the cap: unchanged"
        );
        // Without a detection range the longest horizon (60 m) caps it.
        let (v, _) = avoid(&free, 20.0, 3.0, &AutonomyConfig::default());
        let stopping = v * 0.5 + v * v / 6.0 + 3.0;
        assert!(
            (stopping - 60.0).abs() < 1e-9,
            "{v} m/s stops in {stopping} m"
        );
        assert_eq!(
            speed_cap_m_s(3.0, &cfg).1,
            SpeedLimit::DetectionRange,
            "the nearer limit"
        );
    }

    /// The horizon grows with speed to the stopping distance plus a step: the jet (1.5 m/s^2)
    /// at 10 m/s needs 0.5 x 10 + 100 / 3 + 3 = 41.3 m, beyond the 30 m it checked before.
    #[test]
    fn the_horizon_grows_with_speed() {
        let cfg = AutonomyConfig::default();
        assert_eq!(horizon_for_m(3.0, 1.5, &cfg), 30.0);
        let h = horizon_for_m(10.0, 1.5, &cfg);
        assert!((h - (5.0 + 100.0 / 3.0 + 3.0 + 0.5)).abs() < 1e-9, "{h}");
        assert_eq!(horizon_for_m(30.0, 1.5, &cfg), 60.0);
    }
}
