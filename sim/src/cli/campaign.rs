//! `taxi-sim campaign run | show`: runs a campaign's variants in parallel with a progress bar
//! (runs done, failures so far, ETA), Ctrl-C stopping cleanly, and prints its summary.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use indicatif::{ProgressBar, ProgressStyle};
use sim::campaign::Campaign;
use sim::campaign::execute::{RunOptions, read_results, run_campaign, total_runs};

/// `taxi-sim campaign ...`.
#[derive(Debug, clap::Subcommand)]
pub enum CampaignCommand {
    /// Run a campaign's variants not yet in DIR (resumable; Ctrl-C keeps every finished run).
    /// Exit code 0 when no run failed, 1 when some did, 2 on bad input.
    Run(CampaignRunArgs),
    /// Print the summary of a campaign directory (rewritten from its results).
    Show {
        /// The campaign's output directory.
        dir: PathBuf,
    },
}

/// Arguments of `taxi-sim campaign run`.
#[derive(Debug, Clone, clap::Args)]
pub struct CampaignRunArgs {
    /// The campaign file (`scenarios/campaigns/*.toml`).
    pub campaign: PathBuf,
    /// Output directory: results.jsonl, summary.md, failures/, maps/.
    #[arg(long)]
    pub out: PathBuf,
    /// Runs at a time (default: the cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Variants 0..N (default: the campaign's `runs`).
    #[arg(long)]
    pub runs: Option<u64>,
    /// Sampler instead of the file's (`grid`, `random`, `halton`, `falsify`): the same family
    /// searched another way (its results go to another directory).
    #[arg(long)]
    pub sampler: Option<String>,
}

/// Runs `taxi-sim campaign ...`; returns whether no run failed.
pub fn run(cmd: &CampaignCommand) -> anyhow::Result<bool> {
    match cmd {
        CampaignCommand::Show { dir } => {
            let records = read_results(dir)?;
            anyhow::ensure!(
                dir.join("campaign.json").exists(),
                "{}: not a campaign directory (no campaign.json)",
                dir.display()
            );
            sim::campaign::summary::write(dir, &records)?;
            let text = std::fs::read_to_string(dir.join("summary.md"))?;
            crate::emit(&text)?;
            Ok(records.iter().all(|r| !r.failed))
        }
        CampaignCommand::Run(args) => {
            let (failed, interrupted) = run_args(args)?;
            Ok(failed == 0 && !interrupted)
        }
    }
}

/// Runs (or resumes) the campaign of `args`; returns the failed runs and whether Ctrl-C cut it.
pub(crate) fn run_args(args: &CampaignRunArgs) -> anyhow::Result<(usize, bool)> {
    anyhow::ensure!(args.jobs != Some(0), "--jobs 0: at least one");
    anyhow::ensure!(args.runs != Some(0), "--runs 0: at least one");
    let mut campaign = Campaign::from_file(&args.campaign)?;
    if let Some(name) = &args.sampler {
        let kind: sim::campaign::SamplerKind =
            serde_json::from_value(serde_json::Value::String(name.clone())).map_err(|_| {
                anyhow::anyhow!("--sampler {name}: expected grid, random, halton or falsify")
            })?;
        campaign.set_sampler(kind);
    }
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let total = total_runs(&campaign, args.runs);
    let before = read_results(&args.out)?
        .iter()
        .filter(|r| r.index < total)
        .count();
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {msg} [{elapsed} < {eta}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_position(before as u64);
    eprintln!(
        "campaign {}: {} runs ({} already in {}), {} random dimensions, {} parameter settings, {} at a time",
        campaign.name,
        total,
        before,
        args.out.display(),
        campaign.layout.dims.len(),
        campaign.settings.len(),
        jobs
    );
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let failures = AtomicUsize::new(0);
    let outcome = run_campaign(
        &campaign,
        &RunOptions {
            out: args.out.clone(),
            jobs,
            runs: args.runs,
            stop: &stop,
            progress: &|r| {
                let f = failures.fetch_add(usize::from(r.failed), Ordering::Relaxed)
                    + usize::from(r.failed);
                bar.set_message(format!("{f} failed"));
                bar.inc(1);
            },
        },
    )?;
    bar.finish_and_clear();
    let failed = outcome.records.iter().filter(|r| r.failed).count();
    crate::emit(&format!(
        "{}: {} runs recorded ({} now), {} failed; {}\nwrote {}\n",
        campaign.name,
        outcome.records.len(),
        outcome.ran,
        failed,
        if outcome.interrupted {
            "interrupted: run the same command again to resume"
        } else {
            "done"
        },
        args.out.join("summary.md").display()
    ))?;
    Ok((failed, outcome.interrupted))
}
