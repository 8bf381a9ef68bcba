//! The exact answer every representation is judged against: the vehicle's URDF collision shapes
//! against the world's colliders with parry, at poses drawn near the objects the drive saw.

use mapper::BoundingCircle;
use nalgebra::{Isometry2, Point2, Vector2};
use rand::{RngExt as _, SeedableRng as _};
use serde::{Deserialize, Serialize};

use crate::world::{ObjectKind, Solid, World};

/// What was nearest to the vehicle at a pose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Near {
    /// Standing on the ground: cones, containers, markers, buildings, piers.
    Ground,
    /// Held up off the ground (its underside above 0.3 m): bridge decks, canopies, bars.
    Overhang,
    /// A parked aircraft's part: its wings, engines and tail are overhangs of their own kind.
    ParkedAircraft,
}

impl Near {
    /// Every kind, in table order.
    pub const ALL: [Near; 3] = [Near::Ground, Near::Overhang, Near::ParkedAircraft];

    /// The kind of `solid`.
    pub fn of(solid: &Solid) -> Near {
        if solid.kind == ObjectKind::ParkedAircraft {
            Near::ParkedAircraft
        } else if solid.z_min_m > 0.3 {
            Near::Overhang
        } else {
            Near::Ground
        }
    }

    /// Its name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Near::Ground => "ground obstacles",
            Near::Overhang => "overhangs",
            Near::ParkedAircraft => "parked aircraft",
        }
    }
}

/// One pose with its exact answer.
#[derive(Clone, Copy, Debug)]
pub struct TruthPose {
    /// The vehicle's pose.
    pub pose: Isometry2<f64>,
    /// Whether some part touches some object.
    pub colliding: bool,
    /// The kind of the object nearest to a part.
    pub near: Near,
    /// That distance, metres (0 when touching).
    pub clearance_m: f64,
}

/// How the poses are drawn.
#[derive(Clone, Copy, Debug)]
pub struct PoseDraw {
    /// Poses wanted.
    pub count: usize,
    /// Seed of the draw.
    pub seed: u64,
    /// A pose is kept when some part is within this distance of an object, metres.
    pub near_m: f64,
    /// ... or inside one by at most this much, metres: the first touch, which a check must
    /// catch, not a vehicle sunk into a building.
    pub max_depth_m: f64,
    /// Objects farther than this from every revolution's origin are not drawn near, metres.
    pub seen_m: f64,
}

/// Poses near the objects of `world` that the drive passed within `seen_m` of: an object drawn
/// at random, the vehicle's origin within its bounding circle's reach of it, any heading; kept
/// when its bounding circle lies inside `inside` (the window less a margin) and the exact
/// clearance is under `near_m` or the deepest part is at most `max_depth_m` inside an object.
/// Stops after 50 tries a pose.
pub fn draw_poses(
    world: &mut World,
    drive: &[Isometry2<f64>],
    bounding: &BoundingCircle,
    inside: (Point2<f64>, Point2<f64>),
    draw: &PoseDraw,
) -> Vec<TruthPose> {
    let seen = |s: &Solid| {
        drive
            .iter()
            .any(|p| (p.translation.vector - Vector2::new(s.x_m, s.y_m)).norm() < draw.seen_m)
    };
    let candidates: Vec<(usize, f64)> = world
        .scene()
        .solids
        .iter()
        .enumerate()
        .filter(|(_, s)| seen(s))
        .map(|(i, s)| (i, s.shape.footprint_radius_m()))
        .collect();
    let mut out = Vec::with_capacity(draw.count);
    if candidates.is_empty() {
        return out;
    }
    let mut rng = rand::rngs::StdRng::seed_from_u64(draw.seed);
    let reach0 = bounding.center.coords.norm() + bounding.radius_m + 1.0;
    let (lo, hi) = inside;
    for _ in 0..draw.count * 50 {
        if out.len() >= draw.count {
            break;
        }
        let (i, radius) = candidates[rng.random_range(0..candidates.len())];
        let s = &world.scene().solids[i];
        let reach = reach0 + radius;
        let p = Vector2::new(
            s.x_m + rng.random_range(-reach..reach),
            s.y_m + rng.random_range(-reach..reach),
        );
        let pose = Isometry2::new(
            p,
            rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
        );
        let b = pose * bounding.center;
        let r = bounding.radius_m + 1.0;
        if !(b.x - r > lo.x && b.y - r > lo.y && b.x + r < hi.x && b.y + r < hi.y) {
            continue;
        }
        world.set_vehicle_pose(&pose, 0.0);
        let Some((nearest, d)) = world.nearest_object_now() else {
            continue;
        };
        if d >= draw.near_m {
            continue;
        }
        let colliding = d <= 0.0 || !world.touching_now().is_empty();
        if colliding && world.deepest_penetration_m() > draw.max_depth_m {
            continue;
        }
        out.push(TruthPose {
            pose,
            colliding,
            near: Near::of(&world.scene().solids[nearest]),
            clearance_m: d,
        });
    }
    out
}
