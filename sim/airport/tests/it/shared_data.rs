//! Real data from `../shared/data` (not in the repository): Syracuse Hancock (KSYR). Ignored by
//! default - a fresh clone need not have it; CI runs them with `--ignored`.

use std::path::PathBuf;

use airport::paint::{MAX_OFFSET_M, centrelines};
use airport::{Airport, NetworkRoute, PathOptions, Place, RouteRequest, SizeClass};
use nalgebra::Vector2;

use crate::paint::{samples, segment_distance};

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
    let path = airport::smooth(&route, &options(12.0)).expect("path");
    // Along F, T, B, A1 and A to the hold point nearest 28's threshold, across runway 15/33:
    // 1,619 m on the network, 1,622 m on the paint where the network strays from it.
    assert_eq!(route.taxiways, ["F", "T", "B", "A1", "A"]);
    assert_eq!(route.crossings, ["15", "33"]);
    let network = airport::find_on_network(&a, &request).expect("route");
    assert!(
        (network.length_m - 1619.0).abs() < 1.0,
        "{}",
        network.length_m
    );
    assert!((route.length_m - 1622.1).abs() < 1.0, "{}", route.length_m);
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

fn options(min_turn_radius_m: f64) -> PathOptions {
    PathOptions {
        turn_radius_m: 30.0,
        max_corner_cut_m: 2.5,
        min_turn_radius_m,
        straight_speed_m_s: 8.0,
        lateral_acceleration_m_s2: 1.0,
        deceleration_m_s2: 0.5,
    }
}

/// The route's points from node `from` to node `to` (ids).
fn between(a: &Airport, r: &NetworkRoute, from: u32, to: u32) -> Vec<Vector2<f64>> {
    let at = |id: u32| {
        let k = a.network.node_by_id(id).expect("node");
        r.nodes
            .iter()
            .position(|&n| n == Some(k))
            .expect("on the route")
    };
    r.points[at(from)..=at(to)].to_vec()
}

