//! Running a campaign: variants in parallel across cores into `DIR/results.jsonl` (one line per
//! run, appended as each finishes, sorted by index at the end), failing variants as standalone
//! scenario files in `DIR/failures/`, offline maps shared through `DIR/maps/<key>` keyed by the
//! static world's content. Resumable: variants already in the results are skipped. Stoppable:
//! runs cut short by the stop flag are not recorded, so the file holds only whole runs.

use std::collections::{BTreeMap, HashMap};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use serde::{Deserialize, Serialize};

use super::sampler::{self, Proposal, SamplerKind};
use super::{Campaign, Variant};
use crate::config::RunConfig;
use crate::error::{Error, Result};
use crate::judge::{EndReason, PassOutcome};
use crate::observer::NoObserver;
use crate::report::RunReport;
use crate::run::{RunHandles, RunSetup, run_with};
use crate::scenario::{Expectation, ExpectedEnd, Scenario};

/// One pass-level outcome of an obstacle in a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObstacleOutcome {
    /// Its id.
    pub id: String,
    /// Its kind.
    pub kind: String,
    /// What the scenario expects.
    pub expect: String,
    /// Outcome of its worst pass (`collided` over `stopped` over `deviated` over `passed`;
    /// `not_passed` when the vehicle never came by it).
    pub outcome: String,
    /// Whether every pass met the expectation.
    pub met: bool,
    /// Smallest ground-truth clearance per level over its passes, metres.
    pub min_clearance_m: Vec<Option<f64>>,
}

/// One line of `results.jsonl`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Variant index.
    pub index: u64,
    /// Sample (`index / settings`).
    pub sample: u64,
    /// Parameter setting (`index % settings`).
    pub setting: usize,
    /// The scenario seed the run had.
    pub seed: u64,
    /// Each draw by label.
    pub sampled: BTreeMap<String, serde_json::Value>,
    /// The setting's parameters by dotted path.
    pub parameters: BTreeMap<String, serde_json::Value>,
    /// The point of the unit cube (the falsifier refits on these).
    pub u: Vec<f64>,
    /// Why the run ended.
    pub end: String,
    /// Whether every expectation held.
    pub expectations_met: bool,
    /// A contact, or an unmet expectation.
    pub failed: bool,
    /// What failed, one line each.
    pub failures: Vec<String>,
    /// Ground-truth contacts.
    pub contacts: usize,
    /// The objects touched.
    pub contacts_with: Vec<String>,
    /// Contacts that began while the vehicle stood still (something ran into it).
    #[serde(default)]
    pub contacts_while_stopped: usize,
    /// Per run-time obstacle.
    pub obstacles: Vec<ObstacleOutcome>,
    /// Smallest ground-truth clearance per level to any object, metres.
    pub min_clearance_m: Vec<Option<f64>>,
    /// Smallest clearance to any run-time obstacle at any level over the passes, metres.
    pub obstacle_clearance_m: Option<f64>,
    /// Stops of the vehicle.
    pub stops: usize,
    /// Passes that deviated.
    pub deviations: usize,
    /// Passes that stopped where the expectation was to drive on (pass under or deviate).
    pub false_stops: usize,
    /// Passes that deviated where the expectation was to pass under.
    pub needless_deviations: usize,
    /// Lap times, seconds.
    pub lap_times_s: Vec<f64>,
    /// Simulated time, seconds.
    pub sim_time_s: f64,
    /// Wall time of the run, seconds (the one field that differs between identical runs).
    pub wall_time_s: f64,
    /// What the falsifier minimises: the obstacle clearance, minus 1 on failure, minus the
    /// contacts.
    pub score: f64,
    /// The failure file, relative to the campaign directory.
    pub failure_file: Option<String>,
    /// What injected faults did (`[faults]` of the run configuration).
    #[serde(default)]
    pub faults: crate::faults::FaultCounts,
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

fn worst(outcomes: impl Iterator<Item = PassOutcome>) -> Option<PassOutcome> {
    let rank = |o: &PassOutcome| match o {
        PassOutcome::Passed => 0,
        PassOutcome::Deviated => 1,
        PassOutcome::Stopped => 2,
        PassOutcome::Collided => 3,
    };
    outcomes.max_by_key(rank)
}

