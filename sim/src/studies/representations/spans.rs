//! The vehicle's circles with the heights they stand for: what a 3D representation checks.
//!
//! A circle of level k is checked, in the thesis' cumulative map, against everything from h_k up
//! to the ceiling. A representation that keeps heights can ask less: the span from the lowest
//! underside to the highest top of the parts the circle covers - the parts of level k or above
//! whose footprint meets the circle. A wing's circle then spans the wing, not the tail above it.

use aircraft::Vehicle;
use aircraft::fit::level_of;
use mapper::CollisionModel;
use nalgebra::{Isometry2, Point2};

/// One circle of the model with the height span of the parts it covers, vehicle frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpanCircle {
    /// Centre in the vehicle frame, metres.
    pub centre: Point2<f64>,
    /// Radius, metres.
    pub radius_m: f64,
    /// The circle's level (the map it is checked against in the multi-height representations).
    pub level: usize,
    /// Lowest underside of the parts it covers, metres above the ground.
    pub z_lo_m: f64,
    /// Highest top of the parts it covers, metres above the ground.
    pub z_hi_m: f64,
}

/// The circles of `model` with their height spans from `vehicle`'s parts. A circle that meets
/// no part of its level or above (it cannot: circles cover footprints) spans h_k to the top.
pub fn span_circles(model: &CollisionModel, vehicle: &Vehicle) -> Vec<SpanCircle> {
    let heights = model.level_heights_m();
    let parts: Vec<(usize, f64, f64, aircraft::footprint::Footprint)> = vehicle
        .parts
        .iter()
        .map(|p| {
            (
                level_of(p.underside_m(), heights),
                p.underside_m().max(0.0),
                p.top_m(),
                p.footprint(),
            )
        })
        .collect();
    model
        .circles()
        .iter()
        .map(|c| {
            let centre = Point2::new(c.x_m, c.y_m);
            let (lo, hi) = parts
                .iter()
                .filter(|(level, _, _, f)| *level >= c.level && f.distance(&centre) < c.radius_m)
                .fold(
                    (f64::INFINITY, f64::NEG_INFINITY),
                    |(lo, hi), (_, u, t, _)| (lo.min(*u), hi.max(*t)),
                );
            let (z_lo_m, z_hi_m) = if lo.is_finite() {
                (lo, hi)
            } else {
                (heights[c.level], vehicle.top_m())
            };
            SpanCircle {
                centre,
                radius_m: c.radius_m,
                level: c.level,
                z_lo_m,
                z_hi_m,
            }
        })
        .collect()
}

/// A circle placed in the world at a vehicle pose: (centre, radius, z_lo, z_hi).
pub fn placed(c: &SpanCircle, world_from_vehicle: &Isometry2<f64>) -> (Point2<f64>, f64, f64, f64) {
    (
        world_from_vehicle * c.centre,
        c.radius_m,
        c.z_lo_m,
        c.z_hi_m,
    )
}
