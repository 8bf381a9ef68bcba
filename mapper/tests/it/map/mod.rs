//! The map (`MultiHeightMap`) on analytic scenes, by subject: scan insertion, the window and
//! block files, the distance maps, forgetting. Here: the helpers they share.

mod distance;
mod forgetting;
mod insert;
mod window;

use mapper::synthetic::{Lidar, Scene, Solid, car_sensor_mount};
use mapper::{Levels, MapConfig, MultiHeightMap};
use nalgebra::{Isometry2, Point2, Vector2};

fn scene(solids: Vec<Solid>) -> Scene {
    Scene {
        solids,
        ground_intensity: 0.3,
        solid_intensity: 0.8,
    }
}

fn scan_from(scene: &Scene, x: f64, y: f64) -> mapper::Scan {
    Lidar::hdl32e()
        .scan(
            scene,
            &Isometry2::new(Vector2::new(x, y), 0.0),
            &car_sensor_mount(),
            |_, _| 0.0,
        )
        .unwrap()
}

fn map_with(levels: Levels) -> MultiHeightMap {
    MultiHeightMap::new(MapConfig::default(), levels, Point2::origin()).unwrap()
}

fn p(level: &MultiHeightMap, k: usize, x: f64, y: f64) -> Option<f32> {
    level.probability_at(k, &Point2::new(x, y))
}

fn insert(map: &mut MultiHeightMap, scene: &Scene, times: usize) {
    let scan = scan_from(scene, 0.0, 0.0);
    for _ in 0..times {
        map.insert_scan(&scan, None).unwrap();
    }
}
