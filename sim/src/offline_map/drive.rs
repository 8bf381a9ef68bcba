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
use mapper::export::{
    PngRows, ROS_UNKNOWN, RosImage, TrinaryThresholds, occupancy_pixel, ros_image_path,
    write_ros_map_yaml,
};
use mapper::{BlockIndex, BlockStore, GridGeometry, Levels, MultiHeightMap};
use nalgebra::{Isometry2, Point2};

use super::manifest::{MapManifest, fingerprint};
use super::settings::{drive_seed_and_speed, levels_of, map_config, self_filter_model};
use crate::error::{Error, Result};
use crate::scenario::RunConfig;
use crate::scenario::Scenario;
use crate::world::World;
use crate::world::{Lidar, SweepPoses};

/// One revolution of the mapping drive as it is inserted: when (simulated seconds), the
/// vehicle's pose, the scan.
pub type DriveRevolution<'a> = (f64, &'a Isometry2<f64>, &'a mapper::Scan);

/// Drives the route once with the LiDAR and map settings of `config` and writes the offline map
/// into `out`. `progress(done, total)` after each scan.
pub fn map_drive(
    scenario: &Scenario,
    config: &RunConfig,
    out: &Path,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<MapManifest> {
    map_drive_with(scenario, config, out, progress, &mut |_| Ok(()))
}

/// Removes a map directory's old blocks.
pub(crate) fn clear_blocks(blocks_dir: &Path) -> Result<()> {
    if blocks_dir.exists() {
        std::fs::remove_dir_all(blocks_dir).map_err(|source| Error::Io {
            what: "clearing the old map blocks",
            path: blocks_dir.to_path_buf(),
            source,
        })?;
    }
    Ok(())
}

/// [`map_drive`], showing `revolution` each revolution before it is inserted (the bag of
/// `taxi-sim map --record`).
pub fn map_drive_with(
    scenario: &Scenario,
    config: &RunConfig,
    out: &Path,
    progress: &mut dyn FnMut(usize, usize),
    revolution: &mut dyn FnMut(DriveRevolution<'_>) -> Result<()>,
) -> Result<MapManifest> {
    let vehicle = &scenario.vehicle.vehicle;
    let self_filter = self_filter_model(vehicle)?;
    let levels = levels_of(scenario, config)?;
    let blocks_dir = out.join("blocks");
    clear_blocks(&blocks_dir)?;
    let route = RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed);
    let (seed, speed_m_s) = drive_seed_and_speed(scenario);
    // One revolution every 0.1 s at the drive's speed.
    let spacing = (speed_m_s * 0.1).max(0.05);
    let poses = drive_poses(scenario, &route, spacing);
    // A survey starts where it starts, not where the run does.
    let start = match (&scenario.survey, poses.first()) {
        (Some(_), Some(first)) => *first,
        _ => scenario.vehicle.world_from_start,
    };
    let scene = crate::world::stale_scene(
        &scenario.survey_scene(),
        &config.faults.stale_map,
        seed,
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
    let scans = poses.len();
    // Each revolution is cast beside the insertion of the one before (the same insertions, in
    // the same order: the same map).
    let mut taken: Option<(Isometry2<f64>, mapper::Scan)> = None;
    for k in 0..=scans {
        if let Some((pose, scan)) = &taken {
            revolution(((k - 1) as f64 * 0.1, pose, scan))?;
        }
        let cast = poses.get(k).map(|pose| {
            world.set_vehicle_pose(pose, k as f64 * 0.1);
            *pose
        });
        let (scan, inserted) = rayon::join(
            || {
                cast.map(|pose| {
                    let scan = lidar.scan(&world, &SweepPoses::still(pose), k as u64, seed);
                    (pose, scan.scan)
                })
            },
            || -> Result<()> {
                if let Some((pose, scan)) = taken.take() {
                    map.recenter(Point2::from(pose.translation.vector))?;
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
    finish_map(
        &map,
        &levels,
        out,
        (
            fingerprint(scenario, config)?,
            scenario.name.clone(),
            scans,
            scenario
                .survey
                .as_ref()
                .map_or(route.length_m(), |s| s.length_m()),
        ),
    )
}

/// The mapping drive's poses, `spacing` metres apart: a survey's legs, each from its first point
/// to its second (and a zero-length leg's one pose); else the push-back's from the stand first,
/// when the route begins with one (so the stand is mapped as the run will meet it), then the
/// route's.
fn drive_poses(scenario: &Scenario, route: &RoutePath, spacing: f64) -> Vec<Isometry2<f64>> {
    let mut poses = Vec::new();
    if let Some(survey) = &scenario.survey {
        for &[a, b] in &survey.legs {
            let d = b - a;
            let (len, yaw) = (d.norm(), d.y.atan2(d.x));
            let steps = (len / spacing).ceil() as usize;
            poses.extend((0..=steps).map(|k| {
                let f = if steps == 0 {
                    0.0
                } else {
                    k as f64 / steps as f64
                };
                Isometry2::new((a + d * f).coords, yaw)
            }));
        }
        return poses;
    }
    if let Some(tow) = &scenario.route.pushback {
        let mut left = 0.0;
        for w in tow.poses.windows(2) {
            let ((a, ya), (b, yb)) = (w[0], w[1]);
            let len = (b - a).norm();
            while left <= len {
                let f = if len > 0.0 { left / len } else { 0.0 };
                let yaw = ya + crate::world::wrap_angle(yb - ya) * f;
                poses.push(Isometry2::new(a + (b - a) * f, yaw));
                left += spacing;
            }
            left -= len;
        }
    }
    let scans = (route.length_m() / spacing).ceil() as usize + 1;
    poses.extend((0..scans).map(|k| {
        let (p, heading) = route.at((k as f64 * spacing).min(route.length_m()));
        Isometry2::new(p.coords, heading)
    }));
    poses
}

/// Exports a flushed map's levels from its blocks in `out` and writes its manifest, made of
/// `(fingerprint, scenario, scans, route_m)` and what the export counted.
pub(crate) fn finish_map(
    map: &MultiHeightMap,
    levels: &Levels,
    out: &Path,
    (fingerprint, scenario, scans, route_m): (String, String, usize, f64),
) -> Result<MapManifest> {
    let store = BlockStore::open(out.join("blocks"), map.block_spec().clone())?;
    let blocks = store.list()?.len();
    let occupied_cells = export_levels(&store, levels, out)?;
    let manifest = MapManifest {
        fingerprint,
        scenario,
        scans,
        route_m,
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

/// Pixels the exports hold at once (both pictures of every level): a strip of pixel rows across
/// the extent, as many rows as fit (at least one, at most a block's).
const EXPORT_BUFFER_PIXELS: usize = 8 << 20;

/// Writes each level over the blocks' extent as a ROS map and a PNG; returns occupied cells per
/// level. The pictures are streamed top row first in strips of pixel rows across the extent, each
/// strip's blocks read once for every level: memory holds one strip (8 MiB of pixels, while a row
/// of 2 million pixels fits), whatever the route's length and extent. A block is read once per
/// strip across it (three times on the aerodrome, for both levels).
fn export_levels(store: &BlockStore, levels: &Levels, out: &Path) -> Result<Vec<usize>> {
    export_levels_in(store, levels, out, EXPORT_BUFFER_PIXELS)
}

/// A level's two pictures, written row by row.
struct LevelPictures {
    ros: PngRows,
    picture: PngRows,
}

/// [`export_levels`] holding at most `buffer_pixels` pixels (tests make strips of a few rows).
fn export_levels_in(
    store: &BlockStore,
    levels: &Levels,
    out: &Path,
    buffer_pixels: usize,
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
    let strip = (buffer_pixels / (2 * levels.count() * w)).clamp(1, side);
    let yaml = |k: usize| out.join(format!("level{k}.yaml"));
    let mut pictures = (0..levels.count())
        .map(|k| {
            Ok(LevelPictures {
                ros: PngRows::create(&ros_image_path(&yaml(k), RosImage::Png), w, h)?,
                picture: PngRows::create(&out.join(format!("level{k}.png")), w, h)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let (mut ros_row, mut picture_row) = (vec![0u8; w], vec![0u8; w]);
    let mut occupied = vec![0; levels.count()];
    for by in (y0..=y1).rev() {
        // Block rows top first; in each, strips of pixel rows top first.
        for top in (0..side).rev().step_by(strip) {
            let rows = top.saturating_sub(strip - 1)..top + 1;
            // Per block of the row, per level: the strip's pixels (None: no block saved).
            let blocks = (x0..=x1)
                .map(|x| block_pixels(store, BlockIndex { x, y: by }, levels, rows.clone()))
                .collect::<Result<Vec<_>>>()?;
            for (k, level) in pictures.iter_mut().enumerate() {
                occupied[k] += blocks
                    .iter()
                    .flatten()
                    .map(|b| b[k].occupied)
                    .sum::<usize>();
                for r in rows.clone().rev() {
                    let cells = (r - rows.start) * side..(r - rows.start + 1) * side;
                    for (bx, block) in blocks.iter().enumerate() {
                        let at = bx * side..(bx + 1) * side;
                        match block {
                            Some(b) => {
                                ros_row[at.clone()].copy_from_slice(&b[k].ros[cells.clone()]);
                                picture_row[at].copy_from_slice(&b[k].picture[cells.clone()]);
                            }
                            None => {
                                ros_row[at.clone()].fill(ROS_UNKNOWN);
                                picture_row[at].fill(ROS_UNKNOWN);
                            }
                        }
                    }
                    level.ros.write_row(&ros_row)?;
                    level.picture.write_row(&picture_row)?;
                }
            }
        }
    }
    for (k, level) in pictures.into_iter().enumerate() {
        level.ros.finish()?;
        level.picture.finish()?;
        write_ros_map_yaml(&yaml(k), &geometry, RosImage::Png)?;
    }
    Ok(occupied)
}

/// Rows of one block's level as the exports' pixels (in the block's order, lowest y first).
struct BlockPixels {
    /// ROS map_server's trinary pixels.
    ros: Vec<u8>,
    /// The picture's grey levels.
    picture: Vec<u8>,
    /// Cells of these rows with p > 0.5.
    occupied: usize,
}

/// Cell rows `rows` of every level of block `index` as pixels, `None` if the block was never
/// saved.
fn block_pixels(
    store: &BlockStore,
    index: BlockIndex,
    levels: &Levels,
    rows: std::ops::Range<usize>,
) -> Result<Option<Vec<BlockPixels>>> {
    let side = store.spec().side;
    let Some(block) = store.load(index)? else {
        return Ok(None);
    };
    let thresholds = TrinaryThresholds::default();
    let probability = |l: f32| {
        if l.is_nan() {
            -1.0
        } else {
            mapper::occupancy::probability(l)
        }
    };
    // The store checked the block's levels against the map's: one array per level.
    debug_assert_eq!(block.levels.len(), levels.count());
    let pixels = block
        .levels
        .iter()
        .map(|level| {
            let level = &level[rows.start * side..rows.end * side];
            BlockPixels {
                ros: level
                    .iter()
                    .map(|&l| thresholds.pixel(probability(l)))
                    .collect(),
                picture: level
                    .iter()
                    .map(|&l| occupancy_pixel(probability(l)))
                    .collect(),
                occupied: level.iter().filter(|&&l| probability(l) > 0.5).count(),
            }
        })
        .collect();
    Ok(Some(pixels))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mapper::{Block, BlockSpec};

    /// The exports of blocks laid out with a gap (a block never saved) are, pixel for pixel, the
    /// levels' probabilities north up, whatever the strips: one strip per block row, strips of 7
    /// rows (not dividing the block), one row at a time.
    #[test]
    fn streamed_exports_are_the_levels_north_up_whatever_the_strips() {
        let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
        let spec = BlockSpec {
            side: 20,
            resolution_m: 0.5,
            levels: levels.clone(),
            l_max: 3.5,
        };
        let dir = tempfile::tempdir().unwrap();
        let store = BlockStore::open(dir.path().join("blocks"), spec.clone()).unwrap();
        // Blocks (0,0), (1,0), (0,1) and (2,1); (1,1) and (2,0) never saved. Cell values from
        // their world position, so a misplaced pixel shows.
        let value = |k: usize, x: i64, y: i64| match (x * 7 + y * 13 + k as i64 * 5) % 9 {
            0 | 1 => f32::NAN,
            v => (v as f32 - 5.0) * 0.8,
        };
        for (bx, by) in [(0i64, 0i64), (1, 0), (0, 1), (2, 1)] {
            let mut block = Block::unknown(&spec, BlockIndex { x: bx, y: by });
            for (k, level) in block.levels.iter_mut().enumerate() {
                for (i, l) in level.iter_mut().enumerate() {
                    let (x, y) = (bx * 20 + (i % 20) as i64, by * 20 + (i / 20) as i64);
                    *l = value(k, x, y);
                }
            }
            store.save(&block).unwrap();
        }
        let (w, h) = (60usize, 40usize);
        let saved = |x: i64, y: i64| [(0, 0), (1, 0), (0, 1), (2, 1)].contains(&(x / 20, y / 20));
        for buffer in [1 << 20, 2 * 2 * w * 7, 1] {
            let out = dir.path().join(format!("out{buffer}"));
            let occupied = export_levels_in(&store, &levels, &out, buffer).unwrap();
            for (k, &occupied) in occupied.iter().enumerate() {
                let ros = image::open(out.join(format!("level{k}.ros.png")))
                    .unwrap()
                    .to_luma8();
                let pic = image::open(out.join(format!("level{k}.png")))
                    .unwrap()
                    .to_luma8();
                assert_eq!(ros.dimensions(), (w as u32, h as u32));
                let mut count = 0;
                for (x, y) in (0..w as i64).flat_map(|x| (0..h as i64).map(move |y| (x, y))) {
                    let p = if saved(x, y) {
                        let l = value(k, x, y);
                        if l.is_nan() {
                            -1.0
                        } else {
                            mapper::occupancy::probability(l)
                        }
                    } else {
                        -1.0
                    };
                    count += usize::from(p > 0.5);
                    let row = (h as i64 - 1 - y) as u32; // north up
                    let thresholds = TrinaryThresholds::default();
                    assert_eq!(
                        ros.get_pixel(x as u32, row).0[0],
                        thresholds.pixel(p),
                        "{x} {y}"
                    );
                    assert_eq!(
                        pic.get_pixel(x as u32, row).0[0],
                        occupancy_pixel(p),
                        "{x} {y}"
                    );
                }
                assert_eq!(occupied, count);
                assert!(count > 100);
            }
            let yaml = std::fs::read_to_string(out.join("level0.yaml")).unwrap();
            assert!(yaml.contains("origin:") && yaml.contains("- 0.0"), "{yaml}");
        }
    }
}
