//! The start overlap: whether a solid meets the vehicle at its start pose ([`start_overlap`]),
//! or anywhere along a path of poses ([`sweep_overlap`]) - its way on a taxi route, the
//! push-back's tow and the route ([`taxi_way`], poses [`densified`]) - from the parts' and the
//! solid's ground footprints and height ranges.

use aircraft::footprint::{ConvexPolygon, Disc, Footprint};
use nalgebra::{Isometry2, Point2, Vector2};

use crate::world::{Solid, SolidShape};

/// Gap under which two footprints touch, metres.
const TOUCH_M: f64 = 1e-9;

/// The first vehicle part a solid overlaps with the vehicle at `world_from_vehicle`, described.
///
/// A part and a solid overlap when their ground footprints intersect and their height ranges
/// intersect (open intervals: touching is not overlapping). Footprints: a part's exact projection
/// ([`aircraft::Part::footprint`]); a box's rectangle; a cone's or cylinder's base disc (a cone
/// is treated as its bounding cylinder, which is conservative).
pub fn start_overlap(
    vehicle: &aircraft::Vehicle,
    world_from_vehicle: &Isometry2<f64>,
    solid: &Solid,
) -> Option<String> {
    let (lo, hi) = solid.shape.z_range_m(solid.z_min_m);
    let footprint = solid_footprint_in_vehicle(solid, world_from_vehicle);
    vehicle.parts.iter().find_map(|part| {
        let (under, top) = (part.underside_m(), part.top_m());
        let heights = lo < top && under < hi;
        (heights && footprints_intersect(&footprint, &part.footprint())).then(|| {
            format!(
                "it meets link `{}` collision {} (z {:.2}..{:.2} m)",
                part.link, part.collision_index, under, top
            )
        })
    })
}

/// The first of `poses` at which a solid meets the vehicle, with which part (as
/// [`start_overlap`]). Poses where the solid's footprint lies beyond the vehicle's reach are
/// skipped untested.
pub fn sweep_overlap(
    vehicle: &aircraft::Vehicle,
    poses: &[Isometry2<f64>],
    solid: &Solid,
) -> Option<(usize, String)> {
    let reach_m = (vehicle.parts.iter())
        .map(|p| {
            let (lo, hi) = p.footprint().bounds();
            lo.coords.abs().sup(&hi.coords.abs()).norm()
        })
        .fold(0.0, f64::max);
    let (lo, hi) = solid_footprint_in_vehicle(solid, &Isometry2::identity()).bounds();
    poses.iter().enumerate().find_map(|(i, pose)| {
        let at = Point2::from(pose.translation.vector);
        let nearest = at.sup(&lo).inf(&hi);
        ((nearest - at).norm() < reach_m)
            .then(|| start_overlap(vehicle, pose, solid))
            .flatten()
            .map(|why| (i, why))
    })
}

/// The vehicle's way on a taxi route, poses at most `step_m` apart: the push-back's tow, if any,
/// then the route's waypoints, each facing along the route there (central differences: the
/// tangent of an arc of equal chords; an end, its one leg); and how many of the poses are the
/// tow's.
pub fn taxi_way(route: &super::model::Route, step_m: f64) -> (Vec<Isometry2<f64>>, usize) {
    let w = &route.waypoints_m;
    let n = w.len();
    let path: Vec<(Vector2<f64>, f64)> = if n < 2 {
        Vec::new()
    } else {
        (0..n)
            .map(|i| {
                let d = w[(i + 1).min(n - 1)] - w[i.saturating_sub(1)];
                (w[i].coords, d.y.atan2(d.x))
            })
            .collect()
    };
    let mut way = route
        .pushback
        .as_ref()
        .map_or_else(Vec::new, |t| densified(&t.poses, step_m));
    let towed = way.len();
    way.extend(densified(&path, step_m));
    (way, towed)
}

/// Poses `(position, heading)` made at most `step_m` apart: positions in a straight line,
/// headings turned the shorter way between each two given.
pub fn densified(poses: &[(Vector2<f64>, f64)], step_m: f64) -> Vec<Isometry2<f64>> {
    let mut out: Vec<Isometry2<f64>> = poses
        .first()
        .map(|(p, yaw)| Isometry2::new(*p, *yaw))
        .into_iter()
        .collect();
    for w in poses.windows(2) {
        let ((a, ya), (b, yb)) = (w[0], w[1]);
        let turn = crate::world::wrap_angle(yb - ya);
        let n = ((b - a).norm() / step_m).ceil().max(1.0) as usize;
        out.extend((1..=n).map(|k| {
            let f = k as f64 / n as f64;
            Isometry2::new(a + (b - a) * f, ya + turn * f)
        }));
    }
    out
}

