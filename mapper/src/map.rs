//! `MultiHeightMap`: the local window of per-level occupancy grids, its scan insertion, the
//! offline/online merge, re-centring with blocks on disk, and the per-level distance maps.
//!
//! The window is `window_blocks` x `window_blocks` blocks (3 x 3 blocks of 70 m: 210 m, 1050 x
//! 1050 cells by default) and re-centres, block by block, so the vehicle stays in the middle one.
//! Each level keeps two log-odds grids: the *prior* (the offline map, read from a block store)
//! and the *live* map (built from this run's scans only). Their merge is what the distance maps
//! see: a cell the live map has not observed takes the prior's value (CARMEN's online map);
//! with [`MergeMode::Decay`] a cell both know is `(10 p_live + p_prior) / 11`. Blocks leaving the
//! window are written to the live store and read back when they re-enter, so memory is bounded
//! by the window whatever the route length.
//!
//! Scan insertion, per level (levels run in parallel):
//! 1. every return is classified once: dropped (no echo, beyond `max_range_m`, or a self-hit
//!    within `self_hit_margin_m` of a vehicle circle), and given its obstacle probability from the
//!    test against the beam below it ([`crate::occupancy::obstacle_probability`]);
//! 2. for the level, a return below h_k is flat ground, one above the level's range is ignored,
//!    one inside it is an obstacle hit when its probability is above 0.5;
//! 3. hits add `l_occ` to their cell, the nearest hit of each column `2 l_occ`;
//! 4. then, per column, one straight cell walk (Bresenham) from the sensor to the farthest
//!    return the level considers adds `l_free`, leaving the last `free_space_stop_cells` cells
//!    of the line (the endpoint's cell included) untouched and stopping at the first live cell
//!    with p >= 0.5 that this scan hit ([`FreeSpaceStop::ScanHits`], the default; older occupied
//!    cells on the way are lowered, so moved obstacles clear) or at any such cell
//!    ([`FreeSpaceStop::AnyOccupied`], CARMEN's rule). The beams of a column share its vertical
//!    plane, so one walk per column covers each of its beams' 2D traces once. Near the sensor
//!    the columns are much closer together than a cell, so by default
//!    ([`FreeSpaceWalks::CoarseToFine`]) only every 2^j-th column walks there, adding 2^j
//!    `l_free`: the same map with fewer cell updates.

use foldhash::HashMap;

use nalgebra::{Point2, Point3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::blocks::{Block, BlockIndex, BlockSpec, BlockStore};
use crate::collision::CollisionModel;
use crate::edt::EdtScratch;
use crate::error::{MapError, Result, positive};
use crate::grid::{Grid, GridGeometry};
use crate::levels::{HeightClass, Levels};
use crate::occupancy::{ObstacleTest, ObstacleTestParams, OccupancyParams, probability};
use crate::odm::{DistanceMap, DistanceMaps};
use crate::remission::RemissionCell;
use crate::scan::Scan;
use crate::self_hits::SelfHitFilter;

/// How the live map and the offline prior combine.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MergeMode {
    /// Live value where the live map knows the cell, prior value elsewhere (CARMEN's default).
    #[default]
    Fallback,
    /// Where both know the cell: `(10 p_live + p_prior) / 11`; otherwise as `Fallback`.
    Decay,
}

/// Everything tunable about a map. Defaults are CARMEN's multi-height ones (FACTS.md).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapConfig {
    /// Cell side, metres. Default 0.2.
    pub resolution_m: f64,
    /// Cells per block side. Default 350 (70 m blocks).
    pub block_cells: usize,
    /// Blocks per window side, odd. Default 3 (a 210 m window).
    pub window_blocks: usize,
    /// The window moves once the position is this far past its middle block's edge, metres
    /// (hysteresis: a route along a block edge would otherwise move it back and forth at every
    /// revolution - 418 moves in an aerodrome lap, a sixth of its wall time). Default 8 m; at
    /// most half a block. What lies beyond the window then starts up to this much nearer on
    /// the side the vehicle crossed.
    pub recenter_margin_m: f64,
    /// Log-odds update.
    pub occupancy: OccupancyParams,
    /// Obstacle test.
    pub obstacle_test: ObstacleTestParams,
    /// Cells left untouched at the end of each free-space walk (the endpoint's cell included). Default 2.
    pub free_space_stop_cells: usize,
    /// Returns within a circle's radius plus this margin are self-hits and dropped, metres. Default 0.8.
    pub self_hit_margin_m: f64,
    /// A cell is an obstacle for the distance map when its probability is above this. Default 0.5.
    pub obstacle_threshold: f32,
    /// Distances are capped here, metres. Default 30 (more than a jet's bounding radius, so the
    /// early out of the collision check can answer far from obstacles).
    pub max_distance_m: f32,
    /// Live / prior merge.
    pub merge: MergeMode,
    /// Which occupied cells end a free-space walk.
    pub free_space_stop: FreeSpaceStop,
    /// Which columns walk free space where.
    pub free_space_walks: FreeSpaceWalks,
}

