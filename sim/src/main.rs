//! The `taxi-sim` command line: scenario checks and scans, benchmarks, the mapping demo, vehicle
//! model fitting.
//!
//! The only place that knows the terminal: progress bars, tables, exit codes (0 success,
//! 2 bad input or failure; clap's own usage errors also exit 2).

mod cli;

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Parser)]
#[command(
    name = "taxi-sim",
    version,
    about = "Closed-loop taxi simulator around a quantized multi-height occupancy grid map"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build a two-level map of a synthetic parking lot with the fake-wing car and export every level.
    Demo {
        /// Output directory.
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
        /// Scans along the 90 m drive.
        #[arg(long, default_value_t = 180)]
        scans: usize,
        /// Seed of the range noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Measure the headline performance figures on this machine.
    Bench {
        /// What to measure.
        what: BenchTarget,
        /// One JSON object per figure on stdout instead of a table.
        #[arg(long)]
        json: bool,
        /// Timed batches per figure, the median reported (default 15; `bench loop`: runs of each
        /// schedule, in alternation, default 1 - it then says it ran once).
        #[arg(long)]
        samples: Option<usize>,
        /// Scenario of `bench loop` and `bench blocks`.
        #[arg(long, default_value = "scenarios/parking_lot.toml")]
        scenario: PathBuf,
        /// Laps of `bench loop` (default 1; 0: the scenario's own).
        #[arg(long, default_value_t = 1)]
        laps: u32,
        /// Campaign of `bench campaign`.
        #[arg(long, default_value = "scenarios/campaigns/parking_lot_random.toml")]
        campaign: PathBuf,
        /// `bench campaign`: variants a round, run both ways.
        #[arg(long, default_value_t = 4)]
        variants: u64,
        /// `bench campaign`: rounds (the median is reported).
        #[arg(long, default_value_t = 3)]
        rounds: usize,
        /// `bench campaign`: runs at a time, both ways (default: the cores).
        #[arg(long)]
        jobs: Option<usize>,
    },
    /// Run a scenario in closed loop (builds its offline map first when missing or stale).
    /// Exit code 0 when every expectation held, 1 when one did not, 2 on bad input.
    Run(cli::run::RunArgs),
    /// The mapping drive: build a scenario's offline multi-height map.
    Map(cli::run::MapArgs),
    /// Validate a scenario file and print a summary.
    Check(cli::check::CheckArgs),
    /// Write one LiDAR revolution of a scenario's world as PLY.
    Scan(cli::scan::ScanArgs),
    /// Vehicle collision models.
    #[command(subcommand)]
    Model(ModelCommand),
    /// Print the default run configuration as TOML (a starting point for `run --config`).
    Config,
    /// Sweep obstacle heights and speeds: the range each obstacle is first mapped at and whether
    /// the vehicle keeps off it.
    SmallObstacles(cli::small::SmallArgs),
    /// Campaigns: scenario families sampled, run in parallel, searched for failures.
    #[command(subcommand)]
    Campaign(cli::campaign::CampaignCommand),
    /// Tune the collision model: run a campaign whose parameters are model settings, then
    /// compare them (Pareto front, exact reference, recommended model, pictures).
    /// Exit code 0 when a setting had no unsafe run, 1 when none did, 2 on bad input.
    Tune(cli::tune::TuneArgs),
}

