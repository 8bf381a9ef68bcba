//! The tuning pictures, drawn with plotters as SVG and PNG: the Pareto front (safety against
//! conservatism, coloured by the check's cost) and a model's circles over its footprints, one
//! panel per level. The PNG's text uses the bundled DejaVu Sans (`sim/assets/fonts`), so a
//! machine without fonts draws the same picture.

use std::path::Path;

use aircraft::FittedModel;
use aircraft::footprint::Footprint;
use mapper::CollisionModel;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::SettingFigures;
use crate::chart::{DrawResult, both};
use crate::error::Result;

/// A colour for a cost between `lo` and `hi` (viridis-like: dark blue cheap, yellow dear).
fn cost_colour(x: f64, lo: f64, hi: f64) -> RGBColor {
    let t = if hi > lo {
        ((x - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let stops = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let s = t * (stops.len() - 1) as f64;
    let i = (s.floor() as usize).min(stops.len() - 2);
    let f = s - i as f64;
    let (a, b) = (stops[i], stops[i + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// One scatter panel: each setting at `at(f)`, coloured by `colour(f)`, large when on the
/// Pareto front, ringed when recommended, labelled with its index.
fn scatter<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    figures: &[SettingFigures],
    recommended: Option<usize>,
    (x_desc, y_desc): (&str, &str),
    at: &dyn Fn(&SettingFigures) -> (f64, f64),
    colour: &dyn Fn(&SettingFigures) -> RGBColor,
) -> DrawResult {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let x_top = figures.iter().map(|f| at(f).0).fold(0.1, f64::max) * 1.15;
    let y_top = figures.iter().map(|f| at(f).1).fold(1.0, f64::max) * 1.15;
    let mut chart = ChartBuilder::on(panel)
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(56)
        .build_cartesian_2d(-0.03 * x_top..x_top, -0.03 * y_top..y_top)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    for f in figures {
        let p = at(f);
        let size = if f.non_dominated { 7 } else { 4 };
        chart
            .draw_series([Circle::new(p, size, colour(f).filled())])
            .map_err(e)?;
        if Some(f.setting) == recommended {
            chart
                .draw_series([Circle::new(p, 11, BLACK.stroke_width(2))])
                .map_err(e)?;
        }
        let label = ("sans-serif", 12).into_font().color(&BLACK);
        chart
            .draw_series([Text::new(format!("{}", f.setting), p, label)])
            .map_err(e)?;
    }
    Ok(())
}

fn pareto_on<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    figures: &[SettingFigures],
    recommended: Option<usize>,
) -> DrawResult {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(e)?;
    let height = root.dim_in_pixel().1;
    let (main, foot) = root.split_vertically(height.saturating_sub(30));
    let panels = main.split_evenly((1, 2));
    let (lo, hi) = figures
        .iter()
        .map(|f| f.probe.circle_ns)
        .fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    scatter(
        &panels[0],
        figures,
        recommended,
        (
            "safe failures per run (false stops, needless deviations, pilot calls)",
            "unsafe runs, %",
        ),
        &|f| (f.conservative_rate(), 100.0 * f.unsafe_rate()),
        &|f| cost_colour(f.probe.circle_ns, lo, hi),
    )?;
    scatter(
        &panels[1],
        figures,
        recommended,
        (
            "false alarms against the exact reference, %",
            "ns per pose check",
        ),
        &|f| {
            (
                100.0 * f.probe.comparison.false_alarm_rate(),
                f.probe.circle_ns,
            )
        },
        &|f| match (f.unsafe_runs > 0, f.failed_runs > f.unsafe_runs) {
            (true, _) => RGBColor(214, 39, 40),
            (false, true) => RGBColor(255, 127, 14),
            _ => RGBColor(31, 119, 180),
        },
    )?;
    foot.draw(&Text::new(
        format!(
            "left: ns per check {lo:.0} (dark) to {hi:.0} (yellow); right: red unsafe, orange a safe failure, blue neither; large: Pareto front; ringed: recommended"
        ),
        (14, 6),
        ("sans-serif", 13).into_font().color(&BLACK),
    ))
    .map_err(e)?;
    root.present().map_err(e)
}

/// Writes `dir/pareto.svg` and `dir/pareto.png`.
pub fn pareto(
    dir: &Path,
    name: &str,
    figures: &[SettingFigures],
    recommended: Option<usize>,
) -> Result<()> {
    let title = format!("{name}: safety against conservatism per setting");
    both(
        dir,
        "pareto",
        (1200, 560),
        |r| pareto_on(r, &title, figures, recommended),
        |r| pareto_on(r, &title, figures, recommended),
    )
}

/// Points of a disc's boundary.
fn disc_points(cx: f64, cy: f64, r: f64) -> Vec<(f64, f64)> {
    (0..=64)
        .map(|k| {
            let a = k as f64 / 64.0 * std::f64::consts::TAU;
            (cx + r * a.cos(), cy + r * a.sin())
        })
        .collect()
}

fn model_on<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    fit: &FittedModel,
    model: &CollisionModel,
) -> DrawResult {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(e)?;
    let b = model.bounding_circle();
    let (mut lo, mut hi) = (
        (b.center.x - b.radius_m, b.center.y - b.radius_m),
        (b.center.x + b.radius_m, b.center.y + b.radius_m),
    );
    for l in &fit.levels {
        for f in &l.footprints {
            let (a, c) = f.bounds();
            lo = (lo.0.min(a.x), lo.1.min(a.y));
            hi = (hi.0.max(c.x), hi.1.max(c.y));
        }
    }
    let panels = root.split_evenly((1, fit.levels.len().max(1)));
    let palette = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
    ];
    for (k, (panel, level)) in panels.iter().zip(&fit.levels).enumerate() {
        let colour = palette[k % palette.len()];
        let own = model.circles().iter().filter(|c| c.level == k).count();
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("level {k}: h = {} m, {own} circles", level.height_m),
                ("sans-serif", 15),
            )
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(lo.0 - 0.5..hi.0 + 0.5, lo.1 - 0.5..hi.1 + 0.5)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("x, m (forward)")
            .y_desc("y, m (left)")
            .draw()
            .map_err(e)?;
        for f in &level.footprints {
            let pts = match f {
                Footprint::Polygon(p) => p.vertices().iter().map(|v| (v.x, v.y)).collect(),
                Footprint::Disc(d) => disc_points(d.center.x, d.center.y, d.radius_m),
            };
            chart
                .draw_series([Polygon::new(pts, RGBColor(200, 200, 200).filled())])
                .map_err(e)?;
        }
        for c in model.circles().iter().filter(|c| c.level == k) {
            chart
                .draw_series([PathElement::new(
                    disc_points(c.x_m, c.y_m, c.radius_m),
                    colour.stroke_width(2),
                )])
                .map_err(e)?;
        }
    }
    root.present().map_err(e)
}

/// Writes `<dir>/<stem>.svg` and `.png`: the footprints of `fit`'s levels in grey and `model`'s
/// circles of each level over them.
pub fn model(
    dir: &Path,
    stem: &str,
    title: &str,
    fit: &FittedModel,
    model: &CollisionModel,
) -> Result<()> {
    let w = 520 * fit.levels.len().max(1) as u32;
    both(
        dir,
        stem,
        (w, 560),
        |r| model_on(r, title, fit, model),
        |r| model_on(r, title, fit, model),
    )
}
