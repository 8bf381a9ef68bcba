//! A circle model against the exact reference on a real offline map: seeded poses near obstacles,
//! false alarms and misses counted, both checks timed on the same poses.

use std::path::Path;
use std::time::Instant;

use aircraft::exact::{Comparison, ExactModel, lookup_slack_m};
use mapper::{CollisionModel, DistanceMaps, MultiHeightMap};
use nalgebra::{Isometry2, Vector2};
use rand::{RngExt as _, SeedableRng as _};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::scenario::RunConfig;
use crate::scenario::Scenario;

/// How far beyond a part's footprint the exact check looks for obstacles, metres.
pub const EXACT_REACH_M: f64 = 3.0;
/// Places along the route the offline map is loaded at (its window is 210 m across).
const PLACES: usize = 4;

/// What the probe measured for one model on one map.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Probe {
    /// False alarms, misses and the rest.
    pub comparison: Comparison,
    /// Mean time of the circle check (`check_pose`, with its early out) per pose, ns.
    pub circle_ns: f64,
    /// Mean time of the exact check per pose, ns.
    pub exact_ns: f64,
}

/// The offline map of `scenario` in `map_dir` as distance maps at `PLACES` points of its route
/// (one window each), all levels.
pub fn distance_maps(
    scenario: &Scenario,
    config: &RunConfig,
    map_dir: &Path,
) -> Result<Vec<DistanceMaps>> {
    let levels = crate::offline_map::levels_of(scenario, config)?;
    let route = autonomy::RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed);
    let blocks = map_dir.join("blocks");
    if !blocks.is_dir() {
        return Err(Error::Invalid(format!(
            "{}: no offline map blocks (run the campaign first)",
            blocks.display()
        )));
    }
    let mut out = Vec::new();
    for k in 0..PLACES {
        let s = route.length_m() * (k as f64 + 0.5) / PLACES as f64;
        let (centre, _) = route.at(s);
        let mut map = MultiHeightMap::with_stores(
            config.mapping.map,
            levels.clone(),
            centre,
            Some(&blocks),
            None,
        )?;
        map.update_distance_maps();
        out.push(map.distance_maps().clone());
    }
    Ok(out)
}

/// Seeded poses near level-0 obstacles of `maps`: an obstacle cell drawn at random, the vehicle
/// origin within its bounding radius (plus 1 m) of it, any heading; poses whose bounding circle
/// leaves the map are drawn again.
pub fn poses_near_obstacles(
    maps: &DistanceMaps,
    model: &CollisionModel,
    count: usize,
    seed: u64,
) -> Vec<Isometry2<f64>> {
    let g = maps.geometry();
    let level0 = maps.levels()[0].grid().data();
    let obstacles: Vec<usize> = (0..level0.len()).filter(|&i| level0[i] <= 0.0).collect();
    if obstacles.is_empty() {
        return Vec::new();
    }
    let b = model.bounding_circle();
    let reach = b.center.coords.norm() + b.radius_m + 1.0;
    let (lo, hi) = (
        g.origin_m(),
        g.origin_m() + Vector2::new(g.width() as f64, g.height() as f64) * g.resolution_m(),
    );
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut poses = Vec::with_capacity(count);
    let mut tries = 0;
    while poses.len() < count && tries < 100 * count {
        tries += 1;
        let i = obstacles[rng.random_range(0..obstacles.len())];
        let Some(cell) = g.cell_of_index(i) else {
            continue;
        };
        let c = g.center_of(cell);
        let p = c + Vector2::new(
            rng.random_range(-reach..reach),
            rng.random_range(-reach..reach),
        );
        let pose = Isometry2::new(
            p.coords,
            rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
        );
        let bc = pose * b.center;
        let r = b.radius_m + 1.0;
        if bc.x - r > lo.x && bc.y - r > lo.y && bc.x + r < hi.x && bc.y + r < hi.y {
            poses.push(pose);
        }
    }
    poses
}

/// Compares `model` with the exact parts of `exact` on `poses` over `maps`, at `safety_m`; times
/// the circle check over repeated passes (at least 20 ms) and the exact one over one pass.
pub fn probe(
    maps: &DistanceMaps,
    model: &CollisionModel,
    exact: &ExactModel,
    poses: &[Isometry2<f64>],
    safety_m: f64,
) -> Result<Probe> {
    let checker = model.checker(maps)?;
    let slack = lookup_slack_m(maps.geometry().resolution_m());
    let mut out = Probe::default();
    let t = Instant::now();
    let exacts: Vec<_> = poses
        .iter()
        .map(|p| exact.check(maps, p, safety_m, EXACT_REACH_M))
        .collect();
    out.exact_ns = t.elapsed().as_nanos() as f64 / poses.len().max(1) as f64;
    for (p, e) in poses.iter().zip(&exacts) {
        let m = checker.clearance(p, safety_m as f32).margin_m as f64;
        out.comparison.add(m, e, slack, EXACT_REACH_M);
    }
    let (mut reps, mut sink) = (0u64, 0.0f32);
    let t = Instant::now();
    while reps == 0 || t.elapsed().as_millis() < 20 {
        for p in poses {
            sink += checker
                .check_pose(std::hint::black_box(p), safety_m as f32)
                .margin_m;
        }
        reps += 1;
    }
    std::hint::black_box(sink);
    out.circle_ns = t.elapsed().as_nanos() as f64 / (reps as f64 * poses.len().max(1) as f64);
    Ok(out)
}

/// Probes `model` over every map of `maps` with `per_map` poses each, summed.
pub fn probe_all(
    maps: &[DistanceMaps],
    model: &CollisionModel,
    exact: &ExactModel,
    per_map: usize,
    seed: u64,
    safety_m: f64,
) -> Result<Probe> {
    let mut total = Probe::default();
    for (k, m) in maps.iter().enumerate() {
        let poses = poses_near_obstacles(m, model, per_map, seed.wrapping_add(k as u64));
        if poses.is_empty() {
            continue;
        }
        let p = probe(m, model, exact, &poses, safety_m)?;
        total.comparison.absorb(&p.comparison);
        let w = p.comparison.poses as f64;
        total.circle_ns += p.circle_ns * w;
        total.exact_ns += p.exact_ns * w;
    }
    let n = total.comparison.poses;
    if n > 0 {
        total.circle_ns /= n as f64;
        total.exact_ns /= n as f64;
    }
    Ok(total)
}
