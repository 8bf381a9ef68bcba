//! Benchmark workloads shared by the criterion benches and `taxi-sim bench mapper`.
//!
//! Each builds, deterministically (a fixed-seed xorshift, no I/O), the input of one headline
//! figure: a parking-lot revolution of the synthetic HDL-32E, a 1050 x 1050 obstacle mask, a
//! 62-circle jet-like collision model and distance maps around it.

use nalgebra::{Isometry2, Point2, Vector2};

use crate::collision::{Circle, CollisionModel};
use crate::edt::EdtScratch;
use crate::grid::GridGeometry;
use crate::levels::{LevelMode, Levels};
use crate::map::{MapConfig, MultiHeightMap};
use crate::odm::{DistanceMap, DistanceMaps};
use crate::scan::Scan;
use crate::synthetic::{Lidar, Scene, Solid, car_sensor_mount};

/// A tiny deterministic generator (xorshift64*), so workloads need no RNG crate.
#[derive(Clone, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// A generator from a seed (0 is replaced by a constant).
    pub fn new(seed: u64) -> Self {
        XorShift(if seed == 0 {
            0x9E37_79B9_7F4A_7C15
        } else {
            seed
        })
    }
    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
}

/// A parking lot of about 200 objects within 60 m: rows of parked cars, lamp posts, scattered cones
/// and wheeled containers, and two cones and two containers placed beside the aisle at y = -3.
pub fn parking_lot_scene() -> Scene {
    let mut rng = XorShift::new(7);
    let mut solids = Vec::new();
    for row in -3..=3 {
        let y = row as f64 * 16.0 + 5.0;
        for i in -12..=12 {
            if rng.next_f64() < 0.8 {
                solids.push(Solid::standing_box(
                    i as f64 * 2.6,
                    y,
                    1.9,
                    4.5,
                    rng.range(1.4, 1.8),
                ));
            }
        }
        for i in -2..=2 {
            solids.push(Solid::post(i as f64 * 13.0, y + 3.5, 0.12, 6.0));
        }
    }
    for _ in 0..40 {
        let (x, y) = (rng.range(-50.0, 50.0), rng.range(-50.0, 50.0));
        if x.abs() > 3.0 || y.abs() > 3.0 {
            solids.push(if rng.next_f64() < 0.6 {
                Solid::post(x, y, 0.18, 0.45)
            } else {
                Solid::standing_box(x, y, 0.8, 0.6, 1.1)
            });
        }
    }
    // The thesis' test obstacles beside the aisle the demo drives (y = -3): short cones a wing
    // passes over and tall wheeled containers it must not.
    solids.extend([
        Solid::post(-40.0, -6.0, 0.18, 0.45),
        Solid::post(-32.0, 0.0, 0.18, 0.45),
        Solid::standing_box(-36.0, 0.0, 0.8, 0.6, 1.1),
        Solid::standing_box(-28.0, -6.0, 0.8, 0.6, 1.1),
    ]);
    Scene {
        solids,
        ground_intensity: 0.3,
        solid_intensity: 0.8,
    }
}

/// One HDL-32E revolution (32 x 2187 = 69,984 rays) of the parking lot, from the origin.
pub fn parking_lot_scan() -> Scan {
    let scene = parking_lot_scene();
    Lidar::hdl32e()
        .scan(
            &scene,
            &Isometry2::new(Vector2::new(0.0, -3.0), 0.1),
            &car_sensor_mount(),
            |_, _| 0.0,
        )
        .unwrap_or_default()
}

/// The IARA car with the fake wing, as CARMEN's collision file describes it (FACTS.md).
pub fn fake_wing_car() -> CollisionModel {
    let mut circles: Vec<Circle> = [-0.76, 0.207, 1.174, 2.141, 3.108]
        .iter()
        .map(|&x| Circle {
            x_m: x,
            y_m: 0.0,
            radius_m: 1.0,
            level: 0,
        })
        .collect();
    for i in 0..5 {
        circles.push(Circle {
            x_m: 3.4,
            y_m: -1.53 + 0.1325 * i as f64,
            radius_m: 0.08,
            level: 1,
        });
    }
    CollisionModel::new(circles, vec![0.0, 0.7])
        .unwrap_or_else(|e| unreachable!("fixed model: {e}"))
}

