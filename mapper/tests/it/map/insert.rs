//! Scan insertion on analytic scenes: obstacles, free space and unknown cells, levels
//! (cumulative and banded), range noise on flat ground, self-hits, the coarse-to-fine walks
//! against the walk of every column, and a scan with a bad return.

use super::{insert, map_with, p, scan_from, scene};
use mapper::synthetic::{Lidar, Solid, car_sensor_mount};
use mapper::{Circle, CollisionModel, LevelMode, Levels, MapConfig, MultiHeightMap};
use nalgebra::{Isometry2, Point2, Vector2};
use rand::RngExt;
use rand::SeedableRng;
use rand::distr::Distribution;

#[test]
fn a_wall_at_3_m_is_occupied_with_free_space_before_it_and_unknown_behind() {
    let scene = scene(vec![Solid::Box {
        min: [3.0, -10.0, 0.0].into(),
        max: [3.2, 10.0, 3.0].into(),
    }]);
    let mut map = map_with(Levels::cumulative(vec![0.0, 0.7]).unwrap());
    insert(&mut map, &scene, 1);
    for k in 0..2 {
        for y in [-1.5, -0.5, 0.0, 0.7, 1.3] {
            assert!(
                p(&map, k, 3.1, y).unwrap() > 0.9,
                "level {k}: wall at y={y}"
            );
            assert!(
                p(&map, k, 2.0, y).unwrap() < 0.1,
                "level {k}: free before the wall at y={y}"
            );
            assert_eq!(
                p(&map, k, 6.0, y),
                None,
                "level {k}: behind the wall is unknown"
            );
        }
    }
    // The free walk stops 2 cells short of the hit: the cell just before the wall face is untouched.
    assert_eq!(p(&map, 0, 2.9, 0.1), None);
}

#[test]
fn a_cone_is_in_level_0_only_and_a_container_in_both() {
    let cone = Solid::post(6.0, 0.0, 0.2, 0.45);
    let container = Solid::standing_box(6.0, 5.0, 0.8, 0.6, 1.1);
    let scene = scene(vec![cone, container]);
    let mut map = map_with(Levels::cumulative(vec![0.0, 0.7]).unwrap());
    insert(&mut map, &scene, 3);
    map.update_distance_maps();
    let odm = map.distance_maps();
    let d = |k: usize, x: f64, y: f64| odm.level(k).unwrap().distance_at(&Point2::new(x, y));
    assert!(d(0, 6.0, 0.0) < 0.3, "cone in level 0: {}", d(0, 6.0, 0.0));
    assert!(
        d(1, 6.0, 0.0) > 2.0,
        "cone not in level 1: {}",
        d(1, 6.0, 0.0)
    );
    assert!(
        d(0, 5.65, 5.0) < 0.3,
        "container in level 0: {}",
        d(0, 5.65, 5.0)
    );
    assert!(
        d(1, 5.65, 5.0) < 0.3,
        "container in level 1: {}",
        d(1, 5.65, 5.0)
    );
    // Level 1 saw the cone's cells as flat ground: they are free there, not unknown.
    assert!(p(&map, 1, 6.0, 0.0).is_some_and(|v| v < 0.5));
}

#[test]
fn banded_levels_put_a_hanging_bar_only_in_its_band() {
    let bar = Solid::Box {
        min: [8.0, -3.0, 2.2].into(),
        max: [8.4, 3.0, 2.8].into(),
    };
    let scene = scene(vec![bar]);
    let levels = Levels::new(vec![0.0, 2.0, 3.0], LevelMode::Banded, Some(6.0)).unwrap();
    let mut map = map_with(levels);
    insert(&mut map, &scene, 2);
    assert!(p(&map, 1, 8.1, 0.0).unwrap() > 0.9, "bar in band [2, 3)");
    assert!(
        p(&map, 0, 8.1, 0.0).is_none_or(|v| v < 0.5),
        "bar not in band [0, 2)"
    );
    assert!(
        p(&map, 2, 8.1, 0.0).is_none_or(|v| v < 0.5),
        "bar not in band [3, 6)"
    );
    // Cumulative from 0 would hold it in level 0: the difference between the interpretations.
    let mut cumulative = map_with(Levels::cumulative(vec![0.0, 2.0, 3.0]).unwrap());
    insert(&mut cumulative, &scene, 2);
    assert!(p(&cumulative, 0, 8.1, 0.0).unwrap() > 0.9);
}

