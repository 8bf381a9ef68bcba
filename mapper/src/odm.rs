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
use crate::ros_occupancy::RosOccupancy;

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

    /// Brings the map from the obstacle cells `old` to `new` (one flag per cell, row-major)
    /// without recomputing it all. A distance is capped, so a cell farther than the cap from
    /// every cell that changed keeps its value; the cells within the cap of a change are
    /// recomputed on a window reaching one more cap out, which holds every obstacle that can be
    /// nearer to them than the cap. Changes whose windows overlap share one window; when the
    /// windows would cover the map, the map is recomputed whole. The result equals
    /// [`Self::recompute`] over `new`. Returns the cells the transform ran over.
    ///
    /// # Panics
    /// If `old` or `new` does not have one flag per cell (a programming error).
    pub fn update(&mut self, old: &[bool], new: &[bool], scratch: &mut EdtScratch) -> usize {
        assert!(old.len() == new.len(), "DistanceMap::update: mask size");
        let changed: Vec<usize> = (0..new.len()).filter(|&i| old[i] != new[i]).collect();
        self.update_cells(&changed, new, scratch)
    }

    /// [`Self::update`] when the caller knows which cells changed: `changed` lists the indices
    /// (row-major, ascending, each once) of the cells whose flag differs from the one the map
    /// was last computed from, and `new` holds every cell's flag now. A cell changed but not
    /// listed keeps a stale distance; a listed cell that did not change costs only time.
    ///
    /// # Panics
    /// If `new` does not have one flag per cell, or an index is out of range (a programming
    /// error).
    pub fn update_cells(
        &mut self,
        changed: &[usize],
        new: &[bool],
        scratch: &mut EdtScratch,
    ) -> usize {
        let g = *self.grid.geometry();
        let (w, h) = (g.width(), g.height());
        assert!(new.len() == w * h, "DistanceMap::update_cells: mask size");
        if changed.is_empty() {
            return 0;
        }
        // Cells (Chebyshev) beyond which a change cannot move a capped distance, with a cell to spare.
        let reach = (self.max_distance_m / g.resolution_m() as f32).ceil() as usize + 1;
        let changes = changed_boxes(changed, w, 4 * reach);
        let cells: usize = changes
            .iter()
            .map(|b| b.grown(2 * reach, w, h).area())
            .sum();
        if cells >= w * h {
            self.recompute(|i| new[i], scratch);
            return w * h;
        }
        let mut out = std::mem::take(&mut scratch.window);
        for b in &changes {
            let win = b.grown(2 * reach, w, h);
            let (ww, wh) = (win.x1 - win.x0, win.y1 - win.y0);
            out.clear();
            out.resize(ww * wh, 0.0);
            exact_edt(
                ww,
                wh,
                g.resolution_m() as f32,
                self.max_distance_m,
                |i| new[(win.y0 + i / ww) * w + win.x0 + i % ww],
                scratch,
                &mut out,
            );
            // Write back the cells within the cap of the changes: their window holds every
            // obstacle that matters to them.
            let keep = b.grown(reach, w, h);
            let data = self.grid.data_mut();
            for y in keep.y0..keep.y1 {
                let src = (y - win.y0) * ww + keep.x0 - win.x0;
                data[y * w + keep.x0..y * w + keep.x1]
                    .copy_from_slice(&out[src..src + keep.x1 - keep.x0]);
            }
        }
        scratch.window = out;
        cells
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
    /// The distances within `half_m` of `center` (clamped to the grid) in ROS `OccupancyGrid`
    /// values, as costmaps are shown: the distance in percent of the cap (0 at an obstacle, 100
    /// at the cap or beyond); row 0 at the lowest y. `None` when nothing is left.
    pub fn ros_distance_around(&self, center: &Point2<f64>, half_m: f64) -> Option<RosOccupancy> {
        let g = self.grid.geometry();
        let (xs, ys) = g.cells_around(center, half_m)?;
        let cap = self.max_distance_m().max(f32::MIN_POSITIVE);
        let mut cells = Vec::with_capacity(xs.len() * ys.len());
        for y in ys.clone() {
            let row = &self.grid.data()[y * g.width() + xs.start..y * g.width() + xs.end];
            cells.extend(
                row.iter()
                    .map(|d| (d / cap * 100.0).round().clamp(0.0, 100.0) as i8),
            );
        }
        let res = g.resolution_m();
        Some(RosOccupancy {
            corner: g.origin_m()
                + nalgebra::Vector2::new(xs.start as f64 * res, ys.start as f64 * res),
            width: xs.len(),
            height: ys.len(),
            resolution_m: res,
            cells,
        })
    }

    /// The cap.
    pub fn max_distance_m(&self) -> f32 {
        self.max_distance_m
    }
}

