//! Collision parts in the vehicle frame (x forward, y left, z up, origin on the ground under the
//! rear axle / main-gear centre): 3D primitives, their undersides and their ground footprints.

use nalgebra::{Isometry3, Point2, Point3, Vector3};

use crate::footprint::{ConvexPolygon, Disc, Footprint};

/// Sides of the polygon that circumscribes a circular rim when a tilted cylinder or capsule is
/// projected (the projection of a circumscribed polygon contains the projection of the circle).
const RIM_SIDES: usize = 64;

/// A collision primitive in its own frame (centred on the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A box with the given half extents along its x, y, z (URDF gives full extents).
    Box {
        /// Half extents, metres.
        half_extents_m: Vector3<f64>,
    },
    /// A cylinder along its z axis.
    Cylinder {
        /// Radius, metres.
        radius_m: f64,
        /// Half the length, metres.
        half_length_m: f64,
    },
    /// A capsule along its z axis: a cylinder of `half_length_m` capped by two hemispheres.
    Capsule {
        /// Radius, metres.
        radius_m: f64,
        /// Half the length of the cylindrical part, metres.
        half_length_m: f64,
    },
    /// A sphere.
    Sphere {
        /// Radius, metres.
        radius_m: f64,
    },
}

impl Shape {
    /// Half extents of the box around the primitive, in its own frame (what pictures and markers
    /// draw for it).
    #[must_use]
    pub fn half_extents_m(&self) -> Vector3<f64> {
        match *self {
            Shape::Box { half_extents_m } => half_extents_m,
            Shape::Cylinder {
                radius_m,
                half_length_m,
            } => Vector3::new(radius_m, radius_m, half_length_m),
            Shape::Capsule {
                radius_m,
                half_length_m,
            } => Vector3::new(radius_m, radius_m, half_length_m + radius_m),
            Shape::Sphere { radius_m } => Vector3::repeat(radius_m),
        }
    }
}

/// One `<collision>` element of a link, placed in the vehicle frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The link it belongs to.
    pub link: String,
    /// Index of the `<collision>` element within the link.
    pub collision_index: usize,
    /// The primitive.
    pub shape: Shape,
    /// Pose of the primitive's frame in the vehicle frame.
    pub vehicle_from_part: Isometry3<f64>,
}

impl Part {
    /// The part's z axis (cylinder/capsule axis) in the vehicle frame.
    fn axis_in_vehicle(&self) -> Vector3<f64> {
        self.vehicle_from_part.rotation * Vector3::z()
    }

    fn center_in_vehicle(&self) -> Point3<f64> {
        Point3::from(self.vehicle_from_part.translation.vector)
    }

    /// Half the vertical extent of the part around its centre, metres.
    fn half_height_m(&self) -> f64 {
        match self.shape {
            Shape::Box { half_extents_m } => {
                let r = self.vehicle_from_part.rotation.to_rotation_matrix();
                let m = r.matrix();
                (0..3).map(|j| m[(2, j)].abs() * half_extents_m[j]).sum()
            }
            Shape::Cylinder {
                radius_m,
                half_length_m,
            } => {
                let az = self.axis_in_vehicle().z.abs().min(1.0);
                half_length_m * az + radius_m * (1.0 - az * az).sqrt()
            }
            Shape::Capsule {
                radius_m,
                half_length_m,
            } => half_length_m * self.axis_in_vehicle().z.abs() + radius_m,
            Shape::Sphere { radius_m } => radius_m,
        }
    }

    /// Lowest point of the part above the ground, metres.
    pub fn underside_m(&self) -> f64 {
        self.center_in_vehicle().z - self.half_height_m()
    }

    /// Highest point of the part above the ground, metres.
    pub fn top_m(&self) -> f64 {
        self.center_in_vehicle().z + self.half_height_m()
    }

