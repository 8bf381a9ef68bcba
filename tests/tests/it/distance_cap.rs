//! The run's distance maps change no decision: over maps capped at `sim::engine::distance_cap_m` and
//! computed only over the square of `sim::engine::distance_map_half_size_m` around the vehicle, the
//! planner and the avoider choose the same paths and speeds as over maps of the whole area capped
//! at 30 m.

use autonomy::{AutonomyConfig, Behaviour, RoutePath, avoid, plan};
use mapper::edt::EdtScratch;
use mapper::{DistanceMap, DistanceMaps, GridGeometry};
use nalgebra::Point2;

const W: usize = 1250;
const H: usize = 500;

/// Obstacle cells scattered around a straight route along y = 0 (a seeded generator: cones,
/// kerb pieces, short walls), on a 250 m x 100 m grid of 0.2 m reaching beyond the region.
fn obstacles(seed: u64) -> (GridGeometry, Vec<bool>) {
    let g = GridGeometry::new(Point2::new(-120.0, -50.0), 0.2, W, H).unwrap();
    let mut mask = vec![false; W * H];
    let mut state = seed | 1;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..600 {
        let (x, y) = ((next() % W as u64) as usize, (next() % H as u64) as usize);
        let (w, h) = (1 + (next() % 4) as usize, 1 + (next() % 12) as usize);
        for yy in y..(y + h).min(H) {
            for xx in x..(x + w).min(W) {
                mask[yy * W + xx] = true;
            }
        }
    }
    (g, mask)
}

/// The maps of the square of half side `half_m` around `center` only (what the run computes).
fn region_maps(
    g: &GridGeometry,
    mask: &[bool],
    center: Point2<f64>,
    half_m: f64,
    cap: f32,
    levels: usize,
    scratch: &mut EdtScratch,
) -> DistanceMaps {
    let (cx, cy) = g.cell_coords(&center);
    let half = (half_m / 0.2).ceil() as i64;
    let (x0, y0) = ((cx - half).max(0) as usize, (cy - half).max(0) as usize);
    let (x1, y1) = (((cx + half) as usize).min(W), ((cy + half) as usize).min(H));
    let origin = g.origin_m() + nalgebra::Vector2::new(x0 as f64, y0 as f64) * 0.2;
    let sub = GridGeometry::new(origin, 0.2, x1 - x0, y1 - y0).unwrap();
    let w = x1 - x0;
    let level = DistanceMap::compute(sub, cap, |i| mask[(y0 + i / w) * W + x0 + i % w], scratch);
    DistanceMaps::new(mapper::LevelMode::Cumulative, vec![level; levels]).unwrap()
}

#[test]
fn capped_region_maps_give_the_same_plans_as_30_m_maps_of_the_whole_area() {
    // The default horizon, and the one the jet (1.5 m/s^2) checks at 10 m/s: it grows with
    // speed, to 0.5 x 10 + 100 / 3 + 3 + 0.5 = 41.8 m.
    let fast = sim::engine::longest_horizon_m(10.0, 1.5, &AutonomyConfig::default());
    assert!((fast - 41.83).abs() < 0.01, "{fast}");
    for horizon_m in [30.0, fast] {
        compare_plans(&AutonomyConfig {
            horizon_m,
            ..AutonomyConfig::default()
        });
    }
}

/// Plans and speeds over maps of the square `distance_map_half_size_m` gives for `cfg`'s
/// horizon against maps of the whole area.
fn compare_plans(cfg: &AutonomyConfig) {
    let cfg = cfg.clone();
    let route = RoutePath::new(&[Point2::new(-15.0, 0.0), Point2::new(75.0, 0.0)], false);
    for (vehicle, behaviour) in [
        ("iara_car_fake_wing", Behaviour::Deviate),
        ("praetor600", Behaviour::StopAndWait),
    ] {
        let model = aircraft::Vehicle::load(vehicle)
            .unwrap()
            .fit()
            .unwrap()
            .model;
        let cap = sim::engine::distance_cap_m(&model, &cfg);
        let half = sim::engine::distance_map_half_size_m(&model, &cfg, cfg.horizon_m);
        assert!(
            cap < 30.0 && half < 75.0,
            "{vehicle}: cap {cap}, half {half}"
        );
        let levels = model.level_count();
        let mut scratch = EdtScratch::default();
        let mut compared = 0;
        for seed in 1..=12u64 {
            let (g, mask) = obstacles(seed * 7919);
            let full = {
                let level = DistanceMap::compute(g, 30.0, |i| mask[i], &mut scratch);
                DistanceMaps::new(mapper::LevelMode::Cumulative, vec![level; levels]).unwrap()
            };
            let b = model.checker(&full).unwrap();
            for s0 in [0.0, 10.0, 20.0, 30.0] {
                for d0 in [-1.0, 0.0, 1.5] {
                    let (p, heading) = route.at(s0);
                    let vehicle_at = p + nalgebra::Vector2::new(-heading.sin(), heading.cos()) * d0;
                    let capped =
                        region_maps(&g, &mask, vehicle_at, half, cap, levels, &mut scratch);
                    let a = model.checker(&capped).unwrap();
                    let (pa, pb) = (
                        plan(&a, &route, s0, d0, 0.0, behaviour, &cfg),
                        plan(&b, &route, s0, d0, 0.0, behaviour, &cfg),
                    );
                    assert_eq!(pa.chosen, pb.chosen, "{vehicle} seed {seed} s {s0} d {d0}");
                    assert_eq!(pa.blocked, pb.blocked);
                    for (ca, cb) in pa.candidates.iter().zip(&pb.candidates) {
                        assert_eq!(ca.collision_at_m, cb.collision_at_m);
                        assert_eq!(ca.cost, cb.cost, "{vehicle} offset {}", ca.offset_m);
                    }
                    let (va, _) = avoid(pa.chosen(), 5.0, 1.5, &cfg);
                    let (vb, _) = avoid(pb.chosen(), 5.0, 1.5, &cfg);
                    assert_eq!(va, vb);
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, 12 * 12);
    }
}
