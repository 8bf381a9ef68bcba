//! Overhead structures: the levels' ceiling (returns at or above it belong to no level) and the
//! cumulative rule for an overhang (a deck over the route is in every level it reaches).

use mapper::synthetic::{Lidar, Scene, Solid, car_sensor_mount};
use mapper::{InsertStats, LevelMode, Levels, MapConfig, MultiHeightMap};
use nalgebra::{Isometry2, Isometry3, Point2, Point3, Vector2};

fn scene(solids: Vec<Solid>) -> Scene {
    Scene {
        solids,
        ground_intensity: 0.3,
        solid_intensity: 0.8,
    }
}

/// A slab across the road (y -10 .. 10) between x0 and x1, from z0 to z1.
fn slab(x0: f64, x1: f64, z0: f64, z1: f64) -> Solid {
    Solid::Box {
        min: Point3::new(x0, -10.0, z0),
        max: Point3::new(x1, 10.0, z1),
    }
}

fn insert_from(
    map: &mut MultiHeightMap,
    scene: &Scene,
    mount: &Isometry3<f64>,
    x: f64,
) -> InsertStats {
    let scan = Lidar::hdl32e()
        .scan(
            scene,
            &Isometry2::new(Vector2::new(x, 0.0), 0.0),
            mount,
            |_, _| 0.0,
        )
        .unwrap();
    map.recenter(Point2::new(x, 0.0)).unwrap();
    map.insert_scan(&scan, None).unwrap()
}

/// Cells of level k with p > 0.5 in the rectangle x0..x1, y -10..10.
fn occupied(map: &MultiHeightMap, k: usize, x0: f64, x1: f64) -> usize {
    let mut n = 0;
    let mut x = x0;
    while x < x1 {
        let mut y = -10.0;
        while y < 10.0 {
            if map
                .probability_at(k, &Point2::new(x, y))
                .is_some_and(|p| p > 0.5)
            {
                n += 1;
            }
            y += 0.2;
        }
        x += 0.2;
    }
    n
}

/// The car's levels (ground and a 0.7 m wing) with a ceiling.
fn car_levels(ceiling_m: Option<f64>) -> Levels {
    Levels::new(vec![0.0, 0.7], LevelMode::Cumulative, ceiling_m).unwrap()
}

/// Drives the car's sensor (2.15 m) from x = -10 to 0 towards a slab at x 6 .. 9.
fn drive_car_to(scene: &Scene, levels: Levels) -> (MultiHeightMap, usize) {
    let mut map = MultiHeightMap::new(MapConfig::default(), levels, Point2::origin()).unwrap();
    let mut above = 0;
    for i in 0..=10 {
        above += insert_from(&mut map, scene, &car_sensor_mount(), -10.0 + i as f64).above_ceiling;
    }
    (map, above)
}

#[test]
fn a_canopy_above_the_ceiling_is_in_no_level_and_without_a_ceiling_in_every_level() {
    // A canopy 2.8 m up; the car's top is 2.22 m, its ceiling 2.62 m.
    let canopy = scene(vec![slab(6.0, 9.0, 2.8, 3.0)]);
    let (map, above) = drive_car_to(&canopy, car_levels(Some(2.62)));
    assert!(above > 1000, "returns dropped above the ceiling: {above}");
    for k in 0..2 {
        assert_eq!(occupied(&map, k, 6.0, 9.0), 0, "level {k}: canopy mapped");
    }
    // The same drive with no ceiling maps the canopy as an obstacle in both levels: what stopped
    // the car under it.
    let (map, above) = drive_car_to(&canopy, car_levels(None));
    assert_eq!(above, 0);
    for k in 0..2 {
        let n = occupied(&map, k, 6.0, 9.0);
        assert!(n > 100, "level {k}: canopy cells without a ceiling: {n}");
    }
}

#[test]
fn a_bar_whose_underside_is_below_the_ceiling_is_an_obstacle_in_every_level() {
    // A bar 1.9 .. 2.1 m up, under the car's ceiling (2.62 m) but over its 0.7 m wing level.
    let bar = scene(vec![slab(6.0, 6.4, 1.9, 2.1)]);
    let (map, above) = drive_car_to(&bar, car_levels(Some(2.62)));
    assert_eq!(above, 0, "nothing above the ceiling");
    for k in 0..2 {
        let n = occupied(&map, k, 5.8, 6.6);
        assert!(n > 20, "level {k}: bar cells: {n}");
    }
}

#[test]
fn a_bridge_straddling_the_ceiling_is_mapped_from_what_lies_below_it() {
    // A deck 2.5 .. 3.5 m: its underside (and face) below the 2.62 m ceiling is an obstacle.
    let deck = scene(vec![slab(6.0, 9.0, 2.5, 3.5)]);
    let (map, above) = drive_car_to(&deck, car_levels(Some(2.62)));
    assert!(above > 0);
    for k in 0..2 {
        let n = occupied(&map, k, 6.0, 9.0);
        assert!(n > 20, "level {k}: deck cells: {n}");
    }
}

#[test]
fn a_ceiling_at_or_below_the_top_level_is_an_error() {
    let e = Levels::new(vec![0.0, 1.1], LevelMode::Cumulative, Some(1.0)).unwrap_err();
    assert!(e.to_string().contains("ceiling_m"), "{e}");
}

/// The cumulative rule for an overhang: a deck over the route, seen from a jet's nose sensor
/// (1.55 m, just above h_1 = 1.1 m) as it drives under it, is in level 1 wherever it is in
/// level 0. Beams passing under the deck are no evidence it has gone: a beam clears an occupied
/// cell only where it crosses the span of heights its obstacle was hit at. Under the older
/// rule (a beam lower than h_k + 0.2 m clears level k) beams between 0.2 m and 1.3 m cleared
/// the deck from level 1 only: 63 deck cells in level 1 against 2693 in level 0.
#[test]
fn a_deck_over_the_route_stays_in_every_level() {
    let deck = scene(vec![slab(30.0, 36.0, 6.0, 7.0)]);
    let mount = Isometry3::translation(11.85, 0.0, 1.55);
    let levels = Levels::new(vec![0.0, 1.1], LevelMode::Cumulative, None).unwrap();
    let mut map = MultiHeightMap::new(MapConfig::default(), levels, Point2::origin()).unwrap();
    // From 58 m before the deck until the sensor is 6 m past it, seeing ahead only (the jet's
    // body hides what is behind its nose sensor).
    for i in 0..140 {
        let x = -40.0 + i as f64 * 0.5;
        let scan = Lidar::hdl32e()
            .scan(
                &deck,
                &Isometry2::new(Vector2::new(x, 0.0), 0.0),
                &mount,
                |_, _| 0.0,
            )
            .unwrap();
        let returns = scan
            .returns()
            .chunks(scan.beams())
            .enumerate()
            .flat_map(|(c, column)| {
                let ahead =
                    (c as f64 / scan.column_count() as f64 * std::f64::consts::TAU).cos() > 0.0;
                column.iter().map(move |r| r.filter(|_| ahead))
            })
            .collect();
        let scan = mapper::Scan::new(scan.beams(), scan.columns().to_vec(), returns).unwrap();
        map.recenter(Point2::new(x, 0.0)).unwrap();
        map.insert_scan(&scan, None).unwrap();
    }
    let (l0, l1) = (occupied(&map, 0, 30.0, 36.0), occupied(&map, 1, 30.0, 36.0));
    assert!(l0 > 2000, "deck cells in level 0: {l0}");
    assert_eq!(l1, l0, "deck cells: level 1 {l1}, level 0 {l0}");
}