#[derive(Subcommand)]
enum ModelCommand {
    /// Fit a vehicle's height-tagged circle model and print coverage per level.
    Fit(cli::model::ModelFitArgs),
    /// Print every part's underside and the candidate heights of interest they give.
    Levels(cli::model::ModelLevelsArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum BenchTarget {
    /// Scan insertion, exact EDT vs chamfer, pose checks.
    Mapper,
    /// One HDL-32E revolution: the fast cast vs Rapier's generic per-ray query.
    Lidar,
    /// The closed loop on `--scenario`: real-time factor and wall time per stage.
    Loop,
    /// A campaign's runs per hour against the same variants as separate `taxi-sim run`
    /// processes.
    Campaign,
    /// The offline map of `--scenario` (built if missing): its blocks written and read in the
    /// compressed format against the uncompressed one, and bytes per block.
    Blocks,
    /// The particle filter on `--scenario`'s offline map (built if missing): one revolution's
    /// update, the weighing's tables against the straightforward way (one thread each).
    Localization,
}

/// Raised by [`emit`] when stdout's reader went away (`taxi-sim ... | head`): not an error.
#[derive(Debug, thiserror::Error)]
#[error("stdout closed")]
struct StdoutClosed;

/// Writes to stdout; a closed pipe ends the command quietly instead of panicking like `print!`.
pub(crate) fn emit(text: &str) -> anyhow::Result<()> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        other => Ok(other?),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) if e.is::<StdoutClosed>() => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Run(args) => cli::run::run_cmd(&args).map(|met| {
            if met {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
        Command::Campaign(cmd) => cli::campaign::run(&cmd).map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
        Command::Tune(args) => cli::tune::run(&args).map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
        other => run_unit(other).map(|()| ExitCode::SUCCESS),
    }
}

fn run_unit(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Demo { out, scans, seed } => demo(out, scans, seed),
        Command::Bench {
            what,
            json,
            samples,
            scenario,
            laps,
            campaign,
            variants,
            rounds,
            jobs,
        } => {
            let campaign = sim::campaign::bench::CampaignBench {
                campaign: &campaign,
                variants,
                rounds,
                jobs: jobs
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                exe: std::env::current_exe()?,
            };
            bench(what, json, samples, (&scenario, laps), &campaign)
        }
        Command::Model(ModelCommand::Fit(args)) => cli::model::run(&args),
        Command::Model(ModelCommand::Levels(args)) => cli::model::levels(&args),
        Command::SmallObstacles(args) => cli::small::run(&args),
        Command::Check(args) => cli::check::run(&args),
        Command::Map(args) => cli::run::map(&args),
        Command::Run(_) | Command::Campaign(_) | Command::Tune(_) => {
            unreachable!("dispatched in run")
        }
        Command::Scan(args) => cli::scan::run(&args),
        Command::Config => emit(&sim::config::RunConfig::default().to_toml()),
    }
}

/// A progress bar in the project's style: `what`, the bar, position, elapsed time and ETA.
pub(crate) fn bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(
            "{msg:>10} [{bar:40}] {pos}/{len} {elapsed_precise} eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

fn demo(out: PathBuf, scans: usize, seed: u64) -> anyhow::Result<()> {
    let options = sim::demo::DemoOptions {
        out: out.clone(),
        scans,
        seed,
        range_noise_m: 0.02,
    };
    let progress = bar(scans as u64, "mapping");
    let summary = sim::demo::run(&options, &mut |done, _| progress.set_position(done as u64))?;
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

fn bench(
    what: BenchTarget,
    json: bool,
    samples: Option<usize>,
    (scenario, laps): (&std::path::Path, u32),
    campaign: &sim::campaign::bench::CampaignBench<'_>,
) -> anyhow::Result<()> {
    let progress = ProgressBar::new_spinner();
    let mut report = |what: &str| progress.set_message(format!("measuring {what}"));
    let figures = match what {
        BenchTarget::Mapper => sim::bench::mapper_figures(samples.unwrap_or(15), &mut report),
        BenchTarget::Lidar => sim::bench::lidar_figures(samples.unwrap_or(15), &mut report)?,
        BenchTarget::Loop => {
            sim::bench::loop_figures(scenario, laps, samples.unwrap_or(1), &mut report)?
        }
        BenchTarget::Campaign => sim::campaign::bench::campaign_figures(campaign, &mut report)?,
        BenchTarget::Blocks => sim::bench_blocks::figures_for(scenario, &mut report)?,
        BenchTarget::Localization => {
            sim::bench_localization::figures_for(scenario, samples.unwrap_or(15), &mut report)?
        }
    };
    progress.finish_and_clear();
    let mut t = String::new();
    if json {
        for f in &figures {
            writeln!(t, "{}", serde_json::to_string(f)?)?;
        }
        return emit(&t);
    }
    writeln!(
        t,
        "{:<45} {:>12}  {:<14} vs baseline",
        "figure", "median", "target"
    )?;
    for f in &figures {
        let vs = match (&f.baseline, f.ratio) {
            (Some(b), Some(r)) => format!("{r:.2}x ({b})"),
            _ => String::new(),
        };
        writeln!(
            t,
            "{:<45} {:>9.3} {:<2}  {:<14} {}",
            f.name,
            f.median,
            f.unit,
            f.target.unwrap_or(""),
            vs
        )?;
    }
    emit(&t)
}
