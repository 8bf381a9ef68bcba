//! `taxi-sim tune`: runs (or resumes) a tuning campaign, then compares its settings - the
//! objectives per setting, the Pareto front, the exact reference - and writes the recommended
//! model with its pictures.

use indicatif::{ProgressBar, ProgressStyle};
use sim::campaign::Campaign;
use sim::campaign::read_results;
use sim::tune::{TuneOptions, figures, write_outputs};

use super::campaign::CampaignRunArgs;

/// Arguments of `taxi-sim tune`.
#[derive(Debug, Clone, clap::Args)]
pub struct TuneArgs {
    /// The campaign (its `[parameters]` are the settings compared) and where its runs go.
    #[command(flatten)]
    pub run: CampaignRunArgs,
    /// Poses near obstacles per map place (4 places along the route) for the comparison with
    /// the exact reference.
    #[arg(long, default_value_t = 250)]
    pub poses: usize,
}

/// Runs `taxi-sim tune`; returns whether some setting had no unsafe run.
pub fn run(args: &TuneArgs) -> anyhow::Result<bool> {
    anyhow::ensure!(args.poses > 0, "--poses 0: at least one");
    let (_, interrupted) = super::campaign::run_args(&args.run)?;
    if interrupted {
        crate::emit("interrupted: the settings are compared once every run is in\n")?;
        return Ok(false);
    }
    let campaign = Campaign::from_file(&args.run.campaign)?;
    let dir = &args.run.out;
    let total = sim::campaign::total_runs(&campaign, args.run.runs);
    let records: Vec<_> = read_results(dir)?
        .into_iter()
        .filter(|r| r.index < total)
        .collect();
    let bar = ProgressBar::new(campaign.settings.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} settings against the exact reference [{elapsed} < {eta}]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let figs = figures(
        &campaign,
        dir,
        &records,
        TuneOptions { poses: args.poses },
        &|done, _| bar.set_position(done as u64),
    )?;
    bar.finish_and_clear();
    let recommended = write_outputs(&campaign, dir, &figs)?;
    crate::emit(&std::fs::read_to_string(dir.join("tune.md"))?)?;
    crate::emit(&format!(
        "wrote {0}/settings.csv, pareto.csv, pareto.svg, pareto.png, tune.md{1}\n",
        dir.display(),
        if recommended.is_some() {
            ", recommended/"
        } else {
            ""
        }
    ))?;
    Ok(figs.iter().any(|f| f.runs > 0 && f.unsafe_runs == 0))
}
