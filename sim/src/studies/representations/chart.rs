//! The comparison's picture per scene (plotters, SVG and PNG): memory against wrong answers and
//! insertion time against wrong answers, per representation (one colour each) its false alarms
//! (discs) and misses (triangles) in percent of the poses, log-scaled costs.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::SceneResult;
use crate::chart::{DrawResult, both};
use crate::error::Result;

const COLOURS: [RGBColor; 7] = crate::chart::PALETTE;

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

/// (name, colour index, cost, false alarms %, misses %).
type Point = (String, usize, f64, f64, f64);

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[Point],
    x_desc: &str,
) -> DrawResult {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let (x_lo, x_hi) = points.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.2), hi.max(p.2))
    });
    let y_hi = points.iter().map(|p| p.3.max(p.4)).fold(1.0, f64::max) * 1.3;
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
        .y_desc("% of poses: false alarms (disc), misses (triangle)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    for (name, k, x, alarms, misses) in points {
        let colour = COLOURS[k % COLOURS.len()];
        chart
            .draw_series([TriangleMarker::new((*x, *misses), 7, colour.filled())])
            .map_err(e)?;
        chart
            .draw_series([Circle::new((*x, *alarms), 6, colour.filled())])
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
    let percent = |n: usize| 100.0 * n as f64 / scene.poses.0.max(1) as f64;
    let point = |k: usize, r: &super::Row, cost: f64| -> Point {
        let a = &r.judged.all;
        (
            r.name.clone(),
            k,
            cost,
            percent(a.false_alarms),
            percent(a.misses),
        )
    };
    let memory: Vec<Point> = scene
        .rows
        .iter()
        .enumerate()
        .map(|(k, r)| point(k, r, r.memory_window_bytes as f64 / 1e6))
        .collect();
    let time: Vec<Point> = scene
        .rows
        .iter()
        .enumerate()
        .filter_map(|(k, r)| r.insert_ms.map(|ms| point(k, r, ms)))
        .collect();
    panel(
        &panels[0],
        &memory,
        "memory over the 210 m window, MB (log)",
    )?;
    panel(&panels[1], &time, "insertion of one revolution, ms (log)")?;
    Ok(())
}
