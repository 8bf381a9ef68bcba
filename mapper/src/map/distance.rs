//! Distance-map updates: each level's obstacle distance map brought up to date, over the whole
//! window or a region around the vehicle, after insertions and forgetting.
//!
//! The rule: only the levels whose obstacle cells changed are recomputed, and only around the
//! changes. Each level keeps a list of the cells whose obstacle state may have changed since its
//! last update ([`TouchedCells`]: the cells a hit raises, the cells a free-space walk lowers from
//! the obstacle side of the threshold or from unknown, the cells forgetting changes) and
//! re-tests only those; a new region, a re-centring or a list past [`TOUCHED_CAP`] sweeps the
//! region instead. Either way the result equals a distance transform computed afresh from the
//! merged map, bit for bit: `distance_maps_kept_from_the_touched_cells_equal_a_fresh_transform`,
//! `distance_maps_around_the_vehicle_equal_the_full_window_inside_their_reach` and
//! `whole_window_distance_maps_after_a_recentring_start_over` (in
//! `mapper/tests/it/map/distance.rs`).

use nalgebra::Point2;
use rayon::prelude::*;

use super::MultiHeightMap;
use super::config::{MapConfig, MergeMode};
use super::query::merge_log_odds;
use crate::grid::GridGeometry;
use crate::odm::{DistanceMap, DistanceMaps};

/// The live cells of one level whose obstacle state (live merged with prior) may have changed
/// since the level's distance map was last brought up to date, so that the update re-tests
/// them instead of sweeping its region: every cell a hit raises, every cell a free-space walk
/// lowers from the obstacle side of the threshold or from unknown (rare once an area has been
/// seen: walks mostly lower free cells, which cannot change state), every cell forgetting
/// changes. A superset, in the order noted, repeats allowed; past [`TOUCHED_CAP`] cells it only
/// remembers that it overflowed, and the update sweeps the region as without it. Re-centring
/// (every index moves) starts the distance maps over instead.
#[derive(Clone, Debug, Default)]
pub(super) struct TouchedCells {
    pub(super) cells: Vec<u32>,
    pub(super) overflowed: bool,
}

/// Cells a [`TouchedCells`] list holds before it overflows (1 MiB of indices; a 100 m square
/// of 0.2 m cells is 250,000).
pub(super) const TOUCHED_CAP: usize = 1 << 18;

impl TouchedCells {
    #[inline]
    pub(super) fn note(&mut self, i: u32) {
        if self.cells.len() < TOUCHED_CAP {
            self.cells.push(i);
        } else {
            self.overflowed = true;
        }
    }
    pub(super) fn clear(&mut self) {
        self.cells.clear();
        self.overflowed = false;
    }
}

/// Live log-odds at or below which a cell is not an obstacle, whatever its prior, under the
/// map's merge and threshold: a free-space walk lowering such a cell cannot change its obstacle
/// state. With [`MergeMode::Fallback`] the merged value of a known live cell is the live one;
/// with [`MergeMode::Decay`] `(10 p_live + p_prior) / 11 > threshold` needs `p_live > (11
/// threshold - 1) / 10` at the least. Lowered by a margin for rounding (a cell noted for
/// nothing costs only time).
pub(super) fn no_obstacle_at_or_below(config: &MapConfig) -> f32 {
    let logit = |p: f32| (p / (1.0 - p)).ln();
    let t = config.obstacle_threshold;
    let bound = match config.merge {
        MergeMode::Fallback => logit(t),
        MergeMode::Decay => {
            let p = (11.0 * t - 1.0) / 10.0;
            if p <= 0.0 {
                return f32::NEG_INFINITY;
            }
            logit(p)
        }
    };
    bound - 1e-3
}

impl MultiHeightMap {
    /// Recomputes the distance maps of the levels that changed since the last call, over the
    /// whole window. Returns how many.
    pub fn update_distance_maps(&mut self) -> usize {
        let (w, h) = (self.geometry.width(), self.geometry.height());
        self.update_distance_region(0, 0, w, h)
    }

