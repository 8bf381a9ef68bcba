//! The window: re-centring it on the vehicle, blocks read in from the stores and written out to
//! the live store, the live blocks a mapping drive saves.
//!
//! Rules it keeps:
//! - Hysteresis: the window moves only once the position is `recenter_margin_m` (8 m by
//!   default) past the middle block's edge, never at each crossing of a block edge, so a route
//!   along one does not move it back and forth at every revolution
//!   (`the_window_moves_past_a_margin_not_at_every_crossing_of_a_block_edge`, in
//!   `mapper/tests/it/map/window.rs`).
//! - A move reads every entering block before it changes anything (the blocks in parallel, the
//!   first error in block order reported), so a bad block file leaves the map as it was; the
//!   leaving live blocks are then saved in parallel, and the grids (every level's live and
//!   prior, both remission layers) are shifted in place side by side: each source row is read
//!   before it is overwritten, so no second window is allocated ([`shift`], equal to a copy then
//!   fill by `tests::shifting_in_place_equals_copying`). Blocks come back with their cells:
//!   `recentring_saves_and_reloads_blocks_with_their_cells`.
//! - Every window index moves: the distance maps, the touched and last-hit lists start over and
//!   the hit spans outside the new window are dropped
//!   (`whole_window_distance_maps_after_a_recentring_start_over`).

use nalgebra::Point2;
use rayon::prelude::*;

use super::MultiHeightMap;
use super::config::MapConfig;
use super::distance::TouchedCells;
use crate::blocks::{Block, BlockIndex, BlockStore};
use crate::error::{MapError, Result};
use crate::grid::Grid;
use crate::odm::{DistanceMap, DistanceMaps};
use crate::remission::RemissionCell;

impl MultiHeightMap {
    pub(super) fn window_lo_for(config: &MapConfig, p: Point2<f64>) -> BlockIndex {
        let half = (config.window_blocks / 2) as i64;
        let b = config.block_m();
        BlockIndex {
            x: (p.x / b).floor() as i64 - half,
            y: (p.y / b).floor() as i64 - half,
        }
    }

    /// Whether `p` is within `recenter_margin_m` of the window's middle block (inside it
    /// included).
    fn near_middle(&self, p: Point2<f64>) -> bool {
        let half = (self.config.window_blocks / 2) as i64;
        let b = self.config.block_m();
        let lo = Point2::new(
            (self.window_lo.x + half) as f64 * b,
            (self.window_lo.y + half) as f64 * b,
        );
        let past = (lo.x - p.x)
            .max(p.x - (lo.x + b))
            .max(lo.y - p.y)
            .max(p.y - (lo.y + b));
        past <= self.config.recenter_margin_m
    }

    pub(super) fn window_blocks(&self, lo: BlockIndex) -> Vec<BlockIndex> {
        let n = self.config.window_blocks as i64;
        (0..n)
            .flat_map(|dy| {
                (0..n).map(move |dx| BlockIndex {
                    x: lo.x + dx,
                    y: lo.y + dy,
                })
            })
            .collect()
    }

    fn in_window(&self, lo: BlockIndex, index: BlockIndex) -> bool {
        let n = self.config.window_blocks as i64;
        (lo.x..lo.x + n).contains(&index.x) && (lo.y..lo.y + n).contains(&index.y)
    }

