//! Scenario regressions: every scenario file under some paths run against its own
//! `[expectations]`, in parallel, each a case with a verdict (`taxi-sim regress`).
//!
//! - [`discover`]: the files under the paths (folders recursed, campaign files skipped), in path
//!   order, filtered by a glob;
//! - [`run_cases`]: the cases in parallel on worker threads, the longest first, one offline map
//!   per static world shared through the campaigns' map cache;
//! - [`verdict`]: a run judged against its file - passed, failed, or a known problem that still
//!   ends as the file states (an expected failure, like pytest's strict xfail: once it passes it
//!   fails, so the mark is removed);
//! - [`golden`]: a case's golden numbers (`[regress] golden`), the quick tier's summary of what
//!   the vehicle did, compared with its file or written anew (`--bless`);
//! - [`results`]: the cases as JUnit XML, JSON lines and a Markdown summary.

pub mod golden;
pub mod results;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use serde::{Deserialize, Serialize};

use crate::campaign::{MapCache, Shard, failures_of};
use crate::engine::{EndReason, NoObserver, RunHandles, RunReport, RunSetup, run_with};
use crate::error::{Error, Result};
use crate::scenario::{KnownProblem, RunConfig, Scenario};

/// A scenario file to run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Case {
    /// The file.
    pub path: PathBuf,
    /// Its folder as given (the JUnit test suite).
    pub suite: String,
    /// Its file name without `.toml` (the JUnit test case).
    pub name: String,
}

/// Which cases run, and how long.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Tier {
    /// Each file's `[regress] quick_laps`; `full_only` files not run.
    Quick,
    /// Every file as written.
    Full,
}

/// A case's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every expectation held.
    Passed,
    /// An expectation failed, or a known problem was fixed or changed.
    Failed,
    /// A known problem that still ends as the file states (an expected failure).
    KnownProblem,
    /// Not run: in this tier (`[regress] full_only`), or a known problem skipped.
    NotRun,
    /// The file is not a valid scenario, or the run could not be made.
    Error,
}

/// One case's result: a line of the JSON output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseResult {
    /// Its place among the files discovered (shards' results merge back in this order).
    pub index: usize,
    /// The folder (JUnit test suite).
    pub suite: String,
    /// The file name without `.toml` (JUnit test case).
    pub name: String,
    /// The file.
    pub file: String,
    /// The verdict.
    pub status: Status,
    /// The tier it ran in.
    pub tier: Tier,
    /// What failed, one line each (for a known problem: how it fails today).
    pub messages: Vec<String>,
    /// The known problem's text, if the file marks one.
    pub known_problem: Option<String>,
    /// The scenario's seed.
    pub seed: u64,
    /// Laps driven in this tier, and in the file.
    pub laps: u32,
    /// Laps the file asks for.
    pub laps_in_file: u32,
    /// Why the run ended (`None`: not run).
    pub end: Option<String>,
    /// Contacts, at fault (moving) and struck (standing).
    pub contacts: usize,
    /// Contacts that began while the vehicle moved.
    pub contacts_at_fault: usize,
    /// Contacts that began while the vehicle stood.
    pub contacts_struck: usize,
    /// Smallest ground-truth clearance to a run-time obstacle over its passes, metres.
    pub obstacle_clearance_m: Option<f64>,
    /// Simulated time, seconds.
    pub sim_time_s: f64,
    /// Wall time, seconds, the mapping drive included when this case built the map.
    pub wall_time_s: f64,
    /// Simulated seconds per wall second of the run itself.
    pub real_time_factor: f64,
    /// The command that runs this case alone.
    pub rerun: String,
}

