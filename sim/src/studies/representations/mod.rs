//! The thesis' open question measured (section 5.3): a few 2D grids, one per height of interest,
//! against a dense 3D voxel grid, OctoMap and a 2.5D elevation-interval map, all fed the same
//! revolutions at the same poses and judged against the exact answer (the vehicle's URDF shapes
//! against the world's colliders) at poses drawn near the objects.
//!
//! One scene: a fixed map window (the 2D map's, 210 m across) on a stretch of the scenario's
//! route; the drive's revolutions inserted into every representation in turn on one thread;
//! then per representation its memory, insertion and distance-update times, the time of one pose
//! check and its false alarms and misses by what was near. Every representation checks the same
//! circles: the 2D maps by level (cumulative: the level's grid holds everything above it; banded:
//! the bands from the circle's own up to the top of the parts it covers), the others with the
//! height span of the parts each circle covers ([`spans`]).

pub mod answers;
pub mod chart;
pub mod drive;
pub mod octomap;
pub mod recording;
pub mod spans;
pub mod table;
pub mod truth;

use std::path::{Path, PathBuf};
use std::time::Instant;

use mapper::edt::EdtScratch;
use mapper::{CollisionModel, DistanceMap, DistanceMaps};
use nalgebra::{Isometry2, Point2, Vector2};
use serde::{Deserialize, Serialize};

use self::answers::{Judged, judge};
use self::drive::{Cloud, InsertTimes, Representations, Stretch};
use self::truth::{PoseDraw, TruthPose};
use crate::error::{Error, Result};
use crate::scenario::{RunConfig, Scenario};

/// How one scene is compared.
#[derive(Clone, Debug)]
pub struct Options {
    /// Where along the route.
    pub stretch: Stretch,
    /// The poses judged.
    pub draw: PoseDraw,
    /// OctoMap through its binding, if wanted.
    pub octomap: Option<OctoMapOptions>,
    /// Also the dense 3D grid without free-space carving (a diagnostic row).
    pub carving_diagnostic: bool,
}

/// How OctoMap is run.
#[derive(Clone, Debug)]
pub struct OctoMapOptions {
    /// The Python with `octomap-python` installed.
    pub python: PathBuf,
    /// Leaf sizes, metres.
    pub resolutions_m: Vec<f64>,
    /// Where the exchange files go (one directory per scene below it).
    pub dir: PathBuf,
    /// Poses checked through the binding itself (timed; the rest judged on its voxels).
    pub timed_poses: usize,
    /// Read a finished run's files from `dir` instead of running the script again.
    pub reuse: bool,
}

/// One representation on one scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    /// Its name.
    pub name: String,
    /// Bytes of its occupancy and query structure over the window.
    pub memory_window_bytes: u64,
    /// The same over the whole route's blocks (dense ones exactly; OctoMap scaled by area).
    pub memory_route_bytes: u64,
    /// Median insertion of one revolution (free space included), ms, one thread.
    pub insert_ms: Option<f64>,
    /// Median distance-structure update after one revolution, ms (`None`: it has none).
    pub update_ms: Option<f64>,
    /// How that update is made.
    pub update_kind: String,
    /// Wrong answers and the time of one pose check.
    pub judged: Judged,
    /// Poses it says colliding where the dense voxel grid says clear, and the reverse.
    pub vs_voxels: (usize, usize),
    /// Up to five poses of the second kind (clear here, colliding in the voxel grid): x, y,
    /// heading (rad), truly colliding, exact clearance (m).
    pub clear_where_voxels_collide: Vec<(f64, f64, f64, bool, f64)>,
}

/// One scene's comparison (as `--out DIR/representations.json` holds it; the answers pose by
/// pose are not written).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneResult {
    /// The scenario's name.
    pub scenario: String,
    /// Its file.
    pub path: String,
    /// The vehicle.
    pub vehicle: String,
    /// Revolutions inserted.
    pub revolutions: usize,
    /// Route driven, metres.
    pub driven_m: f64,
    /// Blocks the whole route's map covers.
    pub route_blocks: usize,
    /// Poses judged, and how many of them truly collide.
    pub poses: (usize, usize),
    /// One row per representation.
    pub rows: Vec<Row>,
    /// OctoMap: the binding's own answers against ours on its voxels (agreeing, sampled).
    pub octomap_agreement: Vec<(f64, usize, usize)>,
    /// What was left out, and why.
    pub notes: Vec<String>,
}

