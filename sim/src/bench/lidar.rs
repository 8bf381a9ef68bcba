//! `taxi-sim bench lidar`: one HDL-32E revolution of a parking lot of about 300 objects with the
//! fast path against Rapier's generic per-ray query, same scene, same run.

use std::hint::black_box;

use mapper::workloads;

use super::timing::{Figure, against, figure, median_seconds};

/// A parking lot of about 300 objects for the LiDAR figures: the mapper's benchmark lot (parked
/// cars, lamp posts, cones, containers) plus 80 cones scattered between the rows.
pub fn lidar_scene() -> crate::world::Scene {
    use crate::world::{ObjectKind, Scene, Solid, SolidShape};
    use mapper::synthetic::Solid as Synthetic;
    let mut solids = Vec::new();
    for (i, s) in workloads::parking_lot_scene().solids.iter().enumerate() {
        let (shape, x, y, kind) = match *s {
            Synthetic::Box { min, max } => {
                let size = max - min;
                let kind = if size.z > 1.3 {
                    ObjectKind::ParkedCar
                } else {
                    ObjectKind::Container
                };
                (
                    SolidShape::Box {
                        size_m: [size.x, size.y, size.z],
                    },
                    0.5 * (min.x + max.x),
                    0.5 * (min.y + max.y),
                    kind,
                )
            }
            Synthetic::Cylinder {
                center,
                radius_m,
                z_max,
                ..
            } => {
                let kind = if z_max > 1.0 {
                    ObjectKind::LampPost
                } else {
                    ObjectKind::Cone
                };
                let shape = if kind == ObjectKind::Cone {
                    SolidShape::Cone {
                        radius_m,
                        height_m: z_max,
                    }
                } else {
                    SolidShape::Cylinder {
                        radius_m,
                        height_m: z_max,
                    }
                };
                (shape, center.x, center.y, kind)
            }
        };
        solids.push(Solid {
            id: format!("lot_{i}"),
            kind,
            shape,
            x_m: x,
            y_m: y,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.6,
            runtime: false,
        });
    }
    let mut rng = workloads::XorShift::new(99);
    for i in 0..80 {
        let (x, y) = (rng.range(-60.0, 60.0), rng.range(-60.0, 60.0));
        if x.abs() < 5.0 && (y + 3.0).abs() < 5.0 {
            continue;
        }
        let shape = SolidShape::Cone {
            radius_m: 0.18,
            height_m: 0.45,
        };
        solids.push(Solid {
            id: format!("cone_{i}"),
            kind: ObjectKind::Cone,
            shape,
            x_m: x,
            y_m: y,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.8,
            runtime: false,
        });
    }
    Scene {
        min_m: [-100.0, -100.0],
        max_m: [100.0, 100.0],
        ground_remission: 0.2,
        pavement_texture: 0.0,
        solids,
        patches: Vec::new(),
        areas: Vec::new(),
    }
}

/// The LiDAR figures: one HDL-32E revolution with the fast path and with Rapier's generic
/// per-ray query, same scene, same run.
pub fn lidar_figures(samples: usize, progress: &mut dyn FnMut(&str)) -> crate::Result<Vec<Figure>> {
    use crate::world::{Lidar, LidarConfig, SweepPoses};
    progress("building the world");
    let scene = lidar_scene();
    let vehicle = aircraft::Vehicle::shipped("iara_car_fake_wing")?;
    let pose = nalgebra::Isometry2::new(nalgebra::Vector2::new(0.0, -3.0), 0.1);
    let world = crate::world::World::with_obstacles(&scene, &vehicle, &pose);
    let lidar = Lidar::new(LidarConfig::default(), vehicle.vehicle_from_lidar())
        .map_err(crate::Error::Invalid)?;
    let sweep = SweepPoses::still(pose);
    progress("generic cast");
    let generic = median_seconds(samples.min(7), 1, || {
        black_box(lidar.scan_generic(&world, &sweep, 0, 1));
    });
    let generic = figure(
        &format!(
            "lidar/generic_query/{}_rays/{}_objects",
            lidar.rays(),
            scene.solids.len()
        ),
        generic,
        "ms",
        None,
    );
    progress("fast cast");
    let fast = median_seconds(samples, 1, || {
        black_box(lidar.scan(&world, &sweep, 0, 1));
    });
    let fast = figure(
        &format!(
            "lidar/fast/{}_rays/{}_objects",
            lidar.rays(),
            scene.solids.len()
        ),
        fast,
        "ms",
        Some("<= 10 ms, >= 3x generic"),
    );
    progress("decoding packets");
    let decode = decoder_figure(samples)?;
    Ok(vec![against(fast, &generic), generic, decode])
}

/// The Velodyne decoder: one HDL-32E revolution's packets (1848 firings in 154 packets, every
/// channel returning) decoded from their bytes, cut and made the mapper's scan - against the
/// sensor's own 10 revolutions a second.
fn decoder_figure(samples: usize) -> crate::Result<Figure> {
    use velodyne::packet::Block;
    let payloads: Vec<Vec<u8>> = (0..154u32)
        .map(|p| {
            let blocks = std::array::from_fn(|k| Block {
                azimuth_cdeg: ((p * 12 + k as u32) * 36000 / 1848) as u16,
                channels: std::array::from_fn(|j| ((2000 + 150 * j) as u16, j as u8)),
            });
            velodyne::DataPacket {
                blocks,
                timestamp_us: 553 * p,
                return_mode: velodyne::ReturnMode::Strongest,
                product: velodyne::Product::Hdl32e,
            }
            .encode()
        })
        .collect();
    let calibration = velodyne::Calibration::built_in(velodyne::Product::Hdl32e)
        .ok_or_else(|| crate::Error::Invalid("no HDL-32E table".into()))?;
    let mount = nalgebra::Isometry3::translation(0.0, 0.0, 2.0);
    let pose = nalgebra::Isometry2::identity();
    let mut failure = None;
    let seconds = median_seconds(samples, 1, || {
        let packets: Result<Vec<_>, String> = payloads
            .iter()
            .map(|b| velodyne::DataPacket::decode(b).map_err(|e| e.to_string()))
            .collect();
        let outcome = packets.and_then(|p| {
            let frames = velodyne::frames(&p, &calibration);
            velodyne::to_scan(&frames[0], &calibration, &mount, &pose)
        });
        match outcome {
            Ok(scan) => {
                black_box(scan);
            }
            Err(e) => failure = Some(e),
        }
    });
    if let Some(e) = failure {
        return Err(crate::Error::Invalid(format!("decoder benchmark: {e}")));
    }
    Ok(figure(
        "lidar/velodyne_decode/hdl32e_revolution_to_scan",
        seconds,
        "ms",
        Some("<= 100 ms (the sensor's 10 Hz)"),
    ))
}