/// A rectangle of cells, `x0..x1` by `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct CellBox {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

impl CellBox {
    /// Grown by `m` cells on every side, clipped to a `w` x `h` grid.
    fn grown(&self, m: usize, w: usize, h: usize) -> CellBox {
        CellBox {
            x0: self.x0.saturating_sub(m),
            y0: self.y0.saturating_sub(m),
            x1: (self.x1 + m).min(w),
            y1: (self.y1 + m).min(h),
        }
    }
    fn area(&self) -> usize {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }
    /// Chebyshev gap between the two boxes, in cells (0 when they touch or overlap).
    fn gap(&self, o: &CellBox) -> usize {
        let gx = (o.x0.saturating_sub(self.x1)).max(self.x0.saturating_sub(o.x1));
        let gy = (o.y0.saturating_sub(self.y1)).max(self.y0.saturating_sub(o.y1));
        gx.max(gy)
    }
    fn union(&self, o: &CellBox) -> CellBox {
        CellBox {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
        }
    }
}

/// Bounding boxes of the `changed` cells (row-major indices, `w` wide), merged until no two
/// boxes are closer than `merge_gap` cells.
fn changed_boxes(changed: &[usize], w: usize, merge_gap: usize) -> Vec<CellBox> {
    let mut boxes: Vec<CellBox> = Vec::new();
    for &i in changed {
        let (x, y) = (i % w, i / w);
        let cell = CellBox {
            x0: x,
            y0: y,
            x1: x + 1,
            y1: y + 1,
        };
        match boxes.iter_mut().find(|b| b.gap(&cell) < merge_gap) {
            Some(b) => *b = b.union(&cell),
            None => boxes.push(cell),
        }
    }
    // Growing a box can bring it within the gap of another: merge until none is.
    let mut merged = true;
    while merged {
        merged = false;
        'pairs: for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if boxes[i].gap(&boxes[j]) < merge_gap {
                    boxes[i] = boxes[i].union(&boxes[j]);
                    boxes.swap_remove(j);
                    merged = true;
                    break 'pairs;
                }
            }
        }
    }
    boxes
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    #[test]
    fn boxes_merge_within_the_gap_and_stay_apart_beyond_it() {
        let (w, h) = (100, 10);
        let old = vec![false; w * h];
        let mut new = old.clone();
        for x in [5, 9, 60] {
            new[3 * w + x] = true;
        }
        let changed: Vec<usize> = (0..w * h).filter(|&i| old[i] != new[i]).collect();
        let boxes = changed_boxes(&changed, w, 10);
        assert_eq!(boxes.len(), 2, "{boxes:?}");
        assert!(boxes.contains(&CellBox {
            x0: 5,
            y0: 3,
            x1: 10,
            y1: 4
        }));
        assert!(changed_boxes(&[], w, 10).is_empty());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]
        /// An update from any obstacle set to any other equals the transform computed afresh.
        #[test]
        fn update_equals_recompute(
            width in 1usize..90, height in 1usize..90, density in 0.0f64..0.2,
            flips in 0usize..12, extra in 0usize..12, cap in 0.2f32..4.0, seed in any::<u64>(),
        ) {
            let mut state = seed | 1;
            let old: Vec<bool> = (0..width * height)
                .map(|_| (xorshift(&mut state) % 10_000) as f64 / 10_000.0 < density)
                .collect();
            let mut new = old.clone();
            for _ in 0..flips {
                let i = (xorshift(&mut state) % (width * height) as u64) as usize;
                new[i] = !new[i];
            }
            let g = GridGeometry::new(Point2::new(-3.0, 2.0), 0.2, width, height).unwrap();
            let mut scratch = EdtScratch::default();
            let mut map = DistanceMap::compute(g, cap, |i| old[i], &mut scratch);
            let mut listed = map.clone();
            map.update(&old, &new, &mut scratch);
            let fresh = DistanceMap::compute(g, cap, |i| new[i], &mut scratch);
            prop_assert_eq!(map.grid().data(), fresh.grid().data());
            // Listing cells that did not change as well (as the mapper's lists of touched cells
            // do) changes nothing but the time.
            let mut cells: Vec<usize> = (0..width * height).filter(|&i| old[i] != new[i]).collect();
            for _ in 0..extra {
                cells.push((xorshift(&mut state) % (width * height) as u64) as usize);
            }
            cells.sort_unstable();
            cells.dedup();
            listed.update_cells(&cells, &new, &mut scratch);
            prop_assert_eq!(listed.grid().data(), fresh.grid().data());
        }
    }

    #[test]
    fn an_update_far_from_the_edges_runs_over_a_window_not_the_map() {
        let g = GridGeometry::new(Point2::origin(), 0.2, 300, 300).unwrap();
        let old = vec![false; 300 * 300];
        let mut new = old.clone();
        new[150 * 300 + 150] = true;
        let mut scratch = EdtScratch::default();
        let mut map = DistanceMap::compute(g, 2.0, |i| old[i], &mut scratch);
        // Cap 2 m = 10 cells, reach 11: a 45 x 45 window around the new obstacle.
        assert_eq!(map.update(&old, &new, &mut scratch), 45 * 45);
        assert!((map.distance_at(&Point2::new(30.1, 30.1 + 1.0)) - 1.0).abs() < 1e-6);
        // Everything changed: the whole map.
        let all = vec![true; 300 * 300];
        assert_eq!(map.update(&new, &all, &mut scratch), 300 * 300);
    }

    /// The ROS view of a distance map: percent of the cap, 0 on the obstacle, 50 at half the
    /// cap, 100 beyond; the square clamped to the grid, its corner the first cell's.
    #[test]
    fn the_ros_view_is_the_distance_in_percent_of_the_cap() {
        let g = GridGeometry::new(Point2::new(-10.0, -10.0), 0.5, 40, 40).unwrap();
        let obstacle = 20 * 40 + 20; // the cell whose corner is (0, 0)
        let mut scratch = EdtScratch::default();
        let map = DistanceMap::compute(g, 2.0, |i| i == obstacle, &mut scratch);
        let view = map
            .ros_distance_around(&Point2::new(0.25, 0.25), 3.0)
            .unwrap();
        assert_eq!((view.width, view.height), (12, 12));
        assert_eq!(view.corner, Point2::new(-3.0, -3.0));
        let at = |x: usize, y: usize| view.cells[y * view.width + x];
        assert_eq!(at(6, 6), 0);
        assert_eq!(at(8, 6), 50);
        assert_eq!(at(0, 0), 100);
        let edge = map
            .ros_distance_around(&Point2::new(-9.9, -9.9), 3.0)
            .unwrap();
        assert_eq!(
            (edge.width, edge.height, edge.corner),
            (6, 6, Point2::new(-10.0, -10.0))
        );
        assert!(
            map.ros_distance_around(&Point2::new(100.0, 0.0), 3.0)
                .is_none()
        );
    }
}
