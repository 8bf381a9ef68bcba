//! The airport drawn with plotters (PNG or SVG by the file's extension): grass, pavement with its
//! holes, runways, painted and lighted lines, the taxi network with its taxiway names, stands,
//! signs, and a taxi route when given.

use std::path::Path;

use airport::{Airport, EdgeClass, Surface};
use nalgebra::Vector2;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart::register_font;
use crate::error::{Error, Result};

/// A route to draw over the airport.
#[derive(Debug, Clone)]
pub struct RouteOverlay {
    /// Its points.
    pub points: Vec<Vector2<f64>>,
    /// The push-back before it, from the stand to where the tug lets go (drawn dashed), if any.
    pub pushback: Vec<Vector2<f64>>,
    /// What it is (the legend).
    pub label: String,
}

const GRASS: RGBColor = RGBColor(196, 218, 168);
const ASPHALT: RGBColor = RGBColor(118, 118, 118);
const CONCRETE: RGBColor = RGBColor(178, 176, 170);
const UNPAVED: RGBColor = RGBColor(170, 150, 110);
const RUNWAY: RGBColor = RGBColor(70, 70, 70);

type DrawResult = std::result::Result<(), String>;
type Plot<DB> = DrawingArea<
    DB,
    plotters::coord::cartesian::Cartesian2d<
        plotters::coord::types::RangedCoordf64,
        plotters::coord::types::RangedCoordf64,
    >,
>;

/// Draws `airport` (and `route`) into `path`: `.png` or `.svg`, written atomically.
///
/// # Errors
/// An extension other than png or svg, a drawing or a writing failure (naming the file).
pub fn draw_airport(airport: &Airport, route: Option<&RouteOverlay>, path: &Path) -> Result<()> {
    register_font();
    let (low, high) = airport.extent();
    let pad = 60.0;
    let (low, high) = (low - Vector2::repeat(pad), high + Vector2::repeat(pad));
    let width = 2000u32;
    let span = high - low;
    let height =
        ((f64::from(width) * span.y / span.x.max(1.0)).round() as u32).clamp(400, 4000) + 60;
    let located = |e: String| Error::Invalid(format!("{}: drawing: {e}", path.display()));
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or_default();
    match extension {
        "svg" => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, (width, height)).into_drawing_area();
                draw(&root, airport, route, (low, high)).map_err(located)?;
            }
            mapper::write_atomically(path, text.as_bytes())?;
        }
        "png" => {
            let mut buf = vec![0u8; (width * height * 3) as usize];
            {
                let root =
                    BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
                draw(&root, airport, route, (low, high)).map_err(located)?;
            }
            let mut bytes = Vec::new();
            image::ImageEncoder::write_image(
                image::codecs::png::PngEncoder::new(&mut bytes),
                &buf,
                width,
                height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| located(e.to_string()))?;
            mapper::write_atomically(path, &bytes)?;
        }
        _ => {
            return Err(Error::Invalid(format!(
                "{}: a picture is .png or .svg, not `{extension}`",
                path.display()
            )));
        }
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    a: &Airport,
    route: Option<&RouteOverlay>,
    (low, high): (Vector2<f64>, Vector2<f64>),
) -> DrawResult {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let title = format!(
        "{} {} - apt.dat {}, local frame (m, x east, y north)",
        a.code, a.name, a.version
    );
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 22))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(low.x..high.x, low.y..high.y)
        .map_err(err)?;
    chart.configure_mesh().disable_mesh().draw().map_err(err)?;
    let plot = chart.plotting_area();
    plot.fill(&GRASS).map_err(err)?;
    let xy = |p: &Vector2<f64>| (p.x, p.y);
    for p in &a.pavements {
        let colour = match p.surface {
            Surface::Asphalt => ASPHALT,
            Surface::Concrete => CONCRETE,
            Surface::Unpaved | Surface::Other | Surface::Water | Surface::Snow => UNPAVED,
            Surface::Transparent => continue,
        };
        plot.draw(&Polygon::new(
            p.outline.iter().map(xy).collect::<Vec<_>>(),
            colour.filled(),
        ))
        .map_err(err)?;
        for hole in &p.holes {
            plot.draw(&Polygon::new(
                hole.iter().map(xy).collect::<Vec<_>>(),
                GRASS.filled(),
            ))
            .map_err(err)?;
        }
    }
    for r in &a.runways {
        let (p, q) = (r.ends[0].at, r.ends[1].at);
        let d = (q - p).normalize();
        let n = Vector2::new(-d.y, d.x) * (r.width_m / 2.0);
        plot.draw(&Polygon::new(
            vec![xy(&(p + n)), xy(&(q + n)), xy(&(q - n)), xy(&(p - n))],
            RUNWAY.filled(),
        ))
        .map_err(err)?;
        for (end, dir) in [(&r.ends[0], -d), (&r.ends[1], d)] {
            let at = end.at + dir * 40.0;
            plot.draw(&Text::new(
                end.number.clone(),
                xy(&at),
                ("sans-serif", 16).into_font().color(&BLACK),
            ))
            .map_err(err)?;
        }
    }
    for line in &a.painted {
        let colour = match line.code {
            20..=25 | 70..=75 => WHITE,
            30..=32 | 80..=82 => RED,
            4..=6 | 12..=14 | 54..=56 | 62..=64 => RGBColor(230, 120, 0),
            _ => RGBColor(235, 200, 0),
        };
        plot.draw(&PathElement::new(
            line.points.iter().map(xy).collect::<Vec<_>>(),
            colour.stroke_width(1),
        ))
        .map_err(err)?;
    }
    for line in &a.lighted {
        plot.draw(&PathElement::new(
            line.points.iter().map(xy).collect::<Vec<_>>(),
            RGBColor(40, 80, 230).stroke_width(1),
        ))
        .map_err(err)?;
    }
    draw_network(plot, a).map_err(err)?;
    for s in &a.stands {
        plot.draw(&Circle::new(xy(&s.at), 3, RGBColor(0, 110, 0).filled()))
            .map_err(err)?;
        plot.draw(&Text::new(
            s.name.clone(),
            (s.at.x + 4.0, s.at.y),
            ("sans-serif", 10).into_font().color(&RGBColor(0, 90, 0)),
        ))
        .map_err(err)?;
    }
    for s in &a.signs {
        let colour = if s.text.contains("{@R}") {
            RED
        } else if s.text.contains("{@Y}") {
            RGBColor(250, 210, 0)
        } else {
            BLACK
        };
        plot.draw(&Rectangle::new(
            [(s.at.x - 4.0, s.at.y - 4.0), (s.at.x + 4.0, s.at.y + 4.0)],
            colour.filled(),
        ))
        .map_err(err)?;
    }
    if let Some(route) = route {
        draw_route(plot, route, low, high).map_err(err)?;
    }
    Ok(())
}

