//! Traffic-conflict measures between the vehicle and one moving obstacle (a mover), by ground
//! truth: the time to collision ([`time_to_collision`]) and the post-encroachment time
//! ([`post_encroachment`]).
//!
//! Footprints. Each body is a set of [`Hull`]s in its own frame: a convex core (a point, a
//! segment or a polygon) grown by a radius. The vehicle's hulls are its URDF collision parts'
//! ground projections (`aircraft::Part::footprint`: exact for boxes, spheres, upright and lying
//! cylinders; a circumscribed polygon for tilted cylinders and capsules), and only the parts whose
//! vertical span `[underside, top]` overlaps the mover's `[z_min, z_min + height]` count: a
//! 1.0 m baggage cart does not conflict with a wing whose underside is above its top (heights as
//! the parts' own, not the collision model's levels, so the measure does not depend on the model
//! a run is configured with). A mover's hull is its solid's footprint: a box its rectangle, a
//! cylinder or a cone its base disc (a cone as its full base, whatever its height). Two bodies
//! touch when any two of their hulls are within [`TOUCH_M`].
//!
//! TTC: both bodies extrapolated from the instant judged, the vehicle along the arc of its
//! speed and yaw rate, the mover at constant velocity (its heading fixed); the first time within
//! [`TTC_HORIZON_S`] at which they touch, found by conservative advancement (each step the
//! distance over a bound of the relative speed of any two points, then a bisection to 1e-9 s
//! when a step of at least 1 ms overshot), so it misses no contact longer than a millisecond.
//!
//! PET: from the run's samples (every 0.1 s). The conflict area is where the vehicle's swept
//! footprint (the union of its footprints between consecutive samples, each the hull of the two
//! placements) and the mover's overlap; a body is in the conflict area at a sample when its
//! footprint then touches the other's swept footprint. Occupancy intervals are runs of such
//! samples; each enters and leaves halfway between its first (last) sample and the one before
//! (after). PET is the smallest gap between an interval of the first and the next of the other,
//! 0 when two share a sample (in it together), `None` when the swept footprints never overlap.

use std::collections::HashMap;

use aircraft::Part;
use aircraft::footprint::{Footprint, convex_hull, segments_distance};
use nalgebra::{Isometry2, Point2, Vector2};

use crate::world::{Solid, SolidShape};

/// How far ahead the time to collision looks, seconds.
pub const TTC_HORIZON_S: f64 = 10.0;
/// Two hulls this close touch, metres.
pub const TOUCH_M: f64 = 1e-9;
/// The smallest step of the conservative advancement, seconds.
const MIN_ADVANCE_S: f64 = 1e-3;

/// A convex core (vertices counter-clockwise; one point or a segment allowed) grown by a radius.
#[derive(Clone, Debug, PartialEq)]
pub struct Hull {
    core: Vec<Point2<f64>>,
    radius_m: f64,
    /// Centre and radius of a circle holding it.
    centre: Point2<f64>,
    reach_m: f64,
}

impl Hull {
    /// The hull of `points` grown by `radius_m`.
    pub fn new(points: &[Point2<f64>], radius_m: f64) -> Self {
        let core = convex_hull(points);
        let centre = if core.is_empty() {
            Point2::origin()
        } else {
            Point2::from(core.iter().map(|p| p.coords).sum::<Vector2<f64>>() / core.len() as f64)
        };
        let reach_m = core.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max) + radius_m;
        Hull {
            core,
            radius_m,
            centre,
            reach_m,
        }
    }

    /// A disc.
    pub fn disc(centre: Point2<f64>, radius_m: f64) -> Self {
        Hull::new(&[centre], radius_m)
    }

    fn placed(&self, pose: &Isometry2<f64>) -> Hull {
        Hull {
            core: self.core.iter().map(|p| pose * p).collect(),
            radius_m: self.radius_m,
            centre: pose * self.centre,
            reach_m: self.reach_m,
        }
    }

    /// The hull of this hull at two poses (a translation's swept footprint, exactly).
    fn swept(&self, a: &Isometry2<f64>, b: &Isometry2<f64>) -> Hull {
        let pts: Vec<Point2<f64>> = self.core.iter().flat_map(|p| [a * p, b * p]).collect();
        Hull::new(&pts, self.radius_m)
    }
}