    /// Like [`Self::update_distance_maps`] but only over a square region around `center` that
    /// holds at least the square of half side `half_size_m` (clipped to the window): what a
    /// vehicle's checks need, at a fraction of the cost. Obstacles outside the region are not
    /// seen, so a distance is exact wherever the nearest obstacle lies inside it - in particular
    /// everywhere the distance is smaller than the gap to the region's edge. The region's corner
    /// snaps to a lattice of `half_size_m / 8` steps, so it moves only every few metres, and a
    /// level whose obstacle cells in the region did not change keeps its map: the result is the
    /// same as recomputing every time.
    pub fn update_distance_maps_around(&mut self, center: Point2<f64>, half_size_m: f64) -> usize {
        let g = self.geometry;
        if !(center.x.is_finite() && center.y.is_finite() && half_size_m.is_finite()) {
            return 0;
        }
        let half = (half_size_m / g.resolution_m()).ceil().max(1.0) as i64;
        let step = (half / 8).max(1);
        let (cx, cy) = g.cell_coords(&center);
        // Cell coordinates are relative to the window, whose origin is on the block lattice:
        // snap in world cells so the region does not move when the window does.
        let (wx, wy) = (
            self.window_lo.x * self.config.block_cells as i64,
            self.window_lo.y * self.config.block_cells as i64,
        );
        let snap = |c: i64, w: i64| (c + w - half).div_euclid(step) * step - w;
        let (lo_x, lo_y) = (snap(cx, wx), snap(cy, wy));
        let side = 2 * half + step;
        let (w, h) = (g.width() as i64, g.height() as i64);
        let (x0, x1) = (lo_x.clamp(0, w), (lo_x + side).clamp(0, w));
        let (y0, y1) = (lo_y.clamp(0, h), (lo_y + side).clamp(0, h));
        if x1 <= x0 || y1 <= y0 {
            return 0;
        }
        self.update_distance_region(
            x0 as usize,
            y0 as usize,
            (x1 - x0) as usize,
            (y1 - y0) as usize,
        )
    }

    /// Recomputes, over the region of `rw` x `rh` cells from (`x0`, `y0`), the distance map of
    /// each level that changed since its last computation and whose obstacle cells differ from
    /// those it was computed from. Returns how many levels were recomputed.
    fn update_distance_region(&mut self, x0: usize, y0: usize, rw: usize, rh: usize) -> usize {
        let g = self.geometry;
        let origin = g.origin_m() + nalgebra::Vector2::new(x0 as f64, y0 as f64) * g.resolution_m();
        let Ok(region) = GridGeometry::new(origin, g.resolution_m(), rw, rh) else {
            return 0;
        };
        if self.odm.geometry() != &region {
            let n = self.levels.count();
            if let Some(maps) = DistanceMaps::new(
                self.levels.mode(),
                vec![DistanceMap::empty(region, self.config.max_distance_m); n],
            ) {
                self.odm = maps;
            }
            self.odm_dirty.iter_mut().for_each(|d| *d = true);
            self.odm_obstacles.iter_mut().for_each(Vec::clear);
        }
        let threshold = self.config.obstacle_threshold;
        let l_threshold = (threshold / (1.0 - threshold)).ln();
        let merge = self.config.merge;
        let is_obstacle = move |l: f32, p: f32| match merge {
            MergeMode::Fallback => (if l.is_nan() { p } else { l }) > l_threshold,
            MergeMode::Decay => merge_log_odds(l, p, merge).is_some_and(|l| l > l_threshold),
        };
        let width = g.width();
        let mut recomputed = 0;
        for k in 0..self.levels.count() {
            if !self.odm_dirty[k] {
                continue;
            }
            let touched = &self.touched[k];
            self.odm_dirty[k] = false;
            let (live, prior) = (self.live[k].data(), self.prior[k].data());
            let odm = &mut self.odm.levels_mut()[k];
            if self.odm_obstacles[k].len() == rw * rh && !touched.overflowed {
                // Computed on this region before: only the touched cells can have changed.
                let (obstacles, changed) = (&mut self.odm_obstacles[k], &mut self.odm_changed);
                changed.clear();
                for &i in &touched.cells {
                    let i = i as usize;
                    let (x, y) = (i % width, i / width);
                    if x < x0 || x >= x0 + rw || y < y0 || y >= y0 + rh {
                        continue;
                    }
                    let j = (y - y0) * rw + (x - x0);
                    let now = is_obstacle(live[i], prior[i]);
                    if now != obstacles[j] {
                        obstacles[j] = now;
                        changed.push(j);
                    }
                }
                if !changed.is_empty() {
                    changed.sort_unstable();
                    odm.update_cells(changed, obstacles, &mut self.edt_scratch);
                    recomputed += 1;
                }
            } else {
                // A new region (or too many touched cells): sweep it.
                let mask = &mut self.odm_mask;
                mask.resize(rw * rh, false);
                mask.par_chunks_mut(rw).enumerate().for_each(|(r, row)| {
                    let j0 = (y0 + r) * width + x0;
                    let (live, prior) = (&live[j0..j0 + rw], &prior[j0..j0 + rw]);
                    for ((m, &l), &p) in row.iter_mut().zip(live).zip(prior) {
                        *m = is_obstacle(l, p);
                    }
                });
                if *mask != self.odm_obstacles[k] {
                    let (mask, old) = (&*mask, &self.odm_obstacles[k]);
                    if old.len() == mask.len() {
                        // Same region: only around the cells that changed.
                        odm.update(old, mask, &mut self.edt_scratch);
                    } else {
                        odm.recompute(|i| mask[i], &mut self.edt_scratch);
                    }
                    std::mem::swap(&mut self.odm_obstacles[k], &mut self.odm_mask);
                    recomputed += 1;
                }
            }
            self.touched[k].clear();
        }
        recomputed
    }

    /// The distance maps (call [`Self::update_distance_maps`] after inserting scans).
    pub fn distance_maps(&self) -> &DistanceMaps {
        &self.odm
    }
}
