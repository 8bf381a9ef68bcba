//! The map's distance maps kept up to date - around the vehicle, from the touched cells, after
//! a re-centring - equal to a transform computed afresh.

use super::{insert, map_with, scan_from, scene};
use mapper::synthetic::Solid;
use mapper::{Levels, MapConfig, MergeMode, MultiHeightMap};
use nalgebra::Point2;

#[test]
fn distance_maps_around_the_vehicle_equal_the_full_window_inside_their_reach() {
    let scene = scene(vec![
        Solid::standing_box(12.0, 5.0, 2.0, 1.0, 1.5),
        Solid::post(-6.0, -9.0, 0.3, 2.0),
        Solid::post(30.0, 0.0, 0.3, 2.0),
    ]);
    let mut map = map_with(Levels::cumulative(vec![0.0, 0.7]).unwrap());
    insert(&mut map, &scene, 2);
    map.update_distance_maps();
    let full: Vec<mapper::DistanceMap> = map.distance_maps().levels().to_vec();
    assert_eq!(
        map.update_distance_maps_around(Point2::new(1.0, 1.0), 20.0),
        2
    );
    let region = map.distance_maps();
    let g = *region.geometry();
    // 2 x 20 m plus one snapping step (20 m / 8, 12 cells), holding the square asked for.
    assert_eq!((g.width(), g.height()), (212, 212));
    let side = g.width() as f64 * g.resolution_m();
    assert!(g.origin_m().x <= 1.0 - 20.0 && g.origin_m().x + side >= 1.0 + 20.0);
    assert!(g.origin_m().y <= 1.0 - 20.0 && g.origin_m().y + side >= 1.0 + 20.0);
    let mut compared = 0;
    for (k, full_k) in full.iter().enumerate() {
        for y in (0..g.height()).step_by(7) {
            for x in (0..g.width()).step_by(7) {
                let p = g.center_of(mapper::Cell { x, y });
                let d_region = region.level(k).unwrap().distance_at(&p);
                let d_full = full_k.distance_at(&p);
                let to_edge = (p.x - g.origin_m().x)
                    .min(p.y - g.origin_m().y)
                    .min(g.origin_m().x + side - p.x)
                    .min(g.origin_m().y + side - p.y);
                if (d_full as f64) < to_edge {
                    assert!(
                        (d_region - d_full).abs() < 1e-5,
                        "level {k} at {p:?}: {d_region} vs {d_full}"
                    );
                    compared += 1;
                } else {
                    assert!(
                        d_region >= d_full,
                        "a region never sees an obstacle the window does not"
                    );
                }
            }
        }
    }
    assert!(compared > 500, "{compared}");
    // Unchanged levels and region: nothing to recompute.
    assert_eq!(
        map.update_distance_maps_around(Point2::new(1.0, 1.0), 20.0),
        0
    );
    // Re-centring hands back full-window maps until the next update.
    assert!(map.recenter(Point2::new(80.0, 0.0)).unwrap());
    assert_eq!(map.distance_maps().geometry().width(), 1050);
}

/// A level's obstacle cells, computed afresh from the merged map over the distance maps' region,
/// and the transform of them: what the kept distance maps must equal.
fn fresh_distance_map(map: &MultiHeightMap, k: usize) -> mapper::DistanceMap {
    let g = *map.distance_maps().geometry();
    let obstacle: Vec<bool> = (0..g.width() * g.height())
        .map(|i| {
            let p = g.center_of(mapper::Cell {
                x: i % g.width(),
                y: i / g.width(),
            });
            map.log_odds_at(k, &p).is_some_and(|l| l > 0.0)
        })
        .collect();
    let cap = map.config().max_distance_m;
    mapper::DistanceMap::compute(g, cap, |i| obstacle[i], &mut Default::default())
}

fn assert_distance_maps_fresh(map: &MultiHeightMap, what: &str) {
    for k in 0..map.levels().count() {
        let want = fresh_distance_map(map, k);
        assert!(
            map.distance_maps().level(k).unwrap().grid().data() == want.grid().data(),
            "{what}, level {k}: the kept distance map differs from a fresh one"
        );
    }
}

