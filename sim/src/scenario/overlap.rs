//! The start overlap: whether a solid meets the vehicle at its start pose ([`start_overlap`]),
//! from the parts' and the solid's ground footprints and height ranges.

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