    /// The part's projection onto the ground plane (exact for boxes, spheres, upright and lying
    /// cylinders; a slightly larger circumscribed polygon for tilted cylinders and capsules).
    pub fn footprint(&self) -> Footprint {
        let c3 = self.center_in_vehicle();
        let c = Point2::new(c3.x, c3.y);
        let axis = self.axis_in_vehicle();
        // Horizontal part of the axis: the sine of its tilt, exact even for tiny tilts.
        let tilt = axis.x.hypot(axis.y);
        let upright = tilt <= 1e-9;
        match self.shape {
            Shape::Sphere { radius_m } => Footprint::Disc(Disc {
                center: c,
                radius_m,
            }),
            Shape::Cylinder {
                radius_m,
                half_length_m,
            }
            | Shape::Capsule {
                radius_m,
                half_length_m,
            } if upright => {
                // Upright to within 1e-9 rad: a disc, grown by the (nanometre) shift of the ends.
                Footprint::Disc(Disc {
                    center: c,
                    radius_m: radius_m + half_length_m * tilt,
                })
            }
            Shape::Box { half_extents_m: h } => {
                let mut pts = Vec::with_capacity(8);
                for sx in [-1.0, 1.0] {
                    for sy in [-1.0, 1.0] {
                        for sz in [-1.0, 1.0] {
                            let p =
                                self.vehicle_from_part * Point3::new(sx * h.x, sy * h.y, sz * h.z);
                            pts.push(Point2::new(p.x, p.y));
                        }
                    }
                }
                polygon_or_disc(&pts, c)
            }
            Shape::Cylinder {
                radius_m,
                half_length_m,
            } => {
                let a = Vector3::new(axis.x, axis.y, 0.0);
                if axis.z.abs() <= 1e-9 {
                    // Lying (to within 1e-9 rad, e.g. a pitch of 1.5707963268 written in a URDF):
                    // a rectangle, exact up to a few nanometres.
                    let u = a.normalize();
                    let (u2, v2) = (
                        // Grown by the rims' (nanometre) reach along the axis for a tiny tilt.
                        nalgebra::Vector2::new(u.x, u.y)
                            * (half_length_m * tilt + radius_m * axis.z.abs()),
                        nalgebra::Vector2::new(-u.y, u.x) * radius_m,
                    );
                    let pts = [c + u2 + v2, c + u2 - v2, c - u2 + v2, c - u2 - v2];
                    polygon_or_disc(&pts, c)
                } else {
                    polygon_or_disc(
                        &self.rim_points(radius_m, &[-half_length_m, half_length_m]),
                        c,
                    )
                }
            }
            Shape::Capsule {
                radius_m,
                half_length_m,
            } => {
                // Both end spheres' footprints are discs of `radius_m` around the projected ends.
                let mut pts = Vec::with_capacity(2 * RIM_SIDES);
                let inflated = radius_m / (std::f64::consts::PI / RIM_SIDES as f64).cos();
                for s in [-half_length_m, half_length_m] {
                    let e = self.vehicle_from_part * Point3::new(0.0, 0.0, s);
                    for k in 0..RIM_SIDES {
                        let t = std::f64::consts::TAU * k as f64 / RIM_SIDES as f64;
                        pts.push(Point2::new(
                            e.x + inflated * t.cos(),
                            e.y + inflated * t.sin(),
                        ));
                    }
                }
                polygon_or_disc(&pts, c)
            }
        }
    }

    /// Points of polygons circumscribing the circular rims at the given heights along the axis.
    fn rim_points(&self, radius_m: f64, along_m: &[f64]) -> Vec<Point2<f64>> {
        let inflated = radius_m / (std::f64::consts::PI / RIM_SIDES as f64).cos();
        let mut pts = Vec::with_capacity(along_m.len() * RIM_SIDES);
        for &s in along_m {
            for k in 0..RIM_SIDES {
                let t = std::f64::consts::TAU * k as f64 / RIM_SIDES as f64;
                let p =
                    self.vehicle_from_part * Point3::new(inflated * t.cos(), inflated * t.sin(), s);
                pts.push(Point2::new(p.x, p.y));
            }
        }
        pts
    }
}