/// The scenario files under `paths` (a file as it is; a folder recursed, `.toml` files only,
/// campaign files - those with a top-level `base` - skipped), in path order, those whose path
/// matches `filter` (a glob on the path as found, e.g. `*traffic*`).
pub fn discover(paths: &[PathBuf], filter: Option<&str>) -> Result<Vec<Case>> {
    let pattern = filter
        .map(glob::Pattern::new)
        .transpose()
        .map_err(|e| Error::Invalid(format!("--filter: not a glob: {e}")))?;
    let mut cases = Vec::new();
    for root in paths {
        if !root.exists() {
            return Err(Error::Invalid(format!(
                "{}: no such file or folder",
                root.display()
            )));
        }
        let suite_of = |p: &Path| {
            p.parent()
                .map(|d| d.display().to_string())
                .filter(|d| !d.is_empty())
                .unwrap_or_else(|| ".".into())
        };
        let mut files = Vec::new();
        if root.is_file() {
            files.push(root.clone());
        } else {
            for entry in walkdir::WalkDir::new(root).sort_by_file_name() {
                let entry =
                    entry.map_err(|e| Error::Invalid(format!("{}: {e}", root.display())))?;
                let p = entry.path();
                if entry.file_type().is_file() && p.extension().is_some_and(|x| x == "toml") {
                    if is_campaign(p)? {
                        continue;
                    }
                    files.push(p.to_path_buf());
                }
            }
        }
        for p in files {
            if pattern.as_ref().is_some_and(|g| !g.matches_path(&p)) {
                continue;
            }
            let name = p
                .file_stem()
                .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
            let case = Case {
                suite: suite_of(&p),
                name,
                path: p,
            };
            if !cases.contains(&case) {
                cases.push(case);
            }
        }
    }
    Ok(cases)
}

/// A campaign file: a TOML table with a top-level string `base` (its base scenario). A file
/// that is not TOML is not a campaign: it runs, and fails with its located error.
fn is_campaign(path: &Path) -> Result<bool> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        what: "reading a scenario",
        path: path.to_path_buf(),
        source,
    })?;
    Ok(toml::from_str::<toml::Table>(&text)
        .is_ok_and(|t| t.get("base").is_some_and(toml::Value::is_str)))
}

/// How the cases are run.
pub struct Options<'a> {
    /// Cases at a time.
    pub jobs: usize,
    /// The quick or the full tier.
    pub tier: Tier,
    /// Where the offline maps are cached (one per static world).
    pub maps_dir: PathBuf,
    /// Run only this shard's cases (the `i`-th case of the discovered list when `i % N == I`).
    pub shard: Option<Shard>,
    /// A bound on each run's simulated time, seconds (`None`: the scenario's own).
    pub time_limit_s: Option<f64>,
    /// Write each case's golden numbers (`[regress] golden`) instead of comparing them.
    pub bless: bool,
    /// Report the known problems (`[expectations] known_problem`) not run instead of running
    /// them: CI's quick tier, whose budget goes to the cases that must pass.
    pub skip_known_problems: bool,
    /// Set from outside (Ctrl-C): runs in flight end, cases not begun are not reported.
    pub stop: &'a AtomicBool,
    /// Told of every finished case.
    pub progress: &'a (dyn Fn(&CaseResult) + Sync),
    /// Told of each case as it starts.
    pub started: &'a (dyn Fn(&Case) + Sync),
}

/// Runs the cases (this shard's) in parallel, the longest first; returns their results in the
/// order of `cases`.
pub fn run_cases(cases: &[Case], opts: &Options<'_>) -> Result<Vec<CaseResult>> {
    let maps = MapCache::new(opts.maps_dir.clone());
    std::fs::create_dir_all(&opts.maps_dir).map_err(|source| Error::Io {
        what: "creating the map cache",
        path: opts.maps_dir.clone(),
        source,
    })?;
    let mine: Vec<(usize, &Case)> = cases
        .iter()
        .enumerate()
        .filter(|(i, _)| opts.shard.is_none_or(|s| s.holds(*i as u64)))
        .collect();
    // Longest first (by the route's length over its speed, times the laps): the last case to
    // start is a short one, so the cores finish together.
    let mut order: Vec<(f64, usize, &Case)> = mine
        .iter()
        .map(|&(i, c)| (estimated_s(c, opts.tier), i, c))
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let next = AtomicUsize::new(0);
    // One pool of `jobs` threads, each pulling cases (a broadcast: a case is never a job another
    // thread could take up while it waits on its own). While a thread runs a case it helps the
    // other cases' parallel parts whenever it waits; a thread with no case left helps the last
    // ones running (the longest started first).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.max(1))
        .build()
        .map_err(|e| Error::Invalid(format!("thread pool: {e}")))?;
    let parts = pool.broadcast(|_| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let mut done = Vec::new();
            loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= order.len() || opts.stop.load(Ordering::Relaxed) {
                    return done;
                }
                let (_, i, case) = order[k];
                (opts.started)(case);
                if let Some(mut r) = run_case(case, opts, &maps, &pool) {
                    r.index = i;
                    (opts.progress)(&r);
                    done.push((i, r));
                }
            }
        }))
    });
    let mut results: Vec<(usize, CaseResult)> = Vec::new();
    for part in parts {
        results.extend(part.map_err(|_| Error::Invalid("a regress worker panicked".into()))?);
    }
    results.sort_by_key(|(i, _)| *i);
    Ok(results.into_iter().map(|(_, r)| r).collect())
}