/// The found scenario `tests/found/ksyr_gear_meets_an_edge_light_on_w.toml` (node 123 to runway
/// 33 along W, the Praetor-like jet: code B): KSYR's network runs W 9-14 m off its painted
/// centreline near the runway 10/28 crossing, and the jet's main gear met an edge light there.
/// On the paint, the route from node 123 across the runway to node 124 stays within 1.5 m of the
/// centreline (0.2 m; 9.7 m on the network), and node 141 - on the runway's centreline - moves
/// the 13.6 m along it to where W's paint crosses it.
#[test]
#[ignore = "reads ../shared/data"]
fn shared_data_ksyr_w_follows_its_painted_centreline_across_runway_10_28() {
    let a = ksyr();
    let request = RouteRequest {
        from: Place::parse("node 123"),
        to: Place::parse("runway 33"),
        via: vec!["W".to_string()],
        code: SizeClass::B,
    };
    let network = airport::find_on_network(&a, &request).expect("route");
    let route = airport::find(&a, &request).expect("route");
    assert_eq!(route.taxiways, ["W"]);
    // Bound for runway 33: the hold point stays where the network has it.
    assert_eq!(route.points.last(), network.points.last());
    let paint: Vec<(Vector2<f64>, Vector2<f64>)> = centrelines(&a)
        .iter()
        .flat_map(|run| run.windows(2).map(|w| (w[0], w[1])).collect::<Vec<_>>())
        .collect();
    let off_paint = |r: &NetworkRoute| {
        samples(&between(&a, r, 123, 124), 0.5)
            .iter()
            .map(|&p| {
                paint
                    .iter()
                    .map(|&(x, y)| segment_distance(p, x, y))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    };
    let (before, after) = (off_paint(&network), off_paint(&route));
    println!(
        "node 123 -> 124 across 10/28: furthest from the paint {before:.2} m on the network, {after:.2} m on the paint"
    );
    assert!(before > 9.0, "{before}");
    assert!(after < 1.5, "{after}");
    // Node 141 on W's paint where it crosses runway 10/28's centreline, 13.6 m from the network's.
    let k = a.network.node_by_id(141).expect("node 141");
    let moved = route.points[route.nodes.iter().position(|&n| n == Some(k)).expect("141")];
    let runway = a
        .runways
        .iter()
        .find(|r| r.name() == "10/28")
        .expect("10/28");
    let on_centreline = segment_distance(moved, runway.ends[0].at, runway.ends[1].at);
    let from_network = (moved - a.network.nodes[k].at).norm();
    assert!(on_centreline < 0.05, "{on_centreline}");
    assert!((from_network - 13.6).abs() < 0.3, "{from_network}");
    // Never further from the network than the limit; rounded as the jet turns.
    for p in samples(&route.points, 0.5) {
        let d = network
            .points
            .windows(2)
            .map(|w| segment_distance(p, w[0], w[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(d <= MAX_OFFSET_M + 1e-9, "{p}: {d}");
    }
    for min in [4.6, 12.0] {
        airport::smooth(&route, &options(min)).unwrap_or_else(|e| panic!("{e}"));
    }
}

/// Every route between KSYR's stands and runway ends, and between every fifth network node: on
/// the paint, never further from the network's route than [`MAX_OFFSET_M`], and rounded
/// wherever the network's is (for an aircraft turning no tighter than 4.6 m or 12 m).
#[test]
#[ignore = "reads ../shared/data"]
fn shared_data_ksyr_routes_on_the_paint_stay_near_the_network_and_round() {
    let a = ksyr();
    let mut places: Vec<String> = a.stands.iter().map(|s| s.name.clone()).collect();
    for r in &a.runways {
        places.extend(r.ends.iter().map(|e| format!("runway {}", e.number)));
    }
    places.extend(
        a.network
            .nodes
            .iter()
            .step_by(5)
            .map(|n| format!("node {}", n.id)),
    );
    let (mut routes, mut moved) = (0, 0);
    for from in &places {
        for to in places.iter().filter(|&t| t != from) {
            let request = RouteRequest {
                from: Place::parse(from),
                to: Place::parse(to),
                via: Vec::new(),
                code: SizeClass::B,
            };
            let (Ok(network), Ok(route)) = (
                airport::find_on_network(&a, &request),
                airport::find(&a, &request),
            ) else {
                continue;
            };
            routes += 1;
            moved += usize::from(route.points != network.points);
            assert_eq!(
                (route.edges.len() + 1, route.nodes.len()),
                (route.points.len(), route.points.len())
            );
            for p in samples(&route.points, 1.0) {
                let d = network
                    .points
                    .windows(2)
                    .map(|w| segment_distance(p, w[0], w[1]))
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= MAX_OFFSET_M + 1e-9, "{from} -> {to}: {p} is {d} m off");
            }
            for min in [4.6, 12.0] {
                if airport::smooth(&network, &options(min)).is_ok() {
                    airport::smooth(&route, &options(min))
                        .unwrap_or_else(|e| panic!("{from} -> {to}: {e}"));
                }
            }
        }
    }
    println!("{routes} routes, {moved} moved onto the paint");
    assert!(routes > 2000 && moved > routes / 2, "{routes} {moved}");
}

/// Every KSYR stand a code-B jet can leave for runway 28: the route starts on the stand (within
/// 1 m and 2 degrees), and where it is pushed back the tug moves it tail first all the way -
/// half way between two poses its tail points where it moves, within 2 degrees (a stand whose
/// axis misses its taxilane is first pushed down its axis, then across); the tug lets go facing
/// the route's first leg.
#[test]
#[ignore = "reads ../shared/data"]
fn ksyr_stands_are_left_from_the_stand_tail_first() {
    let a = ksyr();
    let heading = |p: Vector2<f64>, q: Vector2<f64>| (q.y - p.y).atan2(q.x - p.x);
    let apart = |x: f64, y: f64| {
        let d = (x - y).rem_euclid(std::f64::consts::TAU);
        d.min(std::f64::consts::TAU - d).to_degrees()
    };
    let (mut left, mut pushed) = (0, 0);
    for stand in &a.stands {
        let request = RouteRequest {
            from: Place::Stand(stand.name.clone()),
            to: Place::Runway("28".into()),
            via: Vec::new(),
            code: SizeClass::B,
        };
        // Names the file repeats are refused (`#k` picks one); a stand no code-B route leaves is
        // not this test's.
        let Ok(route) = airport::find(&a, &request) else {
            continue;
        };
        let (route, tow) = airport::leave_stand(stand, &route, 4.6).unwrap();
        left += 1;
        let Some(tow) = tow else {
            assert!((route.points[0] - stand.at).norm() < 1.0, "{}", stand.name);
            continue;
        };
        pushed += 1;
        let (start, yaw) = tow.poses[0];
        assert!((start - stand.at).norm() < 1.0 && apart(yaw, stand.yaw_rad) < 2.0);
        for w in tow.poses.windows(2) {
            let ((p, yp), (q, yq)) = (w[0], w[1]);
            if (q - p).norm() > 0.05 {
                let d = (yq - yp + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                let midway = yp + d / 2.0;
                assert!(
                    apart(midway, heading(q, p)) < 2.0,
                    "{}: between {p:?} and {q:?}",
                    stand.name
                );
            }
        }
        let (release, yaw_end) = tow.poses[tow.poses.len() - 1];
        assert!((route.points[0] - release).norm() < 1e-6, "{}", stand.name);
        assert!(
            apart(yaw_end, heading(route.points[0], route.points[1])) < 2.0,
            "{}",
            stand.name
        );
    }
    // 23 stands left, 19 of them pushed back (2026-12-03).
    assert!(
        left >= 20 && pushed >= 15,
        "{left} stands left, {pushed} pushed back"
    );
}