/// Compares the representations on `scenario`, reporting progress as (stage, done, total).
pub fn compare_scene(
    scenario: &Scenario,
    config: &RunConfig,
    options: &Options,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<SceneResult> {
    let vehicle = &scenario.vehicle.vehicle;
    let route = autonomy::RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed);
    let at = options.stretch.at_m.unwrap_or(0.5 * route.length_m());
    let (centre, _) = route.at(at);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| Error::Invalid(format!("a one-thread pool: {e}")))?;
    let mut reps = Representations::new(scenario, config, centre, options.carving_diagnostic)?;
    let g = *reps.cumulative.geometry();
    let (lo, hi) = (
        g.origin_m(),
        g.origin_m() + Vector2::new(g.width() as f64, g.height() as f64) * g.resolution_m(),
    );
    let spacing = options
        .stretch
        .spacing_m
        .unwrap_or((scenario.route.speed_m_s * 0.1).max(0.05));
    let poses = drive::drive_poses(&route, &options.stretch, spacing, (lo, hi, 20.0));
    if poses.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no route inside the window at {at:.0} m",
            scenario.path.display()
        )));
    }
    let mut world = crate::world::World::with_obstacles(&scenario.full_scene(), vehicle, &poses[0]);
    let lidar = crate::world::Lidar::new(config.lidar.clone(), vehicle.vehicle_from_lidar())
        .map_err(|e| Error::Invalid(format!("lidar: {e}")))?;
    let self_filter = crate::offline_map::self_filter_model(vehicle)?;
    let margin = config.mapping.map.self_hit_margin_m;
    let (mut times, mut clouds) = (InsertTimes::default(), Vec::new());
    for (k, pose) in poses.iter().enumerate() {
        let scan = drive::cast(&lidar, &mut world, pose, k, scenario.seed);
        let scan = drive::without_self_hits(&scan, &self_filter, margin)?;
        one.install(|| reps.insert(&scan, &mut times))?;
        if options.octomap.is_some() {
            clouds.push(Cloud::of(&scan)?);
        }
        progress("drive", k + 1, poses.len());
    }
    progress("exact answers", 0, 1);
    let model = config.collision_model(vehicle)?;
    let truth = truth::draw_poses(
        &mut world,
        &poses,
        &model.bounding_circle(),
        (lo + Vector2::new(5.0, 5.0), hi - Vector2::new(5.0, 5.0)),
        &options.draw,
    );
    let circles = spans::span_circles(&model, vehicle);
    let vehicle_model = (&model, circles.as_slice());
    let mut result =
        one.install(|| judge_all(scenario, vehicle_model, &mut reps, &truth, &times))?;
    result.revolutions = poses.len();
    result.driven_m = spacing * (poses.len().saturating_sub(1)) as f64;
    result.route_blocks = route_blocks(&route, config);
    if let Some(o) = &options.octomap {
        progress("OctoMap", 0, 1);
        let ctx = (scenario, &reps, circles.as_slice());
        octomap_rows(ctx, &truth, &clouds, o, &mut result)?;
    } else {
        result
            .notes
            .push("OctoMap not run (no --octomap-python)".into());
    }
    scale_route_memory(&mut result);
    Ok(result)
}

/// The whole route's blocks: the 3 x 3 windows around its points every 10 m.
fn route_blocks(route: &autonomy::RoutePath, config: &RunConfig) -> usize {
    let block = config.mapping.map.block_m();
    let mut set = std::collections::HashSet::new();
    let n = (route.length_m() / 10.0).ceil() as usize;
    for k in 0..=n {
        let (p, _) = route.at((k as f64 * 10.0).min(route.length_m()));
        let (bx, by) = ((p.x / block).floor() as i64, (p.y / block).floor() as i64);
        for dx in -1..=1 {
            for dy in -1..=1 {
                set.insert((bx + dx, by + dy));
            }
        }
    }
    set.len()
}

/// Memory over the route: the window's bytes per block times the route's blocks.
pub(crate) fn scale_route_memory(result: &mut SceneResult) {
    for row in &mut result.rows {
        row.memory_route_bytes =
            (row.memory_window_bytes as f64 / 9.0 * result.route_blocks as f64) as u64;
    }
}

/// The 2D distance maps recomputed whole from their obstacle cells (the cells at distance 0),
/// seconds: what a full update costs, beside the incremental one the loop uses.
fn full_2d_update_s(maps: &DistanceMaps) -> f64 {
    let mut scratch = EdtScratch::default();
    let g = *maps.geometry();
    let start = Instant::now();
    for m in maps.levels() {
        let data = m.grid().data();
        let d = DistanceMap::compute(g, m.max_distance_m(), |i| data[i] <= 0.0, &mut scratch);
        std::hint::black_box(d);
    }
    start.elapsed().as_secs_f64()
}

