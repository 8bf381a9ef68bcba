//! Taxi routes on the fictional airport: along the named taxiways, by size class and one-way
//! edges, to hold points and stands, rounded into drivable paths; and the routes that cannot be made.

use airport::{Airport, NetworkRoute, PathOptions, Place, RouteRequest, SizeClass};
use nalgebra::Vector2;

use super::fixture::xtsm;

fn route(
    a: &Airport,
    from: &str,
    to: &str,
    via: &[&str],
    code: SizeClass,
) -> Result<NetworkRoute, String> {
    let request = RouteRequest {
        from: Place::parse(from),
        to: Place::parse(to),
        via: via.iter().map(|v| (*v).to_string()).collect(),
        code,
    };
    airport::find(a, &request).map_err(|e| e.to_string())
}

fn node_ids(a: &Airport, r: &NetworkRoute) -> Vec<u32> {
    r.nodes
        .iter()
        .flatten()
        .map(|&i| a.network.nodes[i].id)
        .collect()
}

const OPTIONS: PathOptions = PathOptions {
    turn_radius_m: 30.0,
    max_corner_cut_m: 2.5,
    min_turn_radius_m: 5.0,
    straight_speed_m_s: 8.0,
    lateral_acceleration_m_s2: 1.0,
    deceleration_m_s2: 0.5,
};

#[test]
fn a_business_jet_takes_b_then_a_to_runway_27s_hold_point() {
    let a = xtsm();
    let r = route(&a, "S3", "runway 27", &["B", "A"], SizeClass::B).expect("route");
    assert_eq!(node_ids(&a, &r), [11, 4, 5, 6, 7]);
    assert_eq!(r.taxiways, ["B", "A"]);
    assert!(
        (r.points[0] - Vector2::new(75.0, 250.0)).norm() < 0.1,
        "starts abeam the stand: {}",
        r.points[0]
    );
    // 75 m to node 11, 100 m of B, 750 m of A, 90 m down the leg.
    assert!((r.length_m - 1015.0).abs() < 0.2, "{}", r.length_m);
    assert!(r.crossings.is_empty());
}

#[test]
fn an_airliner_may_not_use_b_and_leaves_the_apron_by_its_one_way_exit() {
    let a = xtsm();
    let r = route(&a, "S2", "runway 27", &[], SizeClass::C).expect("route");
    assert_eq!(node_ids(&a, &r), [11, 14, 12, 5, 6, 7]);
    let along_b = route(&a, "S2", "runway 27", &["B", "A"], SizeClass::C).expect_err("B is code B");
    assert!(
        along_b.contains("no path along B, A admitting code C"),
        "{along_b}"
    );
}

#[test]
fn one_way_edges_are_driven_their_way_only() {
    let a = xtsm();
    // From A's east end to the apron's exit node: not up the exit (one way, apron -> A) but round
    // by the entry at x = -300 and along the taxilane: 1,750 m instead of 550.
    let r = route(&a, "node 6", "node 12", &[], SizeClass::C).expect("route");
    assert_eq!(node_ids(&a, &r), [6, 5, 4, 3, 10, 13, 11, 14, 12]);
    assert!((r.length_m - 1750.0).abs() < 0.3, "{}", r.length_m);
}

#[test]
fn vacating_runway_09_to_a_stand() {
    let a = xtsm();
    let r = route(&a, "runway 09", "S1", &["A"], SizeClass::C).expect("route");
    // Off the taxilane abeam S1 (between nodes 10 and 13) into the stand.
    assert_eq!(node_ids(&a, &r), [0, 1, 2, 3, 10]);
    assert!(
        (r.points.last().expect("end") - Vector2::new(-225.0, 300.0)).norm() < 0.1,
        "ends at the stand"
    );
}

