//! The mapping drive: the route driven exactly (the thesis' manual drive) through the world
//! without its run-time obstacles, building the offline multi-height map and remission map.
//!
//! Output directory: `blocks/` (the map blocks, the closed loop's prior), `level<k>.yaml` with
//! `level<k>.ros.png` (ROS map_server, trinary; a PNG, which map_server reads like a PGM at a
//! hundredth of the size) and `level<k>.png` over the route's extent, and `manifest.json` whose
//! fingerprint (scenario and vehicle files, map and LiDAR settings, format) tells `taxi-sim run`
//! whether the map is stale.

use std::path::Path;

use autonomy::RoutePath;
use mapper::export::{RosImage, TrinaryThresholds, write_occupancy_png, write_ros_map_as};
use mapper::{BlockStore, Grid, GridGeometry, Levels, MultiHeightMap};
use nalgebra::{Isometry2, Point2};

use super::manifest::{MapManifest, fingerprint};
use super::settings::{levels_of, map_config, self_filter_model};
use crate::error::{Error, Result};
use crate::scenario::RunConfig;
use crate::scenario::Scenario;
use crate::world::World;
use crate::world::{Lidar, SweepPoses};

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
    let scene = crate::world::stale_scene(
        &scenario.static_scene(),
        &config.faults.stale_map,
        scenario.seed,
        &route,
    );
    let mut world = World::static_only(&scene, vehicle, &start);
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

/// Writes each level over the blocks' extent as a ROS map and a PNG; returns occupied cells per
/// level. One level's image is held at a time (its blocks read again for each level), so the
/// exports' memory is one level's extent, not every level's.
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
    let mut occupied = Vec::new();
    for k in 0..levels.count() {
        let mut grid = Grid::filled(geometry, -1.0f32);
        for &index in &indices {
            let Some(block) = store.load(index)? else {
                continue;
            };
            let Some(level) = block.levels.get(k) else {
                continue;
            };
            let (ox, oy) = (
                ((index.x - x0) as usize) * side,
                ((index.y - y0) as usize) * side,
            );
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
        write_ros_map_as(
            &grid,
            &out.join(format!("level{k}.yaml")),
            TrinaryThresholds::default(),
            RosImage::Png,
        )?;
        write_occupancy_png(&grid, &out.join(format!("level{k}.png")))?;
        occupied.push(grid.data().iter().filter(|&&p| p > 0.5).count());
    }
    Ok(occupied)
}
