//! `taxi-sim bench`: the headline performance figures on this machine, each against its
//! straightforward baseline, as a table or JSON lines.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::ValueEnum;
use indicatif::ProgressBar;

use crate::emit;

/// Arguments of `taxi-sim bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// What to measure.
    pub what: BenchTarget,
    /// JSON lines on stdout instead of a table: one object per figure (`bench figures`: one
    /// object; `bench representations`: one per scene, as `representations.json` lists them).
    #[arg(long)]
    pub json: bool,
    /// Timed batches per figure, the median reported (default 15; `bench loop`: runs of each
    /// schedule, in alternation, default 1 - it then says it ran once).
    #[arg(long)]
    pub samples: Option<usize>,
    /// Scenario of `bench blocks` and `bench localization` (default
    /// `scenarios/parking_lot.toml`); `bench loop`: the scenarios, repeatable, one after the
    /// other (default: the parking lot); `bench representations`: the scenes, repeatable
    /// (default: the parking lot, the aerodrome, the low bridge, the footbridge and the parked
    /// jet).
    #[arg(long)]
    pub scenario: Vec<PathBuf>,
    /// `bench loop`: the scenario with this vehicle (a shipped name or a sidecar) against its
    /// own, in alternation, instead of the two schedules - what another sensor layout costs
    /// (e.g. `--scenario scenarios/jet_moves_off_after_the_walk_around.toml --vehicle
    /// praetor600_two_lidars`).
    #[arg(long, value_name = "NAME|SIDECAR")]
    pub vehicle: Option<String>,
    /// Laps of `bench loop` (default 1; 0: the scenario's own).
    #[arg(long, default_value_t = 1)]
    pub laps: u32,
    /// Campaign of `bench campaign`.
    #[arg(long, default_value = "scenarios/campaigns/parking_lot_random.toml")]
    pub campaign: PathBuf,
    /// `bench campaign`: variants a round, run both ways.
    #[arg(long, default_value_t = 4)]
    pub variants: u64,
    /// `bench campaign`: rounds (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub rounds: usize,
    /// `bench campaign`: runs at a time, both ways (default: the cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// `bench figures`: the working directory, for the maps built and each run's report and
    /// output (default: a new directory under the system's temporary directory, deleted at the
    /// end unless `--keep`). `bench loop`: draw where a revolution's wall time goes, a bar per
    /// scenario, as `loop_stages.svg` and `.png` here. `bench representations`: its tables,
    /// JSON and pictures.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// `bench figures`: keep the offline maps built (default: deleted once measured).
    #[arg(long)]
    pub keep: bool,
    /// `bench figures`: also write the JSON object to this file (atomically), for
    /// `.ci/check_figures`.
    #[arg(long, value_name = "FILE")]
    pub json_out: Option<PathBuf>,
    /// `bench figures`: end each run at this simulated time, seconds (the mapping drive is
    /// never cut): a shorter measurement of the same map and, peak memory being flat in the
    /// route's length, of about the same peak (CI's).
    #[arg(long, value_name = "S")]
    pub time_limit_s: Option<f64>,
    /// `bench representations`: how they are compared.
    #[command(flatten)]
    pub representations: super::representations::RepresentationArgs,
}

/// What `taxi-sim bench` measures.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum BenchTarget {
    /// Scan insertion, exact EDT vs chamfer, pose checks.
    Mapper,
    /// One HDL-32E revolution: the fast cast vs Rapier's generic per-ray query; a real
    /// sensor's revolution of packets decoded into a scan.
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
    /// The thesis' multi-height grids against 3D voxels, OctoMap (through its Python binding,
    /// when installed) and a 2.5D map on the same revolutions: memory, time, wrong answers
    /// against the exact collision (`--out DIR`: tables, JSON and pictures).
    Representations,
    /// The ROS 2 boundary: a 70,000-point revolution and its command over DDS against in the
    /// process, and our stack's real-time factor over ROS 2 against in the process on
    /// `--scenario`, in alternation (`--samples` rounds, default 1). Both peers in this process on
    /// `ROS_DOMAIN_ID` (else 0): run it where DDS can multicast (`deploy/ros2/netns.sh`).
    Bridge,
    /// The README's deterministic figures of a first and a later run (offline map on disk,
    /// blocks, occupied cells, peak memory), from `taxi-sim run` child processes on the
    /// aerodrome and the parking lot; run from the repository's root (a few minutes).
    Figures,
}

/// Runs `taxi-sim bench`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    if let BenchTarget::Figures = args.what {
        return super::figures::run(&super::figures::FiguresOptions {
            json: args.json,
            out: args.out.as_deref(),
            keep: args.keep,
            json_out: args.json_out.as_deref(),
            time_limit_s: args.time_limit_s,
        });
    }
    if let BenchTarget::Representations = args.what {
        return super::representations::run(
            &args.scenario,
            args.out.as_deref(),
            &args.representations,
            args.json,
        );
    }
    let scenarios = if args.scenario.is_empty() {
        vec![PathBuf::from("scenarios/parking_lot.toml")]
    } else {
        args.scenario.clone()
    };
    check_loop_options(
        args.what,
        scenarios.len(),
        args.vehicle.as_deref(),
        args.out.as_deref(),
    )?;
    let campaign = sim::bench::campaign::CampaignBench {
        campaign: &args.campaign,
        variants: args.variants,
        rounds: args.rounds,
        jobs: args
            .jobs
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        exe: std::env::current_exe()?,
    };
    bench(
        args.what,
        args.json,
        args.samples,
        (
            &scenarios,
            args.laps,
            args.vehicle.as_deref(),
            args.out.as_deref(),
        ),
        &campaign,
    )
}

