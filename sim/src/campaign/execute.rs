//! Running a campaign: variants in parallel across cores into `DIR/results.jsonl` (one line per
//! run, appended as each finishes, sorted by index at the end), failing variants as standalone
//! scenario files in `DIR/failures/`, offline maps shared through `DIR/maps/<key>` keyed by the
//! static world's content. Resumable: variants already in the results are skipped. Stoppable:
//! runs cut short by the stop flag are not recorded, so the file holds only whole runs.

use std::collections::BTreeMap;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use super::map_cache::MapCache;
use super::record::{RunRecord, invalid, read_results, record};
use super::sampler::{self, Proposal, SamplerKind};
use super::shard::{Shard, claim};
use super::{Campaign, Variant};
use crate::engine::{
    EndReason, ExternalStack, LatePolicy, NoObserver, RunHandles, RunReport, RunSetup,
    run_external, run_with,
};
use crate::error::{Error, Result};
use crate::scenario::{RunConfig, Scenario};

/// How a campaign is run.
pub struct RunOptions<'a> {
    /// Output directory.
    pub out: PathBuf,
    /// Run only this shard's variants (default: all).
    pub shard: Option<Shard>,
    /// Where the offline maps are cached (default `out/maps`); shards on a shared filesystem
    /// share one.
    pub maps_dir: Option<PathBuf>,
    /// Parallel runs (threads).
    pub jobs: usize,
    /// Variants: indices `0..runs` (default the campaign's `runs`).
    pub runs: Option<u64>,
    /// Of those, only these (sorted; `None`: all): `campaign run --variants`.
    pub variants: Option<&'a [u64]>,
    /// Set from outside (Ctrl-C) to stop: runs in flight end and are not recorded.
    pub stop: &'a AtomicBool,
    /// Run each failure again (runs are reproducible from their seed) writing it as a ROS 2
    /// bag, `failures/<index>/<index>.mcap` with its `metadata.yaml`: only failures pay for it.
    pub record_failures: bool,
    /// Told of every recorded run.
    pub progress: &'a (dyn Fn(&RunRecord) + Sync),
    /// The stack outside the process that drives every run (`None`: the shipped stack).
    pub stack: Option<ExternalStacks<'a>>,
}

/// Makes a worker's external stack for a run over the offline map in a directory.
pub type MakeStack<'a> = dyn Fn(usize, &Path) -> Result<Box<dyn ExternalStack>> + Sync + 'a;

/// A stack outside the process for a campaign's runs: a fresh one per run, made for the worker
/// that runs it (worker `w` of `jobs`: a transport isolates each worker's runs from the others',
/// e.g. on ROS domain `base + w`).
#[derive(Clone, Copy)]
pub struct ExternalStacks<'a> {
    /// Makes worker `w`'s stack for its next run, over the offline map in the directory given.
    pub make: &'a MakeStack<'a>,
    /// What a late answer costs.
    pub policy: LatePolicy,
}