/// A body's hulls in its own frame, and the radius about its origin that holds them.
#[derive(Clone, Debug, Default)]
pub struct Body {
    hulls: Vec<Hull>,
    radius_m: f64,
}

impl Body {
    /// A body of `hulls`.
    pub fn new(hulls: Vec<Hull>) -> Self {
        let radius_m = hulls
            .iter()
            .map(|h| h.centre.coords.norm() + h.reach_m)
            .fold(0.0, f64::max);
        Body { hulls, radius_m }
    }

    /// The vehicle's parts whose vertical span overlaps `[z_lo, z_hi]` (metres above ground).
    pub fn of_vehicle(parts: &[Part], z_lo: f64, z_hi: f64) -> Self {
        let hulls = parts
            .iter()
            .filter(|p| p.underside_m() < z_hi && p.top_m() > z_lo)
            .map(|p| match p.footprint() {
                Footprint::Disc(d) => Hull::disc(d.center, d.radius_m),
                Footprint::Polygon(poly) => Hull::new(poly.vertices(), 0.0),
            })
            .collect();
        Body::new(hulls)
    }

    /// A solid's footprint about its own axis (a box's rectangle, a cylinder's or cone's base).
    pub fn of_solid(solid: &Solid) -> Self {
        let hull = match solid.shape {
            SolidShape::Box { size_m } => {
                let (x, y) = (0.5 * size_m[0], 0.5 * size_m[1]);
                Hull::new(
                    &[
                        Point2::new(x, y),
                        Point2::new(-x, y),
                        Point2::new(-x, -y),
                        Point2::new(x, -y),
                    ],
                    0.0,
                )
            }
            SolidShape::Cylinder { radius_m, .. } | SolidShape::Cone { radius_m, .. } => {
                Hull::disc(Point2::origin(), radius_m)
            }
            // A parked aircraft's part never moves: its disc about the vehicle frame will do.
            SolidShape::Part { .. } => {
                Hull::disc(Point2::origin(), solid.shape.footprint_radius_m())
            }
        };
        Body::new(vec![hull])
    }

    /// True when no part counts (nothing of the vehicle can touch the mover).
    pub fn is_empty(&self) -> bool {
        self.hulls.is_empty()
    }

    fn placed(&self, pose: &Isometry2<f64>) -> Vec<Hull> {
        self.hulls.iter().map(|h| h.placed(pose)).collect()
    }

    fn swept(&self, a: &Isometry2<f64>, b: &Isometry2<f64>) -> Vec<Hull> {
        self.hulls.iter().map(|h| h.swept(a, b)).collect()
    }
}

