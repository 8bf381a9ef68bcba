//! Real data from `../shared/data` (not in the repository): Syracuse Hancock (KSYR). Ignored by
//! default - a fresh clone need not have it; CI runs them with `--ignored`.

use std::path::PathBuf;

use airport::{Airport, PathOptions, Place, RouteRequest, SizeClass};

fn ksyr_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/airports/KSYR/apt.dat")
}

fn ksyr() -> Airport {
    let path = ksyr_path();
    Airport::read(&path, None)
        .unwrap_or_else(|e| panic!("{e} (the data is expected at {})", path.display()))
}

const FOOT_M: f64 = 0.3048;

#[test]
#[ignore = "reads ../shared/data"]
fn ksyr_runways_are_their_published_lengths() {
    let a = ksyr();
    // Published (FAA): 10/28 9,003 ft (2,744.1 m), 15/33 7,500 ft (2,286.0 m). Measured between
    // the file's runway ends in the local frame: 2,744.0 m and 2,285.5 m.
    for (name, feet) in [("10/28", 9003.0), ("15/33", 7500.0)] {
        let runway = a
            .runways
            .iter()
            .find(|r| r.name() == name)
            .unwrap_or_else(|| panic!("runway {name}"));
        let published = feet * FOOT_M;
        let length = runway.length_m();
        assert!(
            (length - published).abs() < 1.0,
            "{name}: {length:.1} m against {published:.1} m published"
        );
        assert!((runway.width_m - 150.0 * FOOT_M).abs() < 0.01);
    }
}

#[test]
#[ignore = "reads ../shared/data"]
fn ksyr_has_its_network_stands_and_signs() {
    let a = ksyr();
    assert_eq!((a.version, a.code.as_str()), (1050, "KSYR"));
    assert_eq!(
        (
            a.network.nodes.len(),
            a.network.edges.len(),
            a.network.components()
        ),
        (147, 176, 1)
    );
    let km = a.network.length_m() / 1000.0;
    assert!((km - 20.3).abs() < 0.05, "{km}");
    assert_eq!(
        (
            a.stands.len(),
            a.signs.len(),
            a.pavements.len(),
            a.windsocks.len(),
            a.lights.len()
        ),
        (23, 71, 40, 4, 4)
    );
    assert_eq!(
        a.stands
            .iter()
            .filter(|s| s.size_class == Some(SizeClass::C))
            .count(),
        19
    );
    // 21 taxiway names and the two runways' on the runway edges.
    assert_eq!(a.network.taxiways().len(), 21);
    let names: std::collections::BTreeSet<&str> =
        a.network.edges.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names.len(), 23, "{names:?}");
}

#[test]
#[ignore = "reads ../shared/data"]
fn ksyr_routes_from_a_gate_to_runway_28() {
    let a = ksyr();
    let request = RouteRequest {
        from: Place::parse("Gate 4 South A"),
        to: Place::parse("runway 28"),
        via: vec![],
        code: SizeClass::C,
    };
    let route = airport::find(&a, &request).expect("route");
    let path = airport::smooth(
        &route,
        &PathOptions {
            turn_radius_m: 30.0,
            max_corner_cut_m: 2.5,
            min_turn_radius_m: 12.0,
            straight_speed_m_s: 8.0,
            lateral_acceleration_m_s2: 1.0,
            deceleration_m_s2: 0.5,
        },
    )
    .expect("path");
    // Along F, T, B, A1 and A to the hold point nearest 28's threshold, across runway 15/33.
    assert_eq!(route.taxiways, ["F", "T", "B", "A1", "A"]);
    assert_eq!(route.crossings, ["15", "33"]);
    assert!((route.length_m - 1619.0).abs() < 1.0, "{}", route.length_m);
    assert!(
        path.length_m < route.length_m && path.tightest_radius_m >= 12.0,
        "{} m, {} m radius",
        path.length_m,
        path.tightest_radius_m
    );
}

/// Vacating runway 28 to the B stands drives along 10/28 only, never along 15/33; two gates on
/// one taxilane edge are joined along it (134 m, not 978 m round by S and B); and runway 33's
/// hold points are on no runway, where a taxiway in no runway's zone begins.
#[test]
#[ignore = "reads ../shared/data"]
fn ksyr_routes_keep_off_other_runways_and_join_neighbouring_gates() {
    let a = ksyr();
    let request = |from: &str, to: &str| RouteRequest {
        from: Place::parse(from),
        to: Place::parse(to),
        via: Vec::new(),
        code: SizeClass::B,
    };
    let vacate = airport::find(&a, &request("runway 28", "B21")).expect("vacating 28");
    assert_eq!(vacate.taxiways.first().map(String::as_str), Some("10/28"));
    assert!(
        !vacate.taxiways.iter().any(|t| t == "15/33"),
        "{:?}",
        vacate.taxiways
    );
    let next_door = airport::find(&a, &request("B21", "B22")).expect("B21 to B22");
    assert!(next_door.length_m < 150.0, "{}", next_door.length_m);
    let holds = airport::hold_points(&a.network, "33");
    assert!(!holds.is_empty());
    for &h in &holds {
        let edges: Vec<_> = a
            .network
            .edges
            .iter()
            .filter(|e| e.from == h || e.to == h)
            .collect();
        assert!(
            edges.iter().all(|e| e.class != airport::EdgeClass::Runway),
            "hold node {h} on a runway"
        );
        assert!(
            edges.iter().any(|e| e.zone_runways.is_empty()),
            "hold node {h} is not where a taxiway in no runway's zone begins"
        );
    }
}