/// The diagnostic grid without carving, if kept: its bytes and answers.
fn judge_hits_only(
    reps: &mut Representations,
    truth: &[TruthPose],
    circles: &[spans::SpanCircle],
) -> Option<(u64, Judged)> {
    let v = reps.voxels_hits_only.as_mut()?;
    v.update_distances();
    let v = &*v;
    let judged = judge(
        truth,
        answers::spans(circles, |c, r, a, b| v.span_collides(c, r, a, b)),
    );
    Some((v.memory_bytes() as u64, judged))
}

/// Median insertion per representation and distance update per 2D map, ms.
fn medians_ms(times: &InsertTimes) -> ([f64; 4], [f64; 2]) {
    let of = |v: Vec<f64>| {
        let mut v = v;
        median(&mut v) * 1e3
    };
    (
        std::array::from_fn(|k| of(times.per_revolution.iter().map(|t| t[k]).collect())),
        std::array::from_fn(|k| of(times.distance_update.iter().map(|t| t[k]).collect())),
    )
}

/// Every representation judged on `truth` with the vehicle's `model` and its circles' `circles`.
pub(crate) fn judge_all(
    scenario: &Scenario,
    (model, circles): (&CollisionModel, &[spans::SpanCircle]),
    reps: &mut Representations,
    truth: &[TruthPose],
    times: &InsertTimes,
) -> Result<SceneResult> {
    let vehicle = &scenario.vehicle.vehicle;
    let heights = model.level_heights_m().to_vec();
    let (col, upd) = medians_ms(times);
    let start = Instant::now();
    reps.voxels.update_distances();
    let voxel_update = start.elapsed().as_secs_f64() * 1e3;
    let cells = reps.cumulative.geometry().len() as u64;
    let map_bytes = |levels: usize| cells * levels as u64 * 8;
    let voxels = judge(
        truth,
        answers::spans(circles, |c, r, a, b| reps.voxels.span_collides(c, r, a, b)),
    );
    let cumulative = judge(
        truth,
        answers::cumulative(model, reps.cumulative.distance_maps())?,
    );
    let banded = judge(
        truth,
        answers::banded(circles, reps.banded.distance_maps(), &heights),
    );
    let elevation = judge(
        truth,
        answers::spans(circles, |c, r, a, b| {
            reps.elevation.span_collides(c, r, a, b)
        }),
    );
    let hits_only = judge_hits_only(reps, truth, circles);
    let full_cumulative = full_2d_update_s(reps.cumulative.distance_maps()) * 1e3;
    let levels = heights.len();
    let row =
        |name: &str, mem: u64, ins: f64, upd: Option<f64>, kind: &'static str, judged: Judged| {
            Row {
                name: name.into(),
                memory_window_bytes: mem,
                memory_route_bytes: 0,
                insert_ms: ins.is_finite().then_some(ins),
                update_ms: upd,
                update_kind: kind.into(),
                vs_voxels: versus(&judged.answers, &voxels.answers),
                clear_where_voxels_collide: examples(&judged.answers, &voxels.answers, truth),
                judged,
            }
        };
    let rows = vec![
        row(
            "multi-height, cumulative",
            map_bytes(levels),
            col[0],
            Some(upd[0]),
            "incremental",
            cumulative,
        ),
        row(
            "multi-height, banded",
            map_bytes(levels),
            col[1],
            Some(upd[1]),
            "incremental",
            banded,
        ),
        row(
            "3D voxels (dense)",
            reps.voxels.memory_bytes() as u64,
            col[2],
            Some(voxel_update),
            "full 3D EDT",
            voxels.clone(),
        ),
        row(
            "2.5D elevation interval",
            reps.elevation.memory_bytes() as u64,
            col[3],
            None,
            "none (cells enumerated)",
            elevation,
        ),
    ];
    let mut rows = rows;
    if let Some((bytes, judged)) = hits_only {
        rows.push(row(
            "3D voxels, no carving (diagnostic)",
            bytes,
            f64::NAN,
            None,
            "full 3D EDT",
            judged,
        ));
    }
    let g = reps.cumulative.geometry();
    let notes = vec![
        format!(
            "2D distance maps recomputed whole: {full_cumulative:.1} ms (all levels); the loop updates them incrementally"
        ),
        format!(
            "memory: 2D maps count log-odds and distance per level (f32); the window is {} x {} cells of {} m",
            g.width(),
            g.height(),
            g.resolution_m()
        ),
    ];
    Ok(SceneResult {
        scenario: scenario.name.clone(),
        path: scenario.path.display().to_string(),
        vehicle: vehicle.spec.name.clone(),
        revolutions: 0,
        driven_m: 0.0,
        route_blocks: 0,
        poses: (truth.len(), truth.iter().filter(|p| p.colliding).count()),
        rows,
        octomap_agreement: Vec::new(),
        notes,
    })
}