/// A case's expected simulated time, seconds (0 when the file does not read: it fails fast).
fn estimated_s(case: &Case, tier: Tier) -> f64 {
    Scenario::from_file(&case.path).map_or(0.0, |s| {
        let route = autonomy::RoutePath::new(&s.route.waypoints_m, s.route.closed);
        route.length_m() / s.route.speed_m_s.max(0.1) * f64::from(laps_in(&s, tier))
    })
}

/// The laps a scenario drives in `tier`.
pub fn laps_in(s: &Scenario, tier: Tier) -> u32 {
    match tier {
        Tier::Full => s.laps,
        Tier::Quick => s.quick_laps.map_or(s.laps, |q| q.min(s.laps)),
    }
}

/// Runs one case; `None` when the stop flag cut it short.
fn run_case(
    case: &Case,
    opts: &Options<'_>,
    maps: &MapCache,
    pool: &rayon::ThreadPool,
) -> Option<CaseResult> {
    let t0 = std::time::Instant::now();
    let mut scenario = match Scenario::from_file(&case.path) {
        Ok(s) => s,
        Err(e) => return Some(error_result(case, opts.tier, e.to_string())),
    };
    let laps_in_file = scenario.laps;
    let skipped = if opts.tier == Tier::Quick && scenario.full_only {
        Some("full tier only (`[regress] full_only`): run with --full")
    } else if opts.skip_known_problems && scenario.known_problem.is_some() {
        Some("a known problem, not run (--skip-known-problems): run without it")
    } else {
        None
    };
    if let Some(why) = skipped {
        let mut r = blank(case, &scenario, opts.tier);
        r.status = Status::NotRun;
        r.messages = vec![why.into()];
        return Some(r);
    }
    scenario.laps = laps_in(&scenario, opts.tier);
    let outcome = (|| -> Result<RunReport> {
        let config = RunConfig::for_scenario(&scenario, None)?;
        let map_dir = maps.get_for_file(&scenario, &config)?;
        let setup = RunSetup {
            config,
            time_limit_s: opts.time_limit_s,
            ..RunSetup::new(map_dir)
        };
        pool.install(|| {
            run_with(
                &scenario,
                &setup,
                RunHandles {
                    stop: Some(opts.stop),
                    progress: &mut |_| {},
                    observer: &mut NoObserver,
                },
            )
        })
    })();
    let report = match outcome {
        Ok(r) if r.end == EndReason::Interrupted => return None,
        Ok(r) => r,
        Err(e) => return Some(error_result(case, opts.tier, e.to_string())),
    };
    let (mut status, mut messages) = verdict(&scenario, &report);
    if let Some(path) = &scenario.golden {
        golden_numbers(path, &report, opts, &mut status, &mut messages);
    }
    let mut r = blank(case, &scenario, opts.tier);
    r.laps_in_file = laps_in_file;
    r.status = status;
    r.messages = messages;
    r.end = Some(end_name(report.end));
    r.contacts = report.contacts.len();
    r.contacts_at_fault = report.contacts_at_fault;
    r.contacts_struck = report.contacts_struck;
    r.obstacle_clearance_m = report
        .obstacles
        .iter()
        .flat_map(|o| {
            o.passes
                .iter()
                .flat_map(|p| p.min_clearance_m.iter().copied())
        })
        .filter(|c| c.is_finite())
        .reduce(f64::min);
    r.sim_time_s = report.sim_time_s;
    r.wall_time_s = t0.elapsed().as_secs_f64();
    r.real_time_factor = report.real_time_factor;
    Some(r)
}

/// A case's golden numbers: compared with the file, or written there (`--bless`, a case that
/// did not fail), in the quick tier without a time limit (the laps they hold); a difference
/// fails the case, a file blessed says so.
fn golden_numbers(
    path: &Path,
    report: &RunReport,
    opts: &Options<'_>,
    status: &mut Status,
    messages: &mut Vec<String>,
) {
    if opts.tier != Tier::Quick || opts.time_limit_s.is_some() {
        return;
    }
    if opts.bless && *status == Status::Failed {
        messages.push(format!("not blessed (the case failed): {}", path.display()));
        return;
    }
    match golden::check(path, &golden::summary(report), opts.bless) {
        Ok(lines) if lines.is_empty() => {
            if opts.bless {
                messages.push(format!("golden numbers blessed: {}", path.display()));
            }
        }
        Ok(lines) => {
            *status = Status::Failed;
            messages.extend(lines);
        }
        Err(e) => {
            *status = Status::Failed;
            messages.push(format!("golden numbers {}: {e}", path.display()));
        }
    }
}

