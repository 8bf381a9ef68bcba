//! The map as the measurement update reads it: one window's remission means and weights and
//! the likelihood field of its level-0 obstacles, as flat tables.

use mapper::{GridGeometry, MultiHeightMap, RemissionCell};

use super::LocalizerConfig;

/// The map as the measurement update reads it, one window: per cell the remission mean and the
/// weight `-0.5 / (variance + floor^2)` (NaN mean: no sample), and the likelihood field's
/// log-likelihood of an obstacle return there.
#[derive(Clone, Debug)]
pub struct LocalizationMap {
    /// The window's grid.
    pub(super) geometry: GridGeometry,
    /// Mean, weight per cell.
    pub(super) remission: Vec<[f32; 2]>,
    /// The likelihood field's log-likelihood per cell.
    pub(super) field: Vec<f32>,
}

impl LocalizationMap {
    /// Built from `map`'s window: its remission layer, and the distance to the nearest level-0
    /// obstacle cell of its offline (prior) occupancy, capped at `outlier_sigmas` field sigmas
    /// (an exact EDT of level 0 only; the map's own distance maps would cover every level).
    pub fn from_map(map: &MultiHeightMap, config: &LocalizerConfig) -> Self {
        let floor2 = (config.remission_sigma_floor * config.remission_sigma_floor) as f32;
        let remission = map
            .remission_grid()
            .data()
            .iter()
            .map(|c| remission_entry(c, floor2))
            .collect();
        let sigma = config.field_sigma_m as f32;
        let floor = config.floor();
        let field = match level0_distance(map, config) {
            Some(distance) => distance
                .grid()
                .data()
                .iter()
                .map(|d| (-0.5 * (d / sigma) * (d / sigma)).max(floor))
                .collect(),
            None => vec![floor; map.geometry().len()],
        };
        LocalizationMap {
            geometry: *map.geometry(),
            remission,
            field,
        }
    }

    /// The window's geometry.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }
}

/// The distance from each cell of `map`'s window to the nearest level-0 obstacle cell (the
/// filter's map holds the offline occupancy only), capped at `outlier_sigmas` field sigmas: an exact EDT of level 0
/// only (the map's own distance maps would cover every level). `None` without levels.
pub fn level0_distance(
    map: &MultiHeightMap,
    config: &LocalizerConfig,
) -> Option<mapper::DistanceMap> {
    let (prior, live) = (map.prior_log_odds(0)?.data(), map.live_log_odds(0)?.data());
    let t = map.config().obstacle_threshold;
    let l_obstacle = (t / (1.0 - t)).ln();
    let cap = (config.outlier_sigmas * config.field_sigma_m) as f32;
    let merge = map.config().merge;
    Some(mapper::DistanceMap::compute(
        *map.geometry(),
        cap.max(map.config().resolution_m as f32),
        |i| mapper::map::merge_log_odds(live[i], prior[i], merge).is_some_and(|l| l > l_obstacle),
        &mut mapper::edt::EdtScratch::default(),
    ))
}

#[inline]
fn remission_entry(c: &RemissionCell, floor2: f32) -> [f32; 2] {
    match (c.mean(), c.variance()) {
        (Some(mean), Some(var)) => [mean, -0.5 / (var + floor2)],
        _ => [f32::NAN, 0.0],
    }
}