/// Drawn or set values as JSON, by label.
fn as_json<'a>(
    pairs: impl Iterator<Item = (&'a String, &'a toml::Value)>,
) -> BTreeMap<String, serde_json::Value> {
    pairs
        .map(|(k, x)| (k.clone(), serde_json::to_value(x).unwrap_or_default()))
        .collect()
}

/// The record of a run of variant `v`.
pub fn record(campaign: &Campaign, v: &Variant, scenario: &Scenario, r: &RunReport) -> RunRecord {
    let mut failures = Vec::new();
    let mut contacts_with: Vec<String> = r.contacts.iter().map(|c| c.object.clone()).collect();
    contacts_with.dedup();
    let standing = |t: f64| {
        r.stops
            .iter()
            .any(|s| s.start_s <= t && s.end_s.is_none_or(|e| t <= e))
    };
    let mut contacts_while_stopped = 0;
    for c in &r.contacts {
        let still = standing(c.time_s);
        contacts_while_stopped += usize::from(still);
        let how = if still { " (standing)" } else { "" };
        failures.push(format!(
            "contact{how}: {} with {} at {:.1} s",
            c.part, c.object, c.time_s
        ));
    }
    let (mut false_stops, mut needless, mut deviations) = (0, 0, 0);
    let mut obstacles = Vec::new();
    let mut obstacle_clearance = f64::INFINITY;
    for o in &r.obstacles {
        for p in &o.passes {
            let expect_drive = matches!(o.expected, Expectation::PassUnder | Expectation::Deviate);
            false_stops += usize::from(p.outcome == PassOutcome::Stopped && expect_drive);
            needless += usize::from(
                p.outcome == PassOutcome::Deviated && o.expected == Expectation::PassUnder,
            );
            deviations += usize::from(p.outcome == PassOutcome::Deviated);
            if !p.met {
                failures.push(format!(
                    "{} lap {}: {}, expected {} (clearance {:.2} m)",
                    o.id,
                    p.lap,
                    p.outcome,
                    o.expected,
                    p.min_clearance_m
                        .iter()
                        .copied()
                        .fold(f64::INFINITY, f64::min)
                ));
            }
        }
        let levels = o.passes.first().map_or(0, |p| p.min_clearance_m.len());
        let per_level: Vec<f64> = (0..levels)
            .map(|k| {
                o.passes
                    .iter()
                    .map(|p| p.min_clearance_m[k])
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        obstacle_clearance = per_level.iter().copied().fold(obstacle_clearance, f64::min);
        obstacles.push(ObstacleOutcome {
            id: o.id.clone(),
            kind: o.kind.clone(),
            expect: o.expected.as_str().into(),
            outcome: worst(o.passes.iter().map(|p| p.outcome))
                .map_or("not_passed".into(), |p| p.as_str().into()),
            met: o.passes.iter().all(|p| p.met),
            min_clearance_m: per_level.into_iter().map(finite).collect(),
        });
    }
    let end = serde_json::to_value(r.end)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default();
    let end_met = match scenario.expected_end {
        ExpectedEnd::Completed => r.end == EndReason::Completed,
        ExpectedEnd::WaitingForHiddenObstacle => r.end == EndReason::WaitingForHiddenObstacle,
        ExpectedEnd::StoppedForGood => r.end != EndReason::Completed,
        ExpectedEnd::Any => true,
    };
    if !end_met {
        failures.push(format!("ended {end}, expected {:?}", scenario.expected_end).to_lowercase());
    }
    if !r.expectations_met && failures.is_empty() {
        failures.push("an expectation was not met".into());
    }
    let failed = !r.contacts.is_empty() || !r.expectations_met;
    let clearance = finite(obstacle_clearance);
    let score = clearance.unwrap_or(10.0).min(10.0)
        - if failed { 1.0 } else { 0.0 }
        - r.contacts.len() as f64;
    RunRecord {
        index: v.index,
        sample: v.sample,
        setting: v.setting,
        seed: scenario.seed,
        sampled: as_json(v.drawn.iter()),
        parameters: as_json(campaign.settings[v.setting].iter().map(|(k, x)| (k, x))),
        u: v.u.clone(),
        end,
        expectations_met: r.expectations_met,
        failed,
        failures,
        contacts: r.contacts.len(),
        contacts_with,
        contacts_while_stopped,
        obstacles,
        min_clearance_m: r.min_clearance_m.iter().copied().map(finite).collect(),
        obstacle_clearance_m: clearance,
        stops: r.stops.len(),
        deviations,
        false_stops,
        needless_deviations: needless,
        lap_times_s: r.lap_times_s.clone(),
        sim_time_s: r.sim_time_s,
        wall_time_s: r.wall_time_s,
        score,
        failure_file: failed.then(|| format!("failures/{}.toml", v.index)),
        faults: r.faults,
    }
}

/// The static world's key: what the mapping drive depends on (world, static objects, patches,
/// route, vehicle and start, seed, levels, map and LiDAR settings, a stale map's faults, the
/// map format: a campaign directory of an older build gets new maps, not blocks it cannot read).
/// Variants with the same key share one offline map.
pub fn static_world_key(scenario: &Scenario, config: &RunConfig) -> Result<String> {
    let mut text = format!(
        "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{}|{:?}|{:?}|{:?}|{}",
        scenario.world,
        scenario.objects,
        scenario.patches,
        scenario.route,
        scenario.vehicle.vehicle,
        scenario.vehicle.world_from_start,
        scenario.seed,
        crate::mapping::levels_of(scenario, config)?,
        crate::mapping::map_config(config),
        config.lidar,
        crate::mapping::MAP_FORMAT,
    );
    if config.faults.stale_map.any() {
        text.push_str(&format!("|{:?}", config.faults.stale_map));
    }
    Ok(format!(
        "{:08x}{:06x}",
        crc32fast::hash(text.as_bytes()),
        text.len() & 0xff_ffff
    ))
}

/// One static world's map directory, once built (or why it could not be).
type MapSlot = OnceLock<std::result::Result<PathBuf, String>>;

/// The offline maps of a campaign directory, built once per static world.
struct MapCache {
    dir: PathBuf,
    entries: Mutex<HashMap<String, Arc<MapSlot>>>,
}

impl MapCache {
    /// The map of `scenario` (whose text is `text`) under `config`, built on first use; other
    /// variants wanting the same map wait for it. Built in a scratch directory and renamed into
    /// place, so a map directory is never seen half written (by this process or another).
    fn get(&self, scenario_text: &str, scenario: &Scenario, config: &RunConfig) -> Result<PathBuf> {
        let key = static_world_key(scenario, config)?;
        let cell = self
            .entries
            .lock()
            .map_err(|_| Error::Invalid("map cache poisoned".into()))?
            .entry(key.clone())
            .or_default()
            .clone();
        cell.get_or_init(|| {
            let done = self.dir.join(&key);
            if done.join("manifest.json").exists() {
                return Ok(done);
            }
            // Unique across the machines of a shared filesystem, not only across processes.
            let nonce = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos());
            let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
                .unwrap_or_default()
                .trim()
                .to_string();
            let scratch = self.dir.join(format!(
                "{key}.partial-{host}-{}-{nonce}",
                std::process::id()
            ));
            let build = || -> Result<()> {
                std::fs::create_dir_all(&scratch).map_err(|source| Error::Io {
                    what: "creating a map directory",
                    path: scratch.clone(),
                    source,
                })?;
                // The map holds the scenario it was driven in: `fingerprint` reads it.
                let file = scratch.join("scenario.toml");
                mapper::write_atomically(&file, scenario_text.as_bytes())?;
                let s = Scenario::from_file(&file)?;
                crate::mapping::map_drive(&s, config, &scratch, &mut |_, _| {})?;
                match std::fs::rename(&scratch, &done) {
                    Ok(()) => Ok(()),
                    // Another process got there first: theirs is the same map.
                    Err(_) if done.join("manifest.json").exists() => {
                        let _ = std::fs::remove_dir_all(&scratch);
                        Ok(())
                    }
                    Err(source) => Err(Error::Io {
                        what: "moving a map into the cache",
                        path: done.clone(),
                        source,
                    }),
                }
            };
            build().map(|()| done).map_err(|e| e.to_string())
        })
        .clone()
        .map_err(Error::Invalid)
    }
}

/// One shard of a campaign split across machines: the variants `i` with `i % count == index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: u64,
    /// Shards in all.
    pub count: u64,
}

