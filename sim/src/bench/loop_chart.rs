//! The picture of `bench loop --out DIR`: where a revolution's wall time goes, one stacked bar
//! per scenario (`loop_stages.svg` and `.png`), from the median sequential run's stage
//! counters - each stage there has both cores to itself, so the bar's length is the wall time a
//! revolution takes when nothing overlaps.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::closed_loop::StageSplit;
use crate::error::Result;

/// The picture's file stem.
pub const STEM: &str = "loop_stages";

/// Draws `splits` into `<dir>/loop_stages.svg` and `.png` (written atomically). Nothing to draw
/// is an error, not an empty picture.
pub fn draw(splits: &[StageSplit], dir: &Path) -> Result<()> {
    if splits.is_empty() {
        return Err(crate::Error::Invalid(
            "bench loop: no scenario measured, nothing to draw".into(),
        ));
    }
    std::fs::create_dir_all(dir).map_err(|source| crate::Error::Io {
        what: "creating the picture's directory",
        path: dir.to_path_buf(),
        source,
    })?;
    let size = (900, 200 + 80 * splits.len() as u32);
    crate::chart::both(
        dir,
        STEM,
        size,
        |root| draw_on(&root, splits),
        |root| draw_on(&root, splits),
    )
}

/// The label of a scenario's bar: its name, real-time factor and milliseconds a revolution.
fn label(s: &StageSplit) -> String {
    let total: f64 = s.ms_per_revolution.iter().sum();
    format!(
        "{} ({:.1}x, {:.1} ms)",
        s.scenario, s.real_time_factor, total
    )
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    splits: &[StageSplit],
) -> crate::chart::DrawResult {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let longest = splits
        .iter()
        .map(|s| s.ms_per_revolution.iter().sum::<f64>())
        .fold(0.0f64, f64::max);
    let n = splits.len();
    // A row a scenario, the first at the top: its label, then its bar below it.
    let row = |i: usize| (n - 1 - i) as f64;
    let mut chart = ChartBuilder::on(root)
        .caption(
            "Wall time of one revolution (0.1 s simulated) by stage, sequential schedule",
            ("sans-serif", 17),
        )
        .margin(12)
        .x_label_area_size(36)
        // Room on the right for the legend.
        .build_cartesian_2d(0.0..(longest * 1.4).max(1.0), 0.0..n as f64)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .disable_y_axis()
        .x_desc("milliseconds per revolution")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    let labels = splits.iter().enumerate().map(|(i, s)| {
        Text::new(
            label(s),
            (0.0, row(i) + 0.95),
            ("sans-serif", 14).into_font(),
        )
    });
    chart.draw_series(labels).map_err(err)?;
    for (k, stage) in super::STAGES.iter().enumerate() {
        let colour = crate::chart::PALETTE[k % crate::chart::PALETTE.len()];
        let bars = splits.iter().enumerate().map(|(i, s)| {
            let before: f64 = s.ms_per_revolution[..k].iter().sum();
            let ms = s.ms_per_revolution[k];
            Rectangle::new(
                [(before, row(i) + 0.1), (before + ms, row(i) + 0.65)],
                colour.filled(),
            )
        });
        chart
            .draw_series(bars)
            .map_err(err)?
            .label(stage.replace('_', " "))
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split(name: &str, ms: [f64; 6]) -> StageSplit {
        StageSplit {
            scenario: name.into(),
            real_time_factor: 20.0,
            ms_per_revolution: ms,
        }
    }

    /// The picture is drawn both ways, and a bar's label says its scenario, factor and total.
    #[test]
    fn draws_a_bar_per_scenario_with_its_total() {
        let dir = tempfile::tempdir().unwrap();
        let splits = [
            split("parking_lot", [1.0, 2.0, 0.5, 0.1, 0.2, 0.7]),
            split("ksyr", [2.0, 2.5, 0.5, 0.1, 0.3, 0.6]),
        ];
        draw(&splits[..1], dir.path()).unwrap(); // one bar
        draw(&splits, dir.path()).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("loop_stages.svg")).unwrap();
        assert!(svg.contains("parking_lot (20.0x, 4.5 ms)"), "{svg}");
        assert!(svg.contains("ksyr (20.0x, 6.0 ms)"));
        assert!(svg.contains("localization") && svg.contains("distance maps"));
        let png = std::fs::read(dir.path().join("loop_stages.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        assert!(draw(&[], dir.path()).is_err());
    }
}
