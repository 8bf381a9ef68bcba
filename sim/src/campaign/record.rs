//! A run's record in a campaign's `results.jsonl` ([`RunRecord`], one JSON line per run: the
//! sampled values, the setting, contacts and who was at fault, clearances, passes, the movers'
//! traffic-conflict figures, the end, the wall time), made from
//! a run's report ([`record`]) or for a variant that is not a valid scenario ([`INVALID`]), and
//! read back ([`read_results`], which drops a last line cut short).

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{Campaign, Variant};
use crate::engine::{EndReason, PassOutcome, RunReport};
use crate::error::{Error, Result};
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
    /// A mover's smallest time to collision, seconds (`None`: never on a collision course, or
    /// not a mover).
    #[serde(default)]
    pub min_ttc_s: Option<f64>,
    /// A mover's post-encroachment time, seconds (`None`: no conflict area, or not a mover).
    #[serde(default)]
    pub pet_s: Option<f64>,
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
    /// A contact (with `[expectations] no_contact_at_fault`: a contact at fault), or an unmet
    /// expectation.
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
    /// Contacts judged at fault: the vehicle moving into them (|true speed| > 0.05 m/s), or
    /// driven into while they lasted. Records before 2026-12-08 held every contact begun while
    /// the vehicle moved at fault.
    #[serde(default)]
    pub contacts_at_fault: usize,
    /// Contacts judged struck by a mover: the vehicle standing, or moving while the mover came
    /// into room it held.
    #[serde(default)]
    pub contacts_struck: usize,
    /// Of those, struck while the vehicle moved (0 in records before 2026-12-08).
    #[serde(default)]
    pub contacts_struck_while_moving: usize,
    /// Smallest time to collision with any mover, seconds (`None`: never on a collision course,
    /// or no mover).
    #[serde(default)]
    pub min_ttc_s: Option<f64>,
    /// Smallest post-encroachment time with any mover, seconds (`None`: no conflict area).
    #[serde(default)]
    pub min_pet_s: Option<f64>,
    /// Per run-time obstacle.
    pub obstacles: Vec<ObstacleOutcome>,
    /// Smallest ground-truth clearance per level to any object, metres.
    pub min_clearance_m: Vec<Option<f64>>,
    /// Smallest clearance to any run-time obstacle at any level over the passes, metres.
    pub obstacle_clearance_m: Option<f64>,
    /// Smallest ground-truth clearance to a static object (sign, light, parked aircraft), metres
    /// (`None`: none came within 5 m).
    #[serde(default)]
    pub static_clearance_m: Option<f64>,
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
    pub faults: crate::world::FaultCounts,
    /// The pilot call that ended the run, as `call/hold` (`blocked/mover`,
    /// `hidden_obstacle/lost_obstacle`, `hidden_obstacle/mover_lost_at_body`,
    /// `walk_around/unseen_ground`, ...; see
    /// `engine::PilotCallReport`).
    #[serde(default)]
    pub pilot_call: Option<String>,
    /// That call was needless: ground truth had no object near what held the vehicle.
    #[serde(default)]
    pub needless_pilot_call: bool,
    /// Ground truth at that call: the object nearest what held the vehicle, and how far, metres.
    #[serde(default)]
    pub pilot_call_object: Option<(String, f64)>,
    /// The scenario file of a run whose pilot call was needless, relative to the campaign
    /// directory (`needless/<index>.toml`): to run it alone and read why the stack held.
    #[serde(default)]
    pub needless_file: Option<String>,
    /// The scenario file of a run that ended with a pilot call, needless or not, relative to the
    /// campaign directory (`called/<index>.toml`): to run it alone or replay it.
    #[serde(default)]
    pub called_file: Option<String>,
}

