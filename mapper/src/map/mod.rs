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
//!
//! This file holds the type, its fields and its constructors; its other methods are spread by
//! job over private submodules, each adding an `impl MultiHeightMap` block for its subject, and
//! what they make public is re-exported here:
//! - `config`: [`MapConfig`] and the choices it names;
//! - `window`: re-centring, blocks in from the stores and out to the live store;
//! - `classified`: one return as the classification pass leaves it, what `insert` writes and
//!   `open_top` reads;
//! - `insert`: [`MultiHeightMap::insert_scan`] (classification, hits, the walks' schedule);
//! - `open_top`: how high each hit object may reach unseen, from the beam above it
//!   ([`MultiHeightMap::last_scan_open_tops`]);
//! - `walk`: the Bresenham free-space walk;
//! - `distance`: the distance maps brought up to date from the touched cells;
//! - `forget`: forgetting on evidence, [`MultiHeightMap::clear_live`],
//!   [`MultiHeightMap::forget_unseen`];
//! - `query`: accessors, world-lattice cells, obstacle and probability queries.

mod classified;
mod config;
mod distance;
mod forget;
mod insert;
mod open_top;
mod query;
mod walk;
mod window;

pub use crate::ros_occupancy::RosOccupancy;
pub use config::{FreeSpaceStop, FreeSpaceWalks, MapConfig, MergeMode};
pub use insert::InsertStats;
pub use query::merge_log_odds;

use foldhash::HashMap;
use nalgebra::Point2;

use crate::blocks::{BlockIndex, BlockSpec, BlockStore};
use crate::edt::EdtScratch;
use crate::error::{MapError, Result};
use crate::grid::{Grid, GridGeometry};
use crate::levels::Levels;
use crate::odm::{DistanceMap, DistanceMaps};
use crate::remission::RemissionCell;
use crate::self_hits::SelfHitFilter;
use classified::Classified;
use distance::TouchedCells;
use forget::{HitSpan, OccupiedCells};
use insert::ColumnLevel;

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
    /// Each beam's elevation in the sensor frame, from the latest revolution in which three of
    /// its echoes agreed on it (`None`: none yet - a dead beam never has one); forgotten when
    /// the beams per column change (two sensors of different beam counts feeding one map
    /// remember nothing across revolutions).
    elevations: Vec<Option<f64>>,
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
            elevations: Vec::new(),
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
}