#[test]
fn flat_ground_with_range_noise_produces_no_obstacle_at_any_range() {
    let lidar = Lidar::hdl32e();
    let mut map = map_with(Levels::cumulative(vec![0.0, 0.7]).unwrap());
    let normal = rand_distr_normal();
    for seed in 0..3u64 {
        // Seeded 2 cm Gaussian range noise (the HDL-32E's accuracy), a fresh draw per ray.
        let noise: Vec<f64> = {
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            (0..lidar.columns * 32)
                .map(|_| normal.sample(&mut rng))
                .collect()
        };
        let scan = lidar
            .scan(
                &scene(vec![]),
                &Isometry2::new(Vector2::new(0.0, 0.0), 0.3),
                &car_sensor_mount(),
                |c, b| noise[c * 32 + b],
            )
            .unwrap();
        let stats = map.insert_scan(&scan, None).unwrap();
        assert_eq!(stats.hits, vec![0, 0], "seed {seed}");
        assert!(stats.free_cells[0] > 100_000);
    }
    map.update_distance_maps();
    for k in 0..2 {
        let grid = map.probability_grid(k).unwrap();
        assert!(
            grid.data().iter().all(|&v| v < 0.5),
            "level {k} has an obstacle cell"
        );
        assert!(
            grid.data().iter().filter(|&&v| v >= 0.0).count() > 30_000,
            "level {k}: ground seen as free"
        );
    }
}

/// N(0, 0.02) with rand only: Box-Muller over two uniforms.
fn rand_distr_normal() -> impl Distribution<f64> {
    struct Normal;
    impl Distribution<f64> for Normal {
        fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> f64 {
            let (u1, u2): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random());
            0.02 * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        }
    }
    Normal
}

#[test]
fn self_hits_are_dropped_only_for_the_parts_that_can_make_them() {
    // A "wing" board at 0.9-1.0 m, 1-2 m left of the sensor, and a cone under it.
    let wing = Solid::Box {
        min: [0.5, 1.0, 0.9].into(),
        max: [1.5, 2.0, 1.0].into(),
    };
    let cone = Solid::post(1.0, 1.5, 0.1, 0.45);
    let scene = scene(vec![wing, cone]);
    let model = CollisionModel::new(
        vec![
            Circle {
                x_m: 0.0,
                y_m: 0.0,
                radius_m: 0.5,
                level: 0,
            },
            Circle {
                x_m: 1.0,
                y_m: 1.5,
                radius_m: 0.7,
                level: 1,
            },
        ],
        vec![0.0, 0.7],
    )
    .unwrap();
    let config = MapConfig {
        self_hit_margin_m: 0.0,
        ..Default::default()
    };
    let mut map = MultiHeightMap::new(
        config,
        Levels::cumulative(vec![0.0, 0.7]).unwrap(),
        Point2::origin(),
    )
    .unwrap();
    let scan = scan_from(&scene, 0.0, 0.0);
    let stats = map.insert_scan(&scan, Some(&model)).unwrap();
    assert!(stats.self_hits > 0);
    assert!(
        p(&map, 1, 1.0, 1.5).is_none_or(|v| v < 0.5),
        "the wing is not mapped as an obstacle"
    );
    // Under the wing, the cone (below the wing's level height) is still seen.
    let mut without = MultiHeightMap::new(
        config,
        Levels::cumulative(vec![0.0, 0.7]).unwrap(),
        Point2::origin(),
    )
    .unwrap();
    without.insert_scan(&scan, None).unwrap();
    assert!(
        p(&without, 1, 1.2, 1.2).unwrap() > 0.5,
        "without the filter the wing is an obstacle"
    );
}

