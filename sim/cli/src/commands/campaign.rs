//! `taxi-sim campaign run | show | compare | merge`: runs a campaign's variants in parallel with a
//! progress bar (runs done, failures so far, ETA), Ctrl-C stopping cleanly, and prints its
//! summary; compares two runs of it; merges its shards.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use indicatif::{ProgressBar, ProgressStyle};
use sim::campaign::Campaign;
use sim::campaign::{ExternalStacks, RunOptions, Shard, read_results, run_campaign, total_runs};
use sim::engine::ExternalStack;

use super::stack::StackKind;

/// Makes job `j`'s external stack for its next run.
type MakeStack<'a> =
    dyn Fn(usize, &std::path::Path) -> sim::Result<Box<dyn ExternalStack>> + Sync + 'a;

/// `taxi-sim campaign ...`.
#[derive(Debug, clap::Subcommand)]
pub enum CampaignCommand {
    /// Run a campaign's variants not yet in DIR (resumable; Ctrl-C keeps every finished run).
    /// Exit code 0 when no run failed, 1 when some did, 2 on bad input.
    Run(Box<CampaignRunArgs>),
    /// Print the summary of a campaign directory (rewritten from its results).
    Show {
        /// The campaign's output directory.
        dir: PathBuf,
    },
    /// Compare two runs of one campaign - two builds, or a `--set` - on the variants both hold:
    /// runs at fault, pilot calls (by cause, needless ones), clearance, TTC, PET and lap times
    /// side by side, and the variants whose outcome changed. Each is a campaign directory or a
    /// kept record (`NAME.jsonl.gz` beside `NAME.campaign.json`). Exit code 0 when AFTER has no
    /// more runs at fault, pilot calls or needless calls than BEFORE, 1 when it has, 2 on bad
    /// input.
    Compare {
        /// The run to compare against (e.g. a record in docs/campaigns/records/).
        before: PathBuf,
        /// The run compared.
        after: PathBuf,
        /// Also write the comparison (Markdown) here.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Merge the output directories of a campaign's shards into one (as if run on one
    /// machine). Exit code 0 when every variant is in, 1 when some are missing (it says which,
    /// and how to run them).
    Merge {
        /// The merged directory: results.jsonl, summary.md, failures/.
        #[arg(long)]
        out: PathBuf,
        /// The shards' output directories.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
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
    /// Set a scenario field in every variant, over the file: `--set FIELD=VALUE` (dotted as in
    /// the file's `[scenario]`, VALUE a TOML value or else a string; repeatable). The same
    /// variants with that changed, e.g. `--set airport.surveyed_stands=as_run` (results go to
    /// another directory).
    #[arg(long = "set", value_name = "FIELD=VALUE")]
    pub set: Vec<String>,
    /// Run one shard of the campaign: `I/N` runs the variants `i` with `i % N == I`; `auto/N`
    /// takes `I` from SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX. Merge the shards' `--out`
    /// directories with `campaign merge`.
    #[arg(long)]
    pub shard: Option<String>,
    /// Where the offline maps are cached (default: OUT/maps). Shards on a shared filesystem can
    /// share one: maps are built in a scratch directory and renamed into place under a name
    /// that is a digest of what they depend on.
    #[arg(long)]
    pub maps_dir: Option<PathBuf>,
    /// Only these variants: indices and ranges (`266,338,400-410`), or `WHAT@RUN` - those of an
    /// earlier run of this campaign (its directory, or a kept record `NAME.jsonl.gz`) that
    /// `failed`, made a contact `at-fault`, were `called` (a pilot call ended them), made a
    /// `needless` call, or `any` it holds: to run them again on this build or with `--set`,
    /// into another --out (then `campaign compare RUN OUT`). Not with the falsify sampler.
    #[arg(long, value_name = "LIST")]
    pub variants: Option<String>,
    /// Complete a merged directory: run only the variants missing from it (refuses a directory
    /// with no results).
    #[arg(long)]
    pub only_missing: bool,
    /// Run each failure again writing it as a ROS 2 bag (`failures/<i>/<i>.mcap`, for Foxglove,
    /// `ros2 bag play`, `taxi-sim map --from-bag`); runs are reproducible, so only failures pay.
    #[arg(long)]
    pub record_failures: bool,
    /// The stack that drives every run (`--stack ros2`: yours over DDS, each parallel job on ROS
    /// domain `--ros-domain-id` + its number, a stack `--stack-command` starts per run; its
    /// output in OUT/stack-job-J.log, or `--stack-log` with the job in its extension).
    #[command(flatten)]
    pub stack: super::stack::StackArgs,
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
        CampaignCommand::Merge { out, shards } => merge(out, shards),
        CampaignCommand::Compare { before, after, out } => {
            use sim::campaign::compare::{Side, compare, render};
            let (before, after) = (Side::read(before)?, Side::read(after)?);
            let c = compare(&before, &after)?;
            let text = render(&c, &before, &after);
            if let Some(out) = out {
                mapper::write_atomically(out, text.as_bytes())?;
            }
            crate::emit(&text)?;
            Ok(c.worse().is_empty())
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
    for set in &args.set {
        let (field, value) = parse_set(set)?;
        campaign.set_field(&field, value)?;
    }
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let shard = match &args.shard {
        Some(text) => {
            Some(Shard::parse(text, &|k| std::env::var(k).ok()).map_err(anyhow::Error::msg)?)
        }
        None => None,
    };
    let existing = read_results(&args.out)?;
    let mut runs = args.runs;
    if args.only_missing {
        anyhow::ensure!(
            !existing.is_empty(),
            "--only-missing: {} holds no results to complete (merge the shards into it first, or run without --only-missing)",
            args.out.display()
        );
        // The merged directory says how many variants the shards were asked for.
        if runs.is_none() {
            runs = std::fs::read_to_string(args.out.join("campaign.json"))
                .ok()
                .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
                .and_then(|m| m.get("total").and_then(|t| t.as_u64()));
        }
    }
    let total = total_runs(&campaign, runs);
    let variants = picked_variants(args.variants.as_deref(), &campaign, total)?;
    let picked = |i: u64| {
        variants
            .as_ref()
            .is_none_or(|v| v.binary_search(&i).is_ok())
    };
    let mine = |i: u64| i < total && shard.is_none_or(|s| s.holds(i)) && picked(i);
    let before = existing.iter().filter(|r| mine(r.index)).count();
    let bar = ProgressBar::new((0..total).filter(|i| mine(*i)).count() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {msg} [{elapsed} < {eta}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_position(before as u64);
    if variants.is_some() && bar.length() == Some(before as u64) {
        eprintln!(
            "--variants: every variant named is already in {} or outside this shard: nothing to run",
            args.out.display()
        );
    }
    eprintln!(
        "campaign {}{}: {} runs ({} already in {}), {} random dimensions, {} parameter settings, {} at a time",
        campaign.name,
        shard.map_or(String::new(), |s| format!(", shard {s}")),
        bar.length().unwrap_or(0),
        before,
        args.out.display(),
        campaign.layout.dims.len(),
        campaign.settings.len(),
        jobs
    );
    let stacks = external_stacks(args, jobs)?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let failures = AtomicUsize::new(0);
    let outcome = run_campaign(
        &campaign,
        &RunOptions {
            out: args.out.clone(),
            shard,
            maps_dir: args.maps_dir.clone(),
            jobs,
            runs,
            variants: variants.as_deref(),
            stop: &stop,
            record_failures: args.record_failures,
            progress: &|r| {
                let f = failures.fetch_add(usize::from(r.failed), Ordering::Relaxed)
                    + usize::from(r.failed);
                bar.set_message(format!("{f} failed"));
                bar.inc(1);
            },
            stack: stacks.as_ref().map(|make| ExternalStacks {
                make: &**make,
                policy: args.stack.policy(),
            }),
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

/// The variants `--variants` names (`None`: all), checked against `campaign` as it is run now.
fn picked_variants(
    text: Option<&str>,
    campaign: &Campaign,
    total: u64,
) -> anyhow::Result<Option<Vec<u64>>> {
    let Some(text) = text else {
        return Ok(None);
    };
    let (v, meta) = sim::campaign::select::parse_variants(text, total)?;
    if let Some(meta) = meta
        && let Some(note) = sim::campaign::select::check_same_campaign(&meta, campaign)?
    {
        eprintln!("{note}");
    }
    Ok(Some(v))
}

/// `taxi-sim campaign merge`: returns whether every variant is in.
fn merge(out: &std::path::Path, shards: &[PathBuf]) -> anyhow::Result<bool> {
    let m = sim::campaign::merge::merge(shards, out)?;
    let failed = m.records.iter().filter(|r| r.failed).count();
    let mut text = format!(
        "merged {} shard directories into {}: {} of {} runs, {} failed\nwrote {}\n",
        shards.len(),
        out.display(),
        m.records.len(),
        m.total,
        failed,
        out.join("summary.md").display()
    );
    if !m.missing.is_empty() {
        let campaign = std::fs::read_to_string(out.join("campaign.json"))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|v| v.get("campaign").and_then(|c| c.as_str()).map(String::from))
            .unwrap_or_else(|| "<campaign.toml>".into());
        text += &format!(
            "missing {} variants: {}\nrun them with: taxi-sim campaign run {campaign} --out {} --only-missing\n",
            m.missing.len(),
            sim::campaign::merge::ranges(&m.missing),
            out.display()
        );
    }
    crate::emit(&text)?;
    Ok(m.missing.is_empty())
}

/// `--stack ros2`: each job's stack on its own ROS domain (`--ros-domain-id` + the job), so
/// parallel runs never hear each other; `None` for the shipped stack.
fn external_stacks(
    args: &CampaignRunArgs,
    jobs: usize,
) -> anyhow::Result<Option<Box<MakeStack<'_>>>> {
    if args.stack.stack == StackKind::Shipped {
        return Ok(None);
    }
    let base = ros2_live::LiveOptions::domain_id(args.stack.ros_domain_id)?;
    let last = base as usize + jobs - 1;
    anyhow::ensure!(
        last <= ros2_live::MAX_DOMAIN_ID as usize,
        "--ros-domain-id {base} with {jobs} jobs: domains up to {last}, beyond {}",
        ros2_live::MAX_DOMAIN_ID
    );
    args.stack.live_options(base)?;
    eprintln!(
        "each run driven by a ROS 2 stack{}, job j on ROS domain {base} + j",
        if args.stack.stack_command.is_some() {
            " the simulator starts"
        } else {
            " already running"
        }
    );
    Ok(Some(Box::new(
        move |job: usize, map_dir: &std::path::Path| {
            let mut options = args
                .stack
                .live_options(base + job as u16)
                .map_err(|e| sim::Error::Invalid(e.to_string()))?;
            options.map_dir = Some(map_dir.to_path_buf());
            if options.command.is_some() {
                // One log per job: the jobs' stacks run side by side.
                options.log = Some(match &args.stack.stack_log {
                    Some(p) => p.with_extension(format!("job-{job}.log")),
                    None => args.out.join(format!("stack-job-{job}.log")),
                });
            }
            Ok(Box::new(ros2_live::Ros2Stack::new(options)?) as Box<dyn ExternalStack>)
        },
    )))
}

/// `--set FIELD=VALUE`: the field and its value (a TOML value, or else the text as a string).
fn parse_set(text: &str) -> anyhow::Result<(String, toml::Value)> {
    let (field, value) = text
        .split_once('=')
        .ok_or_else(|| anyhow::anyhow!("--set {text}: expected FIELD=VALUE"))?;
    let field = field.trim();
    anyhow::ensure!(
        !field.is_empty() && field.split('.').all(|p| !p.is_empty()),
        "--set {text}: the field is a dotted path such as airport.surveyed_stands"
    );
    let value = value.trim();
    let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    Ok((field.to_string(), parsed))
}
