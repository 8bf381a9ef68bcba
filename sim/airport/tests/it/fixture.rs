//! The shipped fictional airport (`scenarios/airports/xtsm/apt.dat`) read: every feature where it
//! was drawn.

use std::path::PathBuf;

use airport::{Airport, EdgeClass, SizeClass, Surface};
use nalgebra::Vector2;

pub fn xtsm_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/airports/xtsm/apt.dat")
}

pub fn xtsm() -> Airport {
    Airport::read(&xtsm_path(), None).expect("the fixture reads")
}

/// The fixture's positions were written from a local-radius approximation at the datum: within
/// a few centimetres of the geodesic frame over its 1.6 km.
const DRAWN_M: f64 = 0.05;

#[test]
fn the_runway_and_the_header_are_where_they_were_drawn() {
    let a = xtsm();
    assert_eq!((a.code.as_str(), a.version), ("XTSM", 1100));
    assert!((a.elevation_m - 350.0 * 0.3048).abs() < 1e-9);
    assert_eq!(a.runways.len(), 1);
    let r = &a.runways[0];
    assert_eq!(r.name(), "09/27");
    assert_eq!(r.surface, Surface::Asphalt);
    assert!((r.length_m() - 1600.0).abs() < DRAWN_M, "{}", r.length_m());
    assert!(
        (r.ends[0].at - Vector2::new(-800.0, 0.0)).norm() < DRAWN_M,
        "{}",
        r.ends[0].at
    );
}

#[test]
fn pavements_are_polygons_with_their_holes_and_curves() {
    let a = xtsm();
    assert_eq!(a.pavements.len(), 7);
    let apron = a
        .pavements
        .iter()
        .find(|p| p.name == "Apron")
        .expect("apron");
    assert_eq!(apron.surface, Surface::Concrete);
    assert_eq!(
        (apron.outline.len(), apron.holes.len(), apron.holes[0].len()),
        (4, 1, 4)
    );
    let taxiway_a = a
        .pavements
        .iter()
        .find(|p| p.name == "Taxiway A")
        .expect("A");
    // Four plain corners, then the closing Bezier node's two curved segments cut into <= 1 m chords.
    assert!(taxiway_a.outline.len() > 20, "{}", taxiway_a.outline.len());
    for w in taxiway_a.outline.windows(2) {
        let chord = (w[1] - w[0]).norm();
        assert!(
            chord <= 1.0 + 1e-6 || (chord - 1500.0).abs() < 0.1 || (chord - 20.0).abs() < 0.1,
            "{chord}"
        );
    }
    // The curve bulges west of the strip's plain corners (x = -740) toward its node at x = -760.
    let west = taxiway_a
        .outline
        .iter()
        .map(|p| p.x)
        .fold(f64::INFINITY, f64::min);
    assert!((west + 760.0).abs() < 0.1, "{west}");
}

#[test]
fn painted_and_lighted_lines_keep_their_types() {
    let a = xtsm();
    let holds: Vec<_> = a.painted.iter().filter(|l| l.code == 4).collect();
    assert_eq!(holds.len(), 2);
    assert!(
        holds
            .iter()
            .all(|l| ((l.points[0] - l.points[1]).norm() - 20.0).abs() < DRAWN_M)
    );
    assert_eq!(a.lighted.iter().filter(|l| l.code == 102).count(), 2);
    assert_eq!(a.lighted.iter().filter(|l| l.code == 104).count(), 2);
    let centreline: f64 = a
        .painted
        .iter()
        .filter(|l| l.code == 1)
        .map(|l| {
            l.points
                .windows(2)
                .map(|w| (w[1] - w[0]).norm())
                .sum::<f64>()
        })
        .sum();
    // A: legs of 115 m, curves of about 31 m, a 1,460 m straight; the apron taxilane: 80 m legs,
    // curves, 560 m: about 2,530 m of centreline.
    assert!((2450.0..2600.0).contains(&centreline), "{centreline}");
}

#[test]
fn network_stands_signs_and_objects_are_read() {
    let a = xtsm();
    assert_eq!(
        (
            a.network.nodes.len(),
            a.network.edges.len(),
            a.network.components()
        ),
        (15, 17, 1)
    );
    let taxiways = a.network.taxiways();
    assert_eq!(taxiways.keys().collect::<Vec<_>>(), ["A", "B"]);
    assert!((taxiways["B"] - 100.0).abs() < DRAWN_M);
    let b = a.network.edges.iter().find(|e| e.name == "B").expect("B");
    assert_eq!(b.class, EdgeClass::Taxiway(SizeClass::B));
    assert_eq!(a.network.edges.iter().filter(|e| e.one_way).count(), 2);
    assert_eq!(
        a.network
            .edges
            .iter()
            .filter(|e| e.in_zone_of("27"))
            .count(),
        4
    );
    assert_eq!(a.stands.len(), 4);
    let s4 = a.stand("S4").expect("S4");
    assert_eq!(
        (s4.kind.as_str(), s4.size_class, s4.operation.as_deref()),
        ("tie_down", Some(SizeClass::A), Some("general_aviation"))
    );
    assert!(
        (s4.yaw_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-3,
        "heading north: {}",
        s4.yaw_rad
    );
    assert_eq!(a.signs.len(), 4);
    assert_eq!(
        a.signs.iter().map(|s| s.size).collect::<Vec<_>>(),
        [2, 2, 1, 3]
    );
    assert_eq!(
        (a.lights.len(), a.lights[0].kind, a.windsocks.len()),
        (1, 2, 1)
    );
}
