//! The mapping drive: the route driven exactly (the thesis' manual drive) through the world
//! without its run-time obstacles, building the offline multi-height map and remission map.
//!
//! Output directory: `blocks/` (the map blocks, the closed loop's prior), `level<k>.yaml` with
//! `level<k>.ros.png` (ROS map_server, trinary; a PNG, which map_server reads like a PGM at a
//! hundredth of the size) and `level<k>.png` over the route's extent, and `manifest.json` whose
//! fingerprint (scenario and vehicle files, map and LiDAR settings, format) tells `taxi-sim run`
//! whether the map is stale.

use std::path::{Path, PathBuf};

use autonomy::RoutePath;
use mapper::export::{RosImage, TrinaryThresholds, write_occupancy_png, write_ros_map_as};
use mapper::{BlockStore, Grid, GridGeometry, Levels, MapConfig, MultiHeightMap};
use nalgebra::{Isometry2, Point2};

use crate::config::RunConfig;
use crate::error::{Error, Result};
use crate::lidar::{Lidar, SweepPoses};
use crate::scenario::Scenario;
use crate::world::World;

/// Bumped when the mapping drive changes what it builds (2: the vehicle's ceiling; 3: compressed
/// blocks; 4: the ROS image a PNG).
pub(crate) const MAP_FORMAT: u32 = 4;

/// What a mapping drive did.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct MapManifest {
    /// Fingerprint of everything the map depends on (hex CRC-32).
    pub fingerprint: String,
    /// Scenario name.
    pub scenario: String,
    /// Revolutions inserted.
    pub scans: usize,
    /// Route length driven, metres.
    pub route_m: f64,
    /// Block files written.
    pub blocks: usize,
    /// Heights of interest of the levels, metres.
    pub level_heights_m: Vec<f64>,
    /// Occupied cells (p > 0.5) per level over the exported extent.
    pub occupied_cells: Vec<usize>,
}

/// The map settings of a configuration's mapping drive (its mapping settings as they are).
pub fn map_config(config: &RunConfig) -> MapConfig {
    config.mapping.map
}

/// Fingerprint of a scenario's offline map inputs: the scenario and vehicle files, the levels
/// (heights and ceiling), the map and LiDAR settings of `config`, a stale map's faults, the
/// format.
pub fn fingerprint(scenario: &Scenario, config: &RunConfig) -> Result<String> {
    let mut h = crc32fast::Hasher::new();
    h.update(&std::fs::read(&scenario.path).map_err(|source| Error::Io {
        what: "reading the scenario",
        path: scenario.path.clone(),
        source,
    })?);
    // The world as resolved (a default the code changes, like the pavement's texture, is not in
    // the file).
    h.update(format!("{:?}{:?}", scenario.world, scenario.patches).as_bytes());
    h.update(format!("{:?}", scenario.vehicle.vehicle).as_bytes());
    h.update(format!("{:?}", levels_of(scenario, config)?).as_bytes());
    h.update(format!("{:?}{:?}{MAP_FORMAT}", map_config(config), config.lidar).as_bytes());
    if config.faults.stale_map.any() {
        h.update(format!("{:?}", config.faults.stale_map).as_bytes());
    }
    Ok(format!("{:08x}", h.finalize()))
}

/// A map's `manifest.json` exists but cannot be used: rebuilding over it would hide the cause.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// The file exists but cannot be read (permissions, not UTF-8, a directory...).
    #[error("{}: cannot read the map manifest: {error}; {remedy}", path.display())]
    Read {
        /// The manifest file.
        path: PathBuf,
        /// The underlying error.
        error: std::io::Error,
        /// What to do about it.
        remedy: String,
    },
    /// The file is not a manifest (garbage, truncated, another format).
    #[error("{}:{line}:{column}: not a map manifest: {message}; {remedy}", path.display())]
    Parse {
        /// The manifest file.
        path: PathBuf,
        /// 1-based line of the mistake (serde_json's).
        line: usize,
        /// 1-based column of the mistake (serde_json's).
        column: usize,
        /// What serde_json says is wrong.
        message: String,
        /// What to do about it.
        remedy: String,
    },
}

