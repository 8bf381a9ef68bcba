//! Scan insertion: [`MultiHeightMap::insert_scan`], the classification of a revolution's returns
//! and the per-level work it runs in parallel (hits, then the free-space walks' schedule).
//!
//! One pass classifies every return once for every level (`classify`): returns at or above the
//! levels' ceiling are dropped before the obstacle test pairs them, self-hits are dropped through
//! the binned [`SelfHitFilter`] (the model's circles on a 0.5 m grid, which answers as the
//! circle-by-circle test: `the_binned_test_answers_as_the_straightforward_one` in
//! `self_hits.rs`), and each column is summarised per level: its farthest return the level
//! considers and its nearest obstacle hit ([`ColumnLevel`]). Then one rayon task per level
//! ([`LevelHits`], then [`LevelWalks`]) - beside them the remission of level 0's ground returns:
//! - the hits first, so this scan's obstacles already stop its own walks. A column's beams up
//!   one face mostly hit one cell: its consecutive hits in one cell are merged into one height
//!   span before one lookup of the level's span table (a lookup is a cache miss in a table that
//!   size; the tables are hashed with foldhash). The spans are what forgetting on evidence
//!   reads (`forget.rs`);
//! - then the free-space walks, coarse to fine ([`ColumnHierarchy`]); an older occupied cell
//!   they meet is lowered where a beam of the column crossed it where its obstacle was hit
//!   (`forget.rs`), a beam with no echo counting within `MapConfig::no_echo_clears_within_m`
//!   when it stays above the ground that far. With
//!   [`FreeSpaceWalks::CoarseToFine`], the default, only every 2^j-th column walks near the
//!   sensor, adding 2^j `l_free`, where stride 2^j keeps the walkers within half a cell
//!   ([`COVER`]) of each other, and a column starts where its band begins or a cell before where
//!   a coarser neighbour's walk stopped. [`FreeSpaceWalks::EveryColumn`], CARMEN's walk of every
//!   column, is the reference it is measured against:
//!   `coarse_to_fine_walks_map_what_every_column_maps_with_fewer_updates` (in
//!   `mapper/tests/it/map/insert.rs`) checks the two maps agree with fewer cell updates.

use foldhash::HashMap;
use nalgebra::{Point2, Point3};
use rayon::prelude::*;

use super::classified::{Classified, DROPPED};
use super::config::{FreeSpaceWalks, MapConfig};
use super::distance::{TouchedCells, no_obstacle_at_or_below};
use super::forget::{CLEAR_MARGIN_M, HitSpan, OccupiedCells, WalkStops};
use super::open_top::{BeamRises, NO_CLAIM, agreed_elevations, beam_elevations, claim_open_tops};
use super::walk::{Walk, walk_free};
use super::{MultiHeightMap, WorldCell};
use crate::collision::CollisionModel;
use crate::error::Result;
use crate::grid::{Grid, GridGeometry};
use crate::levels::{HeightClass, Levels};
use crate::occupancy::ObstacleTest;
use crate::scan::Scan;
use crate::self_hits::SelfHitFilter;
use crate::self_mask::SelfMask;

/// What one scan insertion did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InsertStats {
    /// Returns with an echo.
    pub returns: usize,
    /// Dropped as self-hits.
    pub self_hits: usize,
    /// Dropped beyond the maximum range or outside the window.
    pub out_of_range: usize,
    /// Dropped at or above the levels' ceiling (in no level, no evidence to the obstacle test).
    pub above_ceiling: usize,
    /// Obstacle hits per level.
    pub hits: Vec<usize>,
    /// Cells updated as free per level.
    pub free_cells: Vec<usize>,
}

/// What one level needs to know of one column before walking it, from the classification pass:
/// the farthest return it considers (not above it) and its nearest obstacle hit, as beam and
/// horizontal range (`NONE` and infinity when there is none).
#[derive(Clone, Copy, Debug)]
pub(super) struct ColumnLevel {
    far_m: f32,
    nearest_hit_m: f32,
    far: u16,
    nearest_hit: u16,
}

const NONE: u16 = u16::MAX;