/// A map with the fake-wing car's levels, centred on the origin.
pub fn two_level_map() -> MultiHeightMap {
    two_level_map_with(MapConfig::default()).unwrap_or_else(|e| unreachable!("fixed config: {e}"))
}

/// [`two_level_map`] with other settings.
pub fn two_level_map_with(config: MapConfig) -> crate::error::Result<MultiHeightMap> {
    MultiHeightMap::new(config, fake_wing_car_levels(), Point2::origin())
}

fn fake_wing_car_levels() -> Levels {
    Levels::new(vec![0.0, 0.7], LevelMode::Cumulative, None)
        .unwrap_or_else(|e| unreachable!("fixed levels: {e}"))
}

/// A 1050 x 1050 obstacle mask with the given fraction of obstacle cells, uniformly placed.
pub fn obstacle_mask(fraction: f64, seed: u64) -> Vec<bool> {
    let mut rng = XorShift::new(seed);
    (0..1050 * 1050)
        .map(|_| rng.next_f64() < fraction)
        .collect()
}

/// A Praetor-like jet as 62 circles: 14 along the fuselage and 4 on the tail cone at level 0,
/// 40 along the wings and 4 on the engines at level 1.
pub fn jet_62_circles() -> CollisionModel {
    let mut c = Vec::new();
    for i in 0..14 {
        c.push(Circle {
            x_m: -4.0 + i as f64 * 1.3,
            y_m: 0.0,
            radius_m: 1.1,
            level: 0,
        });
    }
    for i in 0..4 {
        c.push(Circle {
            x_m: -6.5 + i as f64 * 0.7,
            y_m: 0.0,
            radius_m: 0.8,
            level: 0,
        });
    }
    for side in [-1.0, 1.0] {
        for i in 0..20 {
            let s = 1.3 + i as f64 * 0.46;
            c.push(Circle {
                x_m: 0.5 - 0.12 * i as f64,
                y_m: side * s,
                radius_m: 1.2 - 0.04 * i as f64,
                level: 1,
            });
        }
        for i in 0..2 {
            c.push(Circle {
                x_m: -3.5 - i as f64 * 1.2,
                y_m: side * 1.6,
                radius_m: 0.6,
                level: 1,
            });
        }
    }
    CollisionModel::new(c, vec![0.0, 1.2]).unwrap_or_else(|e| unreachable!("fixed model: {e}"))
}

/// Distance maps of a 210 m window with 2 % obstacle cells in its outer ring and a clear
/// 60 m square in the middle: poses near the middle are far from everything, poses at the ring
/// are near obstacles.
pub fn distance_maps_for_checks() -> DistanceMaps {
    let g = GridGeometry::new(Point2::new(-105.0, -105.0), 0.2, 1050, 1050)
        .unwrap_or_else(|e| unreachable!("fixed geometry: {e}"));
    let mask = obstacle_mask(0.02, 3);
    let clear = |i: usize| {
        let c = g.center_of(
            g.cell_of_index(i)
                .unwrap_or(crate::grid::Cell { x: 0, y: 0 }),
        );
        c.x.abs() < 30.0 && c.y.abs() < 30.0
    };
    let mut s = EdtScratch::default();
    let l0 = DistanceMap::compute(g, 30.0, |i| mask[i] && !clear(i), &mut s);
    let l1 = DistanceMap::compute(g, 30.0, |i| mask[i] && !clear(i) && i % 2 == 0, &mut s);
    DistanceMaps::new(LevelMode::Cumulative, vec![l0, l1])
        .unwrap_or_else(|| unreachable!("same geometry"))
}

/// A pose in the clear middle of [`distance_maps_for_checks`] (the early out answers) and one at
/// the obstacle ring (every circle is looked up).
pub fn far_and_near_poses() -> (Isometry2<f64>, Isometry2<f64>) {
    (
        Isometry2::new(Vector2::new(0.0, 0.0), 0.3),
        Isometry2::new(Vector2::new(45.0, 45.0), 0.3),
    )
}