    /// Re-centres the window on the block holding `position` once it is more than
    /// `recenter_margin_m` past the middle block's edge. Returns whether the window moved. On
    /// error (a bad block file) the map is unchanged.
    pub fn recenter(&mut self, position: Point2<f64>) -> Result<bool> {
        crate::error::finite("position.x", position.x)?;
        crate::error::finite("position.y", position.y)?;
        if self.near_middle(position) {
            return Ok(false);
        }
        let new_lo = Self::window_lo_for(&self.config, position);
        let old_lo = self.window_lo;
        let entering: Vec<BlockIndex> = self
            .window_blocks(new_lo)
            .into_iter()
            .filter(|i| !self.in_window(old_lo, *i))
            .collect();
        let leaving: Vec<BlockIndex> = self
            .window_blocks(old_lo)
            .into_iter()
            .filter(|i| !self.in_window(new_lo, *i))
            .collect();
        // Read everything first so a bad file leaves the map as it was. The blocks in parallel;
        // the first error in block order is the one reported.
        let read: Vec<Result<_>> = entering
            .par_iter()
            .map(|&index| self.read_stores(index).map(|r| (index, r)))
            .collect();
        let loaded = read.into_iter().collect::<Result<Vec<_>>>()?;
        if let Some(store) = &self.live_store {
            let saved: Vec<Result<()>> = leaving
                .par_iter()
                .map(|&index| {
                    let block = self.extract_live(index);
                    if block.is_unknown() {
                        Ok(())
                    } else {
                        store.save(&block)
                    }
                })
                .collect();
            saved.into_iter().collect::<Result<()>>()?;
        }
        let (dx, dy) = (
            (new_lo.x - old_lo.x) * self.config.block_cells as i64,
            (new_lo.y - old_lo.y) * self.config.block_cells as i64,
        );
        let (live_rem, prior_rem) = (&mut self.live_remission, &mut self.prior_remission);
        rayon::join(
            || {
                self.live
                    .par_iter_mut()
                    .chain(self.prior.par_iter_mut())
                    .for_each(|g| shift(g, dx, dy, f32::NAN));
            },
            || {
                rayon::join(
                    || shift(live_rem, dx, dy, RemissionCell::default()),
                    || shift(prior_rem, dx, dy, RemissionCell::default()),
                )
            },
        );
        self.window_lo = new_lo;
        let origin = Point2::new(
            new_lo.x as f64 * self.config.block_m(),
            new_lo.y as f64 * self.config.block_m(),
        );
        self.geometry = self.geometry.with_origin(origin);
        for g in self.live.iter_mut().chain(self.prior.iter_mut()) {
            g.set_origin(origin);
        }
        self.live_remission.set_origin(origin);
        self.prior_remission.set_origin(origin);
        // The distance maps (a region of the old window, perhaps) start over on the new window.
        let n = self.levels.count();
        if let Some(maps) = DistanceMaps::new(
            self.levels.mode(),
            vec![DistanceMap::empty(self.geometry, self.config.max_distance_m); n],
        ) {
            self.odm = maps;
        }
        for (index, (prior, live)) in loaded {
            self.put_blocks(index, prior.as_ref(), live.as_ref());
        }
        self.list_occupied();
        self.odm_dirty.iter_mut().for_each(|d| *d = true);
        // Every cell index moved: what the distance maps were computed from is void, whatever
        // region they are asked for next.
        self.odm_obstacles.iter_mut().for_each(Vec::clear);
        self.touched.iter_mut().for_each(TouchedCells::clear);
        self.last_hits.iter_mut().for_each(Vec::clear);
        let (x0, y0) = self.window_cell0();
        let (w, h) = (self.geometry.width() as i64, self.geometry.height() as i64);
        for spans in &mut self.hit_spans {
            spans.retain(|c, _| c.0 >= x0 && c.1 >= y0 && c.0 < x0 + w && c.1 < y0 + h);
        }
        Ok(true)
    }

    fn read_stores(&self, index: BlockIndex) -> Result<(Option<Block>, Option<Block>)> {
        let prior = match &self.prior_store {
            Some(s) => s.load(index)?,
            None => None,
        };
        let live = match &self.live_store {
            Some(s) => s.load(index)?,
            None => None,
        };
        Ok((prior, live))
    }

    pub(super) fn load_into_window(&mut self, index: BlockIndex) -> Result<()> {
        let (prior, live) = self.read_stores(index)?;
        self.put_blocks(index, prior.as_ref(), live.as_ref());
        Ok(())
    }

    /// Cell offset of a block's lower-left cell in the window.
    fn block_offset(&self, index: BlockIndex) -> (usize, usize) {
        let s = self.config.block_cells;
        (
            ((index.x - self.window_lo.x) as usize) * s,
            ((index.y - self.window_lo.y) as usize) * s,
        )
    }

    fn put_blocks(&mut self, index: BlockIndex, prior: Option<&Block>, live: Option<&Block>) {
        let (ox, oy) = self.block_offset(index);
        let (s, w) = (self.config.block_cells, self.geometry.width());
        let copy_in = |dst: &mut [f32], src: &[f32]| {
            for r in 0..s {
                dst[(oy + r) * w + ox..][..s].copy_from_slice(&src[r * s..(r + 1) * s]);
            }
        };
        for (grids, rem, block) in [
            (&mut self.prior, &mut self.prior_remission, prior),
            (&mut self.live, &mut self.live_remission, live),
        ] {
            let Some(block) = block else { continue };
            for (g, src) in grids.iter_mut().zip(&block.levels) {
                copy_in(g.data_mut(), src);
            }
            let d = rem.data_mut();
            for r in 0..s {
                d[(oy + r) * w + ox..][..s].copy_from_slice(&block.remission[r * s..(r + 1) * s]);
            }
        }
    }

