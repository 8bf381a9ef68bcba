//! A network route rounded into a path an aircraft can drive: a fillet (circular arc) at every
//! corner, as wide as `turn_radius_m` where the legs leave room and the arc stays within
//! `max_corner_cut_m` of the corner (a junction's pavement), never tighter than the aircraft
//! turns; and the speed pilots taxi at - `straight_speed_m_s` on straights, in turns
//! what `lateral_acceleration_m_s2` allows, slowed beforehand at `deceleration_m_s2`.

use nalgebra::Vector2;

use crate::error::AirportError;
use crate::network::NetworkRoute;

/// How a route is rounded and how fast it is driven.
#[derive(Debug, Clone, Copy)]
pub struct PathOptions {
    /// The radius of a turn where there is room (m).
    pub turn_radius_m: f64,
    /// How far inside a corner the arc may pass (m): a junction's fillet pavement. A sharp turn
    /// gets a tighter radius (90 degrees and 2.5 m: 6 m), down to the aircraft's tightest.
    pub max_corner_cut_m: f64,
    /// The aircraft's tightest turn (m): a corner with less room is an error.
    pub min_turn_radius_m: f64,
    /// Speed on straights (m/s).
    pub straight_speed_m_s: f64,
    /// Lateral acceleration in turns (m/s^2): v = sqrt(a r).
    pub lateral_acceleration_m_s2: f64,
    /// Braking into a turn (m/s^2).
    pub deceleration_m_s2: f64,
}

/// The drivable path.
#[derive(Debug, Clone)]
pub struct TaxiPath {
    /// Its points, at most 1 m apart on arcs.
    pub points: Vec<Vector2<f64>>,
    /// The speed limit at each point (m/s).
    pub speed_m_s: Vec<f64>,
    /// The tightest fillet's radius (m; infinite on a straight route).
    pub tightest_radius_m: f64,
    /// Length (m).
    pub length_m: f64,
}

/// Longest chord of an arc (m).
const ARC_CHORD_M: f64 = 1.0;
/// Longest step along a straight (m): the speed limits between points are interpolated, so a
/// straight's braking into the next turn needs points along it.
const STRAIGHT_STEP_M: f64 = 5.0;
/// Corners turning less than this are left as they are (rad).
pub(crate) const STRAIGHT_RAD: f64 = 1e-4;

/// Rounds `route` and gives it its speeds.
///
/// # Errors
/// A corner whose legs leave no room for a turn the aircraft can make (`AirportError::Route`,
/// naming the node, the turn and the radius it has room for).
pub fn smooth(route: &NetworkRoute, options: &PathOptions) -> Result<TaxiPath, AirportError> {
    let p = &route.points;
    let n = p.len();
    let legs: Vec<f64> = p.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let Corners {
        deflection,
        tangent,
        ..
    } = corners(p, options);
    let mut points = vec![p[0]];
    let mut curvature = vec![0.0];
    let mut tightest = f64::INFINITY;
    for i in 1..n.saturating_sub(1) {
        if deflection[i] < STRAIGHT_RAD {
            continue;
        }
        let radius = tangent[i] / (deflection[i] / 2.0).tan();
        if radius < options.min_turn_radius_m - 1e-9 {
            let node = route.nodes[i].map_or_else(
                || format!("the corner at ({:.1}, {:.1})", p[i].x, p[i].y),
                |k| format!("network node {k}"),
            );
            return Err(AirportError::Route {
                from: route.from.clone(),
                to: route.to.clone(),
                why: format!(
                    "turn too sharp at {node}: a {:.0}-degree turn between legs of {:.1} m and {:.1} m has room for a {radius:.1} m radius; the aircraft turns no tighter than {:.1} m",
                    deflection[i].to_degrees(),
                    legs[i - 1],
                    legs[i],
                    options.min_turn_radius_m
                ),
            });
        }
        tightest = tightest.min(radius);
        let (u, v) = ((p[i] - p[i - 1]).normalize(), (p[i + 1] - p[i]).normalize());
        let (a, b) = (p[i] - u * tangent[i], p[i] + v * tangent[i]);
        let left = u.perp(&v) > 0.0;
        let normal = if left {
            Vector2::new(-u.y, u.x)
        } else {
            Vector2::new(u.y, -u.x)
        };
        let centre = a + normal * radius;
        let pieces = ((radius * deflection[i] / ARC_CHORD_M).ceil() as usize).max(1);
        let start_angle = (a - centre).y.atan2((a - centre).x);
        let sweep = if left { deflection[i] } else { -deflection[i] };
        straight_to(&mut points, &mut curvature, a);
        push(&mut points, &mut curvature, a, 1.0 / radius);
        for k in 1..pieces {
            let angle = start_angle + sweep * k as f64 / pieces as f64;
            push(
                &mut points,
                &mut curvature,
                centre + Vector2::new(angle.cos(), angle.sin()) * radius,
                1.0 / radius,
            );
        }
        push(&mut points, &mut curvature, b, 0.0);
    }
    straight_to(&mut points, &mut curvature, p[n - 1]);
    push(&mut points, &mut curvature, p[n - 1], 0.0);
    let speed_m_s = speeds(&points, &curvature, options);
    let length_m = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    Ok(TaxiPath {
        points,
        speed_m_s,
        tightest_radius_m: tightest,
        length_m,
    })
}

