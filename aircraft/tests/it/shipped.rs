//! The shipped vehicles: their geometry matches FACTS.md, and their fitted models cover them
//! totally, land near CARMEN's car / the thesis' jet, and are deterministic.

use crate::common;

use aircraft::{FitOptions, SHIPPED_VEHICLES, Vehicle, evaluate};
use nalgebra::Point2;

fn extents(v: &Vehicle) -> (Point2<f64>, Point2<f64>) {
    let mut lo = Point2::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in &v.parts {
        let (a, b) = p.footprint().bounds();
        lo = lo.inf(&a);
        hi = hi.sup(&b);
    }
    (lo, hi)
}

fn part<'a>(v: &'a Vehicle, link: &str, index: usize) -> &'a aircraft::Part {
    v.parts
        .iter()
        .find(|p| p.link == link && p.collision_index == index)
        .unwrap_or_else(|| panic!("no part {link}#{index}"))
}

#[test]
fn every_shipped_vehicle_loads_from_its_files_as_compiled_in() {
    for name in SHIPPED_VEHICLES {
        let shipped = Vehicle::shipped(name).expect("shipped vehicle loads");
        let path = format!("{}/vehicles/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let from_file = Vehicle::from_file(std::path::Path::new(&path)).expect("from file");
        assert_eq!(shipped, from_file, "{name}");
        assert_eq!(shipped.spec.name, name);
        assert_eq!(Vehicle::load(&path).expect("load by path"), shipped);
    }
    // A bare name that is neither shipped nor a file: the error lists the shipped names.
    match Vehicle::load("cessna") {
        Err(aircraft::Error::UnknownVehicle { name, known }) => {
            assert_eq!(name, "cessna");
            assert!(
                known.contains("praetor600") && known.contains("iara_car_fake_wing"),
                "{known}"
            );
        }
        other => panic!("expected UnknownVehicle, got {other:?}"),
    }
    // A path that does not exist: an I/O error naming it.
    assert!(matches!(
        Vehicle::load("no/such/vehicle.toml"),
        Err(aircraft::Error::Io { .. })
    ));
    assert!(matches!(
        Vehicle::shipped("cessna"),
        Err(aircraft::Error::UnknownVehicle { .. })
    ));
}

#[test]
fn car_geometry_matches_the_ford_escape() {
    let car = Vehicle::shipped("iara_car").expect("car");
    let (lo, hi) = extents(&car);
    assert!((hi.x - lo.x - 4.425).abs() < 1e-9, "length {}", hi.x - lo.x);
    assert!((lo.x + 0.96).abs() < 1e-9, "rear overhang {}", -lo.x);
    assert!((hi.y - lo.y - 1.806).abs() < 1e-9);
    let wheel = part(&car, "wheel_front_right", 0);
    let t = wheel.vehicle_from_part.translation.vector;
    assert!((t.x - 2.625).abs() < 1e-12 && (t.y + 0.7675).abs() < 1e-12);
    assert!(wheel.underside_m().abs() < 1e-9, "wheels touch the ground");
    // The velodyne sits 2.15 m above the ground, through a three-joint chain.
    let velodyne = part(&car, "velodyne", 0);
    assert!((velodyne.vehicle_from_part.translation.vector.z - 2.15).abs() < 1e-9);
    assert!((car.spec.lidar.xyz_m[2] - 2.15).abs() < 1e-12);
    assert_eq!(car.spec.motion.steering, aircraft::Steering::FrontWheels);
    assert!((car.spec.motion.max_steering_angle_rad - 0.5537).abs() < 1e-12);
    assert_eq!(car.spec.heights_of_interest_m, vec![0.0]);
}

#[test]
fn fake_wing_is_a_board_at_0_7_m_one_metre_beyond_the_right_side() {
    let v = Vehicle::shipped("iara_car_fake_wing").expect("fake wing");
    let wing = part(&v, "fake_wing", 0);
    assert!((wing.underside_m() - 0.7).abs() < 1e-9);
    let (lo, hi) = wing.footprint().bounds();
    assert!((lo.y + 0.903 + 1.0).abs() < 1e-9, "reaches y = {}", lo.y);
    assert!(hi.y > -0.903, "attached to the body");
    assert!(lo.x < 3.4 && hi.x > 3.4);
    assert_eq!(v.spec.heights_of_interest_m, vec![0.0, 0.7]);
}

#[test]
fn praetor_geometry_is_plausible() {
    let jet = Vehicle::shipped("praetor600").expect("jet");
    let (lo, hi) = extents(&jet);
    assert!((hi.x - lo.x - 20.7).abs() < 0.3, "length {}", hi.x - lo.x);
    assert!((hi.y - lo.y - 21.5).abs() < 0.3, "span {}", hi.y - lo.y);
    let fuselage = part(&jet, "fuselage", 0);
    assert!((fuselage.underside_m() - 0.6).abs() < 1e-9);
    let root = part(&jet, "wing_left", 0);
    assert!((root.underside_m() - 1.2).abs() < 1e-9);
    let tip = part(&jet, "wing_right", 2);
    assert!(tip.underside_m() > root.underside_m() + 0.3, "dihedral");
    let stab = part(&jet, "stabiliser", 0);
    assert!(
        (stab.underside_m() - 6.0).abs() < 0.3,
        "T-tail at {}",
        stab.underside_m()
    );
    let top = jet.parts.iter().map(|p| p.top_m()).fold(0.0, f64::max);
    assert!((top - 6.5).abs() < 0.4, "height {top}");
    assert_eq!(jet.spec.motion.steering, aircraft::Steering::NoseWheel);
    assert!((jet.spec.motion.wheelbase_m - 8.0).abs() < 1e-12);
    let nose_wheel = part(&jet, "nose_gear", 0);
    assert!((nose_wheel.vehicle_from_part.translation.vector.x - 8.0).abs() < 1e-12);
    // Levels: gears and cabin at 0; wings, engines and tail at 1.
    let h = &jet.spec.heights_of_interest_m;
    let level =
        |link: &str, i: usize| aircraft::fit::level_of(part(&jet, link, i).underside_m(), h);
    assert_eq!(level("fuselage", 0), 0);
    assert_eq!(level("main_gear_left", 0), 0);
    assert_eq!(level("nose", 1), 0);
    assert_eq!(level("wing_left", 0), 1);
    assert_eq!(level("nacelle_right", 0), 1);
    assert_eq!(level("stabiliser", 1), 1);
}

#[test]
fn shipped_fits_cover_every_part() {
    for name in SHIPPED_VEHICLES {
        let v = Vehicle::shipped(name).expect("vehicle");
        for options in [
            v.spec.fit.clone(),
            FitOptions::default(),
            FitOptions {
                max_overshoot_m: Some(0.3),
                ..FitOptions::default()
            },
        ] {
            let fit = v
                .fit_with(&v.spec.heights_of_interest_m, &options)
                .expect("fit");
            assert_eq!(
                common::uncovered_point(&fit, 60),
                None,
                "{name} {options:?}"
            );
            for r in evaluate(&fit, 300) {
                assert_eq!(r.coverage, 1.0, "{name} level {}", r.level);
            }
        }
    }
}

#[test]
fn car_fit_lands_on_carmens_car() {
    // CARMEN bin/ford_escape/ford_escape_col.txt: 5 circles, r = 1.0, y = 0, spaced 0.967 m.
    let carmen_x = [-0.76, 0.207, 1.174, 2.141, 3.108];
    let car = Vehicle::shipped("iara_car").expect("car");
    let fit = car.fit().expect("fit");
    let circles = fit.model.circles();
    assert_eq!(circles.len(), 5);
    for (c, x) in circles.iter().zip(carmen_x) {
        assert_eq!(c.level, 0);
        assert!(c.y_m.abs() < 1e-9);
        assert!((c.radius_m - 1.0).abs() < 0.01, "r = {}", c.radius_m);
        assert!((c.x_m - x).abs() < 0.25, "x = {} vs {x}", c.x_m);
    }
    // A budget of 3 gives fewer, larger circles; still total coverage.
    let three = car
        .fit_with(
            &[0.0],
            &FitOptions {
                max_circles: Some(3),
                ..FitOptions::default()
            },
        )
        .expect("fit");
    assert!(three.model.circles().len() <= 3);
    assert_eq!(common::uncovered_point(&three, 60), None);
}

#[test]
fn fake_wing_gets_a_few_small_level_1_circles() {
    let v = Vehicle::shipped("iara_car_fake_wing").expect("fake wing");
    let fit = v.fit().expect("fit");
    let wing: Vec<_> = fit
        .model
        .circles()
        .iter()
        .filter(|c| c.level == 1)
        .collect();
    assert!((2..=6).contains(&wing.len()), "{} wing circles", wing.len());
    for c in &wing {
        assert!(c.radius_m < 0.3, "r = {}", c.radius_m);
        assert!((c.x_m - 3.4).abs() < 0.2);
        assert!(c.y_m < -0.7 && c.y_m > -2.0);
    }
    // The cabin (underside 1.0 m) lies over the body: left to level 0, no level-1 circles.
    assert!(fit.levels[1].below.len() >= 2);
}

#[test]
fn jet_fit_has_tens_of_varied_circles_and_is_deterministic() {
    let jet = Vehicle::shipped("praetor600").expect("jet");
    let fit = jet.fit().expect("fit");
    let n = fit.model.circles().len();
    assert!((20..=62).contains(&n), "{n} circles");
    let radii: Vec<f64> = fit.model.circles().iter().map(|c| c.radius_m).collect();
    let (min, max) = radii
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(*r), b.max(*r)));
    assert!(max > 2.0 * min, "radii {min}..{max}");
    for k in 0..2 {
        assert!(fit.model.circles().iter().any(|c| c.level == k));
    }
    let direct = aircraft::fit_parts(&jet.parts, &jet.spec.heights_of_interest_m, &jet.spec.fit);
    assert_eq!(direct.expect("fit without the memo"), fit);
    // More circles, tighter: the overshoot falls.
    let loose = evaluate(&fit, 200);
    let tight_fit = jet
        .fit_with(
            &[0.0, 1.1],
            &FitOptions {
                max_circles: Some(150),
                ..FitOptions::default()
            },
        )
        .expect("fit");
    let tight = evaluate(&tight_fit, 200);
    for (a, b) in loose.iter().zip(&tight) {
        assert!(b.area_ratio < a.area_ratio, "level {}", a.level);
    }
}