impl Shard {
    /// Parses `I/N` (0 <= I < N), or `auto/N`, which takes `I` from `SLURM_ARRAY_TASK_ID` (a
    /// Slurm array task) or `JOB_COMPLETION_INDEX` (a Kubernetes indexed Job) through `env`.
    pub fn parse(
        text: &str,
        env: &dyn Fn(&str) -> Option<String>,
    ) -> std::result::Result<Self, String> {
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| format!("--shard {text}: expected I/N or auto/N"))?;
        let count: u64 = n
            .trim()
            .parse()
            .ok()
            .filter(|n| *n >= 1)
            .ok_or_else(|| format!("--shard {text}: N must be a whole number >= 1"))?;
        let (i, from) = if i.trim() == "auto" {
            ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"]
                .iter()
                .find_map(|k| env(k).map(|v| (v, *k)))
                .ok_or_else(|| {
                    format!("--shard {text}: neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set")
                })?
        } else {
            (i.trim().to_string(), "--shard")
        };
        let index: u64 = i
            .trim()
            .parse()
            .map_err(|_| format!("--shard {text}: {from} = {i:?} is not a whole number"))?;
        if index >= count {
            return Err(format!(
                "--shard {text}: {from} = {index} is not below N = {count} (shards are numbered from 0)"
            ));
        }
        Ok(Shard { index, count })
    }

    /// Whether variant `i` belongs to this shard.
    pub fn holds(&self, i: u64) -> bool {
        i % self.count == self.index
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

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
    /// Set from outside (Ctrl-C) to stop: runs in flight end and are not recorded.
    pub stop: &'a AtomicBool,
    /// Told of every recorded run.
    pub progress: &'a (dyn Fn(&RunRecord) + Sync),
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

/// Reads `results.jsonl`; a last line cut short (a killed process) is dropped and the file
/// rewritten without it. Any other bad line is an error naming it.
pub fn read_results(dir: &Path) -> Result<Vec<RunRecord>> {
    let path = dir.join("results.jsonl");
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(source) => {
            return Err(Error::Io {
                what: "reading the results",
                path,
                source,
            });
        }
    };
    let lines: Vec<&str> = text.lines().collect();
    let mut records = Vec::with_capacity(lines.len());
    for (i, line) in lines.iter().enumerate() {
        match serde_json::from_str::<RunRecord>(line) {
            Ok(r) => records.push(r),
            Err(_) if i + 1 == lines.len() && !text.ends_with('\n') => {
                let mut kept: String = lines[..i].iter().map(|l| format!("{l}\n")).collect();
                kept.shrink_to_fit();
                mapper::write_atomically(&path, kept.as_bytes())?;
            }
            Err(e) => {
                return Err(Error::BadFile {
                    path,
                    message: format!("line {}: not a run record: {e}", i + 1),
                });
            }
        }
    }
    records.sort_by_key(|r| r.index);
    records.dedup_by_key(|r| r.index);
    Ok(records)
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
    dir: &Path,
    stop: &AtomicBool,
    pool: &rayon::ThreadPool,
) -> Result<Option<RunRecord>> {
    let scenario = match Scenario::from_str(&v.text, &campaign.variant_path(v.index)) {
        Ok(s) => s,
        // A draw the scenario rules refuse (an obstacle over the start pose...): recorded,
        // kept out of the statistics, and the campaign goes on.
        Err(e) => return Ok(Some(invalid(campaign, v, &e.to_string()))),
    };
    let config = campaign.config(v.setting)?;
    let map_dir = maps.get(&v.text, &scenario, &config)?;
    let setup = RunSetup {
        config,
        ..RunSetup::new(map_dir)
    };
    let report = pool.install(|| {
        run_with(
            &scenario,
            &setup,
            RunHandles {
                stop: Some(stop),
                progress: &mut |_| {},
                observer: &mut NoObserver,
            },
        )
    })?;
    if report.end == EndReason::Interrupted {
        return Ok(None);
    }
    let rec = record(campaign, v, &scenario, &report);
    if let Some(f) = &rec.failure_file {
        mapper::write_atomically(&dir.join(f), v.text.as_bytes())?;
    }
    Ok(Some(rec))
}

