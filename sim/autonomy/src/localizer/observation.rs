//! A revolution reduced to what the filter weighs: ground and obstacle returns in the vehicle
//! frame, classified by height, decimated.

use mapper::{CollisionModel, MapConfig};
use nalgebra::{Isometry2, Point2};

use super::LocalizerConfig;
use crate::messages::LidarRevolution;

/// One revolution as the filter uses it, in the vehicle frame: ground returns (x, y, intensity)
/// and obstacle returns (x, y), decimated to the configured counts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Observation {
    /// Ground returns: x, y (metres, vehicle frame), intensity.
    pub ground: Vec<[f64; 3]>,
    /// Obstacle returns: x, y (metres, vehicle frame).
    pub obstacles: Vec<[f64; 2]>,
}

impl Observation {
    /// The returns of `revolution` in the vehicle frame (each column's points taken back through
    /// the pose the column was placed at), the vehicle's own body left out (`self_filter`, with
    /// `self_margin_m`), spread evenly over the revolution down to the configured counts; the
    /// ground returns' intensities as remissions, by the calibration of the map they are compared
    /// with (`map`: [`MapConfig::remission_of`]).
    pub fn from_revolution(
        revolution: &LidarRevolution,
        config: &LocalizerConfig,
        self_filter: Option<&CollisionModel>,
        self_margin_m: f64,
        map: &MapConfig,
    ) -> Self {
        let scan = &revolution.scan;
        let beams = scan.beams().max(1);
        // Classified by height first (the world point's z is the vehicle frame's), decimated,
        // and only then taken to the vehicle frame: a revolution has ~70,000 returns, the filter
        // uses a few hundred.
        let (mut ground, mut obstacles) = (Vec::new(), Vec::new());
        let max_range = config.max_ground_range_m as f32;
        let heights = config.obstacle_min_height_m..config.obstacle_max_height_m;
        for (i, r) in scan.returns().iter().enumerate() {
            let Some(r) = r else { continue };
            let z = r.point_in_world.z;
            if z < config.ground_height_m {
                if r.range_m <= max_range {
                    ground.push(i);
                }
            } else if heights.contains(&z) {
                obstacles.push(i);
            }
        }
        let in_vehicle = |i: usize| -> Option<(Point2<f64>, &mapper::Return)> {
            let r = scan.returns()[i].as_ref()?;
            let column = scan.columns().get(i / beams)?;
            let p = r.point_in_world;
            Some((
                column.world_from_vehicle.inverse() * Point2::new(p.x, p.y),
                r,
            ))
        };
        let ground = decimate(ground, config.remission_points)
            .into_iter()
            .filter_map(in_vehicle)
            .map(|(v, r)| {
                let remission = map.remission_of(r.intensity, r.range_m);
                [v.x, v.y, f64::from(remission)]
            })
            .collect();
        // Four times as many obstacle returns as wanted, then the vehicle's own body left out.
        let obstacles = decimate(obstacles, 4 * config.field_points)
            .into_iter()
            .filter_map(in_vehicle)
            .filter(|(v, r)| {
                !self_filter.is_some_and(|m| m.is_self_hit(v, r.point_in_world.z, self_margin_m))
            })
            .map(|(v, _)| [v.x, v.y])
            .collect();
        Observation {
            ground,
            obstacles: decimate(obstacles, config.field_points),
        }
    }
}

impl Observation {
    /// The returns taken into another frame of the vehicle (`new_from_old`).
    pub fn transform(&mut self, new_from_old: &Isometry2<f64>) {
        for g in &mut self.ground {
            let p = new_from_old * Point2::new(g[0], g[1]);
            (g[0], g[1]) = (p.x, p.y);
        }
        for o in &mut self.obstacles {
            let p = new_from_old * Point2::new(o[0], o[1]);
            *o = [p.x, p.y];
        }
    }
}

/// At most `n` of `v`, evenly spaced.
fn decimate<T: Copy>(v: Vec<T>, n: usize) -> Vec<T> {
    if v.len() <= n {
        return v;
    }
    (0..n).map(|k| v[k * v.len() / n]).collect()
}
