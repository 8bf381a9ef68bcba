//! The comparison's picture per scene (plotters, SVG and PNG): memory against wrong answers and
//! insertion time against wrong answers, one point per representation, log-scaled costs.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::SceneResult;
use crate::chart::{DrawResult, both};
use crate::error::Result;

const COLOURS: [RGBColor; 7] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
];

/// Draws `<dir>/<stem>.svg` and `.png` for `scene`.
pub fn draw(scene: &SceneResult, dir: &Path, stem: &str) -> Result<()> {
    both(
        dir,
        stem,
        (1100, 480),
        |root| draw_on(root, scene),
        |root| draw_on(root, scene),
    )
}

type Point = (String, f64, f64);

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[Point],
    x_desc: &str,
) -> DrawResult {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let (x_lo, x_hi) = points.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.1), hi.max(p.1))
    });
    let y_hi = points.iter().map(|p| p.2).fold(1.0, f64::max) * 1.2;
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(56)
        .build_cartesian_2d(
            (x_lo.max(1e-6) / 2.0..x_hi.max(1e-6) * 2.0).log_scale(),
            0.0..y_hi,
        )
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc("wrong answers, % of poses")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    for (k, (name, x, y)) in points.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        chart
            .draw_series([Circle::new((*x, *y), 6, colour.filled())])
            .map_err(e)?
            .label(name.as_str())
            .legend(move |(a, b)| Circle::new((a + 8, b), 5, colour.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)?;
    Ok(())
}

fn draw_on<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, scene: &SceneResult) -> DrawResult {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let title = format!(
        "{} ({}): {} poses, {} colliding",
        scene.scenario, scene.vehicle, scene.poses.0, scene.poses.1
    );
    let root = root.titled(&title, ("sans-serif", 18)).map_err(e)?;
    let panels = root.split_evenly((1, 2));
    let wrong = |r: &super::Row| r.judged.all.wrong_percent();
    let memory: Vec<Point> = scene
        .rows
        .iter()
        .map(|r| (r.name.clone(), r.memory_window_bytes as f64 / 1e6, wrong(r)))
        .collect();
    let time: Vec<Point> = scene
        .rows
        .iter()
        .filter(|r| r.insert_ms.is_finite())
        .map(|r| (r.name.clone(), r.insert_ms, wrong(r)))
        .collect();
    panel(
        &panels[0],
        &memory,
        "memory over the 210 m window, MB (log)",
    )?;
    panel(&panels[1], &time, "insertion of one revolution, ms (log)")?;
    Ok(())
}