impl Default for ColumnLevel {
    fn default() -> Self {
        ColumnLevel {
            far_m: 0.0,
            nearest_hit_m: f32::INFINITY,
            far: NONE,
            nearest_hit: NONE,
        }
    }
}

/// Where a height falls for a level whose band is [lo, hi).
fn height_class(height_m: f32, lo: f32, hi: f32) -> HeightClass {
    if height_m < lo {
        HeightClass::Below
    } else if height_m < hi {
        HeightClass::Inside
    } else {
        HeightClass::Above
    }
}

impl MultiHeightMap {
    /// Inserts one revolution. `vehicle` (its circles) drives the self-hit filter; `None` keeps every return.
    pub fn insert_scan(
        &mut self,
        scan: &Scan,
        vehicle: Option<&CollisionModel>,
    ) -> Result<InsertStats> {
        self.insert_scan_masked(scan, vehicle, None)
    }

    /// [`Self::insert_scan`] with the sensor's self mask too (`mask`, which must fit the scan):
    /// a return is dropped as the vehicle's own when either filter says it is.
    pub fn insert_scan_masked(
        &mut self,
        scan: &Scan,
        vehicle: Option<&CollisionModel>,
        mask: Option<&SelfMask>,
    ) -> Result<InsertStats> {
        if let Some(mask) = mask {
            mask.fits(scan)?;
        }
        let mut stats = InsertStats {
            hits: vec![0; self.levels.count()],
            free_cells: vec![0; self.levels.count()],
            ..Default::default()
        };
        self.classify(scan, vehicle, mask, &mut stats);

        let config = self.config;
        let geometry = self.geometry;
        let elevations: Vec<Option<(f64, f64)>> = (self.elevations.iter())
            .map(|e| e.map(|e| (e.cos(), e.sin())))
            .collect();
        let ctx = ScanContext {
            cell0: self.window_cell0(),
            levels: &self.levels,
            classified: &self.classified,
            column_levels: &self.column_levels,
            elevations: &elevations,
            scan,
            geometry: &geometry,
            config: &config,
        };
        // The levels in parallel - each its hits, then its free-space walks, so this scan's
        // obstacles already stop its own walks - and beside them the remission of the returns
        // that are ground for level 0.
        let (results, ()) = rayon::join(
            || -> Vec<(usize, usize)> {
                self.live
                    .par_iter_mut()
                    .zip(self.occupied.par_iter_mut())
                    .zip(self.touched.par_iter_mut())
                    .zip(self.last_hits.par_iter_mut())
                    .zip(self.hit_spans.par_iter_mut())
                    .enumerate()
                    .map(|(k, ((((grid, occupied), touched), hit_cells), spans))| {
                        let hits = LevelHits {
                            k,
                            ctx,
                            grid: &mut *grid,
                            occupied,
                            touched: &mut *touched,
                            hit_cells: &mut *hit_cells,
                            spans: &mut *spans,
                        }
                        .insert();
                        let free = LevelWalks {
                            k,
                            ctx,
                            grid,
                            touched,
                            hit_cells,
                            spans,
                        }
                        .walk();
                        (hits, free)
                    })
                    .collect()
            },
            || {
                let rem = self.live_remission.data_mut();
                for (c, r) in ctx.classified.iter().zip(scan.returns()) {
                    if let (Some(r), false, true) = (r, c.obstacle, c.cell != DROPPED) {
                        rem[c.cell as usize].add(config.remission_of(r.intensity, r.range_m));
                    }
                }
            },
        );
        for (k, (hits, free)) in results.into_iter().enumerate() {
            stats.hits[k] = hits;
            stats.free_cells[k] = free;
            if hits + free > 0 {
                self.odm_dirty[k] = true;
            }
        }
        Ok(stats)
    }

    /// The circles' self-hit filter for `vehicle` at the map's margin, made when it changes.
    fn prepare_self_filter(&mut self, vehicle: Option<&CollisionModel>) {
        let margin = self.config.self_hit_margin_m;
        if let Some(model) = vehicle
            && !self
                .self_hits
                .as_ref()
                .is_some_and(|f| f.is_for(model, margin))
        {
            self.self_hits = Some(SelfHitFilter::new(model, margin));
        }
    }

