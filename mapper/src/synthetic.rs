//! Analytic test scenes and a synthetic HDL-32E, for the mapper's tests and benchmarks.
//!
//! Not the simulator (that is the `sim` crate, on Rapier): a flat ground plane plus axis-aligned
//! boxes and vertical cylinders, cast exactly, so tests know the ground truth to the millimetre
//! and benchmarks get a realistic revolution without the simulator's dependencies.

use nalgebra::{Isometry2, Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector3};
use rayon::prelude::*;

use crate::scan::{Return, Scan, ScanColumn};

/// A solid of a synthetic scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solid {
    /// Axis-aligned box between two corners (world frame).
    Box {
        /// Lowest corner.
        min: Point3<f64>,
        /// Highest corner.
        max: Point3<f64>,
    },
    /// Vertical cylinder (a cone's stand-in: same footprint and height).
    Cylinder {
        /// Axis position.
        center: Point2<f64>,
        /// Radius, metres.
        radius_m: f64,
        /// Bottom height.
        z_min: f64,
        /// Top height.
        z_max: f64,
    },
}

impl Solid {
    /// A box standing on the ground, centred at (x, y).
    pub fn standing_box(x: f64, y: f64, size_x: f64, size_y: f64, height: f64) -> Self {
        Solid::Box {
            min: Point3::new(x - size_x / 2.0, y - size_y / 2.0, 0.0),
            max: Point3::new(x + size_x / 2.0, y + size_y / 2.0, height),
        }
    }
    /// A cylinder standing on the ground.
    pub fn post(x: f64, y: f64, radius_m: f64, height: f64) -> Self {
        Solid::Cylinder {
            center: Point2::new(x, y),
            radius_m,
            z_min: 0.0,
            z_max: height,
        }
    }

    /// Distance along a unit ray to the first hit, if any.
    pub fn cast(&self, o: &Point3<f64>, d: &Vector3<f64>) -> Option<f64> {
        match *self {
            Solid::Box { min, max } => {
                let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
                for a in 0..3 {
                    let inv = 1.0 / d[a];
                    let (mut ta, mut tb) = ((min[a] - o[a]) * inv, (max[a] - o[a]) * inv);
                    if ta > tb {
                        std::mem::swap(&mut ta, &mut tb);
                    }
                    t0 = t0.max(ta);
                    t1 = t1.min(tb);
                    if t0 > t1 {
                        return None;
                    }
                }
                Some(t0)
            }
            Solid::Cylinder {
                center,
                radius_m,
                z_min,
                z_max,
            } => {
                let mut best: Option<f64> = None;
                let (ox, oy) = (o.x - center.x, o.y - center.y);
                let a = d.x * d.x + d.y * d.y;
                if a > 1e-12 {
                    let b = 2.0 * (ox * d.x + oy * d.y);
                    let c = ox * ox + oy * oy - radius_m * radius_m;
                    let disc = b * b - 4.0 * a * c;
                    if disc >= 0.0 {
                        let t = (-b - disc.sqrt()) / (2.0 * a);
                        let z = o.z + t * d.z;
                        if t >= 0.0 && z >= z_min && z <= z_max {
                            best = Some(t);
                        }
                    }
                }
                if d.z.abs() > 1e-12 {
                    for zc in [z_min, z_max] {
                        let t = (zc - o.z) / d.z;
                        let (x, y) = (ox + t * d.x, oy + t * d.y);
                        if t >= 0.0
                            && x * x + y * y <= radius_m * radius_m
                            && best.is_none_or(|b| t < b)
                        {
                            best = Some(t);
                        }
                    }
                }
                best
            }
        }
    }
}

/// A flat ground at z = 0 with solids on it.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// The solids.
    pub solids: Vec<Solid>,
    /// Intensity of the ground.
    pub ground_intensity: f32,
    /// Intensity of the solids.
    pub solid_intensity: f32,
}

/// A spinning multi-beam LiDAR.
#[derive(Clone, Debug)]
pub struct Lidar {
    /// Elevation of each beam, lowest first, radians.
    pub elevations_rad: Vec<f64>,
    /// Columns per revolution.
    pub columns: usize,
    /// Maximum range, metres.
    pub max_range_m: f64,
}

impl Lidar {
    /// Velodyne HDL-32E: 32 beams from -30.67 to +10.67 deg, 2187 columns (69,984 rays), 100 m.
    pub fn hdl32e() -> Self {
        let (lo, hi) = (-30.67f64, 10.67f64);
        Lidar {
            elevations_rad: (0..32)
                .map(|i| (lo + (hi - lo) * i as f64 / 31.0).to_radians())
                .collect(),
            columns: 2187,
            max_range_m: 100.0,
        }
    }

    /// One revolution of `scene` from a vehicle at `world_from_vehicle` carrying the sensor at
    /// `vehicle_from_sensor`. `range_noise(column, beam)` is added to each range (return 0 for none).
    pub fn scan(
        &self,
        scene: &Scene,
        world_from_vehicle: &Isometry2<f64>,
        vehicle_from_sensor: &Isometry3<f64>,
        range_noise: impl Fn(usize, usize) -> f64 + Sync,
    ) -> crate::Result<Scan> {
        let v = world_from_vehicle;
        let world_from_vehicle3 = Isometry3::from_parts(
            Translation3::new(v.translation.x, v.translation.y, 0.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), v.rotation.angle()),
        );
        let world_from_sensor = world_from_vehicle3 * vehicle_from_sensor;
        let origin = Point3::from(world_from_sensor.translation.vector);
        let beams = self.elevations_rad.len();
        let returns: Vec<Option<Return>> = (0..self.columns)
            .into_par_iter()
            .flat_map_iter(|c| {
                let azimuth = std::f64::consts::TAU * c as f64 / self.columns as f64;
                let noise = &range_noise;
                self.elevations_rad.iter().enumerate().map(move |(b, el)| {
                    let dir_s =
                        Vector3::new(el.cos() * azimuth.cos(), el.cos() * azimuth.sin(), el.sin());
                    let d = world_from_sensor.rotation * dir_s;
                    let mut best: Option<(f64, f32)> = None;
                    if d.z < 0.0 {
                        best = Some((-origin.z / d.z, scene.ground_intensity));
                    }
                    for s in &scene.solids {
                        if let Some(t) = s.cast(&origin, &d)
                            && best.is_none_or(|(bt, _)| t < bt)
                        {
                            best = Some((t, scene.solid_intensity));
                        }
                    }
                    let (t, intensity) = best.filter(|(t, _)| *t <= self.max_range_m)?;
                    let r = t + noise(c, b);
                    Some(Return {
                        point_in_world: origin + d * r,
                        range_m: r as f32,
                        intensity,
                    })
                })
            })
            .collect();
        let column = ScanColumn {
            world_from_sensor,
            world_from_vehicle: *world_from_vehicle,
        };
        Scan::new(beams, vec![column; self.columns], returns)
    }
}

/// The sensor mount of the IARA car: 2.15 m above the ground over the rear axle.
pub fn car_sensor_mount() -> Isometry3<f64> {
    Isometry3::translation(0.0, 0.0, 2.15)
}