/// A solid's ground footprint in the vehicle frame.
fn solid_footprint_in_vehicle(solid: &Solid, world_from_vehicle: &Isometry2<f64>) -> Footprint {
    let vehicle_from_world = world_from_vehicle.inverse();
    let center = vehicle_from_world * Point2::new(solid.x_m, solid.y_m);
    if let Some(part) = solid.shape.as_part() {
        // The part's footprint in its vehicle frame, placed by the solid, into the vehicle's.
        let placed =
            vehicle_from_world * Isometry2::new(Vector2::new(solid.x_m, solid.y_m), solid.yaw_rad);
        return match part.footprint() {
            Footprint::Disc(d) => Footprint::Disc(Disc {
                center: placed * d.center,
                radius_m: d.radius_m,
            }),
            Footprint::Polygon(p) => {
                let corners: Vec<Point2<f64>> = p.vertices().iter().map(|v| placed * v).collect();
                ConvexPolygon::hull(&corners).map_or(
                    Footprint::Disc(Disc {
                        center,
                        radius_m: 0.0,
                    }),
                    Footprint::Polygon,
                )
            }
        };
    }
    match solid.shape {
        SolidShape::Cone { radius_m, .. } | SolidShape::Cylinder { radius_m, .. } => {
            Footprint::Disc(Disc { center, radius_m })
        }
        SolidShape::Part { .. } => Footprint::Disc(Disc {
            center,
            radius_m: solid.shape.footprint_radius_m(),
        }),
        SolidShape::Box { size_m } => {
            let yaw = solid.yaw_rad - world_from_vehicle.rotation.angle();
            let (s, c) = yaw.sin_cos();
            let (u, v) = (
                Vector2::new(c, s) * (0.5 * size_m[0]),
                Vector2::new(-s, c) * (0.5 * size_m[1]),
            );
            let corners = [
                center + u + v,
                center - u + v,
                center - u - v,
                center + u - v,
            ];
            match ConvexPolygon::hull(&corners) {
                Some(p) => Footprint::Polygon(p),
                None => Footprint::Disc(Disc {
                    center,
                    radius_m: 0.5 * size_m[0].hypot(size_m[1]),
                }),
            }
        }
    }
}

fn project(points: &[Point2<f64>], axis: &Vector2<f64>) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let d = axis.dot(&p.coords);
            (lo.min(d), hi.max(d))
        })
}