/// One run by the shipped stack, or by worker `worker`'s external stack.
fn drive(
    scenario: &Scenario,
    setup: &RunSetup,
    handles: RunHandles<'_>,
    stack: Option<(ExternalStacks<'_>, usize)>,
) -> Result<RunReport> {
    match stack {
        None => run_with(scenario, setup, handles),
        Some((stacks, worker)) => {
            let mut stack = (stacks.make)(worker, &setup.map_dir)?;
            run_external(scenario, setup, handles, stack.as_mut(), stacks.policy)
        }
    }
}

/// What a campaign run did.
#[derive(Debug)]
pub struct Outcome {
    /// Every record in the directory, by index.
    pub records: Vec<RunRecord>,
    /// Runs made now (the rest were there already).
    pub ran: usize,
    /// Variants asked for.
    pub total: u64,
    /// Whether the stop flag cut it short.
    pub interrupted: bool,
}

/// The variants asked for: `runs` or the campaign's; a grid stops at its last point.
pub fn total_runs(campaign: &Campaign, runs: Option<u64>) -> u64 {
    let n = runs.unwrap_or(campaign.runs);
    if campaign.sampler == SamplerKind::Grid {
        let points = sampler::grid_size(&campaign.layout.dims, campaign.grid_steps);
        n.min(points.saturating_mul(campaign.settings.len() as u64))
    } else {
        n
    }
}

/// The point of variant `index`; `done` holds the records so far (the falsifier's evidence).
fn point_of(campaign: &Campaign, sample: u64, proposals: &[Proposal]) -> Vec<f64> {
    let dims = &campaign.layout.dims;
    match campaign.sampler {
        SamplerKind::Grid => sampler::grid_point(dims, campaign.grid_steps, sample),
        SamplerKind::Random => sampler::random_point(dims.len(), campaign.seed, sample),
        SamplerKind::Halton => sampler::halton_point(dims.len(), campaign.seed, sample),
        SamplerKind::Falsify => sampler::propose(proposals, campaign.seed, sample),
    }
}

/// The falsifier's proposals for generation `g`, refitted generation by generation from the
/// records of the earlier ones (a sample's score: its lowest over the settings).
pub fn proposals_for(campaign: &Campaign, g: u64, records: &[RunRecord]) -> Vec<Proposal> {
    let mut p = sampler::initial(&campaign.layout.dims);
    let batch = campaign.falsify.batch;
    for generation in 1..=g {
        let mut by_sample: BTreeMap<u64, (f64, &[f64])> = BTreeMap::new();
        for r in records.iter().filter(|r| r.sample < generation * batch) {
            let e = by_sample.entry(r.sample).or_insert((f64::INFINITY, &r.u));
            e.0 = e.0.min(r.score);
        }
        let mut scored: Vec<(f64, &[f64])> = by_sample.into_values().collect();
        scored.sort_by(|a, b| a.0.total_cmp(&b.0));
        let n = ((scored.len() as f64 * campaign.falsify.elite_fraction).ceil() as usize)
            .max(1)
            .min(scored.len());
        let elites: Vec<&[f64]> = scored[..n].iter().map(|s| s.1).collect();
        p = sampler::refit(&p, &elites, campaign.falsify.smoothing);
    }
    p
}

/// Variant `index` (for the falsifier, given the earlier generations' records).
pub fn variant(campaign: &Campaign, index: u64, records: &[RunRecord]) -> Variant {
    let sample = index / campaign.settings.len() as u64;
    let proposals = if campaign.sampler == SamplerKind::Falsify {
        proposals_for(campaign, sample / campaign.falsify.batch, records)
    } else {
        Vec::new()
    };
    campaign.variant_at(index, &point_of(campaign, sample, &proposals))
}

/// Runs one variant over the cache's map; `None` when the stop flag cut it short.
fn run_variant(
    campaign: &Campaign,
    v: &Variant,
    maps: &MapCache,
    (dir, record_failures): (&Path, bool),
    stop: &AtomicBool,
    (pool, stack): (&rayon::ThreadPool, Option<(ExternalStacks<'_>, usize)>),
) -> Result<Option<RunRecord>> {
    let scenario = match Scenario::from_str(&v.text, &campaign.variant_path(v.index)) {
        Ok(s) => s,
        // A draw the scenario rules refuse (an obstacle over the start pose...): recorded,
        // kept out of the statistics, and the campaign goes on.
        Err(e) => return Ok(Some(invalid(campaign, v, &e.to_string()))),
    };
    // The variant's own `[config]`, as a run of its file reads it (a `--set config.*` in it).
    let config = RunConfig::for_scenario(&scenario, None)?;
    let map_dir = maps.get(&v.text, &scenario, &config)?;
    let setup = RunSetup {
        config,
        ..RunSetup::new(map_dir)
    };
    let report = pool.install(|| {
        drive(
            &scenario,
            &setup,
            RunHandles {
                stop: Some(stop),
                progress: &mut |_| {},
                observer: &mut NoObserver,
            },
            stack,
        )
    })?;
    if report.end == EndReason::Interrupted {
        return Ok(None);
    }
    let rec = record(campaign, v, &scenario, &report);
    for f in rec.needless_file.iter().chain(&rec.called_file) {
        mapper::write_atomically(&dir.join(f), v.text.as_bytes())?;
    }
    if let Some(f) = &rec.failure_file {
        mapper::write_atomically(&dir.join(f), v.text.as_bytes())?;
        if record_failures {
            let bag = dir
                .join("failures")
                .join(v.index.to_string())
                .join(format!("{}.mcap", v.index));
            record_again(&scenario, &setup, &bag, stop, (pool, stack), &report)?;
        }
    }
    Ok(Some(rec))
}

/// Runs a failed variant again into a ROS 2 bag at `bag`; the run must end as it did (it is
/// reproducible from its seed), or the bag is refused as not that failure's.
fn record_again(
    scenario: &Scenario,
    setup: &RunSetup,
    bag: &Path,
    stop: &AtomicBool,
    (pool, stack): (&rayon::ThreadPool, Option<(ExternalStacks<'_>, usize)>),
    first: &RunReport,
) -> Result<()> {
    if let Some(parent) = bag.parent() {
        std::fs::create_dir_all(parent).map_err(|source| Error::Io {
            what: "creating a failure's bag directory",
            path: parent.to_path_buf(),
            source,
        })?;
    }
    let mut writer = crate::rosbag::RosBag::create(bag)?;
    let again = pool.install(|| {
        drive(
            scenario,
            setup,
            RunHandles {
                stop: Some(stop),
                progress: &mut |_| {},
                observer: &mut writer,
            },
            stack,
        )
    })?;
    let same = |r: &RunReport| (r.end, r.contacts.len(), r.stops.len());
    if again.end != EndReason::Interrupted && same(&again) != same(first) {
        return Err(Error::Invalid(format!(
            "{}: the failure ran again ended {:?} with {} contacts and {} stops, not {:?} with \
             {} and {} as it first did: not reproducible from its seed",
            bag.display(),
            again.end,
            again.contacts.len(),
            again.stops.len(),
            first.end,
            first.contacts.len(),
            first.stops.len()
        )));
    }
    Ok(())
}

/// Runs one variant on a worker's pool: the worker's number is the third argument.
type RunOne<'a> =
    dyn Fn(&Variant, &rayon::ThreadPool, usize) -> Result<Option<RunRecord>> + Sync + 'a;

/// Runs `each` over `todo` on `jobs` worker threads, each pulling the next variant; a worker
/// runs a variant's stages on its own rayon pool of `jobs / todo` threads (one when there are
/// more variants than cores). Stops taking variants once `stop` is set.
fn run_parallel(
    todo: &[Variant],
    jobs: usize,
    stop: &AtomicBool,
    each: &RunOne<'_>,
) -> Result<Vec<RunRecord>> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = jobs.min(todo.len()).max(1);
    let threads = (jobs / workers).max(1);
    let results: Vec<Result<Vec<RunRecord>>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|worker| {
                let next = &next;
                scope.spawn(move || -> Result<Vec<RunRecord>> {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .map_err(|e| Error::Invalid(format!("thread pool: {e}")))?;
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= todo.len() || stop.load(Ordering::Relaxed) {
                            return Ok(mine);
                        }
                        mine.extend(each(&todo[i], &pool, worker)?);
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(Error::Invalid("a campaign worker panicked".into())))
            })
            .collect()
    });
    let mut all = Vec::new();
    for r in results {
        all.extend(r?);
    }
    Ok(all)
}

/// Appends records to `results.jsonl`, a whole line per write.
struct Appender(Mutex<std::fs::File>, PathBuf);

impl Appender {
    fn push(&self, r: &RunRecord) -> Result<()> {
        let line = serde_json::to_string(r)? + "\n";
        let mut f = self
            .0
            .lock()
            .map_err(|_| Error::Invalid("results file lock poisoned".into()))?;
        f.write_all(line.as_bytes())
            .and_then(|()| f.flush())
            .map_err(|source| Error::Io {
                what: "appending to the results",
                path: self.1.clone(),
                source,
            })
    }
}

/// Runs the campaign's variants not yet in `opts.out`.
pub fn run_campaign(campaign: &Campaign, opts: &RunOptions<'_>) -> Result<Outcome> {
    let dir = &opts.out;
    let maps_dir = opts.maps_dir.clone().unwrap_or_else(|| dir.join("maps"));
    for p in [dir.join("failures"), maps_dir] {
        std::fs::create_dir_all(&p).map_err(|source| Error::Io {
            what: "creating the campaign directory",
            path: p,
            source,
        })?;
    }
    if opts.shard.is_some() && campaign.sampler == SamplerKind::Falsify {
        return Err(Error::Invalid(
            "--shard: the falsify sampler's generations depend on every earlier run, so it cannot be split; use random or halton".into(),
        ));
    }
    if opts.variants.is_some() && campaign.sampler == SamplerKind::Falsify {
        return Err(Error::Invalid(
            "--variants: the falsify sampler's variants depend on every earlier run, so an index names no variant on its own; use random, halton or grid".into(),
        ));
    }
    let total = total_runs(campaign, opts.runs);
    claim(campaign, dir, opts.shard, total)?;
    let mut records = read_results(dir)?;
    let path = dir.join("results.jsonl");
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|source| Error::Io {
            what: "opening the results",
            path: path.clone(),
            source,
        })?;
    let out = Appender(Mutex::new(file), path.clone());
    let maps = MapCache::new(opts.maps_dir.clone().unwrap_or_else(|| dir.join("maps")));
    // The falsifier runs generation by generation; the others all at once.
    let step = match campaign.sampler {
        SamplerKind::Falsify => campaign.falsify.batch * campaign.settings.len() as u64,
        _ => total.max(1),
    };
    let mut ran = 0;
    let mut start = 0;
    while start < total && !opts.stop.load(Ordering::Relaxed) {
        let end = (start + step).min(total);
        let have: std::collections::HashSet<u64> = records.iter().map(|r| r.index).collect();
        let todo: Vec<Variant> = (start..end)
            .filter(|i| !have.contains(i) && opts.shard.is_none_or(|s| s.holds(*i)))
            .filter(|i| opts.variants.is_none_or(|v| v.binary_search(i).is_ok()))
            .map(|i| variant(campaign, i, &records))
            .collect();
        let fresh = run_parallel(&todo, opts.jobs.max(1), opts.stop, &|v, pool, worker| {
            let rec = run_variant(
                campaign,
                v,
                &maps,
                (dir, opts.record_failures),
                opts.stop,
                (pool, opts.stack.map(|s| (s, worker))),
            )?;
            if let Some(r) = &rec {
                out.push(r)?;
                (opts.progress)(r);
            }
            Ok(rec)
        })?;
        ran += fresh.len();
        records.extend(fresh);
        records.sort_by_key(|r| r.index);
        start = end;
    }
    let interrupted = opts.stop.load(Ordering::Relaxed);
    // Sorted by index: the file is the same whatever --jobs (wall times aside).
    let text: String = records
        .iter()
        .map(|r| serde_json::to_string(r).map(|l| l + "\n"))
        .collect::<std::result::Result<_, _>>()?;
    mapper::write_atomically(&path, text.as_bytes())?;
    super::summary::write(dir, &records)?;
    Ok(Outcome {
        records,
        ran,
        total,
        interrupted,
    })
}
