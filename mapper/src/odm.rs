//! Obstacle distance maps (ODM): per level, the distance from every cell to the nearest obstacle.
//!
//! An obstacle is a cell whose occupancy probability is above a threshold (0.5 by default);
//! unknown cells are not obstacles. Distances are in metres between cell centres, exact
//! (see [`crate::edt`]), capped at `max_distance_m`. A query by world position returns the value
//! of the cell holding the point, so it is within half a cell diagonal of the true distance;
//! the safety distance of the collision check absorbs that. A position outside the map reads 0:
//! the unknown beyond the map is never reported as free space.

use nalgebra::Point2;

use crate::edt::{EdtScratch, exact_edt};
use crate::grid::{Grid, GridGeometry};
use crate::levels::LevelMode;

/// Distance to the nearest obstacle, in metres, for every cell of one level.
#[derive(Clone, Debug)]
pub struct DistanceMap {
    grid: Grid<f32>,
    max_distance_m: f32,
}

impl DistanceMap {
    /// A map with no obstacle (every cell at `max_distance_m`).
    pub fn empty(geometry: GridGeometry, max_distance_m: f32) -> Self {
        DistanceMap {
            grid: Grid::filled(geometry, max_distance_m),
            max_distance_m,
        }
    }

    /// Computes the exact distance map of the cells for which `is_obstacle(index)` holds.
    pub fn compute(
        geometry: GridGeometry,
        max_distance_m: f32,
        is_obstacle: impl Fn(usize) -> bool + Sync,
        scratch: &mut EdtScratch,
    ) -> Self {
        let mut map = Self::empty(geometry, max_distance_m);
        map.recompute(is_obstacle, scratch);
        map
    }

    /// Recomputes in place (same geometry), reusing the buffers.
    pub fn recompute(
        &mut self,
        is_obstacle: impl Fn(usize) -> bool + Sync,
        scratch: &mut EdtScratch,
    ) {
        let g = *self.grid.geometry();
        exact_edt(
            g.width(),
            g.height(),
            g.resolution_m() as f32,
            self.max_distance_m,
            is_obstacle,
            scratch,
            self.grid.data_mut(),
        );
    }

    /// Distance in metres at a world position; 0 outside the map.
    #[inline]
    pub fn distance_at(&self, point_m: &Point2<f64>) -> f32 {
        self.grid.at(point_m).copied().unwrap_or(0.0)
    }

    /// The underlying grid of distances.
    pub fn grid(&self) -> &Grid<f32> {
        &self.grid
    }
    /// The cap.
    pub fn max_distance_m(&self) -> f32 {
        self.max_distance_m
    }
}

/// The distance maps of every level of a map, on one shared geometry.
#[derive(Clone, Debug)]
pub struct DistanceMaps {
    mode: LevelMode,
    levels: Vec<DistanceMap>,
}

impl DistanceMaps {
    /// Bundles per-level maps. They must share one geometry (`None` otherwise, or if empty).
    pub fn new(mode: LevelMode, levels: Vec<DistanceMap>) -> Option<Self> {
        let first = levels.first()?.grid.geometry();
        levels
            .iter()
            .all(|l| l.grid.geometry() == first)
            .then_some(DistanceMaps { mode, levels })
    }
    /// Number of levels.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }
    /// The map of level k, `None` past the last level.
    pub fn level(&self, k: usize) -> Option<&DistanceMap> {
        self.levels.get(k)
    }
    /// All levels, level 0 first.
    pub fn levels(&self) -> &[DistanceMap] {
        &self.levels
    }
    pub(crate) fn levels_mut(&mut self) -> &mut [DistanceMap] {
        &mut self.levels
    }
    /// The shared geometry.
    pub fn geometry(&self) -> &GridGeometry {
        self.levels[0].grid.geometry()
    }
    /// Cumulative or banded.
    pub fn mode(&self) -> LevelMode {
        self.mode
    }
}
