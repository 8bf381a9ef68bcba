//! How things look in the replay: colours, the LiDAR's point classes, entity path parts,
//! conversions to Rerun's types and the thinning of logged paths.

use nalgebra::{Isometry2, UnitQuaternion, Vector3};
use rerun::datatypes::{Quaternion, Rgba32};

use crate::world::ObjectKind;

/// Class ids of the LiDAR points (see the annotation context at `world/lidar`).
pub(super) const CLASS_GROUND: u16 = 0;
pub(super) const CLASS_VEHICLE: u16 = 1;
pub(super) const CLASS_UNMAPPED: u16 = 2;
pub(super) const CLASS_ABOVE: u16 = 3;
pub(super) const CLASS_LEVEL0: u16 = 10;

/// The colour of level k (circles, points, plots).
pub(super) fn level_color(k: usize) -> Rgba32 {
    const COLORS: [(u8, u8, u8); 6] = [
        (255, 140, 0),
        (0, 190, 255),
        (230, 60, 230),
        (120, 220, 60),
        (255, 220, 0),
        (255, 90, 90),
    ];
    let (r, g, b) = COLORS[k % COLORS.len()];
    Rgba32::from_rgb(r, g, b)
}

/// The colour of an object of this kind.
pub(super) fn kind_color(kind: ObjectKind) -> Rgba32 {
    match kind {
        ObjectKind::Cone => Rgba32::from_rgb(255, 110, 20),
        ObjectKind::Container => Rgba32::from_rgb(60, 110, 200),
        ObjectKind::Marker => Rgba32::from_rgb(240, 220, 40),
        ObjectKind::Building => Rgba32::from_rgb(150, 150, 160),
        ObjectKind::LampPost => Rgba32::from_rgb(110, 110, 110),
        ObjectKind::ParkedCar => Rgba32::from_rgb(170, 60, 60),
        ObjectKind::Vehicle => Rgba32::from_rgb(220, 40, 40),
        ObjectKind::Debris => Rgba32::from_rgb(200, 0, 160),
        ObjectKind::Box | ObjectKind::Cylinder => Rgba32::from_rgb(140, 120, 90),
        ObjectKind::Person => Rgba32::from_rgb(255, 160, 200),
        ObjectKind::Tug | ObjectKind::FuelTruck => Rgba32::from_rgb(240, 180, 0),
        ObjectKind::ParkedAircraft => Rgba32::from_rgb(225, 228, 235),
        ObjectKind::Sign => Rgba32::from_rgb(250, 210, 0),
        ObjectKind::EdgeLight => Rgba32::from_rgb(40, 80, 230),
        ObjectKind::Windsock => Rgba32::from_rgb(255, 120, 0),
        ObjectKind::LightUnit => Rgba32::from_rgb(200, 30, 30),
        ObjectKind::BaggageCart => Rgba32::from_rgb(60, 110, 200),
    }
}

/// An entity path part from a name (ids and link names may hold any character).
pub(super) fn path_part(name: &str) -> String {
    let cleaned: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if cleaned.is_empty() {
        "_".into()
    } else {
        cleaned
    }
}

/// A rotation as Rerun's quaternion.
pub(super) fn quat(q: &UnitQuaternion<f64>) -> Quaternion {
    Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
}

/// A rotation about +z by `yaw_rad` as Rerun's quaternion.
pub(super) fn yaw_quat(yaw_rad: f64) -> Quaternion {
    let h = 0.5 * yaw_rad;
    Quaternion::from_xyzw([0.0, 0.0, h.sin() as f32, h.cos() as f32])
}

/// A vector as Rerun's `f32` triple.
pub(super) fn v3(v: &Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Every `every`-th pose of a path as a line strip just above the ground, ending at its last
/// pose.
pub(super) fn strip(poses: &[Isometry2<f64>], every: usize) -> Vec<[f32; 3]> {
    let mut out: Vec<[f32; 3]> = poses
        .iter()
        .step_by(every)
        .map(|p| [p.translation.x as f32, p.translation.y as f32, 0.06])
        .collect();
    if let Some(last) = poses.last()
        && poses.len() % every != 1 % every
    {
        out.push([last.translation.x as f32, last.translation.y as f32, 0.06]);
    }
    out
}