/// A polygon, or (for a degenerate projection, which positive sizes never give) a tiny disc.
fn polygon_or_disc(pts: &[Point2<f64>], center: Point2<f64>) -> Footprint {
    match ConvexPolygon::hull(pts) {
        Some(p) => Footprint::Polygon(p),
        None => Footprint::Disc(Disc {
            center,
            radius_m: pts
                .iter()
                .map(|p| (p - center).norm())
                .fold(crate::footprint::EPS_M, f64::max),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn part(shape: Shape, xyz: [f64; 3], rpy: [f64; 3]) -> Part {
        Part {
            link: "l".into(),
            collision_index: 0,
            shape,
            vehicle_from_part: Isometry3::from_parts(
                Translation3::new(xyz[0], xyz[1], xyz[2]),
                UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
            ),
        }
    }

    #[test]
    fn yawed_box_footprint_and_underside() {
        let p = part(
            Shape::Box {
                half_extents_m: Vector3::new(2.0, 0.5, 0.25),
            },
            [1.0, 0.0, 1.0],
            [0.0, 0.0, std::f64::consts::FRAC_PI_2],
        );
        assert!((p.underside_m() - 0.75).abs() < 1e-12);
        let (lo, hi) = p.footprint().bounds();
        assert!((lo.x - 0.5).abs() < 1e-9 && (hi.x - 1.5).abs() < 1e-9);
        assert!((lo.y + 2.0).abs() < 1e-9 && (hi.y - 2.0).abs() < 1e-9);
    }

    #[test]
    fn lying_wheel_is_a_rectangle() {
        // A wheel: cylinder rolled 90 degrees about x, axis along y.
        let p = part(
            Shape::Cylinder {
                radius_m: 0.28,
                half_length_m: 0.1,
            },
            [0.0, 0.7, 0.28],
            [std::f64::consts::FRAC_PI_2, 0.0, 0.0],
        );
        assert!(p.underside_m().abs() < 1e-12);
        let f = p.footprint();
        assert!((f.area_m2() - 0.56 * 0.2).abs() < 1e-9);
    }

    #[test]
    fn cylinder_pitched_by_rounded_half_pi_is_a_rectangle() {
        // Regression: a fuselage pitched by 1.5707963268 (pi/2 rounded) came out as a sheared
        // quadrilateral that missed part of the fuselage, because the hull's collinearity
        // tolerance dropped points of the nearly flat rims.
        let half_pi = std::f64::consts::FRAC_PI_2;
        // pi/2 as written 1.5707963268, 1.57079632 and 1.5707.
        for pitch in [half_pi + 2.05e-11, half_pi - 6.79e-9, half_pi - 9.63e-5] {
            let p = part(
                Shape::Cylinder {
                    radius_m: 1.15,
                    half_length_m: 6.0,
                },
                [2.5, 0.0, 1.75],
                [0.0, pitch, 0.0],
            );
            let f = p.footprint();
            let (lo, hi) = f.bounds();
            assert!(
                (hi.y - lo.y - 2.3).abs() < 0.01,
                "pitch {pitch}: width {}",
                hi.y - lo.y
            );
            assert!(
                (f.area_m2() - 2.3 * 12.0).abs() < 0.1,
                "pitch {pitch}: {}",
                f.area_m2()
            );
            for (x, y) in [(-3.49, 1.14), (-3.49, -1.14), (8.49, 1.14), (8.49, -1.14)] {
                assert!(f.contains(&Point2::new(x, y)), "pitch {pitch}: ({x}, {y})");
            }
        }
    }

    #[test]
    fn rolled_box_underside_rises_with_dihedral() {
        let roll = 0.1f64;
        let p = part(
            Shape::Box {
                half_extents_m: Vector3::new(1.0, 5.0, 0.1),
            },
            [0.0, 5.0, 2.0],
            [roll, 0.0, 0.0],
        );
        let expected = 2.0 - (5.0 * roll.sin() + 0.1 * roll.cos());
        assert!((p.underside_m() - expected).abs() < 1e-12);
    }
}
