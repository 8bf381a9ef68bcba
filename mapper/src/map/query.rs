//! Reading the map: its accessors, world-lattice cells, the obstacle queries of the driver and
//! the tracker (`is_obstacle`, `obstacles_within`, `last_scan_hits`), and the merged log-odds,
//! probabilities and remission of the window.

use nalgebra::Point2;

use super::config::{MapConfig, MergeMode};
use super::{MultiHeightMap, WorldCell};
use crate::blocks::{BlockIndex, BlockSpec};
use crate::grid::{Grid, GridGeometry};
use crate::levels::Levels;
use crate::occupancy::probability;
use crate::remission::RemissionCell;
use crate::ros_occupancy::RosOccupancy;

impl MultiHeightMap {
    /// The map's configuration.
    pub fn config(&self) -> &MapConfig {
        &self.config
    }
    /// The levels.
    pub fn levels(&self) -> &Levels {
        &self.levels
    }
    /// Geometry of the window (every level's grid and distance map).
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }
    /// The window's lower-left block.
    pub fn window_origin_block(&self) -> BlockIndex {
        self.window_lo
    }
    /// What a block of this map looks like.
    pub fn block_spec(&self) -> &BlockSpec {
        &self.spec
    }

    /// The world-lattice cell of the window's cell (0, 0).
    pub(super) fn window_cell0(&self) -> WorldCell {
        let b = self.config.block_cells as i64;
        (self.window_lo.x * b, self.window_lo.y * b)
    }

    /// The world-lattice cell holding `point`.
    pub fn world_cell(&self, point: &Point2<f64>) -> WorldCell {
        let (x, y) = self.geometry.cell_coords(point);
        let (x0, y0) = self.window_cell0();
        (x + x0, y + y0)
    }

    /// The centre of a world-lattice cell, metres.
    pub fn world_cell_center(&self, cell: WorldCell) -> Point2<f64> {
        let r = self.config.resolution_m;
        Point2::new((cell.0 as f64 + 0.5) * r, (cell.1 as f64 + 0.5) * r)
    }

    /// The window index of a world-lattice cell, `None` outside the window.
    pub(super) fn window_index(&self, cell: WorldCell) -> Option<usize> {
        let (x0, y0) = self.window_cell0();
        let (x, y) = (cell.0 - x0, cell.1 - y0);
        let (w, h) = (self.geometry.width() as i64, self.geometry.height() as i64);
        (x >= 0 && y >= 0 && x < w && y < h).then(|| (y * w + x) as usize)
    }

    /// The cells the last revolution hit as obstacles, in any level, in world-lattice order.
    /// Empty after a re-centre until the next insertion.
    pub fn last_scan_hits(&self) -> Vec<WorldCell> {
        let width = self.geometry.width();
        let (x0, y0) = self.window_cell0();
        let mut all: Vec<WorldCell> = self
            .last_hits
            .iter()
            .flatten()
            .map(|&i| {
                let i = i as usize;
                ((i % width) as i64 + x0, (i / width) as i64 + y0)
            })
            .collect();
        all.sort_unstable();
        all.dedup();
        all
    }

    /// The cells the last revolution hit as obstacles, each with the levels it was hit in (bit
    /// `l` set: level `l`), in world-lattice order. Empty after a re-centre until the next
    /// insertion. Levels beyond 32 are not told apart (bit 31 stands for them all).
    pub fn last_scan_hits_by_level(&self) -> Vec<(WorldCell, u32)> {
        let width = self.geometry.width();
        let (x0, y0) = self.window_cell0();
        let mut all: Vec<(WorldCell, u32)> = self
            .last_hits
            .iter()
            .enumerate()
            .flat_map(|(level, hits)| {
                let bit = 1u32 << level.min(31);
                hits.iter().map(move |&i| {
                    let i = i as usize;
                    (((i % width) as i64 + x0, (i / width) as i64 + y0), bit)
                })
            })
            .collect();
        all.sort_unstable();
        all.dedup_by(|later, first| {
            if later.0 == first.0 {
                first.1 |= later.1;
                true
            } else {
                false
            }
        });
        all
    }

    /// Whether a world-lattice cell is an obstacle of level `level` in the prior (the offline
    /// map) alone; false outside the window.
    pub fn is_prior_obstacle(&self, level: usize, cell: WorldCell) -> bool {
        let (Some(i), Some(prior)) = (self.window_index(cell), self.prior.get(level)) else {
            return false;
        };
        let t = self.config.obstacle_threshold;
        let l = prior.data()[i];
        !l.is_nan() && l > (t / (1.0 - t)).ln()
    }

    /// Whether a world-lattice cell is an obstacle of level `level` (live merged with prior above
    /// the obstacle threshold); false outside the window.
    pub fn is_obstacle(&self, level: usize, cell: WorldCell) -> bool {
        let (Some(i), Some(live)) = (self.window_index(cell), self.live.get(level)) else {
            return false;
        };
        let t = self.config.obstacle_threshold;
        merge_log_odds(
            live.data()[i],
            self.prior[level].data()[i],
            self.config.merge,
        )
        .is_some_and(|l| l > (t / (1.0 - t)).ln())
    }

    /// The obstacle cells of `level` whose centres lie within `radius_m` of `center`.
    pub fn obstacles_within(
        &self,
        level: usize,
        center: &Point2<f64>,
        radius_m: f64,
    ) -> Vec<WorldCell> {
        let r = self.config.resolution_m;
        if !(radius_m.is_finite() && radius_m >= 0.0) {
            return Vec::new();
        }
        let (cx, cy) = self.world_cell(center);
        let n = (radius_m / r).ceil() as i64 + 1;
        let mut out = Vec::new();
        for y in cy - n..=cy + n {
            for x in cx - n..=cx + n {
                let c = (x, y);
                if (self.world_cell_center(c) - center).norm() <= radius_m
                    && self.is_obstacle(level, c)
                {
                    out.push(c);
                }
            }
        }
        out
    }

    /// Merged log-odds of a level at a world position; `None` when unknown or outside the window.
    pub fn log_odds_at(&self, level: usize, point: &Point2<f64>) -> Option<f32> {
        let i = self.geometry.index_of(point)?;
        merge_log_odds(
            self.live.get(level)?.data()[i],
            self.prior[level].data()[i],
            self.config.merge,
        )
    }

    /// Merged occupancy probability of a level at a world position; `None` when unknown or outside.
    pub fn probability_at(&self, level: usize, point: &Point2<f64>) -> Option<f32> {
        self.log_odds_at(level, point).map(probability)
    }

    /// The merged occupancy of a level as probabilities, -1 for unknown (CARMEN's convention);
    /// `None` past the last level.
    pub fn probability_grid(&self, level: usize) -> Option<Grid<f32>> {
        let live = self.live.get(level)?.data();
        let prior = self.prior[level].data();
        let merge = self.config.merge;
        let data = live
            .iter()
            .zip(prior)
            .map(|(l, p)| merge_log_odds(*l, *p, merge).map_or(-1.0, probability))
            .collect();
        Grid::from_vec(self.geometry, data).ok()
    }

    /// The merged occupancy of a level within `half_m` of `center` (clamped to the window), as
    /// ROS `OccupancyGrid` values: the probability in percent, -1 unknown; row 0 at the lowest y.
    /// `None` past the last level or when nothing of the window is left.
    pub fn ros_occupancy_around(
        &self,
        level: usize,
        center: &Point2<f64>,
        half_m: f64,
    ) -> Option<RosOccupancy> {
        let (live, prior) = (self.live.get(level)?, self.prior.get(level)?);
        let g = self.geometry;
        let res = g.resolution_m();
        let (xs, ys) = g.cells_around(center, half_m)?;
        let (x0, x1, y0, y1) = (xs.start, xs.end, ys.start, ys.end);
        let mut cells = Vec::with_capacity((x1 - x0) * (y1 - y0));
        for y in y0..y1 {
            let row = y * g.width();
            let (l, p) = (
                &live.data()[row + x0..row + x1],
                &prior.data()[row + x0..row + x1],
            );
            cells.extend(l.iter().zip(p).map(|(l, p)| {
                merge_log_odds(*l, *p, self.config.merge)
                    .map_or(-1, |lo| (probability(lo) * 100.0).round() as i8)
            }));
        }
        Some(RosOccupancy {
            corner: g.origin_m() + nalgebra::Vector2::new(x0 as f64 * res, y0 as f64 * res),
            width: x1 - x0,
            height: y1 - y0,
            resolution_m: res,
            cells,
        })
    }

    /// The live log-odds of a level (NaN = unknown).
    pub fn live_log_odds(&self, level: usize) -> Option<&Grid<f32>> {
        self.live.get(level)
    }
    /// The prior (offline) log-odds of a level (NaN = unknown).
    pub fn prior_log_odds(&self, level: usize) -> Option<&Grid<f32>> {
        self.prior.get(level)
    }

    /// Remission statistics of a cell: offline and live samples together.
    pub fn remission_at(&self, point: &Point2<f64>) -> Option<RemissionCell> {
        let i = self.geometry.index_of(point)?;
        Some(self.live_remission.data()[i].merged(&self.prior_remission.data()[i]))
    }
    /// The remission layer of the window, offline and live samples together.
    pub fn remission_grid(&self) -> Grid<RemissionCell> {
        let data = self
            .live_remission
            .data()
            .iter()
            .zip(self.prior_remission.data())
            .map(|(l, p)| l.merged(p))
            .collect();
        Grid::from_vec(self.geometry, data)
            .unwrap_or_else(|_| Grid::filled(self.geometry, RemissionCell::default()))
    }
}

/// Merged log-odds of a live and a prior value (NaN = unknown); `None` when both are unknown.
#[inline]
pub fn merge_log_odds(live: f32, prior: f32, mode: MergeMode) -> Option<f32> {
    match (live.is_nan(), prior.is_nan()) {
        (true, true) => None,
        (false, true) => Some(live),
        (true, false) => Some(prior),
        (false, false) => match mode {
            MergeMode::Fallback => Some(live),
            MergeMode::Decay => {
                let p = (10.0 * probability(live) + probability(prior)) / 11.0;
                Some((p / (1.0 - p)).ln())
            }
        },
    }
}
