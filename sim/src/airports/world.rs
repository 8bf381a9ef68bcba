//! An airport as the simulator's world: its pavement and runways as ground areas, its painted
//! lines as patches (the remission the localizer reads), its signs, light units, windsocks and
//! taxiway edge lights as solids where the file puts them.

use airport::{Airport, Surface};
use nalgebra::Vector2;

use crate::world::{Area, ObjectKind, Patch, Solid, SolidShape};

/// Remission of grass, the ground around an airport's pavement.
pub const GRASS_REMISSION: f32 = 0.12;
/// Spacing of taxiway edge lights along their lines (m): FAA AC 150/5340-30 allows up to 60 m on
/// straights; 30 m is a common spacing and what curves need.
pub const EDGE_LIGHT_SPACING_M: f64 = 30.0;

/// What of the airport becomes the world.
#[derive(Debug, Clone, Copy)]
pub struct Furniture {
    /// Signs (`20`).
    pub signs: bool,
    /// Light units (`21`), windsocks (`19`) and elevated taxiway edge lights (`102` lines).
    pub lights: bool,
}

/// The airport's ground and objects.
#[derive(Debug, Clone, Default)]
pub struct AirportWorld {
    /// Pavement, then runways over it.
    pub areas: Vec<Area>,
    /// Painted lines, one patch per segment.
    pub patches: Vec<Patch>,
    /// Signs, light units, windsocks, edge lights.
    pub solids: Vec<Solid>,
}

fn surface_remission(surface: Surface) -> f32 {
    match surface {
        Surface::Asphalt => 0.2,
        Surface::Concrete => 0.35,
        Surface::Unpaved => 0.15,
        // Water reflects a 905 nm beam away from the sensor; snow sends much of it back.
        Surface::Water => 0.03,
        Surface::Snow => 0.8,
        Surface::Other | Surface::Transparent => GRASS_REMISSION,
    }
}

/// Width and remission of a painted line type: centrelines 0.15 m, edges (double) 0.45 m, hold
/// lines (four stripes) 0.9 m; yellow 0.55, white 0.65.
fn line_style(code: u32) -> (f64, f32) {
    let white = matches!(code, 20..=25 | 70..=75);
    let width = match code {
        4..=6 | 12..=14 | 54..=56 | 62..=64 => 0.9,
        3 | 53 => 0.45,
        10 | 11 | 19 | 24 | 25 | 60 | 61 | 74 | 75 => 0.3,
        _ => 0.15,
    };
    (width, if white { 0.65 } else { 0.55 })
}

/// The sign's size class as (face height, top above the ground), metres: FAA AC 150/5345-44's
/// sizes 1 to 3 (legends of 12, 15 and 18 in), the distance-remaining signs 4 (large) and 5.
fn sign_size_m(size: u32) -> (f64, f64) {
    match size {
        1 => (0.46, 0.76),
        2 => (0.61, 0.91),
        4 => (1.22, 1.52),
        5 => (0.76, 1.07),
        _ => (0.76, 1.07),
    }
}

/// How many glyphs the wider face of a sign's text shows: `{@Y}`-style switches take none, any
/// other braced name one, `{@@}` separates the faces.
#[must_use]
pub fn sign_glyphs(text: &str) -> usize {
    text.split("{@@}")
        .map(|face| {
            let (mut count, mut depth) = (0, false);
            let mut braced = String::new();
            for c in face.chars() {
                match (c, depth) {
                    ('{', _) => {
                        depth = true;
                        braced.clear();
                    }
                    ('}', true) => {
                        depth = false;
                        if !braced.starts_with('@') {
                            count += 1;
                        }
                    }
                    (_, true) => braced.push(c),
                    (_, false) => count += 1,
                }
            }
            count
        })
        .max()
        .unwrap_or(0)
}

