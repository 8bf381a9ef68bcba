//! `taxi-sim demo`: a mapping drive through the mapper's synthetic parking lot with the
//! fake-wing car, exporting every level.

use std::fmt::Write as _;
use std::path::PathBuf;

use crate::{bar, emit};

/// Arguments of `taxi-sim demo`.
#[derive(Debug, Clone, clap::Args)]
pub struct DemoArgs {
    /// Output directory.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Scans along the 90 m drive.
    #[arg(long, default_value_t = 180)]
    pub scans: usize,
    /// Seed of the range noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Runs `taxi-sim demo`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let DemoArgs { out, scans, seed } = args.clone();
    let options = sim::studies::demo::DemoOptions {
        out: out.clone(),
        scans,
        seed,
        range_noise_m: 0.02,
    };
    let progress = bar(scans as u64, "mapping");
    let summary =
        sim::studies::demo::run(&options, &mut |done, _| progress.set_position(done as u64))?;
    progress.finish_and_clear();
    let mut t = String::new();
    writeln!(
        t,
        "mapping drive: {} scans, {} returns, {} self-hits dropped, {} re-centrings",
        summary.scans, summary.returns, summary.self_hits, summary.recentres
    )?;
    writeln!(
        t,
        "insert + distance maps: {:.1} ms per scan (mean)",
        summary.ms_per_scan
    )?;
    writeln!(
        t,
        "{:>6} {:>10} {:>15}",
        "level", "height_m", "occupied_cells"
    )?;
    for (k, (h, n)) in summary.levels.iter().enumerate() {
        writeln!(t, "{k:>6} {h:>10.2} {n:>15}")?;
    }
    writeln!(
        t,
        "{} block files in {}",
        summary.blocks,
        out.join("blocks").display()
    )?;
    writeln!(t, "wrote:")?;
    for f in &summary.files {
        writeln!(t, "  {}", f.display())?;
    }
    emit(&t)
}