fn cross(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// True when `p` is inside or on a counter-clockwise convex polygon of at least 3 vertices.
fn polygon_contains(poly: &[Point2<f64>], p: &Point2<f64>) -> bool {
    let n = poly.len();
    n >= 3 && (0..n).all(|i| cross(poly[(i + 1) % n] - poly[i], p - poly[i]) >= 0.0)
}

fn edges(core: &[Point2<f64>]) -> impl Iterator<Item = (&Point2<f64>, &Point2<f64>)> {
    let n = core.len();
    let count = if n <= 2 { n.min(1) } else { n };
    (0..count).map(move |i| (&core[i], &core[(i + 1) % n]))
}

/// The distance between two hulls, 0 when they overlap.
fn hull_distance(a: &Hull, b: &Hull) -> f64 {
    let (Some(a0), Some(b0)) = (a.core.first(), b.core.first()) else {
        return f64::INFINITY;
    };
    let core = if polygon_contains(&a.core, b0) || polygon_contains(&b.core, a0) {
        0.0
    } else {
        let mut d = f64::INFINITY;
        for ea in edges(&a.core) {
            for eb in edges(&b.core) {
                d = d.min(segments_distance(ea.0, ea.1, eb.0, eb.1));
            }
        }
        d
    };
    (core - a.radius_m - b.radius_m).max(0.0)
}

/// The distance between two placed bodies (0 when touching): stops at the first touch.
fn bodies_distance(a: &[Hull], b: &[Hull]) -> f64 {
    let mut best = f64::INFINITY;
    for ha in a {
        for hb in b {
            if (ha.centre - hb.centre).norm() - ha.reach_m - hb.reach_m >= best {
                continue;
            }
            best = best.min(hull_distance(ha, hb));
            if best <= TOUCH_M {
                return 0.0;
            }
        }
    }
    best
}

/// The distance between two bodies at their poses, metres (0 when touching).
pub fn distance(a: &Body, pa: &Isometry2<f64>, b: &Body, pb: &Isometry2<f64>) -> f64 {
    bodies_distance(&a.placed(pa), &b.placed(pb))
}

/// The vehicle's motion as extrapolated: its pose, speed along its heading and yaw rate.
#[derive(Clone, Copy, Debug)]
pub struct VehicleMotion {
    /// Pose of the vehicle frame.
    pub pose: Isometry2<f64>,
    /// Signed speed along the heading, m/s.
    pub speed_m_s: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_rad_s: f64,
}

impl VehicleMotion {
    /// The pose `tau_s` seconds on along the arc.
    pub fn at(&self, tau_s: f64) -> Isometry2<f64> {
        let (v, w) = (self.speed_m_s, self.yaw_rate_rad_s);
        let yaw0 = self.pose.rotation.angle();
        let dyaw = w * tau_s;
        let (dx, dy) = if dyaw.abs() < 1e-9 {
            (v * tau_s, 0.0)
        } else {
            let r = v / w;
            (r * dyaw.sin(), r * (1.0 - dyaw.cos()))
        };
        let (s, c) = yaw0.sin_cos();
        let t = self.pose.translation.vector + Vector2::new(c * dx - s * dy, s * dx + c * dy);
        Isometry2::new(t, yaw0 + dyaw)
    }
}

/// A mover's motion as extrapolated: its pose and velocity (its heading kept).
#[derive(Clone, Copy, Debug)]
pub struct MoverMotion {
    /// Pose of its solid's axis.
    pub pose: Isometry2<f64>,
    /// Velocity, m/s.
    pub velocity_m_s: Vector2<f64>,
}

impl MoverMotion {
    /// The pose `tau_s` seconds on.
    pub fn at(&self, tau_s: f64) -> Isometry2<f64> {
        Isometry2::new(
            self.pose.translation.vector + self.velocity_m_s * tau_s,
            self.pose.rotation.angle(),
        )
    }
}

/// The first time within [`TTC_HORIZON_S`] at which the vehicle and the mover, extrapolated,
/// touch (0 when they touch now); `None` if they do not.
pub fn time_to_collision(
    vehicle: &Body,
    vm: &VehicleMotion,
    mover: &Body,
    mm: &MoverMotion,
) -> Option<f64> {
    if vehicle.is_empty() || mover.is_empty() {
        return None;
    }
    // Any point of the vehicle moves at v h + w x r, |r| <= its radius.
    let heading = Vector2::new(
        vm.pose.rotation.angle().cos(),
        vm.pose.rotation.angle().sin(),
    );
    let bound = (heading * vm.speed_m_s - mm.velocity_m_s).norm()
        + vm.yaw_rate_rad_s.abs() * vehicle.radius_m;
    let dist = |tau: f64| {
        let (pv, pm) = (vm.at(tau), mm.at(tau));
        let far = (pv.translation.vector - pm.translation.vector).norm()
            - vehicle.radius_m
            - mover.radius_m;
        if far > TOUCH_M {
            far
        } else {
            distance(vehicle, &pv, mover, &pm)
        }
    };
    let (mut prev, mut tau) = (0.0, 0.0);
    loop {
        let d = dist(tau);
        if d <= TOUCH_M {
            if tau == 0.0 || tau - prev <= 0.0 {
                return Some(tau);
            }
            // The last step may have overshot the first touch: bisect back to it.
            let (mut lo, mut hi) = (prev, tau);
            while hi - lo > 1e-9 {
                let mid = 0.5 * (lo + hi);
                if dist(mid) <= TOUCH_M {
                    hi = mid
                } else {
                    lo = mid
                }
            }
            return Some(hi);
        }
        if bound <= 1e-12 || tau >= TTC_HORIZON_S {
            return None;
        }
        let exact = d / bound;
        prev = tau;
        tau = (tau + exact.max(MIN_ADVANCE_S)).min(TTC_HORIZON_S);
        if exact >= MIN_ADVANCE_S && tau < TTC_HORIZON_S {
            // A conservative step cannot pass a touch: no bisection needed after it.
            prev = tau;
        }
    }
}

/// The samples of a run the post-encroachment time is measured over.
pub struct Track<'a> {
    /// Sample times, seconds (increasing).
    pub t_s: &'a [f64],
    /// The vehicle's pose at each sample.
    pub vehicle: &'a [Isometry2<f64>],
    /// Whether the vehicle moved continuously from the sample before (false after the vehicle
    /// was put back at the start of an open route, and for the first sample).
    pub joined: &'a [bool],
    /// The mover's pose at each sample (`None`: absent).
    pub mover: &'a [Option<Isometry2<f64>>],
}