impl RunRecord {
    /// The record with its wall time zeroed: what two runs of one variant agree on.
    pub fn timeless(&self) -> RunRecord {
        RunRecord {
            wall_time_s: 0.0,
            ..self.clone()
        }
    }
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

/// One failure line per judged contact that counts (with `no_contact_at_fault`, a contact struck
/// does not); returns how many contacts began during a stop.
fn contact_failures(scenario: &Scenario, r: &RunReport, failures: &mut Vec<String>) -> usize {
    let standing = |t: f64| {
        r.stops
            .iter()
            .any(|s| s.start_s <= t && s.end_s.is_none_or(|e| t <= e))
    };
    let contacts_while_stopped = r.contacts.iter().filter(|c| standing(c.time_s)).count();
    // Each judgement (a pair driven into while it lasts is judged again); contacts no judge
    // saw (none, as the loop runs) count as at fault.
    let judged = r
        .contacts_judged
        .iter()
        .map(|j| (&j.contact, j.at_fault))
        .chain(
            r.contacts
                .iter()
                .skip(r.contacts_judged.len())
                .map(|c| (c, true)),
        );
    for (c, at_fault) in judged {
        let still = standing(c.time_s);
        if scenario.no_contact_at_fault && !at_fault {
            // Struck, standing or while moving: not a failure by this scenario's rule.
            continue;
        }
        let how = match (still, at_fault) {
            (_, false) => " (struck)",
            (true, true) => " (standing)",
            (false, true) => "",
        };
        failures.push(format!(
            "contact{how}: {} with {} at {:.1} s",
            c.part, c.object, c.time_s
        ));
    }
    contacts_while_stopped
}

/// What failed in run `r` of `scenario`, one line each (a contact that counts, a pass that did
/// not meet its obstacle's expectation with its clearance, the end against the expected one),
/// and how many contacts began during a stop.
pub fn failures_of(scenario: &Scenario, r: &RunReport) -> (Vec<String>, usize) {
    let mut failures = Vec::new();
    let contacts_while_stopped = contact_failures(scenario, r, &mut failures);
    for o in &r.obstacles {
        for p in o.passes.iter().filter(|p| !p.met) {
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
        if o.passes.is_empty() && scenario.expected_end != ExpectedEnd::Any && !r.expectations_met {
            failures.push(format!("{}: never passed, expected {}", o.id, o.expected));
        }
    }
    let end_met = match scenario.expected_end {
        ExpectedEnd::Completed => r.end == EndReason::Completed,
        ExpectedEnd::WaitingForHiddenObstacle => r.end == EndReason::WaitingForHiddenObstacle,
        ExpectedEnd::WaitingForWalkAround => r.end == EndReason::WaitingForWalkAround,
        ExpectedEnd::StoppedForGood => r.end != EndReason::Completed,
        ExpectedEnd::Struck => r.end == EndReason::Struck,
        ExpectedEnd::Any => true,
    };
    if !end_met {
        let end = serde_json::to_value(r.end)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default();
        failures.push(format!("ended {end}, expected {:?}", scenario.expected_end).to_lowercase());
    }
    if let Some(m) = scenario.max_stops.filter(|&m| r.stops.len() > m) {
        failures.push(format!("{} stops, at most {m} expected", r.stops.len()));
    }
    failures.extend(crate::engine::localization_misses(
        scenario,
        r.localization.as_ref(),
    ));
    if !r.expectations_met && failures.is_empty() {
        failures.push("an expectation was not met".into());
    }
    (failures, contacts_while_stopped)
}

/// The record of a run of variant `v`.
pub fn record(campaign: &Campaign, v: &Variant, scenario: &Scenario, r: &RunReport) -> RunRecord {
    let (failures, contacts_while_stopped) = failures_of(scenario, r);
    let mut contacts_with: Vec<String> = r.contacts.iter().map(|c| c.object.clone()).collect();
    contacts_with.dedup();
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
            min_ttc_s: o.min_ttc_s,
            pet_s: o.pet_s,
        });
    }
    let end = serde_json::to_value(r.end)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default();
    let counted_contacts = if scenario.no_contact_at_fault {
        r.contacts_at_fault
    } else {
        r.contacts.len()
    };
    let failed = counted_contacts > 0 || !r.expectations_met;
    let needless_call = r.pilot_call.as_ref().is_some_and(|c| c.needless);
    let min_of = |xs: &mut dyn Iterator<Item = f64>| xs.reduce(f64::min);
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
        contacts_at_fault: r.contacts_at_fault,
        contacts_struck: r.contacts_struck,
        contacts_struck_while_moving: r.contacts_struck_while_moving,
        min_ttc_s: min_of(&mut r.obstacles.iter().filter_map(|o| o.min_ttc_s)),
        min_pet_s: min_of(&mut r.obstacles.iter().filter_map(|o| o.pet_s)),
        obstacles,
        min_clearance_m: r.min_clearance_m.iter().copied().map(finite).collect(),
        obstacle_clearance_m: clearance,
        static_clearance_m: r.closest_static.first().map(|c| c.min_clearance_m),
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
        pilot_call: r.pilot_call.as_ref().map(|c| {
            format!(
                "{}/{}",
                c.call,
                c.hold.as_ref().map_or("none", |h| h.name())
            )
        }),
        needless_pilot_call: needless_call,
        pilot_call_object: r.pilot_call.as_ref().and_then(|c| c.nearest_object.clone()),
        needless_file: needless_call.then(|| format!("needless/{}.toml", v.index)),
        called_file: (r.pilot_call.is_some()).then(|| format!("called/{}.toml", v.index)),
    }
}

/// The `end` of a variant that is not a valid scenario.
pub const INVALID: &str = "invalid";

/// The record of a variant that is not a valid scenario: `end` is `invalid`, the reason in
/// `failures`; not a failure, and scored as a clear run so the falsifier does not chase it.
pub(super) fn invalid(campaign: &Campaign, v: &Variant, why: &str) -> RunRecord {
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
        contacts_at_fault: 0,
        contacts_struck: 0,
        contacts_struck_while_moving: 0,
        min_ttc_s: None,
        min_pet_s: None,
        obstacles: Vec::new(),
        min_clearance_m: Vec::new(),
        obstacle_clearance_m: None,
        static_clearance_m: None,
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
        pilot_call: None,
        needless_pilot_call: false,
        pilot_call_object: None,
        needless_file: None,
        called_file: None,
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
    let (records, cut) = parse_results(&text, &path)?;
    if cut {
        // Every line but the last, cut short.
        let whole = text.lines().count() - 1;
        let kept: String = text.lines().take(whole).map(|l| format!("{l}\n")).collect();
        mapper::write_atomically(&path, kept.as_bytes())?;
    }
    Ok(records)
}

/// The run records of `text`, the lines of a `results.jsonl` read from `path` (named in
/// errors), sorted by index, one per variant; and whether its last line was cut short (a killed
/// process: dropped). Any other bad line is an error naming it.
pub(crate) fn parse_results(text: &str, path: &Path) -> Result<(Vec<RunRecord>, bool)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut records = Vec::with_capacity(lines.len());
    let mut cut = false;
    for (i, line) in lines.iter().enumerate() {
        match serde_json::from_str::<RunRecord>(line) {
            Ok(r) => records.push(r),
            Err(_) if i + 1 == lines.len() && !text.ends_with('\n') => cut = true,
            Err(e) => {
                return Err(Error::BadFile {
                    path: path.to_path_buf(),
                    message: format!("line {}: not a run record: {e}", i + 1),
                });
            }
        }
    }
    records.sort_by_key(|r| r.index);
    records.dedup_by_key(|r| r.index);
    Ok((records, cut))
}