/// A run's end as its report names it.
fn end_name(end: EndReason) -> String {
    serde_json::to_value(end)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default()
}

/// A result with the case's identity and nothing run.
fn blank(case: &Case, s: &Scenario, tier: Tier) -> CaseResult {
    let laps = laps_in(s, tier);
    let mut r = empty(case, tier, Status::Passed);
    r.rerun = format!("taxi-sim run {} --seed {}", case.path.display(), s.seed);
    if laps != s.laps {
        r.rerun.push_str(&format!(" --laps {laps}"));
    }
    r.known_problem = s.known_problem.as_ref().map(|k| k.text.clone());
    (r.seed, r.laps, r.laps_in_file) = (s.seed, laps, s.laps);
    r
}

/// The result of a case whose file or run failed before a verdict.
fn error_result(case: &Case, tier: Tier, why: String) -> CaseResult {
    let mut r = empty(case, tier, Status::Error);
    r.messages = vec![why];
    r
}

/// A result naming the case, with `status`, and every figure zero.
fn empty(case: &Case, tier: Tier, status: Status) -> CaseResult {
    CaseResult {
        index: 0,
        suite: case.suite.clone(),
        name: case.name.clone(),
        file: case.path.display().to_string(),
        status,
        tier,
        messages: Vec::new(),
        known_problem: None,
        seed: 0,
        laps: 0,
        laps_in_file: 0,
        end: None,
        contacts: 0,
        contacts_at_fault: 0,
        contacts_struck: 0,
        obstacle_clearance_m: None,
        sim_time_s: 0.0,
        wall_time_s: 0.0,
        real_time_factor: 0.0,
        rerun: format!("taxi-sim run {}", case.path.display()),
    }
}

/// A run judged against its scenario: passed when every expectation held (no contact that
/// counts, every pass as expected, the end as expected); for a known problem, an expected
/// failure while it fails and ends as `today` states, a failure once it passes or ends otherwise.
pub fn verdict(scenario: &Scenario, r: &RunReport) -> (Status, Vec<String>) {
    let (failures, _) = failures_of(scenario, r);
    let counted = if scenario.no_contact_at_fault {
        r.contacts_at_fault
    } else {
        r.contacts.len()
    };
    let met = r.expectations_met && counted == 0;
    match (&scenario.known_problem, met) {
        (None, true) => (Status::Passed, Vec::new()),
        (None, false) => (Status::Failed, failures),
        (Some(k), true) => (
            Status::Failed,
            vec![format!(
                "known problem fixed: the run meets its expectations; remove `known_problem` and `[expectations.today]` from the file (the problem was: {})",
                k.text
            )],
        ),
        (Some(k), false) => {
            let changed = today_mismatches(k, r);
            if changed.is_empty() {
                (Status::KnownProblem, failures)
            } else {
                let mut lines: Vec<String> = changed
                    .into_iter()
                    .map(|c| format!("known problem changed: {c}"))
                    .collect();
                lines.extend(failures);
                (Status::Failed, lines)
            }
        }
    }
}

/// Where run `r` differs from the known problem's `today`, one line each.
fn today_mismatches(k: &KnownProblem, r: &RunReport) -> Vec<String> {
    let t = &k.today;
    let mut out = Vec::new();
    let end = end_name(r.end);
    if let Some(e) = t.end.filter(|e| e.as_str() != end) {
        out.push(format!("ended {end}, today's end is {}", e.as_str()));
    }
    let counts = [
        ("contacts", t.contacts, r.contacts.len()),
        (
            "contacts_at_fault",
            t.contacts_at_fault,
            r.contacts_at_fault,
        ),
        ("contacts_struck", t.contacts_struck, r.contacts_struck),
    ];
    for (what, stated, got) in counts {
        if let Some(n) = stated.filter(|&n| n != got) {
            out.push(format!("{what} {got}, today's is {n}"));
        }
    }
    if let Some(with) = &t.contacts_with {
        let mut got: Vec<&str> = Vec::new();
        for c in &r.contacts {
            if !got.contains(&c.object.as_str()) {
                got.push(&c.object);
            }
        }
        if got != *with {
            out.push(format!("contacts with {got:?}, today's are {with:?}"));
        }
    }
    out
}

#[cfg(test)]
mod tests;
