//! Open tops: how high a hit object may reach where the sensor cannot see, from the beam above
//! its top hit in each column (`MultiHeightMap::last_scan_open_tops`). The jet's nose sensor,
//! 1.55 m up, sees a 1.5 m van at 28 m only below 1.1 m (its 0-degree beam passes over the
//! roof), and a 1.0 m baggage cart at 10 m with the beam above passing over it at 1.08 m.

use mapper::synthetic::{Lidar, Scene, Solid};
use mapper::{LevelMode, Levels, MapConfig, MultiHeightMap};
use nalgebra::{Isometry2, Isometry3, Point2, Point3, Vector2};

/// The Praetor-like jet's levels (ground and the wings' 1.1 m), its 7.0 m ceiling.
fn jet_levels() -> Levels {
    Levels::new(vec![0.0, 1.1], LevelMode::Cumulative, Some(7.0)).unwrap()
}

/// One revolution of `solids` from a sensor 1.55 m up at the origin; the map's open tops of
/// the cells within the box `lo`..`hi` (x, y), and its level-1 hits there.
fn open_tops_in(solids: Vec<Solid>, lo: [f64; 2], hi: [f64; 2]) -> (Vec<f32>, usize) {
    let scene = Scene {
        solids,
        ground_intensity: 0.3,
        solid_intensity: 0.8,
    };
    let scan = Lidar::hdl32e()
        .scan(
            &scene,
            &Isometry2::new(Vector2::zeros(), 0.0),
            &Isometry3::translation(0.0, 0.0, 1.55),
            |_, _| 0.0,
        )
        .unwrap();
    let mut map =
        MultiHeightMap::new(MapConfig::default(), jet_levels(), Point2::origin()).unwrap();
    map.insert_scan(&scan, None).unwrap();
    let r = map.config().resolution_m;
    let inside = |(x, y): (i64, i64)| {
        let (x, y) = ((x as f64 + 0.5) * r, (y as f64 + 0.5) * r);
        (lo[0]..=hi[0]).contains(&x) && (lo[1]..=hi[1]).contains(&y)
    };
    let tops = map
        .last_scan_open_tops()
        .into_iter()
        .filter(|&(c, _)| inside(c))
        .map(|(_, t)| t)
        .collect();
    let level1 = map
        .last_scan_hits_by_level()
        .into_iter()
        .filter(|&(c, l)| inside(c) && l & 2 != 0)
        .count();
    (tops, level1)
}

/// A box on the ground, `x0` nearest the sensor, centred on y = 0.
fn vehicle(x0: f64, length: f64, width: f64, height: f64) -> Solid {
    Solid::Box {
        min: Point3::new(x0, -0.5 * width, 0.0),
        max: Point3::new(x0 + length, 0.5 * width, height),
    }
}

#[test]
fn a_van_seen_only_low_may_reach_the_wing_level() {
    // 28 m out the -1.33-degree beam hits the van's side at 0.9 m, the 0-degree beam passes
    // over its 1.5 m roof: no hit in level 1, but its top may reach 1.55 m. A building behind
    // the sensor gives the 0-degree beam an echo, so its elevation is known.
    let van = vehicle(28.0, 4.5, 1.8, 1.5);
    let building = Solid::standing_box(-60.0, 0.0, 10.0, 40.0, 9.0);
    let (tops, level1) = open_tops_in(vec![van, building], [27.5, -1.5], [33.0, 1.5]);
    assert_eq!(level1, 0, "hit in the wing level");
    let highest = tops.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert!((1.5..=1.56).contains(&highest), "{tops:?}");
    // Without it, no echo of the 0-degree beam anywhere says where it went: the top is unknown.
    let (tops, _) = open_tops_in(vec![van], [27.5, -1.5], [33.0, 1.5]);
    assert!(
        !tops.is_empty() && tops.iter().all(|t| *t == f32::INFINITY),
        "{tops:?}"
    );
}

#[test]
fn a_cart_seen_at_ten_metres_stays_below_the_wing_level() {
    // At 10 m the -2.67-degree beam passes over the 1.0 m cart at 1.08 m: below the 1.1 m level.
    let (tops, level1) = open_tops_in(vec![vehicle(10.0, 1.2, 1.0, 1.0)], [9.5, -1.0], [11.5, 1.0]);
    assert_eq!(level1, 0);
    assert!(!tops.is_empty());
    let highest = tops.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert!((1.0..1.1).contains(&highest), "{tops:?}");
}

#[test]
fn a_van_whose_beams_above_are_stopped_nearer_has_an_unknown_top() {
    // A plate 1.5-1.6 m up at 10 m (a wing's stand-in) stops the 0-degree beams toward the van;
    // the -1.33-degree beams pass under it and hit the van: its top is unknown.
    let plate = Solid::Box {
        min: Point3::new(10.0, -3.0, 1.5),
        max: Point3::new(11.0, 3.0, 1.6),
    };
    let (tops, _) = open_tops_in(
        vec![vehicle(28.0, 4.5, 1.8, 1.5), plate],
        [27.5, -1.0],
        [33.0, 1.0],
    );
    assert!(!tops.is_empty());
    assert!(tops.iter().all(|t| t.is_infinite() && *t > 0.0), "{tops:?}");
}