/// The coarse-to-fine free-space walks build the map the walk of every column builds - the same
/// obstacles, the same free and unknown cells but for a few dozen cells, the same probabilities
/// to a few thousandths - with fewer cell updates.
#[test]
fn coarse_to_fine_walks_map_what_every_column_maps_with_fewer_updates() {
    let scene = mapper::workloads::parking_lot_scene();
    let levels = || Levels::new(vec![0.0, 0.7], LevelMode::Cumulative, None).unwrap();
    let mut maps = [
        mapper::FreeSpaceWalks::EveryColumn,
        mapper::FreeSpaceWalks::CoarseToFine,
    ]
    .map(|walks| {
        let config = MapConfig {
            free_space_walks: walks,
            ..Default::default()
        };
        (
            MultiHeightMap::new(config, levels(), Point2::origin()).unwrap(),
            0usize,
        )
    });
    // A drive down the aisle, three revolutions from each stop.
    for i in 0..8 {
        let scan = scan_from(&scene, -35.0 + 10.0 * i as f64, -3.0);
        for _ in 0..3 {
            for (map, updates) in &mut maps {
                let stats = map.insert_scan(&scan, None).unwrap();
                *updates += stats.free_cells.iter().sum::<usize>();
            }
        }
    }
    let [(every, every_updates), (coarse, coarse_updates)] = &maps;
    for k in 0..2 {
        let (a, b) = (
            every.live_log_odds(k).unwrap(),
            coarse.live_log_odds(k).unwrap(),
        );
        // Unknown, free (p <= 0.5), occupied.
        let class = |l: f32| match l {
            l if l.is_nan() => 0,
            l if l > 0.0 => 2,
            _ => 1,
        };
        let (mut known, mut differ, mut occupied, mut occupied_differ) = (0, 0, 0, 0);
        let (mut both, mut gap) = (0, 0.0f64);
        for (&p, &q) in a.data().iter().zip(b.data()) {
            let (cp, cq) = (class(p), class(q));
            if cp != 0 && cq != 0 {
                both += 1;
                gap += (mapper::occupancy::probability(p) - mapper::occupancy::probability(q)).abs()
                    as f64;
            }
            known += usize::from(cp != 0 || cq != 0);
            differ += usize::from(cp != cq);
            occupied += usize::from(cp == 2 || cq == 2);
            occupied_differ += usize::from((cp == 2) != (cq == 2));
        }
        eprintln!(
            "level {k}: {known} known cells, {differ} classed differently; {occupied} occupied, \
             {occupied_differ} differ; mean |p - p'| {:.4} where both know the cell",
            gap / both as f64
        );
        assert!(known > 50_000, "level {k}: the drive maps the lot");
        assert!(
            (differ as f64) < 0.005 * known as f64,
            "level {k}: {differ} of {known} cells differ"
        );
        assert!(
            (occupied_differ as f64) < 0.02 * occupied as f64,
            "level {k}: {occupied_differ} of {occupied} occupied cells differ"
        );
        assert!(
            gap < 0.01 * both as f64,
            "level {k}: the free evidence agrees"
        );
    }
    eprintln!(
        "free-space cell updates: every column {every_updates}, coarse to fine {coarse_updates}"
    );
    assert!(
        (*coarse_updates as f64) < 0.7 * *every_updates as f64,
        "{coarse_updates} vs {every_updates} updates"
    );
}

#[test]
fn a_scan_with_a_bad_return_is_an_error_naming_its_column_and_beam() {
    let full = scan_from(&scene(vec![]), 0.0, 0.0);
    let beams = full.beams();
    // Past the first of the validation's chunks (64 columns), and the first bad one is named
    // even with a later one beside it.
    for (column, beam, bad) in [
        (1500, 7, ret([1.0, 2.0, 0.0], f32::NAN, 0.5)),
        (3, 0, ret([1.0, 2.0, 0.0], -1.0, 0.5)),
        (2186, 31, ret([0.0, f64::INFINITY, 0.0], 3.0, 0.5)),
    ] {
        let mut returns = full.returns().to_vec();
        returns[column * beams + beam] = Some(bad);
        let later = (column + 1).min(full.column_count() - 1) * beams + beam;
        if later != column * beams + beam {
            returns[later] = Some(ret([1.0, 2.0, 0.0], 3.0, f32::NAN));
        }
        let err = mapper::Scan::new(beams, full.columns().to_vec(), returns)
            .expect_err("a bad return is refused")
            .to_string();
        assert!(
            err.contains(&format!("column {column} beam {beam}:")),
            "{err}"
        );
    }
    // And a good scan is accepted as it is.
    let again = mapper::Scan::new(beams, full.columns().to_vec(), full.returns().to_vec()).unwrap();
    assert_eq!(again, full);
}