    fn extract(&self, index: BlockIndex, grids: &[Grid<f32>], rem: &Grid<RemissionCell>) -> Block {
        let (ox, oy) = self.block_offset(index);
        let (s, w) = (self.config.block_cells, self.geometry.width());
        let rows = |data: &[f32]| -> Vec<f32> {
            (0..s)
                .flat_map(|r| data[(oy + r) * w + ox..][..s].iter().copied())
                .collect()
        };
        Block {
            index,
            levels: grids.iter().map(|g| rows(g.data())).collect(),
            remission: (0..s)
                .flat_map(|r| rem.data()[(oy + r) * w + ox..][..s].iter().copied())
                .collect(),
        }
    }

    fn extract_live(&self, index: BlockIndex) -> Block {
        self.extract(index, &self.live, &self.live_remission)
    }

    /// The live blocks of the window (what a mapping drive saves as the next offline map),
    /// skipping blocks that hold no information.
    pub fn live_blocks(&self) -> Vec<Block> {
        self.window_blocks(self.window_lo)
            .into_iter()
            .map(|i| self.extract_live(i))
            .filter(|b| !b.is_unknown())
            .collect()
    }

    /// Writes every informative live block of the window to `store` (e.g. at the end of a mapping drive).
    pub fn save_live(&self, store: &BlockStore) -> Result<usize> {
        if store.spec() != &self.spec {
            return Err(MapError::invalid(
                "block store",
                format!(
                    "{} holds blocks of another map layout",
                    store.dir().display()
                ),
            ));
        }
        let blocks = self.live_blocks();
        for b in &blocks {
            store.save(b)?;
        }
        Ok(blocks.len())
    }

    /// Flushes the live window to the live store, if there is one. Returns the blocks written.
    pub fn flush(&self) -> Result<usize> {
        match &self.live_store {
            Some(store) => self.save_live(store),
            None => Ok(0),
        }
    }
}

/// Moves a grid's content by (-dx, -dy) cells (the window moved by (dx, dy)); uncovered cells get
/// `fill`. In place: rows are visited so that each source row is read before it is overwritten.
fn shift<T: Copy>(grid: &mut Grid<T>, dx: i64, dy: i64, fill: T) {
    let (w, h) = (
        grid.geometry().width() as i64,
        grid.geometry().height() as i64,
    );
    let data = grid.data_mut();
    // The destination columns that have a source column.
    let (x0, x1) = ((-dx).max(0), (w - dx).min(w));
    let mut move_row = |y: i64| {
        let row = (y * w) as usize..((y + 1) * w) as usize;
        let sy = y + dy;
        if !(0..h).contains(&sy) || x0 >= x1 {
            data[row].fill(fill);
            return;
        }
        let src = (sy * w + x0 + dx) as usize..(sy * w + x1 + dx) as usize;
        data.copy_within(src, row.start + x0 as usize);
        data[row.start..row.start + x0 as usize].fill(fill);
        data[row.start + x1 as usize..row.end].fill(fill);
    };
    if dy >= 0 {
        (0..h).for_each(&mut move_row);
    } else {
        (0..h).rev().for_each(&mut move_row);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridGeometry;

    /// The in-place shift moves every cell where a copy-then-fill would, for moves in every
    /// direction, including moves of the whole grid out of the window.
    #[test]
    fn shifting_in_place_equals_copying() {
        let (w, h) = (7usize, 5usize);
        let g = GridGeometry::new(Point2::origin(), 1.0, w, h).unwrap();
        for (dx, dy) in (-8..=8).flat_map(|x| (-6..=6).map(move |y| (x, y))) {
            let mut grid = Grid::filled(g, 0.0f32);
            for (i, v) in grid.data_mut().iter_mut().enumerate() {
                *v = i as f32;
            }
            let old = grid.data().to_vec();
            shift(&mut grid, dx, dy, -1.0);
            for y in 0..h as i64 {
                for x in 0..w as i64 {
                    let (sx, sy) = (x + dx, y + dy);
                    let expected = if (0..w as i64).contains(&sx) && (0..h as i64).contains(&sy) {
                        old[(sy * w as i64 + sx) as usize]
                    } else {
                        -1.0
                    };
                    assert_eq!(
                        grid.data()[(y * w as i64 + x) as usize],
                        expected,
                        "({dx}, {dy}) at ({x}, {y})"
                    );
                }
            }
        }
    }
}
