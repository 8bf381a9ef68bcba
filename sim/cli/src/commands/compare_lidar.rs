//! `taxi-sim compare-lidar`: a real Velodyne capture's figures against the simulator's HDL-32E
//! at the same height over flat ground, as a Markdown table (and JSON with every beam).

use std::path::PathBuf;

use anyhow::Context as _;
use sim::scenario::RunConfig;
use sim::studies::lidar_compare::{real, rows, synthetic, table};

/// Arguments of `taxi-sim compare-lidar`.
#[derive(Debug, Clone, clap::Args)]
pub struct CompareLidarArgs {
    /// The real sensor's capture (pcap or pcapng).
    #[arg(long, value_name = "FILE")]
    pub pcap: PathBuf,
    /// The sensor's VeloView calibration file (XML; default: its built-in table).
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
    /// Run configuration (TOML) whose `[lidar]` and obstacle-test settings to use (default: the
    /// defaults).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Remission of the synthetic flat ground (0-1).
    #[arg(long, default_value_t = 0.2)]
    pub remission: f32,
    /// Revolutions of the synthetic sensor (default: the capture's full revolutions).
    #[arg(long)]
    pub revolutions: Option<usize>,
    /// Seed of the synthetic sensor's noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write both sensors' figures, every beam's, here (atomically): one JSON object, one line.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// Runs `taxi-sim compare-lidar`.
pub fn run(args: &CompareLidarArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        (0.0..=1.0).contains(&args.remission),
        "--remission {}: a remission is 0 to 1",
        args.remission
    );
    let config = match &args.config {
        Some(path) => RunConfig::from_file(path)?,
        None => RunConfig::default(),
    };
    let test = config.mapping.map.obstacle_test;
    let recording = sim::pcap::read(&args.pcap, args.calibration.as_deref())?;
    if let Some(line) = recording.skipped_line(&args.pcap) {
        eprintln!("{line}");
    }
    let label = format!("real ({})", args.pcap.display());
    let real = real(&recording, &label, test).with_context(|| args.pcap.display().to_string())?;
    let revolutions = args.revolutions.unwrap_or(real.revolutions).max(1);
    let synthetic = synthetic(
        &config.lidar,
        real.height_m,
        args.remission,
        revolutions,
        args.seed,
        test,
    )?;
    if let Some(path) = &args.json {
        // One object on one line, as every `--json` writes.
        let text = serde_json::to_string(&serde_json::json!({
            "sensors": [&real, &synthetic],
            "rows": rows(&real, &synthetic),
        }))? + "\n";
        mapper::write_atomically(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    crate::emit(&table(&real, &synthetic))
}