/// The distance maps kept up to date from the cells each scan, forgetting and re-centring
/// touched (instead of sweeping the region) equal a transform computed afresh from the merged
/// map, bit for bit, after every scan: on a drive over an offline map holding a parked box that
/// is gone at run time (the walks lower its cells from unknown in the live map), past posts and
/// a box that crosses the path (the walks clear its trail; forgetting, when on, fades what they
/// miss), across a re-centring of the window, with both merge modes.
#[test]
fn distance_maps_kept_from_the_touched_cells_equal_a_fresh_transform() {
    let levels = || Levels::cumulative(vec![0.0, 0.7]).unwrap();
    for merge in [MergeMode::Fallback, MergeMode::Decay] {
        let config = MapConfig {
            merge,
            max_distance_m: 3.0,
            ..MapConfig::default()
        };
        // The offline map: a box parked beside the road.
        let prior_dir = tempfile::tempdir().unwrap();
        let mut offline = MultiHeightMap::with_stores(
            config,
            levels(),
            Point2::new(30.0, 0.0),
            None,
            Some(prior_dir.path()),
        )
        .unwrap();
        let parked = scene(vec![Solid::standing_box(52.0, -4.0, 3.0, 1.5, 1.4)]);
        for x in [40.0, 46.0, 52.0] {
            offline
                .insert_scan(&scan_from(&parked, x, 0.0), None)
                .unwrap();
        }
        offline.flush().unwrap();
        for forget in [true, false] {
            let what = format!("{merge:?}, forgetting {forget}");
            let mut map = MultiHeightMap::with_stores(
                config,
                levels(),
                Point2::new(30.0, 0.0),
                Some(prior_dir.path()),
                None,
            )
            .unwrap();
            let mut recentred = 0;
            for step in 0..120 {
                let x = 30.0 + 0.5 * step as f64;
                // The box crosses 10 m ahead, from 6 m right to 6 m left, over 60 scans.
                let crossing = -6.0 + 0.2 * (step % 60) as f64;
                let world = scene(vec![
                    Solid::post(x + 4.0 - (step % 7) as f64, 3.0, 0.3, 2.0),
                    Solid::post(45.0, 2.5, 0.25, 0.4),
                    Solid::standing_box(x + 10.0, crossing, 2.0, 1.0, 1.5),
                ]);
                let at = Point2::new(x, 0.0);
                if map.recenter(at).unwrap() {
                    recentred += 1;
                }
                if forget {
                    map.forget_unseen(at, 50.0, 0.1, 1.0);
                }
                map.insert_scan(&scan_from(&world, x, 0.0), None).unwrap();
                map.update_distance_maps_around(at, 12.0);
                assert_distance_maps_fresh(&map, &format!("{what}, step {step}"));
            }
            assert_eq!(recentred, 1, "{what}: the drive crosses one block edge");
            // The walks did lower offline obstacle cells from unknown in the live map: the
            // parked box's, gone at run time.
            let (live, prior) = (
                map.live_log_odds(0).unwrap(),
                map.prior_log_odds(0).unwrap(),
            );
            let cleared = live
                .data()
                .iter()
                .zip(prior.data())
                .filter(|(l, p)| **p > 0.0 && **l <= 0.0)
                .count();
            assert!(
                cleared > 10,
                "{what}: {cleared} offline obstacle cells cleared"
            );
        }
    }
}

/// Regression: re-centring reset the distance maps but not the obstacle cells they were
/// computed from, so a whole-window update after a whole-window update and a re-centring
/// updated an empty map only around the cells that differed from the old window's.
#[test]
fn whole_window_distance_maps_after_a_recentring_start_over() {
    let mut map = map_with(Levels::cumulative(vec![0.0, 0.7]).unwrap());
    let world = scene(vec![
        Solid::standing_box(12.0, 5.0, 2.0, 1.0, 1.5),
        Solid::post(-6.0, -9.0, 0.3, 2.0),
    ]);
    insert(&mut map, &world, 2);
    map.update_distance_maps();
    assert_distance_maps_fresh(&map, "before");
    assert!(map.recenter(Point2::new(80.0, 0.0)).unwrap());
    map.update_distance_maps();
    assert_distance_maps_fresh(&map, "after re-centring");
}