/// The fits a vehicle keeps answer as fitting anew, whatever the order they are asked in: other
/// heights, other options and another vehicle's parts each get their own fit, and more fits than
/// are kept (the oldest then fitted again) too.
#[test]
fn kept_fits_answer_as_fitting_anew() {
    let jet = Vehicle::shipped("praetor600").expect("jet");
    let car = Vehicle::shipped("iara_car_fake_wing").expect("car");
    let banded = FitOptions {
        banded_maps: true,
        ..jet.spec.fit.clone()
    };
    let budget = |n| FitOptions {
        max_circles: Some(n),
        ..FitOptions::default()
    };
    let mut asks: Vec<(&Vehicle, Vec<f64>, FitOptions)> = vec![
        (&jet, vec![0.0, 1.1], jet.spec.fit.clone()),
        (&jet, vec![0.0, 1.1], banded.clone()),
        (&jet, vec![0.0, 1.3], jet.spec.fit.clone()),
        (&car, vec![0.0, 1.1], jet.spec.fit.clone()),
    ];
    asks.extend((0..aircraft::FIT_MEMO_SIZE).map(|i| (&car, vec![0.0], budget(8 + i))));
    let firsts: Vec<_> = asks.iter().take(4).cloned().collect();
    asks.extend(firsts.iter().cloned().rev());
    let mut distinct = Vec::new();
    for (v, heights, options) in &asks {
        let kept = v.fit_with(heights, options).expect("fit");
        let anew = aircraft::fit_parts(&v.parts, heights, options).expect("fit anew");
        assert_eq!(kept, anew, "{heights:?} {options:?}");
        if !distinct.contains(&kept.model) {
            distinct.push(kept.model);
        }
    }
    assert!(
        distinct.len() >= 12,
        "the asks give different fits: {}",
        distinct.len()
    );
}