/// The post-encroachment time of an encounter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Encroachment {
    /// Seconds between the first leaving the conflict area and the second entering it (0: in it
    /// together).
    pub pet_s: f64,
    /// Whether the mover went through it first (`None`: in it together).
    pub mover_first: Option<bool>,
}

/// Runs of consecutive samples marked `inside` (and `linked` to the one before), as inclusive
/// index ranges with their enter and leave times (halfway to the neighbouring samples).
fn intervals(
    t: &[f64],
    inside: &[bool],
    linked: &dyn Fn(usize) -> bool,
) -> Vec<(usize, usize, f64, f64)> {
    let mut out: Vec<(usize, usize, f64, f64)> = Vec::new();
    let mut k = 0;
    while k < inside.len() {
        if !inside[k] {
            k += 1;
            continue;
        }
        let first = k;
        while k + 1 < inside.len() && inside[k + 1] && linked(k + 1) {
            k += 1;
        }
        let enter = if first > 0 && linked(first) {
            0.5 * (t[first - 1] + t[first])
        } else {
            t[first]
        };
        let leave = if k + 1 < t.len() && linked(k + 1) {
            0.5 * (t[k] + t[k + 1])
        } else {
            t[k]
        };
        out.push((first, k, enter, leave));
        k += 1;
    }
    out
}

/// Marks the samples at which each body touches the other's swept footprint.
fn occupancy(track: &Track<'_>, vehicle: &Body, mover: &Body) -> (Vec<bool>, Vec<bool>) {
    let n = track.t_s.len();
    let v_linked = |k: usize| k < n && track.joined[k];
    let m_linked =
        |k: usize| k < n && track.mover[k].is_some() && k > 0 && track.mover[k - 1].is_some();
    let v_next = |a: usize| {
        if v_linked(a + 1) {
            track.vehicle[a + 1]
        } else {
            track.vehicle[a]
        }
    };
    let m_next = |b: usize, pose: Isometry2<f64>| {
        if m_linked(b + 1) {
            track.mover[b + 1].unwrap_or(pose)
        } else {
            pose
        }
    };
    let step = |p: &Isometry2<f64>, q: &Isometry2<f64>| {
        (p.translation.vector - q.translation.vector).norm()
    };
    let v_step = (0..n)
        .map(|a| step(&track.vehicle[a], &v_next(a)))
        .fold(0.0, f64::max);
    let m_step = (0..n)
        .filter_map(|b| track.mover[b].map(|p| step(&p, &m_next(b, p))))
        .fold(0.0, f64::max);
    let reach = vehicle.radius_m + mover.radius_m + v_step + m_step + 1e-6;
    let cell = reach.max(0.5);
    let key = |p: &Isometry2<f64>| {
        (
            (p.translation.x / cell).floor() as i64,
            (p.translation.y / cell).floor() as i64,
        )
    };
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (b, pose) in track.mover.iter().enumerate() {
        if let Some(p) = pose {
            grid.entry(key(p)).or_default().push(b);
        }
    }
    let (mut in_v, mut in_m) = (vec![false; n], vec![false; n]);
    // Each mover sample's footprint and swept footprint, placed once when first needed.
    let mut mover_hulls: Vec<Option<(Vec<Hull>, Vec<Hull>)>> = vec![None; n];
    for (a, pv) in track.vehicle.iter().enumerate() {
        if a > 0 && v_linked(a) && track.vehicle[a - 1] == *pv && v_next(a) == *pv {
            // Standing: the same footprints as the sample before, found in the same places.
            in_v[a] = in_v[a - 1];
            continue;
        }
        let (kx, ky) = key(pv);
        // Placed and swept only when some mover sample is near.
        let mut placed: Option<(Vec<Hull>, Vec<Hull>)> = None;
        for cx in kx - 1..=kx + 1 {
            for cy in ky - 1..=ky + 1 {
                for &b in grid.get(&(cx, cy)).map_or(&[][..], Vec::as_slice) {
                    let Some(pm) = track.mover[b] else { continue };
                    if (in_v[a] && in_m[b]) || step(pv, &pm) > reach {
                        continue;
                    }
                    let (v_now, v_swept) = placed
                        .get_or_insert_with(|| (vehicle.placed(pv), vehicle.swept(pv, &v_next(a))));
                    let (m_now, m_swept) = mover_hulls[b].get_or_insert_with(|| {
                        (mover.placed(&pm), mover.swept(&pm, &m_next(b, pm)))
                    });
                    if !in_v[a] && bodies_distance(v_now, m_swept) <= TOUCH_M {
                        in_v[a] = true;
                    }
                    if !in_m[b] && bodies_distance(v_swept, m_now) <= TOUCH_M {
                        in_m[b] = true;
                    }
                }
            }
        }
    }
    (in_v, in_m)
}

