//! Cylinders and cones cast in closed form ([`Round`]): parry casts them by GJK iterations,
//! a few millimetres off the surface and, at an airport, a tenth of the LiDAR's time on the
//! parked aircraft's fuselages and engines.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rapier3d::prelude::Ray;

use super::super::scene::{Solid, SolidShape};

/// A cylinder or cone (apex up) about the z axis of its frame, cast in closed form. An upright
/// scene solid is placed by its axis' `(cx, cy)` in the world; a parked vehicle's cylinder part,
/// in any orientation, by `frame` (its URDF frame from the world's, the axis along z).
#[derive(Clone, Copy, Debug)]
pub(super) struct Round {
    frame: Option<Isometry3<f64>>,
    cx: f64,
    cy: f64,
    radius: f64,
    z0: f64,
    z1: f64,
    cone: bool,
}

impl Round {
    /// The closed form of a scene solid, if it has one: an upright cylinder or cone, or a
    /// vehicle part that is a cylinder (boxes and balls parry casts exactly already).
    pub(super) fn of(s: &Solid) -> Option<Self> {
        let (radius, height, cone) = match s.shape {
            SolidShape::Cylinder { radius_m, height_m } => (radius_m, height_m, false),
            SolidShape::Cone { radius_m, height_m } => (radius_m, height_m, true),
            SolidShape::Part {
                shape:
                    aircraft::Shape::Cylinder {
                        radius_m,
                        half_length_m,
                    },
                vehicle_from_part,
            } => {
                let yaw = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), s.yaw_rad);
                let world_from_vehicle =
                    Isometry3::from_parts(Translation3::new(s.x_m, s.y_m, 0.0), yaw);
                return Some(Round {
                    frame: Some((world_from_vehicle * vehicle_from_part).inverse()),
                    cx: 0.0,
                    cy: 0.0,
                    radius: radius_m,
                    z0: -half_length_m,
                    z1: half_length_m,
                    cone: false,
                });
            }
            SolidShape::Box { .. } | SolidShape::Part { .. } => return None,
        };
        Some(Round {
            frame: None,
            cx: s.x_m,
            cy: s.y_m,
            radius,
            z0: s.z_min_m,
            z1: s.z_min_m + height,
            cone,
        })
    }

    /// First time of impact along the ray within `max`, solid (an origin inside gives 0).
    pub(super) fn cast(&self, ray: &Ray, max: f32) -> Option<f32> {
        let origin = Point3::new(
            ray.origin.x as f64,
            ray.origin.y as f64,
            ray.origin.z as f64,
        );
        let dir = Vector3::new(ray.dir.x as f64, ray.dir.y as f64, ray.dir.z as f64);
        let ((ox, oy, oz), (dx, dy, dz)) = match &self.frame {
            None => (
                (origin.x - self.cx, origin.y - self.cy, origin.z),
                (dir.x, dir.y, dir.z),
            ),
            Some(frame) => {
                let (o, d) = (frame * origin, frame.rotation * dir);
                ((o.x, o.y, o.z), (d.x, d.y, d.z))
            }
        };
        self.cast_local((ox, oy, oz), (dx, dy, dz), max as f64)
            .map(|t| t as f32)
    }

    /// [`Self::cast`] of a ray in the solid's frame, its axis through (0, 0).
    fn cast_local(
        &self,
        (ox, oy, oz): (f64, f64, f64),
        (dx, dy, dz): (f64, f64, f64),
        max: f64,
    ) -> Option<f64> {
        // Radius of the solid at height z (a cone narrows to its apex).
        let k = if self.cone {
            self.radius / (self.z1 - self.z0)
        } else {
            0.0
        };
        let radius_at = |z: f64| {
            if self.cone {
                k * (self.z1 - z)
            } else {
                self.radius
            }
        };
        if oz >= self.z0 && oz <= self.z1 && ox * ox + oy * oy <= radius_at(oz).powi(2) {
            return Some(0.0);
        }
        let mut best: Option<f64> = None;
        let mut consider = |t: f64| {
            if t >= 0.0 && t <= max && best.is_none_or(|b| t < b) {
                best = Some(t);
            }
        };
        // Lateral surface: x^2 + y^2 = r(z)^2 with r(z) = R (cylinder) or k (z1 - z) (cone).
        let (a, b, c) = if self.cone {
            let zz = self.z1 - oz;
            (
                dx * dx + dy * dy - k * k * dz * dz,
                2.0 * (ox * dx + oy * dy + k * k * zz * dz),
                ox * ox + oy * oy - k * k * zz * zz,
            )
        } else {
            (
                dx * dx + dy * dy,
                2.0 * (ox * dx + oy * dy),
                ox * ox + oy * oy - self.radius * self.radius,
            )
        };
        if a.abs() > 1e-12 {
            let disc = b * b - 4.0 * a * c;
            if disc >= 0.0 {
                // Numerically stable roots.
                let q = -0.5 * (b + b.signum() * disc.sqrt());
                for t in [q / a, if q != 0.0 { c / q } else { f64::NAN }] {
                    let z = oz + t * dz;
                    if t.is_finite() && z >= self.z0 && z <= self.z1 {
                        consider(t);
                    }
                }
            }
        }
        // Caps: the top disc of a cylinder, the base disc of both.
        if dz.abs() > 1e-12 {
            let caps: &[f64] = if self.cone {
                &[self.z0]
            } else {
                &[self.z0, self.z1]
            };
            for &zc in caps {
                let t = (zc - oz) / dz;
                let (x, y) = (ox + t * dx, oy + t * dy);
                if x * x + y * y <= self.radius * self.radius {
                    consider(t);
                }
            }
        }
        best
    }
}
