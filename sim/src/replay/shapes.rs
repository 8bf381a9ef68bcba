//! The Rerun shapes of solid things: the scene's objects and obstacles (boxes, cylinders,
//! cone meshes), the vehicle's URDF collision primitives and its circles.

use nalgebra::Isometry3;
use rerun::RecordingStream;
use rerun::components::FillMode;
use rerun::datatypes::Rgba32;

use super::Result;
use super::style::{kind_color, quat, v3, yaw_quat};
use crate::world::{Solid, SolidShape};

/// Where and how a solid is logged.
#[derive(Clone, Copy, Debug)]
pub(super) enum Placement {
    /// A static object: placed in the world, logged once (static).
    World,
    /// A run-time obstacle: in its own frame (its pose is its entity's transform), logged on
    /// the timeline.
    Own,
}

/// A cone (apex up) as a mesh, from [`cone_vertices`].
fn cone_mesh(vertices: Vec<[f32; 3]>, color: Rgba32) -> rerun::Mesh3D {
    let sides = vertices.len() as u32 - 2;
    let mut triangles = Vec::new();
    for k in 0..sides {
        let (a, b) = (2 + k, 2 + (k + 1) % sides);
        triangles.push([0, a, b]);
        triangles.push([1, b, a]);
    }
    rerun::Mesh3D::new(vertices)
        .with_triangle_indices(triangles)
        .with_albedo_factor(color)
}

/// Logs a solid's shape: in its own frame, or placed in the world (see [`Placement`]).
pub(super) fn log_solid(
    rec: &RecordingStream,
    path: &str,
    solid: &Solid,
    placement: Placement,
) -> Result<()> {
    let (local, is_static) = match placement {
        Placement::World => (false, true),
        Placement::Own => (true, false),
    };
    let color = kind_color(solid.kind);
    let (x, y, z0, yaw) = if local {
        (0.0, 0.0, solid.z_min_m, 0.0)
    } else {
        (solid.x_m, solid.y_m, solid.z_min_m, solid.yaw_rad)
    };
    let h = solid.shape.height_m();
    let center = [x as f32, y as f32, (z0 + 0.5 * h) as f32];
    let log = |what: &dyn rerun::AsComponents| -> Result<()> {
        if is_static {
            rec.log_static(path, what)?;
        } else {
            rec.log(path, what)?;
        }
        Ok(())
    };
    match solid.shape {
        SolidShape::Part {
            shape,
            vehicle_from_part,
        } => {
            // Drawn as the box around the primitive, turned as it is.
            let half = shape.half_extents_m();
            let world_from_vehicle = Isometry3::from_parts(
                nalgebra::Translation3::new(x, y, 0.0),
                nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), yaw),
            );
            let pose = world_from_vehicle * vehicle_from_part;
            log(&rerun::Boxes3D::from_centers_and_half_sizes(
                [v3(&pose.translation.vector)],
                [v3(&half)],
            )
            .with_quaternions([quat(&pose.rotation)])
            .with_fill_mode(FillMode::Solid)
            .with_colors([color]))
        }
        SolidShape::Box { size_m } => log(&rerun::Boxes3D::from_centers_and_half_sizes(
            [center],
            [[
                0.5 * size_m[0] as f32,
                0.5 * size_m[1] as f32,
                0.5 * size_m[2] as f32,
            ]],
        )
        .with_quaternions([yaw_quat(yaw)])
        .with_fill_mode(FillMode::Solid)
        .with_colors([color])),
        SolidShape::Cylinder { radius_m, height_m } => log(
            &rerun::Cylinders3D::from_lengths_and_radii([height_m as f32], [radius_m as f32])
                .with_centers([center])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
        ),
        SolidShape::Cone { radius_m, height_m } => {
            // A mesh has no pose of its own: a static object's is baked into its vertices.
            log(&cone_mesh(
                cone_vertices(radius_m, height_m, x, y, z0),
                color,
            ))
        }
    }
}

/// A cone of `radius` and `height` standing at (x, y, z0): apex, base centre, base rim.
fn cone_vertices(radius_m: f64, height_m: f64, x: f64, y: f64, z0: f64) -> Vec<[f32; 3]> {
    const SIDES: u32 = 16;
    let mut positions = vec![
        [x as f32, y as f32, (z0 + height_m) as f32],
        [x as f32, y as f32, z0 as f32],
    ];
    for k in 0..SIDES {
        let a = std::f64::consts::TAU * k as f64 / SIDES as f64;
        positions.push([
            (x + radius_m * a.cos()) as f32,
            (y + radius_m * a.sin()) as f32,
            z0 as f32,
        ]);
    }
    positions
}

/// A vehicle part (URDF collision primitive) in the vehicle frame.
pub(super) fn log_part(
    rec: &RecordingStream,
    path: &str,
    part: &aircraft::Part,
    color: Rgba32,
) -> Result<()> {
    let pose: &Isometry3<f64> = &part.vehicle_from_part;
    let center = v3(&pose.translation.vector);
    let q = quat(&pose.rotation);
    let color = Rgba32::from_unmultiplied_rgba(
        color.to_array()[0],
        color.to_array()[1],
        color.to_array()[2],
        200,
    );
    match part.shape {
        aircraft::Shape::Box { half_extents_m } => rec.log_static(
            path,
            &rerun::Boxes3D::from_centers_and_half_sizes([center], [v3(&half_extents_m)])
                .with_quaternions([q])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
        )?,
        aircraft::Shape::Cylinder {
            radius_m,
            half_length_m,
        } => rec.log_static(
            path,
            &rerun::Cylinders3D::from_lengths_and_radii(
                [2.0 * half_length_m as f32],
                [radius_m as f32],
            )
            .with_centers([center])
            .with_quaternions([q])
            .with_fill_mode(FillMode::Solid)
            .with_colors([color]),
        )?,
        aircraft::Shape::Capsule {
            radius_m,
            half_length_m,
        } => {
            // Rerun's capsule runs from its origin along +z.
            let start = pose * nalgebra::Point3::new(0.0, 0.0, -half_length_m);
            rec.log_static(
                path,
                &rerun::Capsules3D::from_lengths_and_radii(
                    [2.0 * half_length_m as f32],
                    [radius_m as f32],
                )
                .with_translations([v3(&start.coords)])
                .with_quaternions([q])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
            )?
        }
        aircraft::Shape::Sphere { radius_m } => rec.log_static(
            path,
            &rerun::Ellipsoids3D::from_centers_and_radii([center], [radius_m as f32])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
        )?,
    }
    Ok(())
}

/// A circle of the plane z = `z` as a closed line strip.
pub(super) fn circle_strip(x: f64, y: f64, r: f64, z: f64) -> Vec<[f32; 3]> {
    const SIDES: usize = 32;
    (0..=SIDES)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / SIDES as f64;
            [(x + r * a.cos()) as f32, (y + r * a.sin()) as f32, z as f32]
        })
        .collect()
}