    /// Step 1 of the insertion: drop and classify every return once (self-hits, returns out of
    /// range or at or above the ceiling are dropped).
    fn classify(
        &mut self,
        scan: &Scan,
        vehicle: Option<&CollisionModel>,
        mask: Option<&SelfMask>,
        stats: &mut InsertStats,
    ) {
        let beams = scan.beams();
        let params = self.config.obstacle_test;
        let test = ObstacleTest::new(params);
        self.prepare_self_filter(vehicle);
        let self_filter = vehicle.and(self.self_hits.as_ref());
        let geometry = self.geometry;
        // Returns at or above the ceiling belong to no level (CARMEN drops points above the
        // vehicle plus a margin): dropped here, before the obstacle test pairs them.
        let ceiling = self.levels.ceiling_m().unwrap_or(f64::INFINITY);
        // Every entry is written below: resizing (not clearing) spares a serial pass over them.
        self.classified
            .resize(scan.returns().len(), Classified::default());
        let bands: Vec<(f32, f32)> = (0..self.levels.count())
            .map(|k| {
                (
                    self.levels.heights_m()[k] as f32,
                    self.levels.upper_m(k) as f32,
                )
            })
            .collect();
        let n_levels = bands.len().max(1);
        let elevations = beam_elevations(scan);
        let agreed = agreed_elevations(scan, &elevations);
        if self.elevations.len() == agreed.len() {
            for (known, e) in self.elevations.iter_mut().zip(agreed) {
                *known = e.or(*known);
            }
        } else {
            self.elevations = agreed;
        }
        let elevations = &elevations;
        self.column_levels
            .resize(scan.columns().len() * n_levels, ColumnLevel::default());
        let counts: (usize, usize, usize, usize) = self
            .classified
            .par_chunks_mut(beams)
            .zip(self.column_levels.par_chunks_mut(n_levels))
            .zip(scan.returns().par_chunks(beams))
            .zip(scan.columns().par_iter())
            .enumerate()
            .map(|(c, (((out, summary), returns), column))| {
                let sensor = Point2::from(column.world_from_sensor.translation.vector.xy());
                let sensor3 = nalgebra::Point3::from(column.world_from_sensor.translation.vector);
                let vehicle_from_world = column.world_from_vehicle.inverse();
                let (mut n, mut self_hits, mut far, mut above) = (0, 0, 0, 0);
                summary.fill(ColumnLevel::default());
                // The return of the beam below (dropped or not) and its horizontal range.
                let mut below: Option<(Point3<f64>, f64)> = None;
                for b in 0..beams {
                    out[b] = Classified {
                        cell: DROPPED,
                        ..Default::default()
                    };
                    let Some(r) = returns[b] else {
                        below = None;
                        continue;
                    };
                    n += 1;
                    let p = r.point_in_world;
                    let xy = Point2::new(p.x, p.y);
                    let (dx, dy) = (p.x - sensor.x, p.y - sensor.y);
                    let range_xy = (dx * dx + dy * dy).sqrt();
                    let height = p.z - params.ground_height_m;
                    if height >= ceiling {
                        // In no level, and no evidence for the beam above: as if it had no echo.
                        below = None;
                        above += 1;
                        continue;
                    }
                    let lower = below.replace((p, range_xy));
                    let Some(cell) = geometry
                        .index_of(&xy)
                        .filter(|_| range_xy <= params.max_range_m)
                    else {
                        far += 1;
                        continue;
                    };
                    let masked = mask.is_some_and(|m| m.is_self_hit(c, b, (p - sensor3).norm()));
                    if masked
                        || self_filter.is_some_and(|filter| {
                            filter.is_self_hit(&(vehicle_from_world * xy), height)
                        })
                    {
                        self_hits += 1;
                        continue;
                    }
                    let obstacle = match lower {
                        Some((lower, lower_range_xy)) => {
                            test.is_obstacle(&sensor3, &lower, lower_range_xy, &p, range_xy)
                        }
                        None => params
                            .unsafe_height_above_ground_m
                            .is_some_and(|h| height >= h),
                    };
                    let c = Classified {
                        cell: cell as u32,
                        height_m: height as f32,
                        range_xy_m: range_xy as f32,
                        obstacle,
                        open_top_m: NO_CLAIM,
                    };
                    out[b] = c;
                    summarise(&bands, summary, &c, b);
                }
                claim_open_tops(out, returns, column, elevations, params.ground_height_m);
                (n, self_hits, far, above)
            })
            .reduce(
                || (0, 0, 0, 0),
                |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3),
            );
        stats.returns = counts.0;
        stats.self_hits = counts.1;
        stats.out_of_range = counts.2;
        stats.above_ceiling = counts.3;
    }
}