/// The airport's world.
#[must_use]
pub fn airport_world(airport: &Airport, furniture: Furniture) -> AirportWorld {
    let xy = |p: &Vector2<f64>| [p.x, p.y];
    let mut out = AirportWorld::default();
    for (i, p) in airport.pavements.iter().enumerate() {
        if p.surface == Surface::Transparent {
            // It carries markings only: the pavement (or grass) under it stays as drawn.
            continue;
        }
        out.areas.push(Area {
            id: format!("pavement_{}", i + 1),
            outline: p.outline.iter().map(xy).collect(),
            holes: p.holes.iter().map(|h| h.iter().map(xy).collect()).collect(),
            remission: surface_remission(p.surface),
        });
    }
    for r in &airport.runways {
        let (a, b) = (r.ends[0].at, r.ends[1].at);
        let d = (b - a).normalize();
        let n = Vector2::new(-d.y, d.x) * (r.width_m / 2.0);
        out.areas.push(Area {
            id: format!("runway_{}", r.name()),
            outline: vec![xy(&(a + n)), xy(&(b + n)), xy(&(b - n)), xy(&(a - n))],
            holes: Vec::new(),
            remission: surface_remission(r.surface),
        });
    }
    for (i, line) in airport.painted.iter().enumerate() {
        let (width_m, remission) = line_style(line.code);
        for (k, w) in line.points.windows(2).enumerate() {
            let d = w[1] - w[0];
            let length_m = d.norm();
            if length_m < 1e-3 {
                continue;
            }
            let mid = (w[0] + w[1]) / 2.0;
            out.patches.push(Patch {
                id: format!("line_{}_{}", i + 1, k + 1),
                x_m: mid.x,
                y_m: mid.y,
                yaw_rad: d.y.atan2(d.x),
                // Overlapping by the width closes the joints of a curve.
                length_m: length_m + width_m,
                width_m,
                remission,
            });
        }
    }
    if furniture.signs {
        signs(airport, &mut out.solids);
    }
    if furniture.lights {
        lights(airport, &mut out.solids);
    }
    out
}

fn solid(id: String, kind: ObjectKind, shape: SolidShape, at: Vector2<f64>, yaw_rad: f64) -> Solid {
    Solid {
        id,
        kind,
        shape,
        x_m: at.x,
        y_m: at.y,
        z_min_m: 0.0,
        yaw_rad,
        remission: kind.default_remission(),
        runtime: false,
    }
}

fn signs(airport: &Airport, solids: &mut Vec<Solid>) {
    for (i, s) in airport.signs.iter().enumerate() {
        let (face_m, top_m) = sign_size_m(s.size);
        // A glyph is about 0.8 of the legend's height (two thirds of the face) wide, plus a
        // frame; the box's x runs along the face's normal (its heading).
        let width_m = sign_glyphs(&s.text) as f64 * 0.55 * face_m + 0.3;
        let shape = SolidShape::Box {
            size_m: [0.3, width_m.max(0.6), top_m],
        };
        solids.push(solid(
            format!("sign_{}", i + 1),
            ObjectKind::Sign,
            shape,
            s.at,
            s.yaw_rad,
        ));
    }
}

fn lights(airport: &Airport, solids: &mut Vec<Solid>) {
    let unit = ObjectKind::LightUnit.default_shape();
    let sock = ObjectKind::Windsock.default_shape();
    let edge = ObjectKind::EdgeLight.default_shape();
    for (i, l) in airport.lights.iter().enumerate() {
        if let Some(shape) = unit {
            solids.push(solid(
                format!("light_unit_{}", i + 1),
                ObjectKind::LightUnit,
                shape,
                l.at,
                l.yaw_rad,
            ));
        }
    }
    for (i, w) in airport.windsocks.iter().enumerate() {
        if let Some(shape) = sock {
            solids.push(solid(
                format!("windsock_{}", i + 1),
                ObjectKind::Windsock,
                shape,
                *w,
                0.0,
            ));
        }
    }
    let Some(edge) = edge else { return };
    let mut n = 0;
    for line in airport
        .lighted
        .iter()
        .filter(|l| l.code == airport::model::line_type::EDGE_LIGHTS)
    {
        // One light at the start and every EDGE_LIGHT_SPACING_M along the line.
        let mut next_m = 0.0;
        let mut along_m = 0.0;
        for w in line.points.windows(2) {
            let length = (w[1] - w[0]).norm();
            while next_m <= along_m + length {
                let at = w[0] + (w[1] - w[0]) * ((next_m - along_m) / length.max(1e-9));
                n += 1;
                solids.push(solid(
                    format!("edge_light_{n}"),
                    ObjectKind::EdgeLight,
                    edge,
                    at,
                    0.0,
                ));
                next_m += EDGE_LIGHT_SPACING_M;
            }
            along_m += length;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_glyphs_count_what_a_face_shows() {
        assert_eq!(sign_glyphs("{@L}B"), 1);
        assert_eq!(sign_glyphs("{@Y}{^l}A{@L}B{@Y}A{^r}"), 5);
        assert_eq!(sign_glyphs("{@R}09-27"), 5);
        assert_eq!(sign_glyphs("{@L}H{@@}{@L}HX"), 2);
    }
}
