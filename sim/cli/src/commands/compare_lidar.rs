//! `taxi-sim compare-lidar`: a real Velodyne capture's figures against the simulator's HDL-32E
//! at the same height over flat ground, as a Markdown table (and JSON with every beam).

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Context as _;
use sim::scenario::RunConfig;
use sim::studies::lidar_compare::{Figures, real, synthetic};

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
    /// Write both sensors' figures, every beam's, as JSON here (atomically).
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
        let text = serde_json::to_string_pretty(&[&real, &synthetic])?;
        mapper::write_atomically(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    crate::emit(&table(&real, &synthetic))
}

/// The two sensors side by side.
fn table(real: &Figures, synthetic: &Figures) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "| figure | {} | {} |\n| --- | --- | --- |",
        real.label, synthetic.label
    );
    let mut row = |name: &str, f: &dyn Fn(&Figures) -> String| {
        let _ = writeln!(t, "| {name} | {} | {} |", f(real), f(synthetic));
    };
    row("revolutions", &|f| f.revolutions.to_string());
    row("firings a revolution", &|f| {
        format!("{:.0}", f.firings_per_revolution)
    });
    row("returns a revolution", &|f| {
        format!("{:.0}", f.returns_per_revolution)
    });
    row("no return, beams 8 deg or more down (mean, max)", &|f| {
        let low: Vec<f64> = f
            .elevations_deg
            .iter()
            .zip(&f.no_return)
            .filter(|(w, _)| **w <= -8.0)
            .map(|(_, n)| *n)
            .collect();
        let mean = low.iter().sum::<f64>() / low.len().max(1) as f64;
        let max = low.iter().copied().fold(0.0, f64::max);
        format!("{:.1} %, {:.1} %", 100.0 * mean, 100.0 * max)
    });
    row("no return, beams above 8 deg down (mean)", &|f| {
        let high: Vec<f64> = f
            .elevations_deg
            .iter()
            .zip(&f.no_return)
            .filter(|(w, _)| **w > -8.0)
            .map(|(_, n)| *n)
            .collect();
        format!(
            "{:.1} %",
            100.0 * high.iter().sum::<f64>() / high.len().max(1) as f64
        )
    });
    row("ground returns a revolution", &|f| {
        format!("{:.0}", f.ground_returns_per_revolution)
    });
    row("height above the fitted ground", &|f| {
        format!("{:.3} m", f.height_m)
    });
    row("pitch, roll (fitted)", &|f| {
        format!("{:.2}, {:.2} deg", f.pitch_roll_deg[0], f.pitch_roll_deg[1])
    });
    row("ground spread about the plane (std)", &|f| {
        format!("{:.1} mm", 1000.0 * f.ground_spread_m)
    });
    row(
        "range noise along the beam (consecutive firings on the ground)",
        &|f| format!("{:.1} mm", 1000.0 * f.range_noise_m),
    );
    row(
        "ground rings against h / tan(elevation) (median error)",
        &|f| {
            let mut e: Vec<f64> = f
                .elevations_deg
                .iter()
                .zip(&f.ring_radius_m)
                .filter_map(|(w, r)| {
                    let expected = f.height_m / (-w.to_radians()).tan();
                    r.map(|r| 100.0 * (r - expected) / expected)
                })
                .collect();
            e.sort_by(f64::total_cmp);
            e.get(e.len() / 2)
                .map_or("-".into(), |m| format!("{m:+.1} % ({} rings)", e.len()))
        },
    );
    row("ground intensity 10 / 50 / 90 % (0-255)", &|f| {
        let d = &f.ground_intensity_deciles;
        format!("{:.0} / {:.0} / {:.0}", d[0], d[4], d[8])
    });
    row(
        "ground returns taken for obstacles a revolution: level; tilt removed; and no unsafe height",
        &|f| {
            let [a, b, c] = f.false_obstacles_per_revolution;
            format!("{a:.0}; {b:.0}; {c:.0}")
        },
    );
    t
}