/// A return kept (`c`, beam `b`) in its column's per-level summary: the farthest return
/// considered (the last of equals) and the nearest obstacle hit (the first of equals).
fn summarise(bands: &[(f32, f32)], summary: &mut [ColumnLevel], c: &Classified, b: usize) {
    for (&(lo, hi), sum) in bands.iter().zip(summary.iter_mut()) {
        let class = height_class(c.height_m, lo, hi);
        if class != HeightClass::Above && c.range_xy_m >= sum.far_m {
            (sum.far, sum.far_m) = (b as u16, c.range_xy_m);
        }
        if c.obstacle && class == HeightClass::Inside && c.range_xy_m < sum.nearest_hit_m {
            (sum.nearest_hit, sum.nearest_hit_m) = (b as u16, c.range_xy_m);
        }
    }
}

/// One level's view of the per-column summaries.
#[derive(Clone, Copy)]
struct ColumnsOfLevel<'a> {
    all: &'a [ColumnLevel],
    levels: usize,
    k: usize,
}

impl ColumnsOfLevel<'_> {
    fn get(&self, column: usize) -> ColumnLevel {
        self.all[column * self.levels + self.k]
    }
}

/// What every level's insertion of one scan reads: the scan, its classified returns and their
/// per-column summaries, the window and the map's settings.
#[derive(Clone, Copy)]
struct ScanContext<'a> {
    /// The world cell of the window's cell 0.
    cell0: WorldCell,
    /// The map's levels.
    levels: &'a Levels,
    /// Every return of the scan, classified.
    classified: &'a [Classified],
    /// Every level's summary of each column.
    column_levels: &'a [ColumnLevel],
    /// The cosine and sine of each beam's elevation in the sensor frame (`None`: no echo in
    /// any scan yet).
    elevations: &'a [Option<(f64, f64)>],
    /// The scan.
    scan: &'a Scan,
    /// The window.
    geometry: &'a GridGeometry,
    /// The map's configuration.
    config: &'a MapConfig,
}

impl<'a> ScanContext<'a> {
    /// Level `k`'s summary of each column.
    fn summary(&self, k: usize) -> ColumnsOfLevel<'a> {
        ColumnsOfLevel {
            all: self.column_levels,
            levels: self.levels.count(),
            k,
        }
    }
}

/// Step 2 of the insertion for one level of one scan: what it updates - the level's grid, its
/// occupied and touched cells, the cells this scan hit and the height spans of its hits.
struct LevelHits<'a> {
    /// The level.
    k: usize,
    /// The scan and the map's settings.
    ctx: ScanContext<'a>,
    /// Its live log-odds.
    grid: &'a mut Grid<f32>,
    /// Its live cells that may be occupied.
    occupied: &'a mut OccupiedCells,
    /// Its cells whose obstacle state may have changed.
    touched: &'a mut TouchedCells,
    /// The cells this scan hits (window indices; sorted once the hits are in).
    hit_cells: &'a mut Vec<u32>,
    /// The height spans of its hits, by world cell.
    spans: &'a mut HashMap<WorldCell, HitSpan>,
}