/// What only `bench loop` without `--vehicle` takes - several scenarios, a picture (`--out`) -
/// refused elsewhere rather than ignored.
fn check_loop_options(
    what: BenchTarget,
    scenarios: usize,
    vehicle: Option<&str>,
    out: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    let all_scenarios = matches!(what, BenchTarget::Loop) && vehicle.is_none();
    if scenarios > 1 && !all_scenarios {
        anyhow::bail!(
            "--scenario: bench {what:?} measures one scenario ({scenarios} given); several \
             are `bench loop` without --vehicle's (and `bench representations`')"
        );
    }
    if out.is_some() && !all_scenarios {
        anyhow::bail!(
            "--out: bench {what:?} draws no picture (`bench loop` without --vehicle does, and \
             `bench figures` and `bench representations` write there)"
        );
    }
    Ok(())
}

/// `bench loop` without `--vehicle`: each scenario's figures, then the traffic check's; with
/// `out`, the picture of where a revolution's time goes.
fn loop_figures(
    scenarios: &[PathBuf],
    laps: u32,
    samples: usize,
    out: Option<&std::path::Path>,
    progress: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<sim::bench::Figure>> {
    let (mut figures, mut splits) = (Vec::new(), Vec::new());
    for scenario in scenarios {
        let (f, split) = sim::bench::loop_figures(scenario, laps, samples, progress)?;
        figures.extend(f);
        splits.push(split);
    }
    progress("traffic: prediction and the space-time check");
    figures.extend(sim::bench::traffic_figures(samples.max(5)));
    if let Some(dir) = out {
        sim::bench::loop_chart::draw(&splits, dir)?;
        eprintln!(
            "drew {}",
            dir.join(format!("{}.svg", sim::bench::loop_chart::STEM))
                .display()
        );
    }
    Ok(figures)
}

fn bench(
    what: BenchTarget,
    json: bool,
    samples: Option<usize>,
    (scenarios, laps, vehicle, out): (&[PathBuf], u32, Option<&str>, Option<&std::path::Path>),
    campaign: &sim::bench::campaign::CampaignBench<'_>,
) -> anyhow::Result<()> {
    let scenario = scenarios[0].as_path();
    let progress = ProgressBar::new_spinner();
    let mut report = |what: &str| progress.set_message(format!("measuring {what}"));
    let figures = match what {
        BenchTarget::Mapper => sim::bench::mapper_figures(samples.unwrap_or(15), &mut report),
        BenchTarget::Lidar => sim::bench::lidar_figures(samples.unwrap_or(15), &mut report)?,
        BenchTarget::Loop => match vehicle {
            Some(v) => {
                sim::bench::vehicle_figures(scenario, v, laps, samples.unwrap_or(1), &mut report)?
            }
            None => loop_figures(scenarios, laps, samples.unwrap_or(1), out, &mut report)?,
        },
        BenchTarget::Campaign => sim::bench::campaign::campaign_figures(campaign, &mut report)?,
        BenchTarget::Blocks => sim::bench::blocks::figures_for(scenario, &mut report)?,
        BenchTarget::Localization => {
            sim::bench::localization::figures_for(scenario, samples.unwrap_or(15), &mut report)?
        }
        BenchTarget::Bridge => bridge(scenario, laps, samples.unwrap_or(1), &mut report)?,
        BenchTarget::Figures | BenchTarget::Representations => {
            unreachable!("dispatched in run")
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

/// `bench bridge`: the revolution's cost, then the stack's real-time factor both ways.
fn bridge(
    scenario: &std::path::Path,
    laps: u32,
    rounds: usize,
    progress: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<sim::bench::Figure>> {
    let domain = ros2_live::LiveOptions::domain_id(None)?;
    progress("a revolution over DDS and in the process");
    let mut figures = ros2_live::bench::revolution_figures(domain, 15)?;
    let scenario = sim::scenario::Scenario::from_file(scenario)?;
    let config = sim::scenario::RunConfig::default();
    let map_dir = sim::offline_map::default_map_dir(&scenario, &config);
    sim::offline_map::ensure(
        &scenario,
        &config,
        &map_dir,
        &mut || progress("mapping drive"),
        &mut |_, _| {},
    )?;
    let setup = sim::engine::RunSetup {
        laps: (laps > 0).then_some(laps),
        config,
        ..sim::engine::RunSetup::new(map_dir)
    };
    figures.extend(ros2_live::bench::stack_figures(
        &scenario, &setup, domain, rounds, progress,
    )?);
    Ok(figures)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Several scenarios and a picture are `bench loop`'s (without `--vehicle`): elsewhere an
    /// error naming the option, not a silent first scenario or no picture.
    #[test]
    fn loop_only_options_are_refused_elsewhere() {
        let dir = Some(std::path::Path::new("docs"));
        assert!(check_loop_options(BenchTarget::Loop, 3, None, dir).is_ok());
        assert!(check_loop_options(BenchTarget::Loop, 1, Some("a320"), None).is_ok());
        assert!(check_loop_options(BenchTarget::Blocks, 1, None, None).is_ok());
        let two = check_loop_options(BenchTarget::Localization, 2, None, None).unwrap_err();
        assert!(two.to_string().starts_with("--scenario:"), "{two}");
        let vehicle = check_loop_options(BenchTarget::Loop, 2, Some("a320"), None).unwrap_err();
        assert!(vehicle.to_string().starts_with("--scenario:"), "{vehicle}");
        let out = check_loop_options(BenchTarget::Loop, 1, Some("a320"), dir).unwrap_err();
        assert!(out.to_string().starts_with("--out:"), "{out}");
        let out = check_loop_options(BenchTarget::Mapper, 1, None, dir).unwrap_err();
        assert!(out.to_string().contains("Mapper"), "{out}");
    }
}
