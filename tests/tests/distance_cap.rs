//! The run's distance cap (`sim::run::distance_cap_m`) changes no decision: the planner and the
//! avoider choose the same paths and speeds over maps capped there as over maps capped at 30 m.

use mapper::edt::EdtScratch;
use mapper::{DistanceMap, DistanceMaps, GridGeometry};
use nalgebra::Point2;
use sim::autonomy::{AutonomyConfig, Behaviour, RoutePath, avoid, plan};

/// Obstacle cells scattered near a straight route along y = 0 (a seeded generator: cones,
/// kerb pieces and one wall at various offsets), on a 100 m x 40 m grid of 0.2 m.
fn obstacles(seed: u64) -> (GridGeometry, Vec<bool>) {
    let g = GridGeometry::new(Point2::new(-20.0, -20.0), 0.2, 500, 200).unwrap();
    let mut mask = vec![false; 500 * 200];
    let mut state = seed | 1;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..40 {
        let (x, y) = ((next() % 480) as usize + 10, (next() % 180) as usize + 10);
        let (w, h) = (1 + (next() % 4) as usize, 1 + (next() % 12) as usize);
        for yy in y..(y + h).min(200) {
            for xx in x..(x + w).min(500) {
                mask[yy * 500 + xx] = true;
            }
        }
    }
    (g, mask)
}

#[test]
fn capped_maps_give_the_same_plans_as_30_m_maps() {
    let cfg = AutonomyConfig::default();
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
        let cap = sim::run::distance_cap_m(&model, &cfg);
        assert!(cap < 30.0, "{vehicle}: cap {cap}");
        let levels = model.level_count();
        let mut scratch = EdtScratch::default();
        let mut compared = 0;
        for seed in 1..=12u64 {
            let (g, mask) = obstacles(seed * 7919);
            let maps = |cap: f32, scratch: &mut EdtScratch| {
                let level = DistanceMap::compute(g, cap, |i| mask[i], scratch);
                DistanceMaps::new(mapper::LevelMode::Cumulative, vec![level; levels]).unwrap()
            };
            let (capped, full) = (maps(cap, &mut scratch), maps(30.0, &mut scratch));
            let (a, b) = (
                model.checker(&capped).unwrap(),
                model.checker(&full).unwrap(),
            );
            for s0 in [0.0, 10.0, 20.0, 30.0] {
                for d0 in [-1.0, 0.0, 1.5] {
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