#[test]
fn overshoot_target_is_met_when_reachable() {
    let car = Vehicle::shipped("iara_car").expect("car");
    let fit = car
        .fit_with(
            &[0.0],
            &FitOptions {
                max_overshoot_m: Some(0.2),
                ..FitOptions::default()
            },
        )
        .expect("fit");
    assert!(fit.overshoot_target_met);
    let r = &evaluate(&fit, 400)[0];
    assert!(r.max_overshoot_m <= 0.2 + 1e-3, "{}", r.max_overshoot_m);
}

#[test]
fn svg_has_one_group_per_level_and_every_circle() {
    let v = Vehicle::shipped("iara_car_fake_wing").expect("fake wing");
    let fit = v.fit().expect("fit");
    let svg = aircraft::svg::to_svg(&fit, "fake <wing>");
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains(r#"<g id="level-0">"#) && svg.contains(r#"<g id="level-1">"#));
    assert!(svg.contains("fake &lt;wing&gt;"));
    assert_eq!(
        svg.matches(r#"fill="none""#).count(),
        fit.model.circles().len()
    );
}

#[test]
fn every_shipped_vehicle_has_its_top_and_a_ceiling_0_4_m_above_it() {
    // (name, top: the highest point of a collision part, m)
    for (name, top) in [
        // The Velodyne on the roof board: 1.72 + 0.43 + 0.144 / 2.
        ("iara_car", 2.222),
        ("iara_car_fake_wing", 2.222),
        // The T-tail's stabiliser on top of the fin.
        ("praetor600", 6.6043),
        // The fin's top.
        ("a320", 11.8),
    ] {
        let v = Vehicle::shipped(name).unwrap();
        assert!((v.top_m() - top).abs() < 1e-4, "{name}: top {}", v.top_m());
        assert_eq!(
            v.spec.overhead_clearance_m,
            aircraft::DEFAULT_OVERHEAD_CLEARANCE_M
        );
        assert!(
            (v.ceiling_m() - (top + 0.4)).abs() < 1e-4,
            "{name}: ceiling {}",
            v.ceiling_m()
        );
    }
}

/// The A320-like airliner's three levels hold what they are for: the gear at the ground level,
/// the underwing nacelles (underside 0.6 m) and the fuselage at 0.55 m, the wings, pylons and
/// tail at 2.1 m; its default fit covers every level.
#[test]
fn the_airliner_has_its_gear_nacelles_and_wings_on_three_levels() {
    let v = Vehicle::shipped("a320").unwrap();
    let heights = v.spec.heights_of_interest_m.clone();
    assert_eq!(heights, vec![0.0, 0.55, 2.1]);
    let level = |link: &str| -> Vec<usize> {
        v.parts
            .iter()
            .filter(|p| p.link == link)
            .map(|p| aircraft::fit::level_of(p.underside_m(), &heights))
            .collect()
    };
    for (link, want) in [
        ("nose_gear", 0),
        ("main_gear_left", 0),
        ("main_gear_right", 0),
        ("nacelle_left", 1),
        ("nacelle_right", 1),
        ("fuselage", 1),
        ("wing_left", 2),
        ("wing_right", 2),
        ("fin", 2),
    ] {
        let levels = level(link);
        assert!(!levels.is_empty(), "{link}: no part");
        assert!(
            levels.iter().all(|&l| l == want),
            "{link}: levels {levels:?}"
        );
    }
    let fit = v.fit().unwrap();
    for r in evaluate(&fit, aircraft::report::DEFAULT_SAMPLES_PER_AXIS) {
        assert_eq!(r.coverage, 1.0, "{r:?}");
    }
}

#[test]
fn the_jets_spans_and_tightest_turns_are_the_real_aircrafts() {
    // Wingspans: Praetor 600 21.5 m (ICAO code B), A320 35.8 m (code C), FACTS.md. The jet's
    // parts reach it; the airliner's swept tip boxes reach 0.39 m beyond each tip (36.58 m), so
    // its sidecar gives the real span.
    let jet = Vehicle::shipped("praetor600").expect("shipped");
    assert!(
        (jet.span_m() - 21.5).abs() < 0.3 && jet.spec.wingspan_m.is_none(),
        "{}",
        jet.span_m()
    );
    let airliner = Vehicle::shipped("a320").expect("shipped");
    assert!(
        (airliner.span_m() - 36.58).abs() < 0.01,
        "{}",
        airliner.span_m()
    );
    assert_eq!(airliner.wingspan_m(), 35.8);
    let radius = jet.min_turn_radius_m();
    assert!((radius - 8.0 / 1.05_f64.tan()).abs() < 1e-12, "{radius}");
}
