//! `taxi-sim regress`: every scenario file under the paths run in parallel against its own
//! expectations, with a progress bar and a table at the end, written as JUnit XML, JSON lines
//! and a Markdown summary for CI; shards of it (Slurm array tasks) merged back with `--merge`.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::{ProgressBar, ProgressStyle};
use sim::campaign::Shard;
use sim::regress::results::{self, Counts, status_word};
use sim::regress::{CaseResult, Options, Status, Tier, discover, run_cases};

/// Arguments of `taxi-sim regress`.
#[derive(Debug, Clone, clap::Args)]
pub struct RegressArgs {
    /// Scenario files and folders (recursed; campaign files skipped). Default: `scenarios`.
    pub paths: Vec<PathBuf>,
    /// Cases at a time (default: the cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Write the results as JUnit XML here (one testsuite per folder, one testcase per file).
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Write the results as JSON lines here (one case a line).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write a Markdown summary here.
    #[arg(long, value_name = "FILE.md")]
    pub summary: Option<PathBuf>,
    /// Only the files whose path matches this glob (e.g. `*traffic*`).
    #[arg(long, value_name = "GLOB")]
    pub filter: Option<String>,
    /// Bound each run's simulated time, seconds (a run that reaches it ends `timed_out`).
    #[arg(long, value_name = "S")]
    pub time_limit_s: Option<f64>,
    /// The full tier: every lap of every file, and the `[regress] full_only` cases (default:
    /// the quick tier, each file's `[regress] quick_laps`).
    #[arg(long)]
    pub full: bool,
    /// Where the offline maps are cached, one per static world (default: a temporary folder).
    /// Kept between runs, it saves the mapping drives; maps of another build are rebuilt only
    /// when their inputs' key changes, so clear it after changing the mapper.
    #[arg(long, value_name = "DIR")]
    pub maps_dir: Option<PathBuf>,
    /// Run one shard: `I/N` runs the cases `i` (in path order) with `i % N == I`; `auto/N` takes
    /// `I` from SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX. Merge the shards' `--json` files
    /// with `--merge`.
    #[arg(long)]
    pub shard: Option<String>,
    /// Run nothing: merge these shards' `--json` files into one run's results (JUnit, JSON,
    /// summary), in the order one machine gives.
    #[arg(long, value_name = "JSON", num_args = 1..)]
    pub merge: Vec<PathBuf>,
    /// Write the golden numbers of the cases that name a file (`[regress] golden`) from this
    /// run instead of comparing them: after a change in behaviour that is meant. The golden
    /// numbers are the quick tier's, compared only without a time limit.
    #[arg(long, conflicts_with_all = ["full", "merge", "time_limit_s"])]
    pub bless: bool,
    /// Report the known problems (files with `[expectations] known_problem`) not run instead of
    /// running them: for a CI budget spent on the cases that must pass (a known problem fixed or
    /// changed is then found by a run without it).
    #[arg(long, conflicts_with = "bless")]
    pub skip_known_problems: bool,
}

/// Runs `taxi-sim regress`; returns its exit code (0 all passed or known problems, 1 a case
/// failed, 2 a file was bad).
pub fn run(args: &RegressArgs) -> anyhow::Result<u8> {
    anyhow::ensure!(args.jobs != Some(0), "--jobs 0: at least one");
    if let Some(t) = args.time_limit_s {
        anyhow::ensure!(
            t.is_finite() && t > 0.0,
            "--time-limit-s {t}: a positive number of seconds"
        );
    }
    let t0 = std::time::Instant::now();
    let results = if args.merge.is_empty() {
        run_here(args)?
    } else {
        merged(&args.merge)?
    };
    let wall_s = t0.elapsed().as_secs_f64();
    if let Some(p) = &args.junit {
        results::write_junit(p, &results)?;
    }
    if let Some(p) = &args.json {
        results::write_json(p, &results)?;
    }
    if let Some(p) = &args.summary {
        results::write_summary(p, &results, wall_s)?;
    }
    crate::emit(&table(&results, wall_s))?;
    Ok(Counts::of(&results).exit_code())
}

/// The shards' results in one machine's order (the order the files were found in).
fn merged(files: &[PathBuf]) -> anyhow::Result<Vec<CaseResult>> {
    let mut all = Vec::new();
    for f in files {
        all.extend(results::read_json(f)?);
    }
    all.sort_by_key(|r| r.index);
    if let Some(w) = all.windows(2).find(|w| w[0].index == w[1].index) {
        anyhow::bail!(
            "--merge: case {} ({}) is in more than one shard's results",
            w[0].index,
            w[0].file
        );
    }
    Ok(all)
}