/// The manifest of the map in `dir`, if it exists and matches `scenario` and `config`: `None`
/// when it is missing or stale (build the map), a [`ManifestError`] when it exists but is
/// unreadable.
pub fn fresh_manifest(
    scenario: &Scenario,
    config: &RunConfig,
    dir: &Path,
) -> Result<Option<MapManifest>> {
    let path = dir.join("manifest.json");
    let remedy = || {
        format!(
            "delete it, or rebuild the map with `taxi-sim map {} --out {}`",
            scenario.path.display(),
            dir.display()
        )
    };
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(error) => {
            let remedy = remedy();
            return Err(ManifestError::Read {
                path,
                error,
                remedy,
            }
            .into());
        }
    };
    let manifest = match serde_json::from_str::<MapManifest>(&text) {
        Ok(manifest) => manifest,
        Err(e) => {
            let (line, column) = (e.line(), e.column());
            let full = e.to_string();
            let at = format!(" at line {line} column {column}");
            let message = full.strip_suffix(&at).unwrap_or(&full).to_string();
            let remedy = remedy();
            return Err(ManifestError::Parse {
                path,
                line,
                column,
                message,
                remedy,
            }
            .into());
        }
    };
    Ok((manifest.fingerprint == fingerprint(scenario, config)?).then_some(manifest))
}

/// The circles the LiDAR self-hit filter uses: every part at its own level (the banded fit keeps
/// the parts a cumulative fit drops because they lie over a lower level's parts, such as a wing
/// root over the fuselage), so returns off the vehicle's own wing are dropped while a cone under
/// the wing is not.
pub fn self_filter_model(vehicle: &aircraft::Vehicle) -> Result<mapper::CollisionModel> {
    let options = aircraft::FitOptions {
        banded_maps: true,
        ..vehicle.spec.fit.clone()
    };
    Ok(vehicle
        .fit_with(&vehicle.spec.heights_of_interest_m, &options)?
        .model)
}

/// The levels a scenario's vehicle asks for under `config`: its heights of interest (or the
/// configuration's), cumulative, under its ceiling (`aircraft::Vehicle::ceiling_m`: its top plus
/// its overhead clearance).
pub fn levels_of(scenario: &Scenario, config: &RunConfig) -> Result<Levels> {
    let vehicle = &scenario.vehicle.vehicle;
    Ok(Levels::new(
        config.heights_of_interest_m(vehicle).to_vec(),
        mapper::LevelMode::Cumulative,
        Some(vehicle.ceiling_m()),
    )?)
}

/// Drives the route once with the LiDAR and map settings of `config` and writes the offline map
/// into `out`. `progress(done, total)` after each scan.
pub fn map_drive(
    scenario: &Scenario,
    config: &RunConfig,
    out: &Path,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<MapManifest> {
    let vehicle = &scenario.vehicle.vehicle;
    let self_filter = self_filter_model(vehicle)?;
    let levels = levels_of(scenario, config)?;
    let blocks_dir = out.join("blocks");
    if blocks_dir.exists() {
        std::fs::remove_dir_all(&blocks_dir).map_err(|source| Error::Io {
            what: "clearing the old map blocks",
            path: blocks_dir.clone(),
            source,
        })?;
    }
    let route = RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed);
    let start = scenario.vehicle.world_from_start;
    let scene = crate::faults::stale_scene(
        &scenario.scene(false),
        &config.faults.stale_map,
        scenario.seed,
        &route,
    );
    let mut world = World::new(&scene, false, vehicle, &start);
    let lidar = Lidar::new(config.lidar.clone(), vehicle.vehicle_from_lidar()).map_err(|e| {
        Error::Config {
            origin: "lidar".into(),
            message: e.to_string(),
        }
    })?;
    let mut map = MultiHeightMap::with_stores(
        map_config(config),
        levels.clone(),
        Point2::from(start.translation.vector),
        None,
        Some(&blocks_dir),
    )?;
    // One revolution every 0.1 s at the route's speed.
    let spacing = (scenario.route.speed_m_s * 0.1).max(0.05);
    let scans = (route.length_m() / spacing).ceil() as usize + 1;
    // Each revolution is cast beside the insertion of the one before (the same insertions, in
    // the same order: the same map).
    let mut taken: Option<(Point2<f64>, mapper::Scan)> = None;
    for k in 0..=scans {
        let cast = (k < scans).then(|| {
            let s = (k as f64 * spacing).min(route.length_m());
            let (p, heading) = route.at(s);
            let pose = Isometry2::new(p.coords, heading);
            world.set_vehicle_pose(&pose, k as f64 * 0.1);
            (p, pose)
        });
        let (scan, inserted) = rayon::join(
            || {
                cast.map(|(p, pose)| {
                    let scan =
                        lidar.scan(&world, &SweepPoses::still(pose), k as u64, scenario.seed);
                    (p, scan.scan)
                })
            },
            || -> Result<()> {
                if let Some((p, scan)) = taken.take() {
                    map.recenter(p)?;
                    map.insert_scan(&scan, Some(&self_filter))?;
                }
                Ok(())
            },
        );
        inserted?;
        if k > 0 {
            progress(k, scans);
        }
        taken = scan;
    }
    map.flush()?;
    let store = BlockStore::open(&blocks_dir, map.block_spec().clone())?;
    let blocks = store.list()?.len();
    let occupied_cells = export_levels(&store, &levels, &route, out)?;
    let manifest = MapManifest {
        fingerprint: fingerprint(scenario, config)?,
        scenario: scenario.name.clone(),
        scans,
        route_m: route.length_m(),
        blocks,
        level_heights_m: levels.heights_m().to_vec(),
        occupied_cells,
    };
    mapper::write_atomically(
        &out.join("manifest.json"),
        serde_json::to_string_pretty(&manifest)?.as_bytes(),
    )?;
    Ok(manifest)
}