impl LevelHits<'_> {
    /// Step 2 of the insertion for one level: its obstacle hits raise their cells (the column's
    /// nearest twice), are listed (this scan's hit cells, sorted) and their heights recorded.
    /// Returns the hits.
    fn insert(self) -> usize {
        let ctx = self.ctx;
        let (beams, width) = (ctx.scan.beams(), ctx.geometry.width());
        let (h_lo, h_hi) = (
            ctx.levels.heights_m()[self.k] as f32,
            ctx.levels.upper_m(self.k) as f32,
        );
        let occ = ctx.config.occupancy;
        let data = self.grid.data_mut();
        let (occupied, touched, hit_cells) = (self.occupied, self.touched, self.hit_cells);
        let (spans, cell0) = (self.spans, ctx.cell0);
        let (classified, summary) = (ctx.classified, ctx.summary(self.k));
        let add = |v: &mut f32, delta: f32| {
            let cur = if v.is_nan() { 0.0 } else { *v };
            *v = (cur + delta).clamp(-occ.l_max, occ.l_max);
        };
        let mut hits = 0;
        hit_cells.clear();
        // The height span of consecutive hits in one cell, not yet merged into `spans`.
        let mut pending: Option<(u32, HitSpan)> = None;
        let mut merge = |cell: u32, HitSpan { lo_m: lo, hi_m: hi }: HitSpan| {
            let i = cell as usize;
            let at = ((i % width) as i64 + cell0.0, (i / width) as i64 + cell0.1);
            let span = spans.entry(at).or_insert(HitSpan { lo_m: lo, hi_m: hi });
            *span = HitSpan {
                lo_m: span.lo_m.min(lo),
                hi_m: span.hi_m.max(hi),
            };
        };
        for ci in 0..classified.len() / beams.max(1) {
            let nearest = summary.get(ci).nearest_hit;
            if nearest == NONE {
                continue;
            }
            for (b, c) in classified[ci * beams..(ci + 1) * beams].iter().enumerate() {
                if !(c.cell != DROPPED
                    && c.obstacle
                    && height_class(c.height_m, h_lo, h_hi) == HeightClass::Inside)
                {
                    continue;
                }
                let v = &mut data[c.cell as usize];
                let weight = if b == nearest as usize { 2.0 } else { 1.0 };
                add(v, weight * occ.l_occ);
                if *v > 0.0 {
                    occupied.note(c.cell);
                }
                hits += 1;
                hit_cells.push(c.cell);
                // A column's beams up one face mostly hit one cell: its heights are gathered here
                // and looked up in the table once (a lookup is a cache miss in a table this size).
                let h = c.height_m;
                match &mut pending {
                    Some((cell, span)) if *cell == c.cell => {
                        *span = HitSpan {
                            lo_m: span.lo_m.min(h),
                            hi_m: span.hi_m.max(h),
                        }
                    }
                    _ => {
                        if let Some((cell, span)) =
                            pending.replace((c.cell, HitSpan { lo_m: h, hi_m: h }))
                        {
                            merge(cell, span);
                        }
                    }
                }
            }
        }
        if let Some((cell, span)) = pending {
            merge(cell, span);
        }
        hit_cells.sort_unstable();
        hit_cells.dedup();
        for &i in hit_cells.iter() {
            touched.note(i);
        }
        hits
    }
}

/// Steps 3-4 of the insertion for one level of one scan, once its hits are in: the free-space
/// walks update the level's grid and touched cells, and read the cells this scan hit and the
/// height spans of the level's hits.
struct LevelWalks<'a> {
    /// The level.
    k: usize,
    /// The scan and the map's settings.
    ctx: ScanContext<'a>,
    /// Its live log-odds.
    grid: &'a mut Grid<f32>,
    /// Its cells whose obstacle state may have changed.
    touched: &'a mut TouchedCells,
    /// The cells this scan hit in the level (window indices, sorted).
    hit_cells: &'a [u32],
    /// The height spans of its hits, by world cell.
    spans: &'a HashMap<WorldCell, HitSpan>,
}

