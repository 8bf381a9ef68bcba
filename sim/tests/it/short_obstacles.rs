//! A short obstacle at range through the simulator's own LiDAR and map settings: a 0.15 m piece
//! of debris ahead of the IARA car, which the consecutive-beam test alone sees only closer than
//! about 14 m, where the car's cabin soon hides it (`sim::scenario::OBSTACLE_HEIGHT_M`).

use aircraft::Vehicle;
use mapper::{Levels, MultiHeightMap};
use nalgebra::{Isometry2, Point2, Vector2};
use sim::offline_map::self_filter_model;
use sim::scenario::RunConfig;
use sim::world::{Lidar, LidarConfig, ObjectKind, Scene, Solid, SolidShape, SweepPoses, World};

/// The scenarios' default debris (0.3 x 0.3 x 0.15 m) centred at (x, 0).
fn debris_at(x_m: f64) -> Scene {
    Scene {
        min_m: [-50.0, -50.0],
        max_m: [100.0, 50.0],
        ground_remission: 0.2,
        pavement_texture: 0.0,
        solids: vec![Solid {
            id: "debris".into(),
            kind: ObjectKind::Debris,
            shape: SolidShape::Box {
                size_m: [0.3, 0.3, 0.15],
            },
            x_m,
            y_m: 0.0,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.2,
            runtime: true,
        }],
        patches: vec![],
        areas: Vec::new(),
    }
}

/// The car drives along +x at 3 m/s (0.3 m a revolution) from `from_m` to `to_m` between its
/// sensor and the debris' near face, each revolution inserted into a level-0 map with the
/// simulator's settings; returns the largest level-0 probability over the debris' footprint
/// after each revolution (`None` while unknown).
fn approach(from_m: f64, to_m: f64) -> Vec<Option<f32>> {
    let car = Vehicle::shipped("iara_car").unwrap();
    let sensor_x = car.vehicle_from_lidar().translation.x;
    let debris_x = 60.0;
    let near_face = debris_x - 0.15;
    let start = Isometry2::new(Vector2::new(near_face - from_m - sensor_x, 0.0), 0.0);
    let mut world = World::with_obstacles(&debris_at(debris_x), &car, &start);
    let lidar = Lidar::new(LidarConfig::default(), car.vehicle_from_lidar()).unwrap();
    let self_filter = self_filter_model(&car).unwrap();
    let levels = Levels::cumulative(vec![0.0]).unwrap();
    let mut map = MultiHeightMap::new(
        RunConfig::default().mapping.map,
        levels,
        Point2::from(start.translation.vector),
    )
    .unwrap();
    let revolutions = ((from_m - to_m) / 0.3).round() as usize + 1;
    (0..revolutions)
        .map(|k| {
            let pose = Isometry2::new(
                start.translation.vector + Vector2::new(0.3 * k as f64, 0.0),
                0.0,
            );
            world.set_vehicle_pose(&pose, 0.1 * k as f64);
            let scan = lidar.scan(&world, &SweepPoses::still(pose), k as u64, 7);
            map.insert_scan(&scan.scan, Some(&self_filter)).unwrap();
            // The footprint's cells, a point every 0.1 m.
            let mut best: Option<f32> = None;
            for i in 0..4 {
                for j in 0..4 {
                    let p = Point2::new(debris_x - 0.15 + 0.1 * i as f64, -0.15 + 0.1 * j as f64);
                    if let Some(pr) = map.probability_at(0, &p) {
                        best = Some(best.map_or(pr, |b| b.max(pr)));
                    }
                }
            }
            best
        })
        .collect()
}

/// The car drives 4 m toward the debris (14 revolutions) from 24, 20 and 16 m between its sensor
/// and the debris' near face: by the end the debris is an obstacle on level 0. The consecutive-beam
/// test alone (the mapper's default 1 m `unsafe_height_above_ground_m`) leaves it free on the
/// first two drives and maps it only from 12.1 m on the third.
#[test]
fn debris_12_to_24_m_ahead_is_on_level_0_after_a_few_revolutions() {
    for from in [24.0, 20.0, 16.0] {
        let seen = approach(from, from - 4.0);
        assert!(
            seen.last().copied().flatten().is_some_and(|p| p > 0.5),
            "driving from {from} m to {} m, level-0 probability after each revolution: {seen:?}",
            from - 4.0
        );
    }
}
