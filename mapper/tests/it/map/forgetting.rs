//! Forgetting: the cells an obstacle left cleared by the beams through them (unless walks stop at
//! any occupied cell), and occupancy no longer seen fading to the prior.

use super::{insert, map_with, scan_from, scene};
use mapper::synthetic::Solid;
use mapper::{Levels, MapConfig, MultiHeightMap};
use nalgebra::Point2;

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

/// An object hit only at and above the sensor's height (a fuel truck's tank seen from a nose
/// sensor, its chassis hidden): in the open, the only beams through where it was hit have no
/// echo. They clear its cells within 30 m once it has gone - a trail held the jet for good
/// before, as it does with them turned off - and not beyond (a far echo-less beam is no
/// evidence).
#[test]
fn cells_hit_only_above_the_sensor_are_cleared_in_the_open_by_beams_with_no_echo_within_30_m() {
    let mount_z = mapper::synthetic::car_sensor_mount().translation.z;
    let tank = |x: f64| Solid::Box {
        min: nalgebra::Point3::new(x - 0.9, -2.0, mount_z + 0.05),
        max: nalgebra::Point3::new(x + 0.9, 2.0, mount_z + 1.0),
    };
    for (x, no_echo_m, cleared) in [
        (10.0, 30.0, true),
        (25.0, 30.0, true),
        (40.0, 30.0, false),
        (10.0, 0.0, false),
    ] {
        let config = MapConfig {
            no_echo_clears_within_m: no_echo_m,
            ..Default::default()
        };
        let levels = Levels::cumulative(vec![0.0, 1.1]).unwrap();
        let mut map = MultiHeightMap::new(config, levels, Point2::origin()).unwrap();
        insert(&mut map, &scene(vec![tank(x)]), 3);
        let face = Point2::new(x - 0.85, 0.0);
        for k in 0..2 {
            assert!(
                map.probability_at(k, &face).unwrap() > 0.9,
                "tank at {x} m, level {k}: mapped"
            );
        }
        insert(&mut map, &scene(vec![]), 40);
        for k in 0..2 {
            let p = map.probability_at(k, &face).unwrap();
            assert_eq!(
                p < 0.5,
                cleared,
                "tank at {x} m, no echo within {no_echo_m} m, level {k}: p = {p} after it left"
            );
        }
    }
}

/// A beam with no echo counts as a look into the open only where the same beam of both
/// neighbouring columns has no echo either. A tank hit only above the sensor is mapped; then a
/// wing the map masks as the vehicle's own (a `SelfMask`) hides it, and every other column's
/// beams on the wing are dropped, as a random drop-out takes them: beside their neighbours'
/// echoes they are no look through the wing into the open, so no walk lowers the tank's face,
/// which this revolution does not see (a parked jet's wing was lowered so before the rule).
/// The same beams dropped in every column are a look into the open: the face is lowered.
#[test]
fn a_beam_with_no_echo_beside_echoes_is_no_look_past_what_it_would_have_hit() {
    let mount_z = mapper::synthetic::car_sensor_mount().translation.z;
    let slab = |x0: f64, x1: f64, z0: f64, z1: f64| Solid::Box {
        min: nalgebra::Point3::new(x0, -3.0, mount_z + z0),
        max: nalgebra::Point3::new(x1, 3.0, mount_z + z1),
    };
    let tank = slab(9.1, 10.9, 0.05, 1.0);
    let wing = slab(3.0, 3.5, 0.02, 0.7);
    let hidden = scan_from(&scene(vec![tank, wing]), 0.0, 0.0);
    let beams = hidden.beams();
    let on_wing = |r: &mapper::Return| r.point_in_world.x < 3.6 && r.point_in_world.z > mount_z;
    let mask_ranges: Vec<Option<f64>> = hidden
        .returns()
        .iter()
        .map(|r| r.filter(|r| on_wing(r)).map(|r| f64::from(r.range_m)))
        .collect();
    let wing_hits = mask_ranges.iter().flatten().count();
    assert!(wing_hits > 200, "the wing is seen: {wing_hits} returns");
    let mask = mapper::SelfMask::new(beams, &mask_ranges, 0.05).unwrap();
    // The wing's returns dropped in the columns `drop(column)` picks.
    let dropped = |drop: &dyn Fn(usize) -> bool| {
        let returns = hidden
            .returns()
            .iter()
            .enumerate()
            .map(|(i, r)| r.filter(|r| !(drop(i / beams) && on_wing(r))))
            .collect();
        mapper::Scan::new(beams, hidden.columns().to_vec(), returns).unwrap()
    };
    let face = Point2::new(9.15, 0.0);
    for (every_other, lowered) in [(true, false), (false, true)] {
        let levels = Levels::cumulative(vec![0.0, 1.1]).unwrap();
        let mut map = MultiHeightMap::new(MapConfig::default(), levels, Point2::origin()).unwrap();
        insert(&mut map, &scene(vec![tank]), 3);
        let before: Vec<f32> = (0..2)
            .map(|k| map.probability_at(k, &face).unwrap())
            .collect();
        assert!(
            before.iter().all(|&p| p > 0.9),
            "the tank is mapped: {before:?}"
        );
        let scan = if every_other {
            dropped(&|c| c % 2 == 1)
        } else {
            dropped(&|_| true)
        };
        for _ in 0..20 {
            map.insert_scan_masked(&scan, None, Some(&mask)).unwrap();
        }
        for (k, &was) in before.iter().enumerate() {
            let now = map.probability_at(k, &face);
            assert_eq!(
                now.is_none_or(|p| p < was),
                lowered,
                "every other column dropped: {every_other}, level {k}: face p {was} -> {now:?}"
            );
        }
    }
}