impl LevelWalks<'_> {
    /// The free-space walks, to the farthest return the level considers in each column. Returns
    /// the free cells updated.
    fn walk(self) -> usize {
        let (k, ctx) = (self.k, self.ctx);
        let (levels, scan, geometry, config) = (ctx.levels, ctx.scan, ctx.geometry, ctx.config);
        let summary = ctx.summary(k);
        let beams = scan.beams();
        let occ = config.occupancy;
        let data = self.grid.data_mut();
        let n = scan.columns().len();
        let width = geometry.width();
        let touched = self.touched;
        let watch = no_obstacle_at_or_below(config);
        // A beam crossing an older occupied cell where its obstacle was hit (or, with no span
        // recorded, below this height) is evidence the cell is free.
        let stops = WalkStops {
            rule: config.free_space_stop,
            hit_cells: self.hit_cells,
            spans: self.spans,
            cell0: ctx.cell0,
            width,
            clear_below: levels.heights_m()[k] + CLEAR_MARGIN_M,
        };
        // Free-space walks, to the farthest return this level considers in each column.
        let mut free = 0;
        let (w, h) = (geometry.width() as i64, geometry.height() as i64);
        let hierarchy = ColumnHierarchy::new(config.free_space_walks, n, geometry.resolution_m());
        // How far each column's walk got (metres from its sensor): where its finer neighbours start
        // at the latest.
        let mut reach = vec![0.0f64; n];
        // (horizontal range, height) of a column's beams' ends (returns, or no echo within
        // `no_echo_clears_within_m`), reused from column to column.
        let mut ends: Vec<(f64, f64)> = Vec::with_capacity(beams);
        for (ci, depth) in hierarchy.order() {
            let sum = summary.get(ci);
            if sum.far == NONE {
                continue;
            }
            let start_m = hierarchy.start_m(ci, depth, &reach);
            // Its own nearest obstacle ends any walk of the column (its cell stops it), so a column
            // starting beyond it would walk what the obstacle hides.
            if sum.nearest_hit_m as f64 <= start_m {
                reach[ci] = sum.nearest_hit_m as f64;
                continue;
            }
            if sum.far_m as f64 <= start_m {
                reach[ci] = sum.far_m as f64;
                continue;
            }
            let Some(end) = scan.returns()[ci * beams + sum.far as usize] else {
                continue;
            };
            let sensor = scan.columns()[ci].world_from_sensor.translation.vector;
            let (sensor_xy, end_xy) = (
                Point2::new(sensor.x, sensor.y),
                Point2::new(end.point_in_world.x, end.point_in_world.y),
            );
            let total = (end_xy - sensor_xy).norm();
            // Whether a beam of the column crosses distance r (returns beyond it) at a height in
            // [lo, hi]: each beam's height at r on its straight line from the sensor.
            let ground = config.obstacle_test.ground_height_m;
            let sensor_z = sensor.z - ground;
            // Gathered only if a walk meets an occupied cell (most never do).
            let mut ends_ready = false;
            let mut crosses = |r: f64, lo: f64, hi: f64| {
                if !ends_ready {
                    ends.clear();
                    // Every return of the column, those the map drops included (beyond the obstacle
                    // test's range, above the ceiling): each beam crossed what lies before it.
                    let column = &scan.returns()[ci * beams..(ci + 1) * beams];
                    ends.extend(column.iter().flatten().map(|ret| {
                        let p = ret.point_in_world;
                        ((p.x - sensor.x).hypot(p.y - sensor.y), p.z - ground)
                    }));
                    // A beam with no echo that stays above the ground out to `no_echo` crossed
                    // what lies before that: in the open, the only beams through an object's
                    // cells hit at the sensor's height and above (a fuel truck's tank seen from
                    // a nose sensor 1.55 m up: its trail held the jet for good). A beam dropped
                    // at random (1.3 % on an HDL-32E) lowers a cell it did not hit by one
                    // free-space update against 5.7 for each hit; a beam dead in every column
                    // has no known elevation and counts for nothing. The elevations are those
                    // of any revolution so far: in the open, the beams above the horizon echo
                    // only now and then (a building, a lamp post, the vehicle's own tail).
                    // Only where the same beam of both neighbouring columns has no echo either:
                    // one dropped at random beside echoes (off the airframe, a cart nearer
                    // than the cell) is no look through what it would have hit.
                    let no_echo = config.no_echo_clears_within_m;
                    let n = scan.columns().len();
                    let open = |c: usize, b: usize| scan.returns()[c * beams + b].is_none();
                    let sky = |b: usize| open((ci + n - 1) % n, b) && open((ci + 1) % n, b);
                    let rises = BeamRises::new(&scan.columns()[ci], &end.point_in_world);
                    let elevations = column.iter().zip(ctx.elevations).enumerate();
                    ends.extend(elevations.filter_map(|(b, (ret, e))| {
                        let rise = rises.rise((*e)?);
                        let z = sensor_z + no_echo * rise;
                        (ret.is_none() && no_echo > 0.0 && z > 0.0 && sky(b))
                            .then_some((no_echo, z))
                    }));
                    ends_ready = true;
                }
                ends.iter().any(|&(range, z)| {
                    range > r && {
                        let at = sensor_z + (z - sensor_z) * r / range.max(1e-6);
                        at >= lo && at <= hi
                    }
                })
            };
            let walk = Walk {
                from: geometry.cell_coords(&sensor_xy),
                to: geometry.cell_coords(&end_xy),
                length_m: total,
                start_m,
                stop_short: config.free_space_stop_cells,
            };
            let (updated, reached_m) = walk_free(
                data,
                (w, h),
                &walk,
                |r| hierarchy.weight(depth, r) * occ.l_free,
                occ.l_max,
                |i, r| stops.stops(i, &mut |lo, hi| crosses(r, lo, hi)),
                (watch, &mut *touched),
            );
            free += updated;
            reach[ci] = reached_m;
        }
        free
    }
}

