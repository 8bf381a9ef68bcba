//! Forgetting: what makes live evidence of an obstacle go away - free-space walks on evidence,
//! cells handed back to the prior, and (an option) fading with time.
//!
//! - On evidence ([`FreeSpaceStop::ScanHits`], the default): a free-space walk lowers an older
//!   occupied cell only when a beam of its column crosses the cell within the span of heights
//!   its obstacle was hit at ([`HitSpan`], recorded per level and world cell by the insertion;
//!   [`WalkStops`] decides; a beam with no echo counts out to `no_echo_clears_within_m`, as
//!   `cells_hit_only_above_the_sensor_are_cleared_in_the_open_by_beams_with_no_echo_within_30_m`
//!   checks); otherwise the cell stops the walk. A beam over a cone or under a
//!   deck is no evidence the obstacle left, and a cell no beam crosses keeps its state. Guarded
//!   by `cells_an_obstacle_left_are_cleared_unless_walks_stop_at_any_occupied_cell` (in
//!   `mapper/tests/it/map/forgetting.rs`) and, for overhangs kept in every level they reach,
//!   `a_deck_over_the_route_stays_in_every_level` and
//!   `a_bar_whose_underside_is_below_the_ceiling_is_an_obstacle_in_every_level`
//!   (`mapper/tests/it/overhead.rs`).
//! - [`MultiHeightMap::clear_live`] hands cells back to the prior (the tracker of moving objects
//!   says which).
//! - [`MultiHeightMap::forget_unseen`] (the `time_decay` option only) fades live occupancy to
//!   the prior in log-odds with a time constant. It visits a per-level list of the cells that
//!   may be occupied ([`OccupiedCells`]) instead of sweeping its square, and changes exactly the
//!   cells a sweep would: `forgetting_changes_exactly_the_cells_a_sweep_of_its_square_changes`.

use foldhash::HashMap;
use nalgebra::Point2;
use rayon::prelude::*;

use super::config::FreeSpaceStop;
use super::{MultiHeightMap, WorldCell};

/// With [`FreeSpaceStop::ScanHits`], a beam clears an older occupied cell when it crosses the
/// cell's column within the span of heights its obstacle was hit at (recorded per live cell):
/// a beam through where the obstacle was is evidence it has gone; a beam over a cone or under a
/// deck is none. An obstacle standing on the ground (lowest hit under [`ON_GROUND_BELOW_M`]) is
/// cleared by a beam lower than its highest hit or than this above the level's height, metres
/// (so a stray hit just above the ground near the sensor, which no beam crosses lower down, is
/// still cleared); an overhead one by a beam within [`OVERHEAD_SPAN_SLACK_M`] of its span; a
/// cell with no recorded span (a live block read back from disk) by a beam
/// lower than this above the level's height.
///
/// The span, not this margin alone, decides for an obstacle with hits: a beam passing under a
/// deck or a bar, however low, is no evidence it has gone, so an overhang stays in every level
/// the cumulative rule puts it in (`a_deck_over_the_route_stays_in_every_level`); and no margin
/// is added above a ground obstacle's highest hit, so beams just over a low box do not clear it.
pub(super) const CLEAR_MARGIN_M: f64 = 0.2;

/// An obstacle whose lowest hit is below this stands on the ground (hits under the obstacle
/// height are ground to the test), metres: a beam through its column lower down clears it too.
const ON_GROUND_BELOW_M: f32 = 0.3;

/// How far beyond the span of its hits a beam may cross an overhead obstacle's column and still
/// count as passing where it was, metres: a span is often a single hit, and a beam's height
/// changes across a cell (0.2 m of a beam 27 degrees down: 0.1 m).
const OVERHEAD_SPAN_SLACK_M: f64 = 0.1;

/// The lowest and highest heights above ground a cell was hit at as an obstacle, metres.
#[derive(Clone, Copy, Debug)]
pub(super) struct HitSpan {
    /// The lowest hit's height, metres.
    pub(super) lo_m: f32,
    /// The highest hit's height, metres.
    pub(super) hi_m: f32,
}