/// Which columns of a scan walk free space, and where.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FreeSpaceWalks {
    /// Every column walks from the sensor to its farthest return (CARMEN's one update per beam
    /// and cell crossed). Near the sensor the columns are far closer together than a cell (2187
    /// columns at 0.2 m: 7 columns a cell at 10 m), so a cell there is walked many times a scan.
    EveryColumn,
    /// The same free-space evidence with about a third of the cell visits: at range r only the
    /// columns that are multiples of 2^j walk, for the largest 2^j that keeps them within a cell
    /// of each other (`2^j r dtheta <= resolution`), and each adds `2^j l_free`, the share of the
    /// 2^j columns it stands for. A column starts walking where it is first needed - or where
    /// a coarser neighbour stopped short (an obstacle, its last return), so nothing in the
    /// shadow of a coarse column's obstacle is left unwalked. The default.
    #[default]
    CoarseToFine,
}

/// Which occupied cells (p >= 0.5) end a free-space walk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FreeSpaceStop {
    /// Cells hit by the scan being inserted, and older occupied cells the beam passes above
    /// the level's height plus 0.2 m (a beam over a cone is no evidence the cone left). An older
    /// occupied cell the beam passes lower through is lowered by `l_free`, so an obstacle that
    /// moved away (a crossing vehicle) is cleared. The default.
    #[default]
    ScanHits,
    /// Any live cell with p >= 0.5 (CARMEN's rule): what was once occupied and is not hit again
    /// is never walked through, so the cells a moving obstacle left stay occupied.
    AnyOccupied,
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            resolution_m: 0.2,
            block_cells: 350,
            window_blocks: 3,
            recenter_margin_m: 8.0,
            occupancy: OccupancyParams::default(),
            obstacle_test: ObstacleTestParams::default(),
            free_space_stop_cells: 2,
            self_hit_margin_m: 0.8,
            obstacle_threshold: 0.5,
            max_distance_m: 30.0,
            merge: MergeMode::Fallback,
            free_space_stop: FreeSpaceStop::ScanHits,
            free_space_walks: FreeSpaceWalks::CoarseToFine,
        }
    }
}

impl MapConfig {
    /// Checks every field, naming the first wrong one.
    pub fn validate(&self) -> Result<()> {
        positive("resolution_m", self.resolution_m)?;
        if self.block_cells == 0 {
            return Err(MapError::invalid("block_cells", "must be > 0"));
        }
        if self.window_blocks == 0 || self.window_blocks.is_multiple_of(2) {
            return Err(MapError::invalid(
                "window_blocks",
                format!("{}: must be odd", self.window_blocks),
            ));
        }
        let m = self.recenter_margin_m;
        if !(m.is_finite() && m >= 0.0 && m <= 0.5 * self.block_m()) {
            return Err(MapError::invalid(
                "recenter_margin_m",
                format!(
                    "{m}: must be in [0, half a block: {}]",
                    0.5 * self.block_m()
                ),
            ));
        }
        let o = &self.occupancy;
        if !(o.l_occ.is_finite() && o.l_occ > 0.0) {
            return Err(MapError::invalid(
                "occupancy.l_occ",
                format!("{}: must be > 0", o.l_occ),
            ));
        }
        if !(o.l_free.is_finite() && o.l_free < 0.0) {
            return Err(MapError::invalid(
                "occupancy.l_free",
                format!("{}: must be < 0", o.l_free),
            ));
        }
        positive("occupancy.l_max", o.l_max as f64)?;
        positive("obstacle_test.sigma", self.obstacle_test.sigma)?;
        positive("obstacle_test.max_range_m", self.obstacle_test.max_range_m)?;
        crate::error::finite(
            "obstacle_test.ground_height_m",
            self.obstacle_test.ground_height_m,
        )?;
        if let Some(h) = self.obstacle_test.unsafe_height_above_ground_m {
            positive("obstacle_test.unsafe_height_above_ground_m", h)?;
        }
        if !(self.self_hit_margin_m.is_finite() && self.self_hit_margin_m >= 0.0) {
            return Err(MapError::invalid(
                "self_hit_margin_m",
                format!("{}: must be >= 0", self.self_hit_margin_m),
            ));
        }
        if !(self.obstacle_threshold > 0.0 && self.obstacle_threshold < 1.0) {
            return Err(MapError::invalid(
                "obstacle_threshold",
                format!("{}: must be in (0, 1)", self.obstacle_threshold),
            ));
        }
        positive("max_distance_m", self.max_distance_m as f64)?;
        Ok(())
    }

    /// Side of a block in metres.
    pub fn block_m(&self) -> f64 {
        self.block_cells as f64 * self.resolution_m
    }
}

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

/// One return, classified once for every level.
#[derive(Clone, Copy, Debug, Default)]
struct Classified {
    /// Cell index in the window, `u32::MAX` when dropped.
    cell: u32,
    height_m: f32,
    range_xy_m: f32,
    obstacle: bool,
}

const DROPPED: u32 = u32::MAX;