/// The columns of a revolution as a binary hierarchy for [`FreeSpaceWalks::CoarseToFine`]:
/// column c is at depth `min(trailing zeros of c, max_depth)` (column 0 at `max_depth`), and a
/// column at depth j walks the band of ranges where the stride 2^j keeps walkers within a cell
/// of each other and every range beyond it.
struct ColumnHierarchy {
    columns: usize,
    max_depth: u32,
    resolution_m: f64,
    /// `COVER resolution / dtheta`: where adjacent columns are `COVER` cells apart.
    r1_m: f64,
}

/// Walkers at most this many cells apart (at the outer end of their band). Bresenham lines less
/// than a cell apart still leave cells between them unwalked: on the parking-lot drive of
/// `coarse_to_fine_walks_map_what_every_column_maps_with_fewer_updates` (mapper/tests/it/map/insert.rs,
/// which prints both) 1.0 leaves 1.4 % of what every column maps unknown for 36 % of the cell
/// updates, 0.8 0.3 % for 43 %, 0.5 0.02 % for 58 %.
const COVER: f64 = 0.5;

impl ColumnHierarchy {
    fn new(walks: FreeSpaceWalks, columns: usize, resolution_m: f64) -> Self {
        let max_depth = match walks {
            FreeSpaceWalks::EveryColumn => 0,
            // At least 16 walkers around the sensor; strides up to 256.
            FreeSpaceWalks::CoarseToFine => (columns / 16).max(1).ilog2().min(8),
        };
        ColumnHierarchy {
            columns,
            max_depth,
            resolution_m,
            r1_m: COVER * resolution_m * columns as f64 / std::f64::consts::TAU,
        }
    }

    /// (column, depth), coarsest first, so a column's coarser neighbours come before it.
    fn order(&self) -> impl Iterator<Item = (usize, u32)> + '_ {
        (0..=self.max_depth).rev().flat_map(move |j| {
            let step = 1usize << j;
            let (first, stride) = if j == self.max_depth {
                (0, step)
            } else {
                (step, 2 * step)
            };
            (first..self.columns).step_by(stride).map(move |c| (c, j))
        })
    }

    /// Range beyond which stride 2^j leaves more than a cell between walkers.
    fn band_end_m(&self, j: u32) -> f64 {
        self.r1_m / (1u64 << j) as f64
    }

    /// Where the column at `depth` starts walking: where its band begins, or a cell before
    /// where either coarser neighbour's walk ended.
    fn start_m(&self, c: usize, depth: u32, reach: &[f64]) -> f64 {
        if depth == self.max_depth {
            return 0.0;
        }
        let step = 1usize << depth;
        let right = if c + step < self.columns { c + step } else { 0 };
        self.band_end_m(depth + 1)
            .min(reach[c - step] - self.resolution_m)
            .min(reach[right] - self.resolution_m)
            .max(0.0)
    }

    /// The columns a walk of depth `depth` stands for at range `r_m`.
    fn weight(&self, depth: u32, r_m: f64) -> f32 {
        let mut j = depth;
        while j > 0 && r_m >= self.band_end_m(j) {
            j -= 1;
        }
        (1u32 << j) as f32
    }
}