/// Up to five poses where `answers` says clear and `reference` colliding.
fn examples(
    answers: &[bool],
    reference: &[bool],
    truth: &[TruthPose],
) -> Vec<(f64, f64, f64, bool, f64)> {
    answers
        .iter()
        .zip(reference)
        .zip(truth)
        .filter(|((a, r), _)| !**a && **r)
        .take(5)
        .map(|(_, t)| {
            let p = t.pose.translation.vector;
            (
                p.x,
                p.y,
                t.pose.rotation.angle(),
                t.colliding,
                t.clearance_m,
            )
        })
        .collect()
}

/// The median of `v` (sorted in place; NaN when empty).
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// (says colliding where the reference says clear, says clear where it says colliding).
fn versus(answers: &[bool], reference: &[bool]) -> (usize, usize) {
    answers
        .iter()
        .zip(reference)
        .fold((0, 0), |(a, b), (x, r)| {
            (a + usize::from(*x && !*r), b + usize::from(!*x && *r))
        })
}

/// OctoMap's rows: the drive inserted by the script at each resolution, every pose judged on its
/// occupied voxels, a sample checked by the binding itself (timed, and its answers compared).
pub(crate) fn octomap_rows(
    (scenario, reps, circles): (&Scenario, &Representations, &[spans::SpanCircle]),
    truth: &[TruthPose],
    clouds: &[Cloud],
    o: &OctoMapOptions,
    result: &mut SceneResult,
) -> Result<()> {
    let vehicle = &scenario.vehicle.vehicle;
    let g = *reps.cumulative.geometry();
    let hi = g.origin_m() + Vector2::new(g.width() as f64, g.height() as f64) * g.resolution_m();
    let dir = o.dir.join(file_stem(Path::new(&result.path)));
    let exchange = octomap::Exchange::create(&dir)?;
    let timed: Vec<Isometry2<f64>> = truth.iter().take(o.timed_poses).map(|p| p.pose).collect();
    exchange.write(
        clouds,
        (g.origin_m(), hi, vehicle.ceiling_m()),
        &octomap::cylinders(circles, &timed),
    )?;
    let voxel_answers = result
        .rows
        .iter()
        .find(|r| r.name.starts_with("3D voxels"))
        .map(|r| r.judged.answers.clone())
        .unwrap_or_default();
    for &res in &o.resolutions_m {
        let Some((run, voxels)) = exchange.run(&o.python, res, o.reuse)? else {
            result
                .notes
                .push("OctoMap not run: the octomap-python binding is not installed".into());
            return Ok(());
        };
        let set = octomap::VoxelSet::new(&voxels, res, g);
        // Timed through the binding itself (below), not here.
        let mut judged = answers::judge_untimed(
            truth,
            answers::spans(circles, |c, r, a, b| set.span_collides(c, r, a, b)),
        );
        judged.pose_check_ns = run.pose_check_us.median.map_or(f64::NAN, |us| us * 1e3);
        let agree = run
            .pose_answers
            .iter()
            .zip(&judged.answers)
            .filter(|(a, b)| a == b)
            .count();
        result
            .octomap_agreement
            .push((res, agree, run.pose_answers.len()));
        result.rows.push(Row {
            name: format!("OctoMap {res} m"),
            memory_window_bytes: run.memory_bytes,
            memory_route_bytes: 0,
            insert_ms: Some(run.insert_ms.median),
            update_ms: None,
            update_kind: "none (tree queried)".into(),
            vs_voxels: versus(&judged.answers, &voxel_answers),
            clear_where_voxels_collide: examples(&judged.answers, &voxel_answers, truth),
            judged,
        });
    }
    Ok(())
}

fn file_stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
}

/// The centre of the window for a stretch (for pictures).
pub fn window_centre(scenario: &Scenario, stretch: &Stretch) -> Point2<f64> {
    let route = autonomy::RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed);
    route.at(stretch.at_m.unwrap_or(0.5 * route.length_m())).0
}
