//! Scan insertion, levels, merge, window and block files, checked on analytic scenes.

use mapper::synthetic::{Lidar, Scene, Solid, car_sensor_mount};
use mapper::{Circle, CollisionModel, LevelMode, Levels, MapConfig, MergeMode, MultiHeightMap};
use nalgebra::{Isometry2, Point2, Vector2};
use rand::RngExt;
use rand::SeedableRng;
use rand::distr::Distribution;

fn scene(solids: Vec<Solid>) -> Scene {
    Scene {
        solids,
        ground_intensity: 0.3,
        solid_intensity: 0.8,
    }
}

fn scan_from(scene: &Scene, x: f64, y: f64) -> mapper::Scan {
    Lidar::hdl32e()
        .scan(
            scene,
            &Isometry2::new(Vector2::new(x, y), 0.0),
            &car_sensor_mount(),
            |_, _| 0.0,
        )
        .unwrap()
}

fn map_with(levels: Levels) -> MultiHeightMap {
    MultiHeightMap::new(MapConfig::default(), levels, Point2::origin()).unwrap()
}

fn p(level: &MultiHeightMap, k: usize, x: f64, y: f64) -> Option<f32> {
    level.probability_at(k, &Point2::new(x, y))
}

/// The highest known probability of a level within `r` metres of (x, y): obstacles are mapped
/// on their faces, so presence is tested around an object, not at its centre.
fn max_p_near(map: &MultiHeightMap, k: usize, x: f64, y: f64, r: f64) -> Option<f32> {
    let steps = (r / 0.1).ceil() as i64;
    let mut best: Option<f32> = None;
    for i in -steps..=steps {
        for j in -steps..=steps {
            let (dx, dy) = (i as f64 * 0.1, j as f64 * 0.1);
            if dx * dx + dy * dy <= r * r
                && let Some(v) = p(map, k, x + dx, y + dy)
            {
                best = Some(best.map_or(v, |b: f32| b.max(v)));
            }
        }
    }
    best
}

fn insert(map: &mut MultiHeightMap, scene: &Scene, times: usize) {
    let scan = scan_from(scene, 0.0, 0.0);
    for _ in 0..times {
        map.insert_scan(&scan, None).unwrap();
    }
}

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

