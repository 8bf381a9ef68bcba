//! The autonomy under test: route geometry, motion planner, obstacle avoider, behaviour and path
//! follower. It sees the route, the distance maps (through the collision checker) and its pose
//! estimate - never Rapier or ground truth.
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

use crate::motion::wrap_angle;

/// A route as a polyline with arc length.
#[derive(Clone, Debug)]
pub struct RoutePath {
    points: Vec<Point2<f64>>,
    /// Arc length at each point (and at the closing point for a closed route).
    s: Vec<f64>,
    closed: bool,
}

impl RoutePath {
    /// A path through `points` (at least 2, consecutive points distinct), closed or not.
    pub fn new(points: &[Point2<f64>], closed: bool) -> Self {
        let mut pts = points.to_vec();
        if closed && let Some(first) = pts.first().copied() {
            pts.push(first);
        }
        let mut s = vec![0.0];
        for w in pts.windows(2) {
            let last = s[s.len() - 1];
            s.push(last + (w[1] - w[0]).norm());
        }
        RoutePath {
            points: pts,
            s,
            closed,
        }
    }
    /// Total length, metres.
    pub fn length_m(&self) -> f64 {
        self.s[self.s.len() - 1]
    }
    /// True for a closed circuit.
    pub fn closed(&self) -> bool {
        self.closed
    }
    fn wrap(&self, s: f64) -> f64 {
        if self.closed {
            s.rem_euclid(self.length_m())
        } else {
            s.clamp(0.0, self.length_m())
        }
    }
    fn segment(&self, s: f64) -> usize {
        let i = self.s.partition_point(|&x| x <= s);
        i.saturating_sub(1).min(self.points.len() - 2)
    }
    /// Point and heading at arc length `s` (wrapped on a closed route, clamped on an open one).
    pub fn at(&self, s: f64) -> (Point2<f64>, f64) {
        let s = self.wrap(s);
        let i = self.segment(s);
        let d = self.points[i + 1] - self.points[i];
        let len = d.norm().max(1e-12);
        (self.points[i] + d * ((s - self.s[i]) / len), d.y.atan2(d.x))
    }
    /// Arc length and signed lateral offset (left positive) of a point, searched within
    /// `window_m` of `s_hint` (so a circuit that passes near itself is followed in order).
    /// Only the segments whose arc-length span meets the window are visited (found by bisection),
    /// in index order, so the result is that of testing every segment.
    pub fn project(&self, p: &Point2<f64>, s_hint: f64, window_m: f64) -> (f64, f64) {
        let length = self.length_m();
        let last = self.points.len() - 2;
        // Index ranges of the segments to visit, ascending.
        let mut spans = [(0, last), (1, 0)];
        if window_m.is_finite() && window_m < 0.5 * length {
            let (lo, hi) = if self.closed {
                let h = s_hint.rem_euclid(length);
                (h - window_m, h + window_m)
            } else {
                (s_hint - window_m, s_hint + window_m)
            };
            spans = if self.closed && lo < 0.0 {
                [(0, self.segment(hi)), (self.segment(lo + length), last)]
            } else if self.closed && hi > length {
                [(0, self.segment(hi - length)), (self.segment(lo), last)]
            } else {
                [(self.segment(lo), self.segment(hi)), (1, 0)]
            };
        }
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for i in spans.iter().flat_map(|&(a, b)| a..=b) {
            let (a, b) = (self.points[i], self.points[i + 1]);
            let ab = b - a;
            let len2 = ab.norm_squared().max(1e-12);
            let t = ((p - a).dot(&ab) / len2).clamp(0.0, 1.0);
            let q = a + ab * t;
            let s = self.s[i] + t * len2.sqrt();
            let along = if self.closed {
                let d = (s - s_hint).rem_euclid(length);
                d.min(length - d)
            } else {
                (s - s_hint).abs()
            };
            if along > window_m {
                continue;
            }
            let dist = (p - q).norm();
            if dist < best.0 {
                let side = ab.x * (p.y - a.y) - ab.y * (p.x - a.x);
                best = (dist, s, if side >= 0.0 { dist } else { -dist });
            }
        }
        if best.0.is_infinite() {
            self.project(p, s_hint, f64::INFINITY)
        } else {
            (best.1, best.2)
        }
    }
}

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
    /// How far ahead candidates are checked, metres. Default 30.
    pub horizon_m: f64,
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
}

