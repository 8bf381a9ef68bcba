//! Leaving a stand as the file places the aircraft on it: at the stand's point, on its heading.
//! An aircraft whose taxilane lies behind it (a gate, parked nose in) is pushed back by a tug -
//! tail first down the stand's axis to the taxilane, turned onto it to face the way the route
//! goes, and released a few metres on - then taxis on its own; one that faces its taxilane (a
//! tie-down parked nose out) taxis out on its own from the stand. The route found on the network
//! starts where the stand's axis meets its taxilane (`route::stand_join`), which this module
//! takes as the corner of both.

use nalgebra::Vector2;

use crate::error::AirportError;
use crate::model::Stand;
use crate::network::NetworkRoute;
use crate::path::{PathOptions, smooth};

/// Straight on the taxilane past the push-back's turn before the tug lets go (m).
pub const RELEASE_STRAIGHT_M: f64 = 5.0;

/// A push-back: the aircraft's poses (position, heading in rad from east) as the tug moves it,
/// from the stand to the release point, at most a metre apart on the turn.
#[derive(Debug, Clone, PartialEq)]
pub struct Tow {
    /// The poses, the stand's first.
    pub poses: Vec<(Vector2<f64>, f64)>,
    /// The tightest turn the tug makes (m).
    pub radius_m: f64,
    /// Its length (m).
    pub length_m: f64,
}

/// `route` (from `stand`, starting where the stand's axis meets its taxilane) made to start at
/// the stand: with the stand's point first when the aircraft faces its taxilane (it taxis out),
/// or, when the taxilane lies behind it, from the push-back's release point, with the push-back
/// (a turn of `radius_m` at most, tighter where the stand is nearer its taxilane than that).
///
/// # Errors
/// A route of fewer than two points, or a push-back whose turn cannot be drawn.
pub fn leave_stand(
    stand: &Stand,
    route: &NetworkRoute,
    radius_m: f64,
) -> Result<(NetworkRoute, Option<Tow>), AirportError> {
    let fail = |why: String| AirportError::Route {
        from: route.from.clone(),
        to: route.to.clone(),
        why,
    };
    let (s, heading) = (
        stand.at,
        Vector2::new(stand.yaw_rad.cos(), stand.yaw_rad.sin()),
    );
    let k = *route
        .points
        .first()
        .ok_or_else(|| fail("an empty route".into()))?;
    let next = route
        .points
        .iter()
        .skip(1)
        .find(|p| (*p - k).norm() > 1.0)
        .ok_or_else(|| fail("a route that ends where it leaves the stand".into()))?;
    let mut out = route.clone();
    // Where the stand's axis comes abeam the join point: the aircraft moves along its axis
    // first, so that it leaves the stand on its heading whatever the join's bearing.
    let ahead = (k - s).dot(&heading);
    let abeam = |sign: f64| {
        let lateral = (k - (s + heading * ahead)).norm();
        // Room to turn towards the join: at least the turn's radius along the axis.
        let along = if lateral > 1.0 {
            ahead.abs().max(radius_m + 1.0)
        } else {
            ahead.abs()
        };
        s + heading * sign * along
    };
    if ahead >= 0.0 || (k - s).norm() < radius_m + 1.0 {
        // Facing the taxilane, or standing on it (a ramp start on the network): out on its
        // own, from the stand.
        let a = abeam(1.0);
        let mut lead = vec![s];
        if (a - k).norm() > 1.0 && (a - s).norm() > 1.0 {
            lead.push(a);
        }
        for (i, p) in lead.iter().enumerate() {
            out.points.insert(i, *p);
            out.nodes.insert(i, None);
            out.edges.insert(i, None);
        }
        out.length_m = out.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        return Ok((out, None));
    }
    let d = (next - k).normalize();
    // Tail first down the axis to abeam the join, then (where the axis misses it) across.
    let a = abeam(-1.0);
    let mut tow_points = vec![s];
    if (a - k).norm() > 1.0 {
        tow_points.push(a);
    }
    let u1 = (k - tow_points[tow_points.len() - 1]).normalize();
    let u2 = -d;
    let turn = u1.dot(&u2).clamp(-1.0, 1.0).acos();
    let tangent = |r: f64| r * (turn / 2.0).tan();
    // Room on the last leg for the turn: a tighter one where there is less.
    let leg = (k - tow_points[tow_points.len() - 1]).norm();
    let radius = if tangent(radius_m) + 1.0 > leg && turn > 1e-3 {
        (leg - 1.0).max(1.0) / (turn / 2.0).tan()
    } else {
        radius_m
    };
    let release = k + u2 * (tangent(radius) + RELEASE_STRAIGHT_M);
    tow_points.extend([k, release]);
    let corner = NetworkRoute {
        from: stand.name.clone(),
        to: "the push-back's release point".into(),
        nodes: vec![None; tow_points.len()],
        edges: vec![None; tow_points.len() - 1],
        taxiways: Vec::new(),
        crossings: Vec::new(),
        length_m: tow_points.windows(2).map(|w| (w[1] - w[0]).norm()).sum(),
        points: tow_points,
    };
    let options = PathOptions {
        turn_radius_m: radius,
        max_corner_cut_m: f64::INFINITY,
        min_turn_radius_m: radius.min(1.0),
        straight_speed_m_s: 1.0,
        lateral_acceleration_m_s2: 1.0,
        deceleration_m_s2: 1.0,
    };
    let path = smooth(&corner, &options).map_err(|e| fail(format!("the push-back: {e}")))?;
    let n = path.points.len();
    let poses = (0..n)
        .map(|i| {
            // The path's tangent (central differences: exact on the arcs' equal chords), tail
            // first: the nose points against the way it moves.
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            let travel = path.points[b] - path.points[a];
            let yaw = if i == 0 {
                stand.yaw_rad
            } else {
                (-travel.y).atan2(-travel.x)
            };
            (path.points[i], yaw)
        })
        .collect();
    // Taxiing from the release point: along the taxilane through the corner and on.
    out.points[0] = release;
    out.nodes[0] = None;
    out.length_m = out.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    Ok((
        out,
        Some(Tow {
            poses,
            radius_m: radius,
            length_m: path.length_m,
        }),
    ))
}