#[test]
fn the_online_map_takes_unknown_cells_from_the_offline_map() {
    let dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    // Mapping drive: a parked box at (10, 0) and a pillar at (0, 10).
    let offline_scene = scene(vec![
        Solid::standing_box(10.0, 0.0, 1.0, 1.0, 1.5),
        Solid::post(0.0, 10.0, 0.3, 3.0),
    ]);
    let mut mapping = map_with(levels.clone());
    insert(&mut mapping, &offline_scene, 2);
    let store = mapper::BlockStore::open(dir.path(), mapping.block_spec().clone()).unwrap();
    assert!(mapping.save_live(&store).unwrap() > 0);

    // Online: the parked box left, a cone appeared at (5, 0); the pillar is hidden behind a wall.
    let online_scene = scene(vec![
        Solid::post(5.0, -3.0, 0.2, 0.45),
        Solid::Box {
            min: [-3.0, 5.0, 0.0].into(),
            max: [3.0, 5.2, 3.0].into(),
        },
    ]);
    let mut online = MultiHeightMap::with_stores(
        MapConfig::default(),
        levels,
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap();
    assert!(
        max_p_near(&online, 0, 10.0, 0.0, 0.7).unwrap() > 0.9,
        "before any scan the prior shows the parked box"
    );
    insert(&mut online, &online_scene, 2);
    assert!(
        max_p_near(&online, 0, 5.0, -3.0, 0.4).unwrap() > 0.9,
        "the new cone is in the online map"
    );
    assert!(
        max_p_near(&online, 0, 10.0, 0.0, 0.7).unwrap() < 0.5,
        "the box that left is seen free again"
    );
    assert!(
        max_p_near(&online, 0, 0.0, 10.0, 0.5).unwrap() > 0.9,
        "the hidden pillar comes from the offline map"
    );
    assert!(
        online
            .live_log_odds(0)
            .unwrap()
            .at(&Point2::new(0.0, 9.75))
            .unwrap()
            .is_nan(),
        "the live map never saw the pillar"
    );

    // Decay blend: a cell both know mixes 10:1 in probability.
    let mut decay = MultiHeightMap::with_stores(
        MapConfig {
            merge: MergeMode::Decay,
            ..Default::default()
        },
        Levels::cumulative(vec![0.0, 0.7]).unwrap(),
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap();
    insert(&mut decay, &online_scene, 2);
    let pb = max_p_near(&decay, 0, 10.0, 0.0, 0.7).unwrap();
    assert!(
        pb > 0.05 && pb < 0.5,
        "decay keeps a trace of the prior: {pb}"
    );
}

#[test]
fn recentring_saves_and_reloads_blocks_with_their_cells() {
    let live_dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let mut map = MultiHeightMap::with_stores(
        MapConfig::default(),
        levels,
        Point2::origin(),
        None,
        Some(live_dir.path()),
    )
    .unwrap();
    insert(
        &mut map,
        &scene(vec![Solid::standing_box(8.0, 3.0, 1.0, 1.0, 1.2)]),
        2,
    );
    let before = map.probability_grid(0).unwrap();
    let at = Point2::new(7.5, 3.0); // on the box's near face
    let p_before = map.probability_at(0, &at).unwrap();

    // One block east (past the re-centring margin): the window moves by 70 m, cells move with
    // their world positions.
    assert!(map.recenter(Point2::new(80.0, 0.0)).unwrap());
    assert_eq!(map.probability_at(0, &at), Some(p_before));
    // Far away: the whole window goes to disk.
    assert!(map.recenter(Point2::new(1000.0, 1000.0)).unwrap());
    assert_eq!(map.probability_at(0, &at), None);
    assert!(
        !map.recenter(Point2::new(1001.0, 1001.0)).unwrap(),
        "same middle block: no move"
    );
    // Back: every cell as it was.
    assert!(map.recenter(Point2::origin()).unwrap());
    assert_eq!(map.probability_grid(0).unwrap().data(), before.data());
}

#[test]
fn bad_block_files_are_errors_that_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let mut map = map_with(levels.clone());
    insert(&mut map, &scene(vec![Solid::post(4.0, 4.0, 0.3, 1.0)]), 1);
    let store = mapper::BlockStore::open(dir.path(), map.block_spec().clone()).unwrap();
    map.save_live(&store).unwrap();
    let index = mapper::BlockIndex { x: 0, y: 0 };
    let path = store.path(index);
    let good = std::fs::read(&path).unwrap();
    let loaded = store.load(index).unwrap().unwrap();
    let original = map
        .live_blocks()
        .into_iter()
        .find(|b| b.index == index)
        .unwrap();
    let bits = |b: &mapper::Block| {
        b.levels
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert!(
        bits(&loaded) == bits(&original) && loaded.remission == original.remission,
        "block round trip changed cells"
    );

    let open = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        let err = MultiHeightMap::with_stores(
            MapConfig::default(),
            levels.clone(),
            Point2::origin(),
            Some(dir.path()),
            None,
        )
        .unwrap_err();
        err.to_string()
    };
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 0x40;
    let e = open(&flipped);
    assert!(
        e.contains("block_0_0.tsmb") && e.contains("checksum"),
        "{e}"
    );
    let e = open(&good[..good.len() - 100]);
    assert!(
        e.contains("block_0_0.tsmb") && e.contains("truncated"),
        "{e}"
    );
    let e = open(&good[..20]);
    assert!(e.contains("block_0_0.tsmb"), "{e}");
    let e = open(b"");
    assert!(e.contains("block_0_0.tsmb") && e.contains("magic"), "{e}");
    // A block of the uncompressed format 1 is refused with the remedy.
    let mut v1 = good.clone();
    v1[8..12].copy_from_slice(&1u32.to_le_bytes());
    let e = open(&v1);
    assert!(
        e.contains("block_0_0.tsmb")
            && e.contains("format version 1")
            && e.contains("taxi-sim map"),
        "{e}"
    );
    // The compressed body is smaller than the block it holds.
    let side = map.block_spec().side;
    let raw = (4 * 2 + 12) * side * side;
    assert!(
        good.len() * 4 < raw,
        "{} bytes on disk for {raw}",
        good.len()
    );
    // A block of a map with other levels is refused by field name.
    std::fs::write(&path, &good).unwrap();
    let other = Levels::cumulative(vec![0.0, 0.5]).unwrap();
    let err = MultiHeightMap::with_stores(
        MapConfig::default(),
        other,
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("heights[1]"), "{err}");
}

/// A block whose checksum is valid but which holds a value no map writes (an infinite log-odds,
/// one beyond the clamp, a non-finite remission sum...) is refused, naming the file, the field,
/// the level and the cell; NaN log-odds (unknown) and values at the clamp still load.
#[test]
fn block_with_valid_checksum_and_non_finite_value_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let mut map = map_with(levels.clone());
    insert(&mut map, &scene(vec![Solid::post(4.0, 4.0, 0.3, 1.0)]), 1);
    let spec = map.block_spec().clone();
    let store = mapper::BlockStore::open(dir.path(), spec.clone()).unwrap();
    map.save_live(&store).unwrap();
    let index = mapper::BlockIndex { x: 0, y: 0 };
    let path = store.path(index);
    // A cell with remission samples (a ground return), so a zeroed count contradicts its sums.
    let original = map
        .live_blocks()
        .into_iter()
        .find(|b| b.index == index)
        .unwrap();
    let cell = original
        .remission
        .iter()
        .position(|r| r.count > 0 && r.sum != 0.0)
        .unwrap();
    let (row, column) = (cell / spec.side, cell % spec.side);
    // Writes the block with one value edited (and so a valid checksum) and loads it.
    let load = |edit: &dyn Fn(&mut mapper::Block)| {
        let mut block = original.clone();
        edit(&mut block);
        let bytes = mapper::blocks::encode_block(&spec, &block).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        store.load(index).map(|_| ()).map_err(|e| e.to_string())
    };
    let names = |e: &str, field: &str| {
        e.contains(&path.display().to_string())
            && e.contains(field)
            && e.contains(&format!("cell {cell} (row {row}, column {column})"))
    };
    let e = load(&|b| b.levels[1][cell] = f32::INFINITY).unwrap_err();
    assert!(
        names(&e, "`log_odds` of level 1") && e.contains("inf is infinite"),
        "{e}"
    );
    let e = load(&|b| b.levels[0][cell] = f32::NEG_INFINITY).unwrap_err();
    assert!(names(&e, "`log_odds` of level 0"), "{e}");
    let e = load(&|b| b.levels[0][cell] = 40.0).unwrap_err();
    assert!(
        names(&e, "`log_odds` of level 0") && e.contains("clamp") && e.contains("37"),
        "{e}"
    );
    let e = load(&|b| b.remission[cell].sum = f32::NAN).unwrap_err();
    assert!(names(&e, "`remission.sum`"), "{e}");
    let e = load(&|b| b.remission[cell].sum_sq = -1.0).unwrap_err();
    assert!(names(&e, "`remission.sum_sq`"), "{e}");
    let e = load(&|b| b.remission[cell].count = 0).unwrap_err();
    assert!(
        names(&e, "`remission.count`") && e.contains("0 samples"),
        "{e}"
    );
    // The map refuses to open over such a prior, naming the file too.
    load(&|b| b.levels[1][cell] = f32::INFINITY).unwrap_err();
    let err = MultiHeightMap::with_stores(
        MapConfig::default(),
        levels.clone(),
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(names(&err, "`log_odds` of level 1"), "{err}");
    // What a map can write still loads: unknown (NaN, any payload) and the clamp itself.
    load(&|b| b.levels[1][cell] = f32::from_bits(0x7fc0_1234)).unwrap();
    load(&|b| b.levels[1][cell] = -37.0).unwrap();
    load(&|b| b.levels[0][cell] = 37.0).unwrap();
}

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

/// A crossing vehicle: with CARMEN's walk rule the cells it left stay occupied for ever; with the
/// default rule the beams that now pass through them clear them.
#[test]
fn cells_an_obstacle_left_are_cleared_unless_walks_stop_at_any_occupied_cell() {
    let with_car = scene(vec![Solid::standing_box(10.0, 0.0, 1.8, 4.5, 1.5)]);
    let without = scene(vec![]);
    let face = Point2::new(9.15, 0.0);
    for (rule, cleared) in [
        (mapper::FreeSpaceStop::ScanHits, true),
        (mapper::FreeSpaceStop::AnyOccupied, false),
    ] {
        let config = MapConfig {
            free_space_stop: rule,
            ..Default::default()
        };
        let mut map = MultiHeightMap::new(
            config,
            Levels::cumulative(vec![0.0]).unwrap(),
            Point2::origin(),
        )
        .unwrap();
        insert(&mut map, &with_car, 3);
        assert!(
            map.probability_at(0, &face).unwrap() > 0.9,
            "{rule:?}: the car is mapped"
        );
        insert(&mut map, &without, 40);
        let p = map.probability_at(0, &face).unwrap();
        assert_eq!(p < 0.5, cleared, "{rule:?}: p = {p} after the car left");
    }
}

#[test]
fn occupancy_no_longer_seen_fades_to_the_prior_and_what_is_still_seen_stays() {
    // Two walls: one stays, one vanishes and is never looked at again (the sensor is told
    // nothing about it: scans of the scene with the wall are replaced by scans without any
    // return near it, as if the airframe hid it).
    let stays = Point2::new(9.15, 0.0);
    let hidden = Point2::new(-9.15, 0.0);
    let both = scene(vec![
        Solid::standing_box(10.0, 0.0, 1.8, 4.5, 1.5),
        Solid::standing_box(-10.0, 0.0, 1.8, 4.5, 1.5),
    ]);
    let one = scene(vec![Solid::standing_box(10.0, 0.0, 1.8, 4.5, 1.5)]);
    let mut map = map_with(Levels::cumulative(vec![0.0]).unwrap());
    insert(&mut map, &both, 3);
    assert!(map.probability_at(0, &hidden).unwrap() > 0.99);
    // Scans of `one` that keep only the returns ahead (x > 0): nothing crosses the hidden wall.
    let full = scan_from(&one, 0.0, 0.0);
    let returns = full
        .returns()
        .iter()
        .map(|r| r.filter(|r| r.point_in_world.x > 0.0))
        .collect();
    let ahead = mapper::Scan::new(full.beams(), full.columns().to_vec(), returns).unwrap();
    let tau = 2.0;
    let mut t = 0.0;
    let mut occupied_until = None;
    while t < 8.0 * tau {
        // Fade, then insert (as the closed loop does): what is seen again is refreshed.
        let changed = map.forget_unseen(Point2::origin(), 50.0, 0.1, tau);
        assert!(changed > 0, "both walls fade a little each time");
        map.insert_scan(&ahead, None).unwrap();
        t += 0.1;
        if occupied_until.is_none() && map.probability_at(0, &hidden).is_none_or(|p| p <= 0.5) {
            occupied_until = Some(t);
        }
        assert!(
            map.probability_at(0, &stays).unwrap() > 0.99,
            "t = {t:.1}: the wall still seen stays"
        );
    }
    // From saturation (log-odds 37) over an unknown prior (0) it never crosses one half by
    // fading, but is handed back (unknown) once within 0.05 of it: ln(37 / 0.05) = 6.6 time
    // constants.
    let gone = occupied_until.expect("the hidden wall is forgotten");
    assert!(
        gone > 6.0 * tau && gone < 7.0 * tau,
        "forgotten after {gone:.1} s"
    );
    assert_eq!(
        map.probability_at(0, &hidden),
        None,
        "handed back to the (unknown) prior"
    );
}

/// Forgetting visits a list of the cells that may be occupied instead of sweeping its square:
/// after hits, walks that clear cells, a prior, re-centring away and back (blocks saved and
/// reloaded) and squares that cut through obstacles, every cell equals the sweep of the square
/// done here by hand, and the counts agree.
#[test]
fn forgetting_changes_exactly_the_cells_a_sweep_of_its_square_changes() {
    let prior_dir = tempfile::tempdir().unwrap();
    let live_dir = tempfile::tempdir().unwrap();
    let levels = || Levels::cumulative(vec![0.0, 0.7]).unwrap();
    // The prior: a wall that will stay and a box that will be gone.
    let offline = scene(vec![
        Solid::standing_box(12.0, 0.0, 1.0, 6.0, 1.5),
        Solid::standing_box(-8.0, 4.0, 1.0, 1.0, 1.5),
    ]);
    let mut mapping = map_with(levels());
    insert(&mut mapping, &offline, 1);
    let store = mapper::BlockStore::open(prior_dir.path(), mapping.block_spec().clone()).unwrap();
    mapping.save_live(&store).unwrap();
    let mut map = MultiHeightMap::with_stores(
        MapConfig::default(),
        levels(),
        Point2::origin(),
        Some(prior_dir.path()),
        Some(live_dir.path()),
    )
    .unwrap();
    let with_cars = scene(vec![
        Solid::standing_box(12.0, 0.0, 1.0, 6.0, 1.5),
        Solid::standing_box(4.0, -6.0, 4.5, 1.8, 1.5),
        Solid::post(-5.0, -5.0, 0.2, 0.45),
    ]);
    let empty = scene(vec![Solid::standing_box(12.0, 0.0, 1.0, 6.0, 1.5)]);
    let (tau, dt) = (1.5, 0.1);
    let mut total_changed = 0;
    for step in 0..40 {
        // Cars and a cone for a while, then gone (walks lower the cells they showed), and as they
        // go a trip away and back: the cells behind their faces are reloaded occupied and only
        // forgetting lowers them.
        let world = if step < 10 { &with_cars } else { &empty };
        let x = -2.0 + 0.2 * step as f64;
        if step == 10 {
            assert!(map.recenter(Point2::new(500.0, 0.0)).unwrap());
            assert_eq!(map.forget_unseen(Point2::new(500.0, 0.0), 50.0, dt, tau), 0);
            assert!(map.recenter(Point2::new(x, 0.0)).unwrap());
        }
        map.insert_scan(&scan_from(world, x, 0.0), None).unwrap();
        // A square that moves and cuts through the cars: some occupied cells outside it.
        let (center, half_m) = (Point2::new(x + 3.0, 1.0), 6.0 + 0.1 * step as f64);
        let g = *map.geometry();
        let before: Vec<Vec<f32>> = (0..2)
            .map(|k| map.live_log_odds(k).unwrap().data().to_vec())
            .collect();
        let changed = map.forget_unseen(center, half_m, dt, tau);
        total_changed += changed;
        let keep = (-dt / tau).exp() as f32;
        let half = (half_m / g.resolution_m()).ceil() as i64;
        let (cx, cy) = g.cell_coords(&center);
        let (w, h) = (g.width() as i64, g.height() as i64);
        let mut expected_changed = 0;
        for (k, before) in before.iter().enumerate() {
            let prior = map.prior_log_odds(k).unwrap().data();
            let after = map.live_log_odds(k).unwrap().data();
            for (i, (&l, &got)) in before.iter().zip(after).enumerate() {
                let (x, y) = ((i as i64) % w, (i as i64) / w);
                let inside = (cx - half).clamp(0, w) <= x
                    && x < (cx + half).clamp(0, w)
                    && (cy - half).clamp(0, h) <= y
                    && y < (cy + half).clamp(0, h);
                let l_prior = if prior[i].is_nan() { 0.0 } else { prior[i] };
                let want = if inside && l > 0.0 && l > l_prior {
                    expected_changed += 1;
                    let faded = l_prior + (l - l_prior) * keep;
                    if faded <= 0.0 || faded - l_prior < 0.05 {
                        f32::NAN
                    } else {
                        faded
                    }
                } else {
                    l
                };
                assert!(
                    want.to_bits() == got.to_bits() || (want.is_nan() && got.is_nan()),
                    "step {step} level {k} cell ({x}, {y}): {l} -> {got}, the sweep gives {want}"
                );
            }
        }
        assert_eq!(changed, expected_changed, "step {step}");
    }
    assert!(total_changed > 1000, "{total_changed} cells faded in all");
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

/// A route along a block edge (the aerodrome's taxiway at y = 0) crosses it back and forth:
/// the window moves only once the position is `recenter_margin_m` past the middle block, in
/// any direction, and then centres on the block the position is in.
#[test]
fn the_window_moves_past_a_margin_not_at_every_crossing_of_a_block_edge() {
    let mut map = map_with(Levels::cumulative(vec![0.0]).unwrap());
    let margin = map.config().recenter_margin_m;
    assert_eq!(margin, 8.0);
    let lo = map.window_origin_block();
    // Middle block: [0, 70) x [0, 70). Zig-zag across y = 0 and x = 70, within the margin.
    for k in 0..40 {
        let wiggle = if k % 2 == 0 { -1.0 } else { 1.0 } * (0.05 + 0.19 * k as f64);
        for at in [
            Point2::new(30.0, wiggle),
            Point2::new(70.0 + wiggle, 30.0),
            Point2::new(-margin + 0.01, 70.0 + margin - 0.01),
        ] {
            assert!(!map.recenter(at).unwrap(), "{at:?}");
            assert_eq!(map.window_origin_block(), lo);
        }
    }
    // Just past the margin to the south: the window centres on the block below.
    assert!(map.recenter(Point2::new(30.0, -margin - 0.01)).unwrap());
    assert_eq!(
        (map.window_origin_block().x, map.window_origin_block().y),
        (lo.x, lo.y - 1)
    );
    // Back north across the edge, within the margin of the new middle block: stays.
    assert!(!map.recenter(Point2::new(30.0, margin - 0.01)).unwrap());
    assert!(map.recenter(Point2::new(30.0, margin + 0.01)).unwrap());
    assert_eq!(map.window_origin_block(), lo);
    // A margin over half a block is refused, naming the field.
    let config = MapConfig {
        recenter_margin_m: 36.0,
        ..MapConfig::default()
    };
    let err = config.validate().unwrap_err().to_string();
    assert!(err.contains("recenter_margin_m"), "{err}");
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
