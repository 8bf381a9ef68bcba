//! `taxi-sim small-obstacles`: the small-obstacle sweep (heights x speeds), with a progress bar,
//! a Markdown table on stdout and, with `--out`, the rows as CSV and JSON (written atomically).

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Context as _;
use indicatif::{ProgressBar, ProgressStyle};
use sim::scenario::RunConfig;
use sim::studies::small_obstacles::{SweepRow, SweepSpec, run_sweep};

/// Arguments of `taxi-sim small-obstacles`.
#[derive(Debug, Clone, clap::Args)]
pub struct SmallArgs {
    /// A shipped vehicle or a sidecar path; the obstacle stands in its left wheels' path.
    #[arg(long, default_value = "iara_car")]
    pub vehicle: String,
    /// Obstacle heights, metres, comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0.05,0.08,0.1,0.12,0.15,0.2,0.3"
    )]
    pub heights: Vec<f64>,
    /// Route speeds, m/s, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "2,3,4,5,6,8")]
    pub speeds: Vec<f64>,
    /// Runs per (height, speed): the obstacle moved by a fraction of a revolution's travel.
    #[arg(long, default_value_t = 4)]
    pub phases: usize,
    /// Seed of every run.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Run configuration (TOML; `taxi-sim config` prints the defaults).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Write `small_obstacles.csv` and `.json` here, each run's scenario in `scenarios/` and the
    /// road's offline map in `map/`.
    #[arg(long, default_value = "out/small_obstacles")]
    pub out: PathBuf,
}

/// Runs `taxi-sim small-obstacles`.
pub fn run(args: &SmallArgs) -> anyhow::Result<()> {
    let bad = |v: &f64| !(v.is_finite() && *v > 0.0);
    if args.heights.is_empty() || args.heights.iter().any(bad) {
        anyhow::bail!(
            "--heights: each must be a finite number > 0 (got {:?})",
            args.heights
        );
    }
    if args.speeds.is_empty() || args.speeds.iter().any(bad) {
        anyhow::bail!(
            "--speeds: each must be a finite number > 0 (got {:?})",
            args.speeds
        );
    }
    let config = match &args.config {
        Some(path) => RunConfig::from_file(path)?,
        None => RunConfig::default(),
    };
    let spec = SweepSpec {
        vehicle: args.vehicle.clone(),
        heights_m: args.heights.clone(),
        speeds_m_s: args.speeds.clone(),
        phases: args.phases.max(1),
        seed: args.seed,
        config,
    };
    let bar = ProgressBar::new((args.heights.len() * args.speeds.len() * spec.phases) as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {msg} [{elapsed} < {eta}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let hit = std::sync::atomic::AtomicUsize::new(0);
    let rows = run_sweep(&spec, &args.out, &|row| {
        if !row.avoided() {
            hit.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        bar.set_message(format!(
            "{} not avoided",
            hit.load(std::sync::atomic::Ordering::Relaxed)
        ));
        bar.inc(1);
    })
    .with_context(|| format!("the small-obstacle sweep of {}", args.vehicle))?;
    bar.finish_and_clear();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let csv = args.out.join("small_obstacles.csv");
    mapper::write_atomically(&csv, csv_text(&rows).as_bytes())
        .with_context(|| format!("writing {}", csv.display()))?;
    let json = args.out.join("small_obstacles.json");
    mapper::write_atomically(&json, serde_json::to_string_pretty(&rows)?.as_bytes())
        .with_context(|| format!("writing {}", json.display()))?;
    crate::emit(&table(&rows, &args.speeds))?;
    crate::emit(&format!("wrote {} and {}\n", csv.display(), json.display()))
}

fn csv_text(rows: &[SweepRow]) -> String {
    let mut t =
        String::from("height_m,speed_m_s,first_mapped_m,outcome,contacts,min_clearance_m\n");
    for r in rows {
        let _ = writeln!(
            t,
            "{},{},{},{},{},{:.3}",
            r.height_m,
            r.speed_m_s,
            r.first_mapped_m
                .map_or(String::new(), |m| format!("{m:.2}")),
            r.outcome,
            r.contacts,
            r.min_clearance_m
        );
    }
    t
}

/// One line per height, one column per speed: over the phases, the range it was first mapped
/// at (nearest to farthest) and what the vehicle did (every outcome seen; hits first).
fn table(rows: &[SweepRow], speeds: &[f64]) -> String {
    let mut t = String::from("| height m |");
    for v in speeds {
        let _ = write!(t, " {v} m/s |");
    }
    t.push_str("\n| --- |");
    for _ in speeds {
        t.push_str(" --- |");
    }
    t.push('\n');
    let mut heights: Vec<f64> = rows.iter().map(|r| r.height_m).collect();
    heights.dedup();
    for h in heights {
        let _ = write!(t, "| {h} |");
        for v in speeds {
            let runs: Vec<&SweepRow> = rows
                .iter()
                .filter(|r| r.height_m == h && r.speed_m_s == *v)
                .collect();
            let _ = write!(t, " {} |", cell(&runs));
        }
        t.push('\n');
    }
    t
}

/// One table cell: "mapped at 43.6-44.0 m, deviated" or "never mapped, **hit 4/4**".
fn cell(runs: &[&SweepRow]) -> String {
    if runs.is_empty() {
        return "-".into();
    }
    let ranges: Vec<f64> = runs.iter().filter_map(|r| r.first_mapped_m).collect();
    let seen = match (
        ranges.iter().copied().reduce(f64::min),
        ranges.iter().copied().reduce(f64::max),
    ) {
        (Some(lo), Some(hi)) if ranges.len() == runs.len() && hi - lo < 0.05 => {
            format!("mapped at {lo:.1} m")
        }
        (Some(lo), Some(hi)) if ranges.len() == runs.len() => {
            format!("mapped at {lo:.1}-{hi:.1} m")
        }
        (Some(lo), Some(hi)) => format!(
            "mapped at {lo:.1}-{hi:.1} m in {}/{} runs",
            ranges.len(),
            runs.len()
        ),
        _ => "never mapped".into(),
    };
    let hits = runs.iter().filter(|r| r.contacts > 0).count();
    let mut outcomes: Vec<&str> = runs
        .iter()
        .filter(|r| r.contacts == 0)
        .map(|r| r.outcome.as_str())
        .collect();
    outcomes.sort_unstable();
    outcomes.dedup();
    let mut did = Vec::new();
    if hits > 0 {
        did.push(format!("**hit {hits}/{}**", runs.len()));
    }
    did.extend(outcomes.iter().map(|o| o.to_string()));
    format!("{seen}, {}", did.join(" / "))
}