/// What one level needs to know of one column before walking it, from the classification pass:
/// the farthest return it considers (not above it) and its nearest obstacle hit, as beam and
/// horizontal range (`NONE` and infinity when there is none).
#[derive(Clone, Copy, Debug)]
struct ColumnLevel {
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
/// The older rule, this above the level's height for every cell, broke the cumulative rule for
/// overhangs (issue 19): a beam passing under a deck between 0.2 m and h_k + 0.2 m lowered the
/// deck's cells in level k and not in level 0 (a mapping drive under a 6 m deck left 2693 deck
/// cells in level 0 and 63 in level 1), and a beam under a bar 1.9 m up cleared the bar. A
/// first span rule with 0.2 m of margin above the highest hit cleared a 0.3 m box in a jet's
/// main-gear path with the beams just over it, and the gear struck it.
const CLEAR_MARGIN_M: f64 = 0.2;

/// An obstacle whose lowest hit is below this stands on the ground (hits under the obstacle
/// height are ground to the test), metres: a beam through its column lower down clears it too.
const ON_GROUND_BELOW_M: f32 = 0.3;

/// How far beyond the span of its hits a beam may cross an overhead obstacle's column and still
/// count as passing where it was, metres: a span is often a single hit, and a beam's height
/// changes across a cell (0.2 m of a beam 27 degrees down: 0.1 m).
const OVERHEAD_SPAN_SLACK_M: f64 = 0.1;

/// The local window of a quantized multi-height occupancy grid map.
#[derive(Debug)]
pub struct MultiHeightMap {
    config: MapConfig,
    levels: Levels,
    spec: BlockSpec,
    geometry: GridGeometry,
    /// Block index of the window's lower-left block.
    window_lo: BlockIndex,
    live: Vec<Grid<f32>>,
    prior: Vec<Grid<f32>>,
    live_remission: Grid<RemissionCell>,
    prior_remission: Grid<RemissionCell>,
    odm: DistanceMaps,
    odm_dirty: Vec<bool>,
    /// Per level, the obstacle cells (region order) its distance map was last computed from.
    odm_obstacles: Vec<Vec<bool>>,
    /// Scratch for the obstacle cells of the level being updated.
    odm_mask: Vec<bool>,
    /// Per level, the cells whose obstacle state may have changed since its distance map was
    /// last brought up to date.
    touched: Vec<TouchedCells>,
    /// Scratch for the region cells whose obstacle state did change.
    odm_changed: Vec<usize>,
    prior_store: Option<BlockStore>,
    live_store: Option<BlockStore>,
    classified: Vec<Classified>,
    /// The vehicle's self-hit test, binned; rebuilt when the model or the margin changes.
    self_hits: Option<SelfHitFilter>,
    /// Per column, per level (column-major): the summary of the classification pass.
    column_levels: Vec<ColumnLevel>,
    /// Per level, the live cells that may be occupied: what forgetting visits.
    occupied: Vec<OccupiedCells>,
    /// Per level, the cells the last revolution hit as obstacles (window indices, sorted).
    last_hits: Vec<Vec<u32>>,
    /// Per level, the span of heights (lowest, highest above ground, metres) at which each live
    /// cell was hit as an obstacle: what a later beam must cross to clear it.
    hit_spans: Vec<HashMap<WorldCell, HitSpan>>,
    edt_scratch: EdtScratch,
}

/// A cell on the world lattice: cell (0, 0) has its lower-left corner at the world origin. The
/// same cell whatever the window (window indices move when it re-centres).
pub type WorldCell = (i64, i64);

/// The live cells of one level whose log-odds may be positive (p > 0.5), so that forgetting
/// visits them instead of sweeping its square: a superset, as a list and a flag per cell. A hit
/// that makes a cell positive lists it; forgetting drops the cells that are no longer positive
/// (lowered by free-space walks, handed back to the prior); re-centring lists the window anew.
#[derive(Clone, Debug, Default)]
struct OccupiedCells {
    cells: Vec<u32>,
    listed: Vec<bool>,
}

impl OccupiedCells {
    /// Lists every positive cell of `live`, and only those.
    fn rebuild(&mut self, live: &[f32]) {
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
    fn note(&mut self, i: u32) {
        if !self.listed[i as usize] {
            self.listed[i as usize] = true;
            self.cells.push(i);
        }
    }
}

/// The live cells of one level whose obstacle state (live merged with prior) may have changed
/// since the level's distance map was last brought up to date, so that the update re-tests
/// them instead of sweeping its region: every cell a hit raises, every cell a free-space walk
/// lowers from the obstacle side of the threshold or from unknown (rare once an area has been
/// seen: walks mostly lower free cells, which cannot change state), every cell forgetting
/// changes. A superset, in the order noted, repeats allowed; past [`TOUCHED_CAP`] cells it only
/// remembers that it overflowed, and the update sweeps the region as without it. Re-centring
/// (every index moves) starts the distance maps over instead.
#[derive(Clone, Debug, Default)]
struct TouchedCells {
    cells: Vec<u32>,
    overflowed: bool,
}

/// Cells a [`TouchedCells`] list holds before it overflows (1 MiB of indices; a 100 m square
/// of 0.2 m cells is 250,000).
const TOUCHED_CAP: usize = 1 << 18;

impl TouchedCells {
    #[inline]
    fn note(&mut self, i: u32) {
        if self.cells.len() < TOUCHED_CAP {
            self.cells.push(i);
        } else {
            self.overflowed = true;
        }
    }
    fn clear(&mut self) {
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
fn no_obstacle_at_or_below(config: &MapConfig) -> f32 {
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
    /// An empty map (no prior, no stores) whose window is centred on the block holding `center`.
    pub fn new(config: MapConfig, levels: Levels, center: Point2<f64>) -> Result<Self> {
        Self::with_stores(config, levels, center, None, None)
    }

    /// A map over an offline prior (`prior_dir`, read only) whose live blocks leaving the window
    /// go to `live_dir` (dropped when `None`). Blocks of the first window are loaded now.
    pub fn with_stores(
        config: MapConfig,
        levels: Levels,
        center: Point2<f64>,
        prior_dir: Option<&std::path::Path>,
        live_dir: Option<&std::path::Path>,
    ) -> Result<Self> {
        config.validate()?;
        crate::error::finite("center.x", center.x)?;
        crate::error::finite("center.y", center.y)?;
        let spec = BlockSpec {
            side: config.block_cells,
            resolution_m: config.resolution_m,
            levels: levels.clone(),
            l_max: config.occupancy.l_max,
        };
        let prior_store = prior_dir
            .map(|d| BlockStore::open(d, spec.clone()))
            .transpose()?;
        let live_store = live_dir
            .map(|d| BlockStore::open(d, spec.clone()))
            .transpose()?;
        let side = config.block_cells * config.window_blocks;
        let window_lo = Self::window_lo_for(&config, center);
        let origin = Point2::new(
            window_lo.x as f64 * config.block_m(),
            window_lo.y as f64 * config.block_m(),
        );
        let geometry = GridGeometry::new(origin, config.resolution_m, side, side)?;
        let n = levels.count();
        let odm = DistanceMaps::new(
            levels.mode(),
            vec![DistanceMap::empty(geometry, config.max_distance_m); n],
        )
        .ok_or_else(|| MapError::invalid("levels", "no level"))?;
        let mut map = MultiHeightMap {
            config,
            spec,
            geometry,
            window_lo,
            live: vec![Grid::filled(geometry, f32::NAN); n],
            prior: vec![Grid::filled(geometry, f32::NAN); n],
            live_remission: Grid::filled(geometry, RemissionCell::default()),
            prior_remission: Grid::filled(geometry, RemissionCell::default()),
            odm,
            odm_dirty: vec![true; n],
            odm_obstacles: vec![Vec::new(); n],
            odm_mask: Vec::new(),
            touched: vec![TouchedCells::default(); n],
            odm_changed: Vec::new(),
            prior_store,
            live_store,
            classified: Vec::new(),
            self_hits: None,
            column_levels: Vec::new(),
            occupied: vec![OccupiedCells::default(); n],
            last_hits: vec![Vec::new(); n],
            hit_spans: vec![HashMap::default(); n],
            edt_scratch: EdtScratch::default(),
            levels,
        };
        for index in map.window_blocks(window_lo) {
            map.load_into_window(index)?;
        }
        map.list_occupied();
        Ok(map)
    }

    fn window_lo_for(config: &MapConfig, p: Point2<f64>) -> BlockIndex {
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

    fn window_blocks(&self, lo: BlockIndex) -> Vec<BlockIndex> {
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

    /// Lists the positive live cells of every level anew (after the window changed).
    fn list_occupied(&mut self) {
        self.occupied
            .par_iter_mut()
            .zip(&self.live)
            .for_each(|(o, live)| o.rebuild(live.data()));
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

    fn load_into_window(&mut self, index: BlockIndex) -> Result<()> {
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

    /// Inserts one revolution. `vehicle` (its circles) drives the self-hit filter; `None` keeps every return.
    pub fn insert_scan(
        &mut self,
        scan: &Scan,
        vehicle: Option<&CollisionModel>,
    ) -> Result<InsertStats> {
        let mut stats = InsertStats {
            hits: vec![0; self.levels.count()],
            free_cells: vec![0; self.levels.count()],
            ..Default::default()
        };
        self.classify(scan, vehicle, &mut stats);

        let config = self.config;
        let cell0 = self.window_cell0();
        let levels = &self.levels;
        let classified = &self.classified;
        let column_levels = &self.column_levels;
        let geometry = self.geometry;
        // The levels in parallel, and beside them the remission of the returns that are ground
        // for level 0.
        let (results, ()) = rayon::join(
            || -> Vec<(usize, usize)> {
                self.live
                    .par_iter_mut()
                    .zip(self.occupied.par_iter_mut())
                    .zip(self.touched.par_iter_mut())
                    .zip(self.last_hits.par_iter_mut())
                    .zip(self.hit_spans.par_iter_mut())
                    .enumerate()
                    .map(|(k, ((((grid, occupied), touched), last_hits), spans))| {
                        let summary = ColumnsOfLevel {
                            all: column_levels,
                            levels: levels.count(),
                            k,
                        };
                        insert_level(
                            k,
                            grid,
                            (occupied, touched, last_hits, (spans, cell0)),
                            levels,
                            classified,
                            summary,
                            scan,
                            &geometry,
                            &config,
                        )
                    })
                    .collect()
            },
            || {
                let rem = self.live_remission.data_mut();
                for (c, r) in classified.iter().zip(scan.returns()) {
                    if let (Some(r), false, true) = (r, c.obstacle, c.cell != DROPPED) {
                        rem[c.cell as usize].add(r.intensity);
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

    /// Step 1 of the insertion: drop and classify every return once (self-hits, returns out of
    /// range or at or above the ceiling are dropped).
    fn classify(&mut self, scan: &Scan, vehicle: Option<&CollisionModel>, stats: &mut InsertStats) {
        let beams = scan.beams();
        let params = self.config.obstacle_test;
        let test = ObstacleTest::new(params);
        let margin = self.config.self_hit_margin_m;
        if let Some(model) = vehicle
            && !self
                .self_hits
                .as_ref()
                .is_some_and(|f| f.is_for(model, margin))
        {
            self.self_hits = Some(SelfHitFilter::new(model, margin));
        }
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
        self.column_levels
            .resize(scan.columns().len() * n_levels, ColumnLevel::default());
        let counts: (usize, usize, usize, usize) = self
            .classified
            .par_chunks_mut(beams)
            .zip(self.column_levels.par_chunks_mut(n_levels))
            .zip(scan.returns().par_chunks(beams))
            .zip(scan.columns().par_iter())
            .map(|(((out, summary), returns), column)| {
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
                    if let Some(filter) = self_filter
                        && filter.is_self_hit(&(vehicle_from_world * xy), height)
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
                    };
                    out[b] = c;
                    // Per level: the farthest return considered (the last of equals) and the
                    // nearest obstacle hit (the first of equals).
                    for (&(lo, hi), sum) in bands.iter().zip(summary.iter_mut()) {
                        let class = height_class(c.height_m, lo, hi);
                        if class != HeightClass::Above && c.range_xy_m >= sum.far_m {
                            (sum.far, sum.far_m) = (b as u16, c.range_xy_m);
                        }
                        if c.obstacle
                            && class == HeightClass::Inside
                            && c.range_xy_m < sum.nearest_hit_m
                        {
                            (sum.nearest_hit, sum.nearest_hit_m) = (b as u16, c.range_xy_m);
                        }
                    }
                }
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

    /// The world-lattice cell of the window's cell (0, 0).
    fn window_cell0(&self) -> WorldCell {
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
    fn window_index(&self, cell: WorldCell) -> Option<usize> {
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

/// What the insertion of one level updates beside its grid: its occupied and touched cells, the
/// cells this scan hit, and the height spans of its hits (keyed by world cell, with the world
/// cell of the window's cell 0).
type LevelState<'a> = (
    &'a mut OccupiedCells,
    &'a mut TouchedCells,
    &'a mut Vec<u32>,
    (&'a mut HashMap<WorldCell, HitSpan>, WorldCell),
);

/// The lowest and highest heights above ground a cell was hit at as an obstacle, metres.
type HitSpan = (f32, f32);

/// Step 2 of the insertion for one level: its obstacle hits raise their cells (the column's
/// nearest twice), are listed (this scan's hit cells, sorted) and their heights recorded.
/// Returns the hits.
fn insert_hits(
    data: &mut [f32],
    (occupied, touched, hit_cells, (spans, cell0)): LevelState<'_>,
    classified: &[Classified],
    summary: &ColumnsOfLevel,
    (beams, width): (usize, usize),
    (h_lo, h_hi): (f32, f32),
    occ: OccupancyParams,
) -> usize {
    let add = |v: &mut f32, delta: f32| {
        let cur = if v.is_nan() { 0.0 } else { *v };
        *v = (cur + delta).clamp(-occ.l_max, occ.l_max);
    };
    let mut hits = 0;
    hit_cells.clear();
    // The height span of consecutive hits in one cell, not yet merged into `spans`.
    let mut pending: Option<(u32, HitSpan)> = None;
    let mut merge = |cell: u32, (lo, hi): HitSpan| {
        let i = cell as usize;
        let at = ((i % width) as i64 + cell0.0, (i / width) as i64 + cell0.1);
        let span = spans.entry(at).or_insert((lo, hi));
        *span = (span.0.min(lo), span.1.max(hi));
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
                Some((cell, span)) if *cell == c.cell => *span = (span.0.min(h), span.1.max(h)),
                _ => {
                    if let Some((cell, span)) = pending.replace((c.cell, (h, h))) {
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

/// Steps 2-4 of the insertion for one level. Returns (obstacle hits, free cells updated).
#[allow(clippy::too_many_arguments)]
fn insert_level(
    k: usize,
    grid: &mut Grid<f32>,
    (occupied, touched, hit_cells, (spans, cell0)): LevelState<'_>,
    levels: &Levels,
    classified: &[Classified],
    summary: ColumnsOfLevel,
    scan: &Scan,
    geometry: &GridGeometry,
    config: &MapConfig,
) -> (usize, usize) {
    let beams = scan.beams();
    let occ = config.occupancy;
    let (h_lo, h_hi) = (levels.heights_m()[k] as f32, levels.upper_m(k) as f32);
    let data = grid.data_mut();
    let n = scan.columns().len();
    let width = geometry.width();
    // Hits first, so this scan's obstacles already stop this scan's free-space walks.
    let hits = insert_hits(
        data,
        (
            &mut *occupied,
            &mut *touched,
            &mut *hit_cells,
            (&mut *spans, cell0),
        ),
        classified,
        &summary,
        (beams, width),
        (h_lo, h_hi),
        occ,
    );
    let watch = no_obstacle_at_or_below(config);
    // A beam crossing an older occupied cell where its obstacle was hit (or, with no span
    // recorded, below this height) is evidence the cell is free.
    let clear_below = levels.heights_m()[k] + CLEAR_MARGIN_M;
    let stops_walk =
        |i: usize, crosses: &mut dyn FnMut(f64, f64) -> bool| match config.free_space_stop {
            FreeSpaceStop::AnyOccupied => true,
            FreeSpaceStop::ScanHits => {
                if hit_cells.binary_search(&(i as u32)).is_ok() {
                    return true;
                }
                let at = ((i % width) as i64 + cell0.0, (i / width) as i64 + cell0.1);
                let evidence = match spans.get(&at) {
                    // Down to the ground for what stands on it (its lowest hits are the
                    // obstacle height up), up to its highest hit or h_k + 0.2 m.
                    Some(&(lo, hi)) if lo < ON_GROUND_BELOW_M => {
                        crosses(f64::NEG_INFINITY, f64::from(hi).max(clear_below))
                    }
                    // Overhead: within the beam's rise across a cell of where it was hit.
                    Some(&(lo, hi)) => crosses(
                        f64::from(lo) - OVERHEAD_SPAN_SLACK_M,
                        f64::from(hi) + OVERHEAD_SPAN_SLACK_M,
                    ),
                    None => crosses(f64::NEG_INFINITY, clear_below),
                };
                !evidence
            }
        };
    // Free-space walks, to the farthest return this level considers in each column.
    let mut free = 0;
    let (w, h) = (geometry.width() as i64, geometry.height() as i64);
    let hierarchy = ColumnHierarchy::new(config.free_space_walks, n, geometry.resolution_m());
    // How far each column's walk got (metres from its sensor): where its finer neighbours start
    // at the latest.
    let mut reach = vec![0.0f64; n];
    // (horizontal range, height) of a column's returns, reused from column to column.
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
        // [lo, hi]: each beam's height at r on its straight line from the sensor. Beams with no
        // return (the sky) count for nothing: their elevation is not in the scan.
        let ground = config.obstacle_test.ground_height_m;
        let sensor_z = sensor.z - ground;
        // Gathered only if a walk meets an occupied cell (most never do).
        let mut ends_ready = false;
        let mut crosses = |r: f64, lo: f64, hi: f64| {
            if !ends_ready {
                ends.clear();
                // Every return of the column, those the map drops included (beyond the obstacle
                // test's range, above the ceiling): each beam crossed what lies before it.
                ends.extend(
                    scan.returns()[ci * beams..(ci + 1) * beams]
                        .iter()
                        .flatten()
                        .map(|ret| {
                            let p = ret.point_in_world;
                            ((p.x - sensor.x).hypot(p.y - sensor.y), p.z - ground)
                        }),
                );
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
            |i, r| stops_walk(i, &mut |lo, hi| crosses(r, lo, hi)),
            (watch, &mut *touched),
        );
        free += updated;
        reach[ci] = reached_m;
    }
    (hits, free)
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
/// `coarse_to_fine_walks_map_what_every_column_maps_with_fewer_updates` (mapper/tests/map.rs,
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

/// A free-space walk along the Bresenham line of cells `from` (the sensor's) to `to`, `length_m`
/// long, updating its cells from `start_m` on and leaving the last `stop_short` untouched.
struct Walk {
    from: (i64, i64),
    to: (i64, i64),
    length_m: f64,
    start_m: f64,
    stop_short: usize,
}

/// A [`Walk`] in Bresenham steps: `d` = (|dx|, -|dy|), `s` the signs, the steps it may take
/// (`stop_short` off its cells), metres per step, and the first step it updates (`start_m`).
struct WalkSteps {
    d: (i64, i64),
    s: (i64, i64),
    steps: i64,
    per_step: f64,
    first: i64,
}

impl Walk {
    fn steps(&self) -> WalkSteps {
        let (a, b) = (self.from, self.to);
        let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
        let cells = dx.max(-dy) + 1;
        let steps = (cells - self.stop_short as i64).max(0);
        let per_step = self.length_m / (cells - 1).max(1) as f64;
        let first = if self.start_m > 0.0 {
            ((self.start_m / per_step).ceil() as i64).min(steps)
        } else {
            0
        };
        WalkSteps {
            d: (dx, dy),
            s: ((b.0 - a.0).signum(), (b.1 - a.1).signum()),
            steps,
            per_step,
            first,
        }
    }
}

/// One step of the all-octant Bresenham loop (`d` = (|dx|, -|dy|), `s` the signs). Without
/// branches: on a slanted line which axis steps is as good as random, and the mispredicted
/// branches cost more than the free-space walk's memory accesses. [`walk_free`] takes the same
/// step on the cell's index instead of (x, y); this is the reference its tests step by.
#[cfg(test)]
fn bresenham_step(x: &mut i64, y: &mut i64, err: &mut i64, d: (i64, i64), s: (i64, i64)) {
    let e2 = 2 * *err;
    let (mx, my) = (i64::from(e2 >= d.1), i64::from(e2 <= d.0));
    *err += mx * d.1 + my * d.0;
    *x += mx * s.0;
    *y += my * s.1;
}

/// The Bresenham state (x, y, error) of the line `a` to `b` after `k` steps, in O(1): the step
/// along the major axis is taken every iteration, the other one `floor((2 minor k + major) / (2
/// major))` times in the first k (the integer form of rounding `k minor / major`).
fn bresenham_at(a: (i64, i64), b: (i64, i64), k: i64) -> (i64, i64, i64) {
    let (ax, ay) = ((b.0 - a.0).abs(), (b.1 - a.1).abs());
    let (sx, sy) = ((b.0 - a.0).signum(), (b.1 - a.1).signum());
    let (nx, ny) = if ax >= ay {
        (k, (2 * ay * k + ax) / (2 * ax).max(1))
    } else {
        ((2 * ax * k + ay) / (2 * ay), k)
    };
    // The loop's error term is ax (y steps + 1) - ay (x steps + 1).
    (a.0 + sx * nx, a.1 + sy * ny, ax * (ny + 1) - ay * (nx + 1))
}

/// Bresenham walk along `walk` adding `l_free(distance from the sensor)` to each cell from
/// `walk.start_m` on, stopping at the window's edge or at the first known cell with p >= 0.5 for
/// which `stops(index, distance)` holds (other occupied cells are lowered and passed). Notes in
/// `touched.1` every cell it lowers from above `touched.0` or from unknown. Returns the cells
/// updated and the distance reached.
///
/// The hot loop of the mapping (a third of a closed-loop run's CPU), so the per-cell work is
/// trimmed: where the line leaves the window is found before the walk (a line from a cell inside
/// leaves a rectangle once and for all), the increment is recomputed every 8 cells in an outer
/// loop, the line steps the cell's index, and a known free cell at or below `touched.0` takes
/// one comparison. Same cells, same increments, same order as the plain per-step loop
/// (`walk_free_plain`, kept for the test that compares them): the maps are the same bit for bit.
fn walk_free(
    data: &mut [f32],
    (w, h): (i64, i64),
    walk: &Walk,
    l_free: impl Fn(f64) -> f32,
    l_max: f32,
    mut stops: impl FnMut(usize, f64) -> bool,
    touched: (f32, &mut TouchedCells),
) -> (usize, f64) {
    let (watch, touched) = touched;
    let (a, b) = (walk.from, walk.to);
    let WalkSteps {
        d: (dx, dy),
        s: (sx, sy),
        steps,
        per_step,
        first,
    } = walk.steps();
    if first >= steps {
        return (0, per_step * steps as f64);
    }
    let inside = |(x, y, _): (i64, i64, i64)| x >= 0 && y >= 0 && x < w && y < h;
    let start = bresenham_at(a, b, first);
    if !inside(start) {
        return (0, per_step * first as f64);
    }
    // The first step outside the window (or `steps`): inside is a prefix of the walk from here.
    let end = if inside(bresenham_at(a, b, steps - 1)) {
        steps
    } else {
        let (mut lo, mut hi) = (first, steps - 1); // lo inside, hi outside
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if inside(bresenham_at(a, b, mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    };
    // The common cell is known free and not above `watch`: one comparison (NaN fails it) and
    // the update; anything else takes the full path. The cell's index is stepped along with the
    // line's error term, x and y are not needed.
    let fast_below = watch.min(-f32::MIN_POSITIVE);
    let (x, y, mut err) = start;
    let mut i = y * w + x;
    let (di_x, di_y) = (sx, sy * w);
    let mut step = first;
    while step < end {
        // The increment changes only a few times along a walk: recomputed every 8 cells.
        let delta = l_free(per_step * step as f64);
        let chunk_end = (step + 8).min(end);
        while step < chunk_end {
            let v = &mut data[i as usize];
            if *v <= fast_below {
                *v = (*v + delta).max(-l_max);
            } else {
                // p >= 0.5 (NaN, unknown, compares false)
                if *v >= 0.0 && stops(i as usize, per_step * step as f64) {
                    return ((step - first) as usize, per_step * step as f64);
                }
                if v.is_nan() || *v > watch {
                    touched.note(i as u32); // may have been an obstacle (NaN: unknown, the prior's)
                }
                let cur = if v.is_nan() { 0.0 } else { *v };
                *v = (cur + delta).max(-l_max);
            }
            let e2 = 2 * err;
            let (mx, my) = (i64::from(e2 >= dy), i64::from(e2 <= dx));
            err += mx * dy + my * dx;
            i += mx * di_x + my * di_y;
            step += 1;
        }
    }
    ((end - first) as usize, per_step * end as f64)
}

/// [`walk_free`] the plain way: one step at a time, the window's edge tested at every step.
#[cfg(test)]
fn walk_free_plain(
    data: &mut [f32],
    (w, h): (i64, i64),
    walk: &Walk,
    l_free: impl Fn(f64) -> f32,
    l_max: f32,
    mut stops: impl FnMut(usize, f64) -> bool,
    touched: (f32, &mut TouchedCells),
) -> (usize, f64) {
    let (watch, touched) = touched;
    let (a, b) = (walk.from, walk.to);
    let WalkSteps {
        d: (dx, dy),
        s: (sx, sy),
        steps,
        per_step,
        first,
    } = walk.steps();
    let (mut x, mut y, mut err) = bresenham_at(a, b, first);
    let mut updated = 0;
    let mut delta = 0.0;
    for step in first..steps {
        let r = per_step * step as f64;
        if x < 0 || y < 0 || x >= w || y >= h {
            return (updated, r);
        }
        if (step - first) & 7 == 0 {
            delta = l_free(r);
        }
        let i = (y * w + x) as usize;
        let v = &mut data[i];
        if *v >= 0.0 && stops(i, r) {
            return (updated, r);
        }
        if v.is_nan() || *v > watch {
            touched.note(i as u32);
        }
        let cur = if v.is_nan() { 0.0 } else { *v };
        *v = (cur + delta).max(-l_max);
        updated += 1;
        bresenham_step(&mut x, &mut y, &mut err, (dx, dy), (sx, sy));
    }
    (updated, per_step * steps as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// The trimmed free-space walk updates the same cells by the same amounts, notes the same
    /// touched cells and stops where the plain per-step loop does: walks from inside and outside
    /// a small window, leaving it on every side, stopped by occupied cells, from a start range on.
    #[test]
    fn the_trimmed_walk_equals_the_plain_one() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(11);
        let (w, h) = (23i64, 17i64);
        let (mut exits, mut stopped, mut complete) = (0, 0, 0);
        for _ in 0..20_000 {
            let cells: Vec<f32> = (0..w * h)
                .map(|_| match rng.random_range(0..10) {
                    0 => f32::NAN,
                    1 => rng.random_range(0.0..4.0),
                    _ => rng.random_range(-4.0..0.0),
                })
                .collect();
            let from = (rng.random_range(-3..w + 3), rng.random_range(-3..h + 3));
            let to = if rng.random_bool(0.5) {
                (rng.random_range(0..w), rng.random_range(0..h))
            } else {
                (rng.random_range(-30..w + 30), rng.random_range(-30..h + 30))
            };
            let length_m = 0.2 * ((to.0 - from.0) as f64).hypot((to.1 - from.1) as f64);
            let walk = Walk {
                from,
                to,
                length_m,
                start_m: [0.0, 0.0, rng.random_range(0.0..length_m.max(0.1))]
                    [rng.random_range(0..3)],
                stop_short: rng.random_range(0..3),
            };
            let stop_every = rng.random_range(1..4usize);
            let l_free = |r: f64| -0.4 * (1.0 + (r * 1.7).floor() as f32);
            let run = |trimmed: bool| {
                let mut data = cells.clone();
                let mut touched = TouchedCells::default();
                let mut asked = Vec::new();
                let stops = |i: usize, r: f64| {
                    asked.push((i, r.to_bits()));
                    i.is_multiple_of(stop_every)
                };
                let out = if trimmed {
                    walk_free(
                        &mut data,
                        (w, h),
                        &walk,
                        l_free,
                        4.0,
                        stops,
                        (1.0, &mut touched),
                    )
                } else {
                    walk_free_plain(
                        &mut data,
                        (w, h),
                        &walk,
                        l_free,
                        4.0,
                        stops,
                        (1.0, &mut touched),
                    )
                };
                (
                    out.0,
                    out.1.to_bits(),
                    data.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    touched.cells,
                    asked,
                )
            };
            let (plain, trimmed) = (run(false), run(true));
            assert_eq!(
                trimmed, plain,
                "{:?} to {:?}, start {} m, {} short",
                walk.from, walk.to, walk.start_m, walk.stop_short
            );
            // Where it ended: stopped by a cell, at the window's edge, or at its last cell.
            let cells = (to.0 - from.0).abs().max((to.1 - from.1).abs()) + 1;
            let steps = (cells - walk.stop_short as i64).max(0);
            let per_step = walk.length_m / (cells - 1).max(1) as f64;
            if per_step == 0.0 {
                continue; // a line of one cell: every step is at 0 m
            }
            let reached = (f64::from_bits(plain.1) / per_step).round() as i64;
            let at = bresenham_at(from, to, reached);
            if plain
                .4
                .last()
                .is_some_and(|&(i, r)| r == plain.1 && i.is_multiple_of(stop_every))
            {
                stopped += 1;
            } else if reached < steps && (at.0 < 0 || at.1 < 0 || at.0 >= w || at.1 >= h) {
                exits += 1;
            } else {
                assert_eq!(
                    reached, steps,
                    "{:?} to {:?} ended early",
                    walk.from, walk.to
                );
                complete += 1;
            }
        }
        assert!(
            exits > 2_000 && stopped > 2_000 && complete > 2_000,
            "{exits} left the window, {stopped} stopped, {complete} ran to their end"
        );
    }

    /// The O(1) jump into a Bresenham line lands where stepping from its start does.
    #[test]
    fn bresenham_jumps_land_on_the_stepped_line() {
        let mut lines = 0;
        for (bx, by) in (-13..=13).flat_map(|x| (-13..=13).map(move |y| (x, y))) {
            let (a, b): ((i64, i64), (i64, i64)) = ((3, -2), (3 + bx, -2 + by));
            let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
            let (sx, sy) = ((b.0 - a.0).signum(), (b.1 - a.1).signum());
            let (mut x, mut y, mut err) = (a.0, a.1, dx + dy);
            for k in 0..=dx.max(-dy) {
                assert_eq!(
                    bresenham_at(a, b, k),
                    (x, y, err),
                    "{a:?} to {b:?}, step {k}"
                );
                bresenham_step(&mut x, &mut y, &mut err, (dx, dy), (sx, sy));
            }
            lines += 1;
        }
        assert_eq!(lines, 27 * 27);
    }
}