/// The route: a thick line (the push-back before it dashed), a green start and a red end, its
/// label top left.
fn draw_route<DB: DrawingBackend>(
    plot: &Plot<DB>,
    route: &RouteOverlay,
    low: Vector2<f64>,
    high: Vector2<f64>,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let xy = |p: &Vector2<f64>| (p.x, p.y);
    let points: Vec<(f64, f64)> = route.points.iter().map(xy).collect();
    plot.draw(&PathElement::new(
        points.clone(),
        RGBColor(20, 20, 160).stroke_width(4),
    ))?;
    // The push-back: the tug's path, dashed in orange, from the stand (the start).
    let tow: Vec<(f64, f64)> = route.pushback.iter().map(xy).collect();
    for pair in tow.chunks(2).filter(|c| c.len() == 2) {
        plot.draw(&PathElement::new(
            pair.to_vec(),
            RGBColor(230, 120, 0).stroke_width(4),
        ))?;
    }
    if let (Some(first), Some(last)) = (tow.first().or(points.first()), points.last()) {
        plot.draw(&Circle::new(*first, 7, RGBColor(0, 170, 0).filled()))?;
        plot.draw(&Circle::new(*last, 7, RED.filled()))?;
        plot.draw(&Text::new(
            route.label.clone(),
            (low.x + 20.0, high.y - 30.0),
            ("sans-serif", 20).into_font().color(&RGBColor(20, 20, 160)),
        ))?;
    }
    Ok(())
}

/// The network's edges (runway edges dashed darker), and each taxiway's name once, at the middle
/// of its longest edge.
fn draw_network<DB: DrawingBackend>(
    plot: &DrawingArea<
        DB,
        plotters::coord::cartesian::Cartesian2d<
            plotters::coord::types::RangedCoordf64,
            plotters::coord::types::RangedCoordf64,
        >,
    >,
    a: &Airport,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let n = &a.network;
    let mut longest: std::collections::BTreeMap<&str, (f64, Vector2<f64>)> =
        std::collections::BTreeMap::new();
    for e in &n.edges {
        let (p, q) = (n.nodes[e.from].at, n.nodes[e.to].at);
        let colour = if e.class == EdgeClass::Runway {
            RGBColor(150, 0, 0)
        } else {
            RGBColor(200, 0, 200)
        };
        plot.draw(&PathElement::new(
            vec![(p.x, p.y), (q.x, q.y)],
            colour.stroke_width(1),
        ))?;
        let length = (q - p).norm();
        if e.class != EdgeClass::Runway
            && !e.name.is_empty()
            && longest
                .get(e.name.as_str())
                .is_none_or(|(l, _)| *l < length)
        {
            longest.insert(&e.name, (length, (p + q) / 2.0));
        }
    }
    for (name, (_, at)) in longest {
        plot.draw(&Text::new(
            name.to_string(),
            (at.x, at.y),
            ("sans-serif", 15).into_font().color(&RGBColor(120, 0, 120)),
        ))?;
    }
    Ok(())
}
