//! The bag's markers (`visualization_msgs/msg/MarkerArray`): the vehicle's collision model - a
//! flat cylinder per circle at its level's height, in `base_link`, frame-locked so it follows the
//! estimate - and the world's solids as boxes and cylinders (a parked aircraft's parts as the
//! boxes around them), in `map`.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use ros2::msgs::{Marker, MarkerShape, Pose};

use super::pose3;
use crate::world::{Solid, SolidShape};

/// The colours of the levels (as the replay draws them), r g b in 0..1.
const LEVEL_COLORS: [[f32; 3]; 6] = [
    [1.0, 0.55, 0.0],
    [0.0, 0.75, 1.0],
    [0.9, 0.24, 0.9],
    [0.47, 0.86, 0.24],
    [1.0, 0.86, 0.0],
    [1.0, 0.35, 0.35],
];

/// The circles of the collision model, `heights_m[k]` the height of level k.
pub(crate) fn collision_model(model: &mapper::CollisionModel, heights_m: &[f64]) -> Vec<Marker> {
    model
        .circles()
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let [r, g, b] = LEVEL_COLORS[c.level % LEVEL_COLORS.len()];
            let z = heights_m.get(c.level).copied().unwrap_or(0.0).max(0.05);
            Marker {
                ns: format!("level_{}", c.level),
                id: i32::try_from(i).unwrap_or(i32::MAX),
                shape: MarkerShape::Cylinder,
                pose: Pose::planar(c.x_m, c.y_m, z, 0.0),
                scale: [2.0 * c.radius_m, 2.0 * c.radius_m, 0.05],
                color: [r, g, b, 0.5],
                frame_locked: true,
            }
        })
        .collect()
}

/// A solid where it stands now, `id` its index in the scene.
pub(crate) fn solid(solid: &Solid, id: usize, ns: &str) -> Marker {
    let color = if solid.runtime {
        [0.86, 0.16, 0.16, 0.9]
    } else {
        [0.6, 0.6, 0.65, 0.9]
    };
    let world_from_solid = Isometry3::from_parts(
        Translation3::new(solid.x_m, solid.y_m, solid.z_min_m),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), solid.yaw_rad),
    );
    let h = solid.shape.height_m();
    let up = |pose: &Isometry3<f64>| pose * Translation3::new(0.0, 0.0, 0.5 * h);
    let (shape, pose, scale) = match solid.shape {
        SolidShape::Box { size_m } => (MarkerShape::Cube, up(&world_from_solid), size_m),
        SolidShape::Cylinder { radius_m, height_m } | SolidShape::Cone { radius_m, height_m } => (
            MarkerShape::Cylinder,
            up(&world_from_solid),
            [2.0 * radius_m, 2.0 * radius_m, height_m],
        ),
        SolidShape::Part {
            shape,
            vehicle_from_part,
        } => {
            let half = shape.half_extents_m();
            let on_ground = Isometry3::from_parts(
                Translation3::new(solid.x_m, solid.y_m, 0.0),
                world_from_solid.rotation,
            );
            (
                MarkerShape::Cube,
                on_ground * vehicle_from_part,
                [2.0 * half.x, 2.0 * half.y, 2.0 * half.z],
            )
        }
    };
    Marker {
        ns: ns.to_string(),
        id: i32::try_from(id).unwrap_or(i32::MAX),
        shape,
        pose: pose3(&pose),
        scale,
        color,
        frame_locked: false,
    }
}