fn ret(point: [f64; 3], range_m: f32, intensity: f32) -> mapper::Return {
    mapper::Return {
        point_in_world: nalgebra::Point3::from(point),
        range_m,
        intensity,
    }
}

/// A sensor's self mask drops the returns of the rays that meet the vehicle, at the range they
/// meet it, and keeps what stands nearer along them: the cone under a "wing" board is mapped, the
/// board is not - where the circles' test with a margin wide enough for the board hides the
/// cone with it.
#[test]
fn a_self_mask_drops_the_airframe_and_keeps_the_cone_in_front_of_it() {
    let wing = Solid::Box {
        min: [4.0, 1.0, 0.9].into(),
        max: [5.0, 2.0, 1.0].into(),
    };
    let on_wing = |p: &nalgebra::Point3<f64>| {
        (3.95..=5.05).contains(&p.x) && (0.95..=2.05).contains(&p.y) && (0.85..=1.05).contains(&p.z)
    };
    // The mask: where each ray of the sensor meets the vehicle alone (the board).
    let vehicle_only = scan_from(&scene(vec![wing]), 0.0, 0.0);
    let ranges: Vec<Option<f64>> = vehicle_only
        .returns()
        .iter()
        .map(|r| {
            r.filter(|r| on_wing(&r.point_in_world))
                .map(|r| f64::from(r.range_m))
        })
        .collect();
    let mask = mapper::SelfMask::new(vehicle_only.beams(), &ranges, 0.1).unwrap();
    assert!(
        mask.rays_on_the_vehicle() > 50,
        "{}",
        mask.rays_on_the_vehicle()
    );
    // Beside the board, 1.5 m from its middle: within the margin below.
    let cone = Solid::post(4.5, 0.0, 0.1, 0.45);
    let scan = scan_from(&scene(vec![wing, cone]), 0.0, 0.0);
    let levels = || Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let mut masked = MultiHeightMap::new(MapConfig::default(), levels(), Point2::origin()).unwrap();
    let stats = masked.insert_scan_masked(&scan, None, Some(&mask)).unwrap();
    assert!(stats.self_hits > 50, "{}", stats.self_hits);
    assert!(p(&masked, 0, 4.5, 0.0).unwrap() > 0.5, "the cone is mapped");
    for (x, y) in [(4.1, 1.1), (4.9, 1.9), (4.5, 1.5)] {
        assert!(
            p(&masked, 1, x, y).is_none_or(|v| v < 0.5),
            "the board is not an obstacle at ({x}, {y})"
        );
    }
    // The circles' test (a circle of the ground level, as a gear's) with a margin that covers
    // the board hides the cone too.
    let model = CollisionModel::new(
        vec![Circle {
            x_m: 4.5,
            y_m: 1.5,
            radius_m: 0.5,
            level: 0,
        }],
        vec![0.0, 0.7],
    )
    .unwrap();
    let config = MapConfig {
        self_hit_margin_m: 1.5,
        ..Default::default()
    };
    let mut circles = MultiHeightMap::new(config, levels(), Point2::origin()).unwrap();
    circles.insert_scan(&scan, Some(&model)).unwrap();
    let mut unfiltered =
        MultiHeightMap::new(MapConfig::default(), levels(), Point2::origin()).unwrap();
    unfiltered.insert_scan(&scan, None).unwrap();
    assert!(
        p(&unfiltered, 1, 4.5, 1.5).unwrap() > 0.5,
        "unfiltered, the board is an obstacle"
    );
    assert!(
        p(&circles, 0, 4.5, 0.0).is_none_or(|v| v < 0.5),
        "hidden by the margin"
    );
    // A mask made for another sensor is refused.
    let other = mapper::SelfMask::new(16, &vec![None; 16 * 10], 0.1).unwrap();
    assert!(
        masked
            .insert_scan_masked(&scan, None, Some(&other))
            .is_err()
    );
}
