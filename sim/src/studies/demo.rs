//! `taxi-sim demo`: a mapping drive through a synthetic parking lot with the fake-wing car,
//! building the two-level map and exporting every level (ROS map, PNG, .npy) and the blocks.
//!
//! It exercises the whole mapper as a user would before the Rapier world exists: scans in,
//! per-level grids, distance maps and files out. Reproducible from its seed.

use std::path::PathBuf;
use std::time::Instant;

use mapper::export::{
    TrinaryThresholds, write_distance_png, write_npy, write_occupancy_png, write_ros_map,
};
use mapper::synthetic::{Lidar, car_sensor_mount};
use mapper::{BlockStore, Levels, MapConfig, MultiHeightMap, workloads};
use nalgebra::{Isometry2, Point2, Vector2};
use rand::{RngExt, SeedableRng};

/// Options of a demo run.
#[derive(Clone, Debug)]
pub struct DemoOptions {
    /// Output directory (created).
    pub out: PathBuf,
    /// Scans along the drive (10 Hz at 5 m/s: one every 0.5 m). Default 180 (90 m).
    pub scans: usize,
    /// Seed of the range noise.
    pub seed: u64,
    /// Standard deviation of the range noise, metres. Default 0.02 (HDL-32E accuracy).
    pub range_noise_m: f64,
}

/// What a demo run did.
#[derive(Clone, Debug)]
pub struct DemoSummary {
    /// Scans inserted.
    pub scans: usize,
    /// Returns inserted over the run.
    pub returns: usize,
    /// Self-hits dropped.
    pub self_hits: usize,
    /// Per level: height of interest and occupied cells (p > 0.5) at the end.
    pub levels: Vec<(f64, usize)>,
    /// Times the window re-centred.
    pub recentres: usize,
    /// Block files written.
    pub blocks: usize,
    /// Mean wall time per scan for insertion + distance maps, milliseconds.
    pub ms_per_scan: f64,
    /// Files written.
    pub files: Vec<PathBuf>,
}

/// Runs the demo; `progress(done, total)` is called after each scan.
pub fn run(
    options: &DemoOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> crate::Result<DemoSummary> {
    std::fs::create_dir_all(&options.out).map_err(|source| crate::Error::Io {
        what: "creating the demo's output directory",
        path: options.out.clone(),
        source,
    })?;
    // The map's live store: blocks a previous run left there would be loaded as this run's
    // live map, so the same inputs would not give the same map. Start from an empty one.
    let blocks_dir = options.out.join("blocks");
    if blocks_dir.exists() {
        std::fs::remove_dir_all(&blocks_dir).map_err(|source| crate::Error::Io {
            what: "clearing the demo's old map blocks",
            path: blocks_dir.clone(),
            source,
        })?;
    }
    let scene = workloads::parking_lot_scene();
    let car = workloads::fake_wing_car();
    let levels = Levels::cumulative(car.level_heights_m().to_vec())?;
    let start = Point2::new(-45.0, -3.0);
    let mut map =
        MultiHeightMap::with_stores(MapConfig::default(), levels, start, None, Some(&blocks_dir))?;
    let lidar = Lidar::hdl32e();
    let mut rng = rand::rngs::StdRng::seed_from_u64(options.seed);
    let mut summary = DemoSummary {
        scans: options.scans,
        returns: 0,
        self_hits: 0,
        levels: Vec::new(),
        recentres: 0,
        blocks: 0,
        ms_per_scan: 0.0,
        files: Vec::new(),
    };
    let mut busy = 0.0;
    for k in 0..options.scans {
        let pose = Isometry2::new(Vector2::new(start.x + 0.5 * k as f64, start.y), 0.0);
        // Gaussian range noise (Box-Muller), one draw per ray, from the seeded generator.
        let noise: Vec<f64> = (0..lidar.columns * lidar.elevations_rad.len())
            .map(|_| {
                let (u1, u2): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random());
                options.range_noise_m * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
            })
            .collect();
        let beams = lidar.elevations_rad.len();
        let scan = lidar.scan(&scene, &pose, &car_sensor_mount(), |c, b| {
            noise[c * beams + b]
        })?;
        let t = Instant::now();
        if map.recenter(Point2::new(pose.translation.x, pose.translation.y))? {
            summary.recentres += 1;
        }
        let stats = map.insert_scan(&scan, Some(&car))?;
        map.update_distance_maps();
        busy += t.elapsed().as_secs_f64();
        summary.returns += stats.returns;
        summary.self_hits += stats.self_hits;
        progress(k + 1, options.scans);
    }
    summary.ms_per_scan = 1e3 * busy / options.scans.max(1) as f64;
    summary.blocks = map.flush()?;
    summary.blocks += BlockStore::open(&blocks_dir, map.block_spec().clone())?
        .list()?
        .len()
        .saturating_sub(summary.blocks);
    for k in 0..map.levels().count() {
        let grid = map
            .probability_grid(k)
            .ok_or_else(|| crate::Error::Invalid(format!("level {k}: no grid")))?;
        let occupied = grid.data().iter().filter(|&&p| p > 0.5).count();
        summary.levels.push((map.levels().heights_m()[k], occupied));
        let file = |name: String| options.out.join(name);
        let yaml = file(format!("level{k}.yaml"));
        summary
            .files
            .push(write_ros_map(&grid, &yaml, TrinaryThresholds::default())?);
        summary.files.push(yaml);
        write_occupancy_png(&grid, &file(format!("level{k}.png")))?;
        summary.files.push(file(format!("level{k}.png")));
        write_npy(&grid, &file(format!("level{k}_occupancy.npy")))?;
        summary.files.push(file(format!("level{k}_occupancy.npy")));
        let odm = &map.distance_maps().levels()[k];
        write_distance_png(odm, &file(format!("level{k}_distance.png")))?;
        summary.files.push(file(format!("level{k}_distance.png")));
        write_npy(odm.grid(), &file(format!("level{k}_distance.npy")))?;
        summary.files.push(file(format!("level{k}_distance.npy")));
    }
    summary.files.push(blocks_dir);
    Ok(summary)
}