/// True when two convex footprints overlap by more than [`TOUCH_M`] (separating axes).
fn footprints_intersect(a: &Footprint, b: &Footprint) -> bool {
    match (a, b) {
        (Footprint::Disc(p), Footprint::Disc(q)) => {
            (p.center - q.center).norm() < p.radius_m + q.radius_m - TOUCH_M
        }
        (Footprint::Polygon(poly), Footprint::Disc(d))
        | (Footprint::Disc(d), Footprint::Polygon(poly)) => {
            poly.distance(&d.center) < d.radius_m - TOUCH_M
        }
        (Footprint::Polygon(p), Footprint::Polygon(q)) => {
            let axes = [p, q].into_iter().flat_map(|poly| {
                let v = poly.vertices();
                (0..v.len()).map(move |i| {
                    let e = v[(i + 1) % v.len()] - v[i];
                    Vector2::new(-e.y, e.x).normalize()
                })
            });
            for axis in axes {
                let (p_lo, p_hi) = project(p.vertices(), &axis);
                let (q_lo, q_hi) = project(q.vertices(), &axis);
                if p_hi <= q_lo + TOUCH_M || q_hi <= p_lo + TOUCH_M {
                    return false;
                }
            }
            true
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::ObjectKind;

    fn block(x_m: f64, y_m: f64, height_m: f64) -> Solid {
        Solid {
            id: "block".into(),
            kind: ObjectKind::Container,
            shape: SolidShape::Box {
                size_m: [1.0, 1.0, height_m],
            },
            x_m,
            y_m,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.5,
            runtime: false,
        }
    }

    #[test]
    fn a_tow_meets_what_its_wing_sweeps_not_what_lies_beyond_the_tip_or_under_the_wing() {
        let jet = aircraft::Vehicle::shipped("praetor600").unwrap();
        let half_span = jet.span_m() / 2.0;
        // Pushed back tail first 30 m along -x, nose east.
        let tow = densified(
            &[(Vector2::zeros(), 0.0), (Vector2::new(-30.0, 0.0), 0.0)],
            0.5,
        );
        assert_eq!(tow.len(), 61);
        // A 3 m block 20 m behind the start, half a span out: the wing meets it on the way.
        let (i, why) = sweep_overlap(&jet, &tow, &block(-20.0, half_span / 2.0, 3.0)).unwrap();
        let x = tow[i].translation.x;
        assert!((-25.0..-15.0).contains(&x), "met at x = {x}: {why}");
        assert!(start_overlap(&jet, &tow[0], &block(-20.0, half_span / 2.0, 3.0)).is_none());
        // A metre beyond the tip, or low enough for the wing to pass over: never met.
        assert!(sweep_overlap(&jet, &tow, &block(-20.0, half_span + 1.5, 3.0)).is_none());
        assert!(sweep_overlap(&jet, &tow, &block(-20.0, half_span / 2.0, 0.3)).is_none());
    }

    /// A route east then north: its poses face east, then north, at the corner half way; ahead
    /// of the last pose the nose meets a tall block that, facing back the way it came, it would
    /// not; the tow's poses come first and are counted.
    #[test]
    fn the_taxi_way_faces_along_the_route_after_the_tow() {
        let jet = aircraft::Vehicle::shipped("praetor600").unwrap();
        let tow = airport::Tow {
            poses: vec![
                (Vector2::new(0.0, -10.0), 1.0),
                (Vector2::new(0.0, -5.0), 1.0),
            ],
            radius_m: 5.0,
            length_m: 5.0,
        };
        let route = super::super::model::Route {
            waypoints_m: vec![
                Point2::origin(),
                Point2::new(20.0, 0.0),
                Point2::new(20.0, 20.0),
            ],
            yaws_rad: vec![None; 3],
            closed: false,
            speed_m_s: 5.0,
            speed_limits_m_s: None,
            pushback: Some(tow),
        };
        let (way, towed) = taxi_way(&route, 0.5);
        assert_eq!(towed, 11);
        assert!(
            way[..towed]
                .iter()
                .all(|p| (p.rotation.angle() - 1.0).abs() < 1e-9)
        );
        let yaw = |i: usize| way[i].rotation.angle().to_degrees();
        // East at the start, north at the end, 45 degrees at the corner (central differences),
        // turning evenly between.
        assert!(yaw(towed).abs() < 1e-9 && (yaw(towed + 20) - 22.5).abs() < 1e-9);
        assert!((yaw(towed + 40) - 45.0).abs() < 1e-9, "{}", yaw(towed + 40));
        assert!((yaw(way.len() - 1) - 90.0).abs() < 1e-9);
        // The nose reaches 11.7 m ahead of the reference point, the tail 8.4 m behind: a block
        // 11 m beyond the route's end is met by the nose, facing north; one 10.5 m behind the
        // start - where the nose would reach facing back - never.
        let (i, why) = sweep_overlap(&jet, &way, &block(20.0, 31.0, 3.0)).unwrap();
        assert!(
            way[i].translation.y > 17.0 && yaw(i) > 80.0,
            "{why} at {}",
            way[i]
        );
        assert!(why.contains("nose"), "{why}");
        assert!(sweep_overlap(&jet, &way[towed..], &block(-10.5, 0.0, 3.0)).is_none());
    }

    #[test]
    fn densified_poses_are_a_step_apart_and_turn_the_shorter_way() {
        let (a, b) = (170f64.to_radians(), -170f64.to_radians());
        let poses = densified(&[(Vector2::zeros(), a), (Vector2::new(2.0, 0.0), b)], 0.5);
        assert_eq!(poses.len(), 5);
        for w in poses.windows(2) {
            let step = (w[1].translation.vector - w[0].translation.vector).norm();
            assert!((step - 0.5).abs() < 1e-9, "{step}");
            // 20 degrees in four steps of 5, through 180, not 340 back the other way.
            let turn = w[1].rotation.angle_to(&w[0].rotation).abs().to_degrees();
            assert!((turn - 5.0).abs() < 1e-6, "{turn}");
        }
    }
}