/// The record of a variant that is not a valid scenario: `end` is `invalid`, the reason in
/// `failures`; not a failure, and scored as a clear run so the falsifier does not chase it.
fn invalid(campaign: &Campaign, v: &Variant, why: &str) -> RunRecord {
    RunRecord {
        index: v.index,
        sample: v.sample,
        setting: v.setting,
        seed: 0,
        sampled: as_json(v.drawn.iter()),
        parameters: as_json(campaign.settings[v.setting].iter().map(|(k, x)| (k, x))),
        u: v.u.clone(),
        end: INVALID.into(),
        expectations_met: false,
        failed: false,
        failures: vec![why.to_string()],
        contacts: 0,
        contacts_with: Vec::new(),
        contacts_while_stopped: 0,
        obstacles: Vec::new(),
        min_clearance_m: Vec::new(),
        obstacle_clearance_m: None,
        stops: 0,
        deviations: 0,
        false_stops: 0,
        needless_deviations: 0,
        lap_times_s: Vec::new(),
        sim_time_s: 0.0,
        wall_time_s: 0.0,
        score: 10.0,
        failure_file: None,
        faults: Default::default(),
    }
}

/// The `end` of a variant that is not a valid scenario.
pub const INVALID: &str = "invalid";

/// Runs `each` over `todo` on `jobs` worker threads, each pulling the next variant; a worker
/// runs a variant's stages on its own rayon pool of `jobs / todo` threads (one when there are
/// more variants than cores). Stops taking variants once `stop` is set.
fn run_parallel(
    todo: &[Variant],
    jobs: usize,
    stop: &AtomicBool,
    each: &(dyn Fn(&Variant, &rayon::ThreadPool) -> Result<Option<RunRecord>> + Sync),
) -> Result<Vec<RunRecord>> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = jobs.min(todo.len()).max(1);
    let threads = (jobs / workers).max(1);
    let results: Vec<Result<Vec<RunRecord>>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| -> Result<Vec<RunRecord>> {
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
                        mine.extend(each(&todo[i], &pool)?);
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

/// Checks (or writes) `DIR/campaign.json`: a directory holds the results of one campaign.
fn claim(campaign: &Campaign, dir: &Path, shard: Option<Shard>, total: u64) -> Result<()> {
    let path = dir.join("campaign.json");
    let mut mine = serde_json::json!({
        "campaign": campaign.path.display().to_string(),
        "name": campaign.name,
        "digest": campaign.digest,
        "settings": campaign.settings.len(),
        "sampler": campaign.sampler.as_str(),
        "batch": campaign.falsify.batch,
        "seed": campaign.seed,
        "total": total,
    });
    if let Some(s) = shard {
        mine["shard"] = serde_json::Value::String(s.to_string());
    }
    if let Ok(text) = std::fs::read_to_string(&path) {
        let theirs: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
        if theirs.get("shard") != mine.get("shard") {
            let show = |v: &serde_json::Value| {
                v.get("shard")
                    .and_then(|s| s.as_str())
                    .map_or("the whole campaign".to_string(), |s| format!("shard {s}"))
            };
            return Err(Error::BadFile {
                path,
                message: format!(
                    "this directory holds {} of this campaign, not {}; give another --out",
                    show(&theirs),
                    show(&mine)
                ),
            });
        }
        if theirs.get("digest") != mine.get("digest") {
            return Err(Error::BadFile {
                path,
                message: format!(
                    "this directory holds the results of another campaign (or of an earlier version of this one: {} vs {}); give another --out or delete the directory",
                    theirs.get("digest").and_then(|d| d.as_str()).unwrap_or("?"),
                    campaign.digest
                ),
            });
        }
        return Ok(());
    }
    mapper::write_atomically(&path, serde_json::to_string_pretty(&mine)?.as_bytes())?;
    Ok(())
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
    let maps = MapCache {
        dir: opts.maps_dir.clone().unwrap_or_else(|| dir.join("maps")),
        entries: Mutex::default(),
    };
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
            .map(|i| variant(campaign, i, &records))
            .collect();
        let fresh = run_parallel(&todo, opts.jobs.max(1), opts.stop, &|v, pool| {
            let rec = run_variant(campaign, v, &maps, dir, opts.stop, pool)?;
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