/// Each corner of a polyline as [`smooth`] rounds it (the ends' entries are 0).
#[derive(Debug, Clone)]
pub(crate) struct Corners {
    /// Deflection from straight on (rad).
    pub deflection: Vec<f64>,
    /// How far along each leg the fillet would reach with the legs to itself (m).
    pub wanted: Vec<f64>,
    /// How far it reaches, each leg shared between its two corners in proportion to what they
    /// want of it (m); the fillet's radius is `tangent / tan(deflection / 2)`.
    pub tangent: Vec<f64>,
}

/// The fillets of `p`'s corners as [`smooth`] makes them.
pub(crate) fn corners(p: &[Vector2<f64>], options: &PathOptions) -> Corners {
    let n = p.len();
    let legs: Vec<f64> = p.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let mut deflection = vec![0.0; n];
    let mut wanted = vec![0.0; n];
    for i in 1..n.saturating_sub(1) {
        let (u, v) = ((p[i] - p[i - 1]).normalize(), (p[i + 1] - p[i]).normalize());
        deflection[i] = u.dot(&v).clamp(-1.0, 1.0).acos();
        // The arc's middle lies r (1 / cos(d/2) - 1) inside the corner.
        let cut_per_m = 1.0 / (deflection[i] / 2.0).cos() - 1.0;
        let radius = if cut_per_m > 0.0 {
            options
                .turn_radius_m
                .min(options.max_corner_cut_m / cut_per_m)
        } else {
            options.turn_radius_m
        };
        wanted[i] = radius.max(options.min_turn_radius_m) * (deflection[i] / 2.0).tan();
    }
    // Each leg is shared between its two corners in proportion to what they want of it.
    let mut tangent = wanted.clone();
    for i in 1..n.saturating_sub(1) {
        for leg in [i - 1, i] {
            let demand = wanted[leg] + wanted[leg + 1];
            if demand > legs[leg] {
                tangent[i] = tangent[i].min(legs[leg] * wanted[i] / demand);
            }
        }
    }
    Corners {
        deflection,
        wanted,
        tangent,
    }
}

/// Points every [`STRAIGHT_STEP_M`] from the last point toward `to` (`to` left out).
fn straight_to(points: &mut Vec<Vector2<f64>>, curvature: &mut Vec<f64>, to: Vector2<f64>) {
    let Some(&from) = points.last() else { return };
    let steps = ((to - from).norm() / STRAIGHT_STEP_M).ceil() as usize;
    for k in 1..steps {
        push(
            points,
            curvature,
            from + (to - from) * (k as f64 / steps as f64),
            0.0,
        );
    }
}

/// Adds a point (the curvature is that of the piece leaving it), skipping one on the last.
fn push(points: &mut Vec<Vector2<f64>>, curvature: &mut Vec<f64>, at: Vector2<f64>, kappa: f64) {
    if points.last().is_some_and(|last| (last - at).norm() < 1e-6) {
        if let Some(k) = curvature.last_mut() {
            *k = k.max(kappa);
        }
        return;
    }
    points.push(at);
    curvature.push(kappa);
}

/// The speed limit at each point: the turns' limits, reached by braking at `deceleration_m_s2`.
fn speeds(points: &[Vector2<f64>], curvature: &[f64], options: &PathOptions) -> Vec<f64> {
    let turn = |kappa: f64| {
        if kappa > 0.0 {
            (options.lateral_acceleration_m_s2 / kappa).sqrt()
        } else {
            f64::INFINITY
        }
    };
    let n = points.len();
    let mut v: Vec<f64> = (0..n)
        .map(|i| {
            let before = if i > 0 {
                turn(curvature[i - 1])
            } else {
                f64::INFINITY
            };
            options
                .straight_speed_m_s
                .min(turn(curvature[i]))
                .min(before)
        })
        .collect();
    for i in (0..n.saturating_sub(1)).rev() {
        let d = (points[i + 1] - points[i]).norm();
        v[i] = v[i].min((v[i + 1] * v[i + 1] + 2.0 * options.deceleration_m_s2 * d).sqrt());
    }
    v
}