/// Writes each level over the blocks' extent as a ROS map and a PNG; returns occupied cells per level.
fn export_levels(
    store: &BlockStore,
    levels: &Levels,
    _route: &RoutePath,
    out: &Path,
) -> Result<Vec<usize>> {
    let spec = store.spec().clone();
    let indices = store.list()?;
    let (Some(x0), Some(x1), Some(y0), Some(y1)) = (
        indices.iter().map(|b| b.x).min(),
        indices.iter().map(|b| b.x).max(),
        indices.iter().map(|b| b.y).min(),
        indices.iter().map(|b| b.y).max(),
    ) else {
        return Ok(vec![0; levels.count()]);
    };
    let side = spec.side;
    let (w, h) = (
        ((x1 - x0 + 1) as usize) * side,
        ((y1 - y0 + 1) as usize) * side,
    );
    let origin = Point2::new(x0 as f64 * spec.side_m(), y0 as f64 * spec.side_m());
    let geometry = GridGeometry::new(origin, spec.resolution_m, w, h)?;
    let mut grids: Vec<Grid<f32>> = (0..levels.count())
        .map(|_| Grid::filled(geometry, -1.0))
        .collect();
    for index in indices {
        let Some(block) = store.load(index)? else {
            continue;
        };
        let (ox, oy) = (
            ((index.x - x0) as usize) * side,
            ((index.y - y0) as usize) * side,
        );
        for (grid, level) in grids.iter_mut().zip(&block.levels) {
            let data = grid.data_mut();
            for r in 0..side {
                for c in 0..side {
                    let l = level[r * side + c];
                    data[(oy + r) * w + ox + c] = if l.is_nan() {
                        -1.0
                    } else {
                        mapper::occupancy::probability(l)
                    };
                }
            }
        }
    }
    let mut occupied = Vec::new();
    for (k, grid) in grids.iter().enumerate() {
        write_ros_map_as(
            grid,
            &out.join(format!("level{k}.yaml")),
            TrinaryThresholds::default(),
            RosImage::Png,
        )?;
        write_occupancy_png(grid, &out.join(format!("level{k}.png")))?;
        occupied.push(grid.data().iter().filter(|&&p| p > 0.5).count());
    }
    Ok(occupied)
}

/// Where a scenario's offline map lives by default: `out/maps/<scenario file stem>`, or
/// `out/maps/<stem>-stale-<digest>` for a stale map's faults (so the good map stays).
pub fn default_map_dir(scenario: &Scenario, config: &RunConfig) -> PathBuf {
    let stem = scenario
        .path
        .file_stem()
        .map_or_else(|| "scenario".into(), |s| s.to_string_lossy().into_owned());
    let stale = &config.faults.stale_map;
    let name = if stale.any() {
        format!(
            "{stem}-stale-{:08x}",
            crc32fast::hash(format!("{stale:?}").as_bytes())
        )
    } else {
        stem
    };
    PathBuf::from("out").join("maps").join(name)
}