/// Which occupied cells end one level's free-space walks ([`FreeSpaceStop`]): with
/// [`FreeSpaceStop::ScanHits`] the cells this scan hit and the older ones no beam of the column
/// crosses where their obstacle was hit (see [`CLEAR_MARGIN_M`]).
pub(super) struct WalkStops<'a> {
    /// The rule.
    pub(super) rule: FreeSpaceStop,
    /// The cells this scan hit in the level (window indices, sorted).
    pub(super) hit_cells: &'a [u32],
    /// The height spans of the level's hits, by world cell.
    pub(super) spans: &'a HashMap<WorldCell, HitSpan>,
    /// The world cell of the window's cell 0.
    pub(super) cell0: WorldCell,
    /// The window's width, cells.
    pub(super) width: usize,
    /// With no span recorded, a beam crossing below this height (the level's height plus
    /// [`CLEAR_MARGIN_M`]) is evidence the cell is free, metres.
    pub(super) clear_below: f64,
}

impl WalkStops<'_> {
    /// Whether the occupied cell `i` (window index) stops the walk. `crosses(lo, hi)`: whether a
    /// beam of the walk's column crosses the cell at a height in [lo, hi].
    pub(super) fn stops(&self, i: usize, crosses: &mut dyn FnMut(f64, f64) -> bool) -> bool {
        match self.rule {
            FreeSpaceStop::AnyOccupied => true,
            FreeSpaceStop::ScanHits => {
                if self.hit_cells.binary_search(&(i as u32)).is_ok() {
                    return true;
                }
                let (width, cell0) = (self.width, self.cell0);
                let at = ((i % width) as i64 + cell0.0, (i / width) as i64 + cell0.1);
                let evidence = match self.spans.get(&at) {
                    // Down to the ground for what stands on it (its lowest hits are the
                    // obstacle height up), up to its highest hit or h_k + 0.2 m.
                    Some(&HitSpan { lo_m: lo, hi_m: hi }) if lo < ON_GROUND_BELOW_M => {
                        crosses(f64::NEG_INFINITY, f64::from(hi).max(self.clear_below))
                    }
                    // Overhead: within the beam's rise across a cell of where it was hit.
                    Some(&HitSpan { lo_m: lo, hi_m: hi }) => crosses(
                        f64::from(lo) - OVERHEAD_SPAN_SLACK_M,
                        f64::from(hi) + OVERHEAD_SPAN_SLACK_M,
                    ),
                    None => crosses(f64::NEG_INFINITY, self.clear_below),
                };
                !evidence
            }
        }
    }
}

/// The live cells of one level whose log-odds may be positive (p > 0.5), so that forgetting
/// visits them instead of sweeping its square: a superset, as a list and a flag per cell. A hit
/// that makes a cell positive lists it; forgetting drops the cells that are no longer positive
/// (lowered by free-space walks, handed back to the prior); re-centring lists the window anew.
#[derive(Clone, Debug, Default)]
pub(super) struct OccupiedCells {
    cells: Vec<u32>,
    listed: Vec<bool>,
}

impl OccupiedCells {
    /// Lists every positive cell of `live`, and only those.
    pub(super) fn rebuild(&mut self, live: &[f32]) {
        self.listed.clear();
        self.listed.extend(live.iter().map(|&l| l > 0.0));
        self.cells.clear();
        self.cells.extend(
            self.listed
                .iter()
                .enumerate()
                .filter(|(_, l)| **l)
                .map(|(i, _)| i as u32),
        );
    }

    /// Lists cell `i` if it is not listed yet.
    #[inline]
    pub(super) fn note(&mut self, i: u32) {
        if !self.listed[i as usize] {
            self.listed[i as usize] = true;
            self.cells.push(i);
        }
    }
}

impl MultiHeightMap {
    /// Lists the positive live cells of every level anew (after the window changed).
    pub(super) fn list_occupied(&mut self) {
        self.occupied
            .par_iter_mut()
            .zip(&self.live)
            .for_each(|(o, live)| o.rebuild(live.data()));
    }

