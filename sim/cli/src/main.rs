//! The `taxi-sim` command line: scenario checks and scans, benchmarks, the mapping demo, vehicle
//! model fitting.
//!
//! The only place that knows the terminal: progress bars, tables, exit codes (0 success,
//! 2 bad input or failure; clap's own usage errors also exit 2).

mod commands;

use std::process::ExitCode;

use clap::{Parser, Subcommand};
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
    Demo(commands::demo::DemoArgs),
    /// Measure the headline performance figures on this machine.
    Bench(commands::bench::BenchArgs),
    /// Run a scenario in closed loop (builds its offline map first when missing or stale).
    /// Exit code 0 when every expectation held, 1 when one did not, 2 on bad input.
    Run(commands::run::RunArgs),
    /// The shipped stack as a ROS 2 node (`/taxi_stack`) for `run --stack ros2`: it takes the
    /// run's flags as its parameters, answers each step's `/cmd_vel`, and ends when the simulator
    /// leaves. `run --stack ros2 --stack-command "taxi-sim stack FILE"` gives the report of
    /// `run FILE --stack node`.
    Stack(commands::node::NodeArgs),
    /// The mapping drive: build a scenario's offline multi-height map.
    Map(commands::map::MapArgs),
    /// Validate a scenario file and print a summary.
    Check(commands::check::CheckArgs),
    /// Write one LiDAR revolution of a scenario's world, or of a Velodyne capture, as PLY.
    Scan(commands::scan::ScanArgs),
    /// A real Velodyne capture's figures against the simulator's HDL-32E at the same height.
    CompareLidar(commands::compare_lidar::CompareLidarArgs),
    /// Vehicle collision models.
    #[command(subcommand)]
    Model(ModelCommand),
    /// Print the default run configuration as TOML (a starting point for `run --config`).
    Config,
    /// Sweep obstacle heights and speeds: the range each obstacle is first mapped at and whether
    /// the vehicle keeps off it.
    SmallObstacles(commands::small::SmallArgs),
    /// Scenario regressions: every scenario file under the paths (default `scenarios`) run in
    /// parallel against its own expectations, with JUnit XML, JSON lines and a Markdown summary.
    /// Exit code 0 when every case passed or is a known problem failing as stated, 1 when one
    /// failed, 2 when a file is not a valid scenario (the run goes on) or on bad input.
    Regress(commands::regress::RegressArgs),
    /// Campaigns: scenario families sampled, run in parallel, searched for failures.
    #[command(subcommand)]
    Campaign(commands::campaign::CampaignCommand),
    /// Airport files (X-Plane apt.dat): summary, picture, taxi routes.
    #[command(subcommand)]
    Airport(commands::airport::AirportCommand),
    /// Tune the collision model: run a campaign whose parameters are model settings, then
    /// compare them (Pareto front, exact reference, recommended model, pictures).
    /// Exit code 0 when a setting had no unsafe run, 1 when none did, 2 on bad input.
    Tune(commands::tune::TuneArgs),
}

#[derive(Subcommand)]
enum ModelCommand {
    /// Fit a vehicle's height-tagged circle model and print coverage per level.
    Fit(commands::model::ModelFitArgs),
    /// Print every part's underside and the candidate heights of interest they give.
    Levels(commands::model::ModelLevelsArgs),
    /// What the vehicle's LiDAR cannot see, per height level: the blind ground around the
    /// airframe (area, nearest to each gear and wing tip, how far ahead), with a picture.
    Coverage(commands::coverage::ModelCoverageArgs),
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
        Command::Run(args) => commands::run::run(&args).map(|met| {
            if met {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
        Command::Campaign(cmd) => commands::campaign::run(&cmd).map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
        Command::Regress(args) => commands::regress::run(&args).map(ExitCode::from),
        Command::Tune(args) => commands::tune::run(&args).map(|ok| {
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
        Command::Demo(args) => commands::demo::run(&args),
        Command::Bench(args) => commands::bench::run(&args),
        Command::Model(ModelCommand::Fit(args)) => commands::model::run(&args),
        Command::Model(ModelCommand::Levels(args)) => commands::model::levels(&args),
        Command::Model(ModelCommand::Coverage(args)) => commands::coverage::run(&args),
        Command::SmallObstacles(args) => commands::small::run(&args),
        Command::CompareLidar(args) => commands::compare_lidar::run(&args),
        Command::Check(args) => commands::check::run(&args),
        Command::Map(args) => commands::map::run(&args),
        Command::Stack(args) => commands::node::serve(&args),
        Command::Run(_) | Command::Campaign(_) | Command::Tune(_) | Command::Regress(_) => {
            unreachable!("dispatched in run")
        }
        Command::Scan(args) => commands::scan::run(&args),
        Command::Airport(cmd) => commands::airport::run(&cmd),
        Command::Config => emit(&sim::scenario::RunConfig::default().to_toml()),
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