/// Discovers and runs the cases here, with a progress bar.
fn run_here(args: &RegressArgs) -> anyhow::Result<Vec<CaseResult>> {
    let paths = if args.paths.is_empty() {
        vec![PathBuf::from("scenarios")]
    } else {
        args.paths.clone()
    };
    let shard = match &args.shard {
        Some(text) => {
            Some(Shard::parse(text, &|k| std::env::var(k).ok()).map_err(anyhow::Error::msg)?)
        }
        None => None,
    };
    let cases = discover(&paths, args.filter.as_deref())?;
    anyhow::ensure!(
        !cases.is_empty(),
        "no scenario files under {}{}",
        paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        args.filter
            .as_ref()
            .map_or(String::new(), |f| format!(" matching {f}"))
    );
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let tier = if args.full { Tier::Full } else { Tier::Quick };
    let temp;
    let maps_dir = match &args.maps_dir {
        Some(d) => d.clone(),
        None => {
            temp = tempfile::tempdir()?;
            temp.path().to_path_buf()
        }
    };
    let mine = (0..cases.len() as u64)
        .filter(|i| shard.is_none_or(|s| s.holds(*i)))
        .count();
    eprintln!(
        "regress: {mine} scenario files{}, {} tier, {jobs} at a time",
        shard.map_or(String::new(), |s| format!(
            " (shard {s} of {})",
            cases.len()
        )),
        if args.full { "full" } else { "quick" },
    );
    let bar = ProgressBar::new(mine as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} cases, {msg} [{elapsed} < {eta}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let running: Mutex<Vec<String>> = Mutex::default();
    let failed = std::sync::atomic::AtomicUsize::new(0);
    let message = |running: &[String], failed: usize| {
        format!("{failed} failed; running {}", running.join(", "))
    };
    let results = run_cases(
        &cases,
        &Options {
            jobs,
            tier,
            maps_dir,
            shard,
            time_limit_s: args.time_limit_s,
            bless: args.bless,
            skip_known_problems: args.skip_known_problems,
            stop: &stop,
            started: &|c| {
                if let Ok(mut r) = running.lock() {
                    r.push(c.name.clone());
                    bar.set_message(message(&r, failed.load(Ordering::Relaxed)));
                }
            },
            progress: &|r| {
                if matches!(r.status, Status::Failed | Status::Error) {
                    failed.fetch_add(1, Ordering::Relaxed);
                    bar.suspend(|| {
                        eprintln!(
                            "{} {}: {}",
                            status_word(r.status),
                            r.file,
                            r.messages.join("; ")
                        )
                    });
                }
                if bar.is_hidden() {
                    // Not a terminal (CI's log): a line per case instead of the bar.
                    eprintln!(
                        "[{}/{mine}] {} {} ({:.0} s sim in {:.1} s)",
                        bar.position() + 1,
                        status_word(r.status),
                        r.file,
                        r.sim_time_s,
                        r.wall_time_s
                    );
                }
                if let Ok(mut running) = running.lock() {
                    running.retain(|n| *n != r.name);
                    bar.set_message(message(&running, failed.load(Ordering::Relaxed)));
                }
                bar.inc(1);
            },
        },
    )?;
    bar.finish_and_clear();
    anyhow::ensure!(
        !stop.load(Ordering::Relaxed),
        "interrupted: {} of {mine} cases finished, nothing written",
        results.len()
    );
    Ok(results)
}

/// The table printed at the end: one row per case, the failures with their rerun commands, the
/// counts.
fn table(results: &[CaseResult], wall_s: f64) -> String {
    let width = results
        .iter()
        .map(|r| r.file.len())
        .max()
        .unwrap_or(4)
        .max(4);
    let mut s = format!(
        "{:width$}  {:13}  {:27}  {:>8}  {:>9}  {:>8}  {:>7}\n",
        "case", "status", "end", "contacts", "clear (m)", "sim (s)", "wall (s)"
    );
    for r in results {
        s += &format!(
            "{:width$}  {:13}  {:27}  {:>8}  {:>9}  {:>8.1}  {:>7.1}\n",
            r.file,
            status_word(r.status),
            r.end.as_deref().unwrap_or("-"),
            format!("{}/{}", r.contacts_at_fault, r.contacts_struck),
            r.obstacle_clearance_m
                .map_or("-".into(), |c| format!("{c:.2}")),
            r.sim_time_s,
            r.wall_time_s
        );
    }
    for r in results
        .iter()
        .filter(|r| matches!(r.status, Status::Failed | Status::Error))
    {
        s += &format!("\n{} {}:\n", status_word(r.status), r.file);
        for m in &r.messages {
            s += &format!("  {m}\n");
        }
        s += &format!("  rerun: {}\n", r.rerun);
    }
    s += &format!(
        "\n{} in {wall_s:.0} s (contacts shown at fault/struck)\n",
        Counts::of(results).sentence()
    );
    s
}