    /// Forgets live occupancy that is no longer seen: over the square of half side
    /// `half_size_m` around `center`, the log-odds of every live cell more occupied than its prior
    /// move toward the prior's (0 where the prior is unknown) by `1 - exp(-dt_s /
    /// time_constant_s)` of the gap, and the cell is handed back to the prior (unknown in the live
    /// map) once it is no longer an obstacle (p <= 0.5) or within 0.05 of the prior. CARMEN's
    /// decay to the offline map, as a time constant rather than a ratio per update, and in
    /// log-odds so that a cell seen many times keeps its confidence against stray free-space
    /// beams while it fades. What the sensor still sees is hit again every revolution and stays
    /// occupied; what it cannot see any more - the trail of a vehicle that drove on, hidden behind
    /// the airframe - stops being an obstacle after `ln 2` time constants from saturation over a
    /// saturated free prior. Returns the cells changed; their levels need their distance maps
    /// again.
    pub fn forget_unseen(
        &mut self,
        center: Point2<f64>,
        half_size_m: f64,
        dt_s: f64,
        time_constant_s: f64,
    ) -> usize {
        if !(dt_s > 0.0 && time_constant_s > 0.0) {
            return 0;
        }
        let keep = (-dt_s / time_constant_s).exp() as f32;
        let g = self.geometry;
        let half = (half_size_m / g.resolution_m()).ceil().max(1.0) as i64;
        let (cx, cy) = g.cell_coords(&center);
        let (w, h) = (g.width() as i64, g.height() as i64);
        let (x0, x1) = (
            (cx - half).clamp(0, w) as usize,
            (cx + half).clamp(0, w) as usize,
        );
        let (y0, y1) = (
            (cy - half).clamp(0, h) as usize,
            (cy + half).clamp(0, h) as usize,
        );
        let width = g.width();
        // The levels in parallel, each over its list of cells that may be occupied (only
        // evidence of an obstacle, p > 0.5, fades), dropping those that no longer are.
        let changed: Vec<usize> = self
            .live
            .par_iter_mut()
            .zip(&self.prior)
            .zip(self.occupied.par_iter_mut())
            .zip(self.touched.par_iter_mut())
            .map(|(((live, prior), occupied), touched)| {
                let mut changed = 0;
                let (live, prior) = (live.data_mut(), prior.data());
                let OccupiedCells { cells, listed } = occupied;
                cells.retain(|&i| {
                    let i = i as usize;
                    let l = live[i];
                    // Unknown (NaN) and free cells are not listed.
                    if l.is_nan() || l <= 0.0 {
                        listed[i] = false;
                        return false;
                    }
                    let (x, y) = (i % width, i / width);
                    if x < x0 || x >= x1 || y < y0 || y >= y1 {
                        return true;
                    }
                    let l_prior = if prior[i].is_nan() { 0.0 } else { prior[i] };
                    if l <= l_prior {
                        return true;
                    }
                    let l = l_prior + (l - l_prior) * keep;
                    changed += 1;
                    touched.note(i as u32);
                    if l <= 0.0 || l - l_prior < 0.05 {
                        // No longer an obstacle, or as good as the prior: hand the cell back.
                        live[i] = f32::NAN;
                        listed[i] = false;
                        false
                    } else {
                        live[i] = l;
                        true
                    }
                });
                changed
            })
            .collect();
        for (dirty, n) in self.odm_dirty.iter_mut().zip(&changed) {
            *dirty |= *n > 0;
        }
        changed.iter().sum()
    }

    /// Hands the live evidence of obstacle at `cells` (world lattice) back to the prior, in every
    /// level: a live cell more occupied than free (log-odds > 0) becomes unknown, so the offline
    /// map speaks for it again. What moved away is cleared this way (the tracker of moving
    /// objects decides what); free live cells and cells outside the window are left alone.
    /// Returns the level cells changed.
    pub fn clear_live(&mut self, cells: &[WorldCell]) -> usize {
        let mut changed = 0;
        for &cell in cells {
            let Some(i) = self.window_index(cell) else {
                continue;
            };
            for k in 0..self.levels.count() {
                self.hit_spans[k].remove(&cell);
                let v = &mut self.live[k].data_mut()[i];
                if *v > 0.0 {
                    *v = f32::NAN;
                    self.touched[k].note(i as u32);
                    self.odm_dirty[k] = true;
                    changed += 1;
                }
            }
        }
        changed
    }
}