#[test]
fn routes_that_cannot_be_made_say_why() {
    let a = xtsm();
    let cases = [
        (
            "S2",
            "S4",
            vec![],
            SizeClass::C,
            "stand `S4` takes aircraft up to code A, not C",
        ),
        (
            "S2",
            "runway 27",
            vec!["Z"],
            SizeClass::C,
            "no taxiway `Z` on the network",
        ),
        ("S9", "runway 27", vec![], SizeClass::C, "no stand `S9`"),
        (
            "S2",
            "runway 18",
            vec![],
            SizeClass::C,
            "no runway end `18`",
        ),
        (
            "node 77",
            "runway 27",
            vec![],
            SizeClass::C,
            "no network node has id 77",
        ),
        (
            "S1",
            "runway 27",
            vec![],
            SizeClass::F,
            "no taxiway admitting code F to leave stand `S1` by",
        ),
    ];
    for (from, to, via, code, expected) in cases {
        let e = route(&a, from, to, &via, code).expect_err("refused");
        assert!(
            e.starts_with(&format!(
                "taxi route {} -> {}:",
                Place::parse(from),
                Place::parse(to)
            )) && e.contains(expected),
            "{e}"
        );
    }
}

#[test]
fn the_path_is_rounded_within_the_aircrafts_turn_and_slower_in_turns() {
    let a = xtsm();
    let r = route(&a, "S3", "runway 27", &["B", "A"], SizeClass::B).expect("route");
    let path = airport::smooth(&r, &OPTIONS).expect("path");
    // Every corner is a right angle (to within the fixture's drawing): its arc passes 2.5 m
    // inside it, a radius of 2.5 / (sqrt 2 - 1) = 6.04 m.
    let radius = 2.5 / (2.0_f64.sqrt() - 1.0);
    assert!(
        (path.tightest_radius_m - radius).abs() < 1e-3,
        "{}",
        path.tightest_radius_m
    );
    let mut right_angles = 0;
    for w in r.points.windows(3) {
        let (u, v) = ((w[1] - w[0]).normalize(), (w[2] - w[1]).normalize());
        if u.dot(&v) > 0.5 {
            continue;
        }
        right_angles += 1;
        let nearest = path
            .points
            .iter()
            .map(|p| (p - w[1]).norm())
            .fold(f64::INFINITY, f64::min);
        assert!((2.499..2.55).contains(&nearest), "{}: {nearest}", w[1]);
    }
    assert_eq!(right_angles, 3);
    assert!(
        path.length_m < r.length_m && path.length_m > r.length_m - 10.0,
        "{} of {}",
        path.length_m,
        r.length_m
    );
    // Points at most 5 m apart on straights (the speed limits are interpolated between them).
    for w in path.points.windows(2) {
        assert!((w[1] - w[0]).norm() > 1e-6 && (w[1] - w[0]).norm() <= 5.0 + 1e-9);
    }
    let turn_speed = (OPTIONS.lateral_acceleration_m_s2 * radius).sqrt();
    let slowest = path.speed_m_s.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((slowest - turn_speed).abs() < 1e-3, "{slowest}");
    assert!(
        path.speed_m_s.iter().any(|&v| (v - 8.0).abs() < 1e-9),
        "full speed on the straights"
    );
    // Braking into a turn at 0.5 m/s^2: no drop between neighbours beyond what that allows.
    for (i, w) in path.speed_m_s.windows(2).enumerate() {
        let d = (path.points[i + 1] - path.points[i]).norm();
        assert!(
            w[0] * w[0] <= w[1] * w[1] + 2.0 * OPTIONS.deceleration_m_s2 * d + 1e-6,
            "{i}"
        );
    }
}

#[test]
fn a_corner_without_room_for_the_aircrafts_turn_is_an_error() {
    let a = xtsm();
    let r = route(&a, "S2", "S3", &[], SizeClass::B).expect("route");
    // The stand's 50 m lead-in leaves room for a 50 m radius at the turn off the taxilane.
    let options = PathOptions {
        turn_radius_m: 60.0,
        min_turn_radius_m: 55.0,
        ..OPTIONS
    };
    let e = airport::smooth(&r, &options)
        .expect_err("too sharp")
        .to_string();
    assert!(e.contains("turn too sharp at the corner at (75.0, 250.0): a 90-degree turn between legs of 75.0 m and 50.0 m has room for a 50.0 m radius; the aircraft turns no tighter than 55.0 m"), "{e}");
}
