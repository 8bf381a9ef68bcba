//! The text summary of an airport: runways with lengths, pavement, lines, the taxi network,
//! taxiways by name, stands by size class and type, signs.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use airport::{Airport, EdgeClass, Surface};
use nalgebra::Vector2;

/// A polygon's area by the shoelace formula (m^2, unsigned).
fn area_m2(ring: &[Vector2<f64>]) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|i| ring[i].perp(&ring[(i + 1) % n]))
        .sum::<f64>()
        .abs()
        / 2.0
}

fn polyline_m(points: &[Vector2<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

fn surface_name(surface: Surface) -> &'static str {
    match surface {
        Surface::Asphalt => "asphalt",
        Surface::Concrete => "concrete",
        Surface::Unpaved => "unpaved",
        Surface::Water => "water",
        Surface::Snow => "snow",
        Surface::Transparent => "transparent",
        Surface::Other => "other",
    }
}

/// The summary, one block of lines.
#[must_use]
pub fn summary(a: &Airport) -> String {
    let mut out = String::new();
    let datum = a.frame.datum();
    let _ = writeln!(
        out,
        "{} {} (apt.dat {}): datum {:.6} {:.6}, elevation {:.0} m",
        a.code, a.name, a.version, datum.lat, datum.lon, a.elevation_m
    );
    for r in &a.runways {
        let _ = writeln!(
            out,
            "runway {}: {:.1} m x {:.1} m, {}",
            r.name(),
            r.length_m(),
            r.width_m,
            surface_name(r.surface)
        );
    }
    let mut by_surface: BTreeMap<&str, (usize, f64)> = BTreeMap::new();
    for p in &a.pavements {
        let entry = by_surface.entry(surface_name(p.surface)).or_default();
        entry.0 += 1;
        entry.1 += area_m2(&p.outline) - p.holes.iter().map(|h| area_m2(h)).sum::<f64>();
    }
    let pavement: Vec<String> = by_surface
        .iter()
        .map(|(s, (n, m2))| format!("{n} {s} ({:.2} km^2)", m2 / 1e6))
        .collect();
    let _ = writeln!(
        out,
        "pavement: {} polygons: {}",
        a.pavements.len(),
        pavement.join(", ")
    );
    let painted: f64 = a.painted.iter().map(|l| polyline_m(&l.points)).sum();
    let lighted: f64 = a.lighted.iter().map(|l| polyline_m(&l.points)).sum();
    let _ = writeln!(
        out,
        "lines: {} painted runs ({:.1} km), {} lighted ({:.1} km)",
        a.painted.len(),
        painted / 1000.0,
        a.lighted.len(),
        lighted / 1000.0
    );
    let n = &a.network;
    let mut classes: BTreeMap<String, usize> = BTreeMap::new();
    for e in &n.edges {
        let key = match e.class {
            EdgeClass::Runway => "runway".to_string(),
            EdgeClass::Taxiway(c) => format!("code {c}"),
        };
        *classes.entry(key).or_default() += 1;
    }
    let classes: Vec<String> = classes.iter().map(|(k, v)| format!("{v} {k}")).collect();
    let _ = writeln!(
        out,
        "taxi network: {} nodes, {} edges ({}, {} one-way), {:.1} km, {} component(s)",
        n.nodes.len(),
        n.edges.len(),
        classes.join(", "),
        n.edges.iter().filter(|e| e.one_way).count(),
        n.length_m() / 1000.0,
        n.components()
    );
    let taxiways: Vec<String> = n
        .taxiways()
        .iter()
        .map(|(name, m)| format!("{name} {m:.0} m"))
        .collect();
    let _ = writeln!(
        out,
        "taxiways ({}): {}",
        taxiways.len(),
        taxiways.join(", ")
    );
    let mut stands: BTreeMap<String, usize> = BTreeMap::new();
    for s in &a.stands {
        let class = s
            .size_class
            .map_or_else(|| "no class".to_string(), |c| format!("code {c}"));
        *stands.entry(format!("{} {class}", s.kind)).or_default() += 1;
    }
    let stands: Vec<String> = stands.iter().map(|(k, v)| format!("{v} {k}")).collect();
    let _ = writeln!(out, "stands ({}): {}", a.stands.len(), stands.join(", "));
    let mut sizes = [0usize; 5];
    for s in &a.signs {
        sizes[(s.size as usize).clamp(1, 5) - 1] += 1;
    }
    let _ = writeln!(
        out,
        "signs: {} (by size 1-5: {:?}); lighting objects: {}; windsocks: {}",
        a.signs.len(),
        sizes,
        a.lights.len(),
        a.windsocks.len()
    );
    out
}