impl Default for AutonomyConfig {
    fn default() -> Self {
        AutonomyConfig {
            max_offset_m: 3.0,
            offset_step_m: 0.25,
            horizon_m: 30.0,
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

/// The avoider: the speed to command on the chosen candidate, and how many 0.95 scalings it took.
pub fn avoid(
    candidate: &Candidate,
    wanted_m_s: f64,
    deceleration_m_s2: f64,
    cfg: &AutonomyConfig,
) -> (f64, u32) {
    let Some(at) = candidate.collision_at_m else {
        return (wanted_m_s, 0);
    };
    let stopping =
        |v: f64| v * cfg.reaction_s + v * v / (2.0 * deceleration_m_s2) + cfg.stop_buffer_m;
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
    fn projection_and_points_agree_on_a_closed_square() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            Point2::new(10.0, 10.0),
            Point2::new(0.0, 10.0),
        ];
        let r = RoutePath::new(&pts, true);
        assert_eq!(r.length_m(), 40.0);
        let (p, h) = r.at(15.0);
        assert!(
            (p - Point2::new(10.0, 5.0)).norm() < 1e-12
                && (h - std::f64::consts::FRAC_PI_2).abs() < 1e-12
        );
        let (p, _) = r.at(41.0);
        assert!((p - Point2::new(1.0, 0.0)).norm() < 1e-12, "wraps");
        let (s, d) = r.project(&Point2::new(5.0, 1.0), 5.0, 10.0);
        assert!(
            (s - 5.0).abs() < 1e-12 && (d - 1.0).abs() < 1e-12,
            "left of the first side: {s} {d}"
        );
        let (_, d) = r.project(&Point2::new(5.0, -1.0), 5.0, 10.0);
        assert!((d + 1.0).abs() < 1e-12);
    }

    /// The windowed search (bisection on arc length) agrees with testing every segment.
    #[test]
    fn windowed_projection_matches_the_exhaustive_search() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        // A wobbly closed loop and an open one of many short segments.
        let pts: Vec<Point2<f64>> = (0..400)
            .map(|i| {
                let a = i as f64 / 400.0 * std::f64::consts::TAU;
                let r = 50.0 + 5.0 * (7.0 * a).sin();
                Point2::new(r * a.cos(), r * a.sin())
            })
            .collect();
        for closed in [true, false] {
            let r = RoutePath::new(&pts, closed);
            // The old search: every segment, and the whole route when none is in the window.
            let brute = |p: &Point2<f64>, hint: f64, w: f64| {
                let mut best = (f64::INFINITY, 0.0, 0.0);
                for w in [w, f64::INFINITY] {
                    for i in 0..r.points.len() - 1 {
                        let (a, b) = (r.points[i], r.points[i + 1]);
                        let ab = b - a;
                        let len2 = ab.norm_squared().max(1e-12);
                        let t = ((p - a).dot(&ab) / len2).clamp(0.0, 1.0);
                        let s = r.s[i] + t * len2.sqrt();
                        let along = if closed {
                            let d = (s - hint).rem_euclid(r.length_m());
                            d.min(r.length_m() - d)
                        } else {
                            (s - hint).abs()
                        };
                        let dist = (p - (a + ab * t)).norm();
                        if along <= w && dist < best.0 {
                            let side = ab.x * (p.y - a.y) - ab.y * (p.x - a.x);
                            best = (dist, s, if side >= 0.0 { dist } else { -dist });
                        }
                    }
                    if best.0.is_finite() {
                        break;
                    }
                }
                (best.1, best.2)
            };
            for _ in 0..2000 {
                let p = Point2::new(rng.random_range(-60.0..60.0), rng.random_range(-60.0..60.0));
                let hint = rng.random_range(-10.0..r.length_m() + 10.0);
                let w = [5.0, 30.0, 100.0][rng.random_range(0..3)];
                let fast = r.project(&p, hint, w);
                let slow = brute(&p, hint, w);
                assert_eq!(fast, slow, "closed {closed} p {p} hint {hint} window {w}");
            }
        }
    }

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
}