/// The post-encroachment time over `track` (see the module's doc): the encounter of smallest
/// PET, `None` if the swept footprints never overlap.
pub fn post_encroachment(track: &Track<'_>, vehicle: &Body, mover: &Body) -> Option<Encroachment> {
    if vehicle.is_empty() || mover.is_empty() || track.t_s.is_empty() {
        return None;
    }
    let (in_v, in_m) = occupancy(track, vehicle, mover);
    let n = track.t_s.len();
    let v_linked = |k: usize| k < n && track.joined[k];
    let m_linked =
        |k: usize| k < n && k > 0 && track.mover[k].is_some() && track.mover[k - 1].is_some();
    let vs = intervals(track.t_s, &in_v, &v_linked);
    let ms = intervals(track.t_s, &in_m, &m_linked);
    let mut best: Option<Encroachment> = None;
    for v in &vs {
        for m in &ms {
            let e = if v.0 <= m.1 && m.0 <= v.1 {
                Encroachment {
                    pet_s: 0.0,
                    mover_first: None,
                }
            } else if v.1 < m.0 {
                Encroachment {
                    pet_s: (m.2 - v.3).max(0.0),
                    mover_first: Some(false),
                }
            } else {
                Encroachment {
                    pet_s: (v.2 - m.3).max(0.0),
                    mover_first: Some(true),
                }
            };
            if best.is_none_or(|b| e.pet_s < b.pet_s) {
                best = Some(e);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc_body(r: f64) -> Body {
        Body::new(vec![Hull::disc(Point2::origin(), r)])
    }

    #[test]
    fn ttc_of_two_discs_closing_head_on_is_gap_over_closing_speed() {
        // Vehicle disc r 1 at the origin heading +x at 3 m/s; mover disc r 0.5 at x = 20
        // coming at 2 m/s: gap 18.5 m, closing 5 m/s.
        let vm = VehicleMotion {
            pose: Isometry2::identity(),
            speed_m_s: 3.0,
            yaw_rate_rad_s: 0.0,
        };
        let mm = MoverMotion {
            pose: Isometry2::new(Vector2::new(20.0, 0.0), 0.3),
            velocity_m_s: Vector2::new(-2.0, 0.0),
        };
        let ttc = time_to_collision(&disc_body(1.0), &vm, &disc_body(0.5), &mm).unwrap();
        assert!((ttc - 18.5 / 5.0).abs() < 1e-6, "{ttc}");
        // Offset by the sum of radii minus a bit, still touching; a box mover too.
        let mm_box = MoverMotion {
            pose: Isometry2::new(Vector2::new(20.0, 0.0), 0.0),
            velocity_m_s: Vector2::new(-2.0, 0.0),
        };
        let solid = Solid {
            id: "van".into(),
            kind: crate::world::ObjectKind::Vehicle,
            shape: SolidShape::Box {
                size_m: [4.0, 2.0, 2.0],
            },
            x_m: 0.0,
            y_m: 0.0,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.3,
            runtime: true,
        };
        let ttc =
            time_to_collision(&disc_body(1.0), &vm, &Body::of_solid(&solid), &mm_box).unwrap();
        assert!((ttc - 17.0 / 5.0).abs() < 1e-6, "{ttc}");
        // Now: overlapping.
        let vm_now = VehicleMotion {
            pose: Isometry2::new(Vector2::new(19.0, 0.0), 0.0),
            ..vm
        };
        assert_eq!(
            time_to_collision(&disc_body(1.0), &vm_now, &disc_body(0.5), &mm),
            Some(0.0)
        );
    }

    #[test]
    fn ttc_of_parallel_discs_and_beyond_the_horizon_is_none() {
        let vm = VehicleMotion {
            pose: Isometry2::identity(),
            speed_m_s: 3.0,
            yaw_rate_rad_s: 0.0,
        };
        // Parallel, 2 m apart (radii 0.5 each), any speeds.
        for u in [0.0, 3.0, 5.0, -4.0] {
            let mm = MoverMotion {
                pose: Isometry2::new(Vector2::new(-10.0, 2.0), 0.0),
                velocity_m_s: Vector2::new(u, 0.0),
            };
            assert_eq!(
                time_to_collision(&disc_body(0.5), &vm, &disc_body(0.5), &mm),
                None
            );
        }
        // Head-on but 60 m apart at 5 m/s closing: 11.8 s, beyond 10 s.
        let mm = MoverMotion {
            pose: Isometry2::new(Vector2::new(60.0, 0.0), 0.0),
            velocity_m_s: Vector2::new(-2.0, 0.0),
        };
        assert_eq!(
            time_to_collision(&disc_body(0.5), &vm, &disc_body(0.5), &mm),
            None
        );
    }

    #[test]
    fn ttc_on_an_arc_finds_the_touch_and_a_grazing_miss_is_none() {
        // Turning left at 2 m/s, 0.2 rad/s: a circle of radius 10 about (0, 10). A still disc
        // on that circle a quarter turn on (at (10, 10)) is reached at (pi/2) / 0.2 s less the
        // arc of the radii.
        let vm = VehicleMotion {
            pose: Isometry2::identity(),
            speed_m_s: 2.0,
            yaw_rate_rad_s: 0.2,
        };
        let mm = MoverMotion {
            pose: Isometry2::new(Vector2::new(10.0, 10.0), 0.0),
            velocity_m_s: Vector2::zeros(),
        };
        let ttc = time_to_collision(&disc_body(0.25), &vm, &disc_body(0.25), &mm).unwrap();
        // Chord of 0.5 m on a 10 m circle: angle 2 asin(0.025).
        let want = (std::f64::consts::FRAC_PI_2 - 2.0 * (0.025f64).asin()) / 0.2;
        assert!((ttc - want).abs() < 1e-6, "{ttc} vs {want}");
        // 0.6 m outside the circle (radii 0.5 together): a miss, and a full turn takes 31 s.
        let beside = MoverMotion {
            pose: Isometry2::new(Vector2::new(10.6, 10.0), 0.0),
            ..mm
        };
        assert_eq!(
            time_to_collision(&disc_body(0.25), &vm, &disc_body(0.25), &beside),
            None
        );
    }

    /// The vehicle drives along +x at `v`, crossing x = 0 at 5 s; the mover along +y at `u`,
    /// crossing y = 0 at 8 s; samples every 0.1 s for 15 s.
    fn crossing(r: f64, v: f64, u: f64) -> Option<Encroachment> {
        let t: Vec<f64> = (0..=150).map(|k| 0.1 * k as f64).collect();
        let vehicle: Vec<Isometry2<f64>> = t
            .iter()
            .map(|t| Isometry2::new(Vector2::new(v * (t - 5.0), 0.0), 0.0))
            .collect();
        let mover: Vec<Option<Isometry2<f64>>> = t
            .iter()
            .map(|t| Some(Isometry2::new(Vector2::new(0.0, u * (t - 8.0)), 1.0)))
            .collect();
        let joined: Vec<bool> = (0..t.len()).map(|k| k > 0).collect();
        let track = Track {
            t_s: &t,
            vehicle: &vehicle,
            joined: &joined,
            mover: &mover,
        };
        post_encroachment(&track, &disc_body(r), &disc_body(r))
    }

    #[test]
    fn pet_of_a_crossing_three_seconds_apart() {
        // Near-points: PET 3 s within the sampling step.
        let e = crossing(0.001, 2.0, 2.0).unwrap();
        assert!((e.pet_s - 3.0).abs() <= 0.1 + 1e-9, "{e:?}");
        assert_eq!(e.mover_first, Some(false));
        // Discs of 0.1 m: the conflict area is the square of side 0.2 m; the vehicle leaves it
        // at 5 + 2r/v, the mover enters at 8 - 2r/u: PET 2.8 s.
        let e = crossing(0.1, 2.0, 2.0).unwrap();
        assert!((e.pet_s - 2.8).abs() <= 0.1, "{e:?}");
        // A mover too fast for the samples to overlap still makes a conflict (swept hulls).
        // Analytic: 3 - 0.1 / 2 - 0.1 / 15 s.
        let e = crossing(0.05, 2.0, 15.0).unwrap();
        assert!((e.pet_s - (3.0 - 0.05 - 0.1 / 15.0)).abs() <= 0.1, "{e:?}");
    }

    #[test]
    fn pet_is_zero_together_and_none_without_conflict() {
        let t: Vec<f64> = (0..=100).map(|k| 0.1 * k as f64).collect();
        let vehicle: Vec<Isometry2<f64>> = t
            .iter()
            .map(|t| Isometry2::new(Vector2::new(2.0 * (t - 5.0), 0.0), 0.0))
            .collect();
        let joined: Vec<bool> = (0..t.len()).map(|k| k > 0).collect();
        // Crossing at the same time: 0.
        let same: Vec<Option<Isometry2<f64>>> = t
            .iter()
            .map(|t| Some(Isometry2::new(Vector2::new(0.0, 2.0 * (t - 5.0)), 0.0)))
            .collect();
        let track = Track {
            t_s: &t,
            vehicle: &vehicle,
            joined: &joined,
            mover: &same,
        };
        let e = post_encroachment(&track, &disc_body(0.5), &disc_body(0.5)).unwrap();
        assert_eq!(
            e,
            Encroachment {
                pet_s: 0.0,
                mover_first: None
            }
        );
        // Driving parallel 5 m to the side: no conflict area.
        let side: Vec<Option<Isometry2<f64>>> = t
            .iter()
            .map(|t| Some(Isometry2::new(Vector2::new(3.0 * t, 5.0), 0.0)))
            .collect();
        let track = Track {
            t_s: &t,
            vehicle: &vehicle,
            joined: &joined,
            mover: &side,
        };
        assert_eq!(
            post_encroachment(&track, &disc_body(0.5), &disc_body(0.5)),
            None
        );
    }

    #[test]
    fn a_low_mover_ignores_the_parts_above_it() {
        let wing = Part {
            link: "wing".into(),
            collision_index: 0,
            shape: aircraft::Shape::Box {
                half_extents_m: nalgebra::Vector3::new(1.0, 8.0, 0.1),
            },
            vehicle_from_part: nalgebra::Isometry3::translation(0.0, 0.0, 2.0),
        };
        let gear = Part {
            link: "gear".into(),
            collision_index: 0,
            shape: aircraft::Shape::Sphere { radius_m: 0.4 },
            vehicle_from_part: nalgebra::Isometry3::translation(0.0, 0.0, 0.4),
        };
        let parts = [wing, gear];
        let low = Body::of_vehicle(&parts, 0.0, 1.0);
        assert_eq!(low.hulls.len(), 1);
        assert!((low.radius_m - 0.4).abs() < 1e-9);
        assert_eq!(Body::of_vehicle(&parts, 0.0, 3.0).hulls.len(), 2);
    }
}
