//! Collision-model tuning: a campaign whose parameters are the circle model (budget, overshoot,
//! hand-made circles), the levels (`mapping.heights_of_interest_m`) and the safety distances,
//! read back as objectives per setting - safety, conservatism, lap time, cost - with the settings
//! no other beats on every objective (the Pareto front), a recommendation, and pictures.
//!
//! One engine: `taxi-sim tune` runs the campaign exactly as `taxi-sim campaign run` does (same
//! directory, resumable), then adds, per setting, what only the model decides: the circle check
//! against the exact reference ([`aircraft::exact`]) on the setting's own offline map (false
//! alarms, misses, ns per check for both), and the maps' memory.

pub mod draw;
pub mod probe;

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::campaign::Campaign;
use crate::campaign::{RunRecord, static_world_key, variant};
use crate::error::{Error, Result};
use crate::scenario::Scenario;
use crate::scenario::{CollisionModelConfig, RunConfig};
use probe::Probe;

/// Everything measured about one setting.
#[derive(Clone, Debug, Serialize)]
pub struct SettingFigures {
    /// Setting index (`variant index % settings`).
    pub setting: usize,
    /// Its parameters, `path = value`, or `base`.
    pub label: String,
    /// Circles of its model.
    pub circles: usize,
    /// Its heights of interest, metres.
    pub heights_m: Vec<f64>,
    /// Runs recorded (invalid variants left out).
    pub runs: usize,
    /// Runs with a contact or an obstacle passed closer than the scenario's danger distance.
    pub unsafe_runs: usize,
    /// Ground-truth contacts, all runs.
    pub contacts: usize,
    /// Smallest clearance to a run-time obstacle over the runs, metres.
    pub min_clearance_m: Option<f64>,
    /// Stops where the expectation was to drive on.
    pub false_stops: usize,
    /// Deviations where the expectation was to pass under.
    pub needless_deviations: usize,
    /// Runs with an unmet expectation.
    pub failed_runs: usize,
    /// Mean lap time, seconds.
    pub mean_lap_s: Option<f64>,
    /// The circle check against the exact reference on the setting's offline map.
    pub probe: Probe,
    /// Memory of the maps the stack holds: levels x window cells x (live and prior log-odds,
    /// distance), bytes.
    pub map_bytes: u64,
    /// No other setting is at least as good on every objective and better on one.
    pub non_dominated: bool,
}

impl SettingFigures {
    /// Unsafe runs per run.
    pub fn unsafe_rate(&self) -> f64 {
        ratio(self.unsafe_runs, self.runs)
    }

    /// Runs that failed without being unsafe - a false stop, a needless deviation, a pilot
    /// called or a time-out where the run should have completed - per run.
    pub fn conservative_rate(&self) -> f64 {
        ratio(self.failed_runs.saturating_sub(self.unsafe_runs), self.runs)
    }

    /// The objectives, all minimised: unsafe runs, conservatism in the loop (safe failures) and
    /// against the exact reference (false alarms), lap time, ns per check.
    fn objectives(&self) -> [f64; 5] {
        [
            self.unsafe_rate(),
            self.conservative_rate(),
            self.probe.comparison.false_alarm_rate(),
            self.mean_lap_s.unwrap_or(f64::INFINITY),
            self.probe.circle_ns,
        ]
    }
}

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 { 0.0 } else { a as f64 / b as f64 }
}

/// Options of the analysis.
#[derive(Clone, Copy, Debug)]
pub struct TuneOptions {
    /// Poses per map place for the exact comparison.
    pub poses: usize,
}

/// The scenario of the first valid variant of `setting` and its offline map directory.
fn setting_world(
    campaign: &Campaign,
    dir: &Path,
    records: &[RunRecord],
    setting: usize,
) -> Result<Option<(Scenario, std::path::PathBuf)>> {
    let Some(r) = records
        .iter()
        .find(|r| r.setting == setting && r.end != "invalid")
    else {
        return Ok(None);
    };
    let v = variant(campaign, r.index, records);
    let scenario = Scenario::from_str(&v.text, &campaign.variant_path(r.index))?;
    let config = RunConfig::for_scenario(&scenario, None)?;
    let key = static_world_key(&scenario, &config)?;
    Ok(Some((scenario, dir.join("maps").join(key))))
}

/// The run-level objectives of `records` of one setting.
fn from_records(setting: usize, records: &[&RunRecord], danger_m: Option<f64>) -> SettingFigures {
    let laps: Vec<f64> = records.iter().flat_map(|r| r.lap_times_s.clone()).collect();
    SettingFigures {
        setting,
        label: "base".into(),
        circles: 0,
        heights_m: Vec::new(),
        runs: records.len(),
        unsafe_runs: records
            .iter()
            .filter(|r| {
                r.contacts > 0
                    || r.obstacle_clearance_m
                        .zip(danger_m)
                        .is_some_and(|(c, d)| c < d)
            })
            .count(),
        contacts: records.iter().map(|r| r.contacts).sum(),
        min_clearance_m: records
            .iter()
            .filter_map(|r| r.obstacle_clearance_m)
            .reduce(f64::min),
        false_stops: records.iter().map(|r| r.false_stops).sum(),
        needless_deviations: records.iter().map(|r| r.needless_deviations).sum(),
        failed_runs: records.iter().filter(|r| r.failed).count(),
        mean_lap_s: (!laps.is_empty()).then(|| laps.iter().sum::<f64>() / laps.len() as f64),
        probe: Probe::default(),
        map_bytes: 0,
        non_dominated: false,
    }
}

/// A setting in a few words: the circle model (`sidecar` / `fit k=v` / `N given circles`), the
/// levels, and every other parameter as `last.path.segment=value`.
pub fn short_label(setting: &crate::campaign::Setting) -> String {
    if setting.is_empty() {
        return "base".into();
    }
    let compact = |v: &toml::Value| v.to_string().replace(".0,", ",").replace(".0]", "]");
    setting
        .iter()
        .map(|(path, v)| match (path.as_str(), v) {
            ("collision_model", toml::Value::Table(t)) => {
                match t.get("source").and_then(toml::Value::as_str) {
                    Some("fit") => {
                        let options = t
                            .get("options")
                            .and_then(toml::Value::as_table)
                            .map(|o| {
                                o.iter()
                                    .map(|(k, v)| format!("{k}={v}"))
                                    .collect::<Vec<_>>()
                                    .join(" ")
                            })
                            .unwrap_or_default();
                        format!("fit {options}")
                    }
                    Some("circles") => format!(
                        "{} given circles",
                        t.get("circles")
                            .and_then(toml::Value::as_array)
                            .map_or(0, Vec::len)
                    ),
                    _ => "sidecar model".into(),
                }
            }
            ("mapping.heights_of_interest_m", v) => format!("levels {}", compact(v)),
            (p, v) => format!("{}={v}", p.rsplit('.').next().unwrap_or(p)),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Per setting: the objectives from the records and the probe on its map. `progress(done,
/// total)` after each setting.
pub fn figures(
    campaign: &Campaign,
    dir: &Path,
    records: &[RunRecord],
    opts: TuneOptions,
    progress: &dyn Fn(usize, usize),
) -> Result<Vec<SettingFigures>> {
    // By map directory: its name is the digest of everything the map depends on (its settings
    // included), so settings that share a directory share the maps.
    let mut maps_by_dir: HashMap<std::path::PathBuf, Vec<mapper::DistanceMaps>> = HashMap::new();
    let vehicle = &campaign.base().vehicle.vehicle;
    let mut out = Vec::new();
    let n = campaign.settings.len();
    for setting in 0..n {
        let config = campaign.config(setting)?;
        let mine: Vec<&RunRecord> = records
            .iter()
            .filter(|r| r.setting == setting && r.end != "invalid")
            .collect();
        let mut f = from_records(setting, &mine, campaign.base().danger_distance_m);
        f.label = short_label(&campaign.settings[setting]);
        let model = config.collision_model(vehicle)?;
        let heights = config.heights_of_interest_m(vehicle).to_vec();
        f.circles = model.circles().len();
        let m = &config.mapping.map;
        let cells = (m.block_cells * m.window_blocks).pow(2) as u64;
        f.map_bytes = heights.len() as u64 * cells * 12;
        f.heights_m = heights.clone();
        if let Some((scenario, map_dir)) = setting_world(campaign, dir, records, setting)? {
            if !maps_by_dir.contains_key(&map_dir) {
                let maps = probe::distance_maps(&scenario, &config, &map_dir)?;
                maps_by_dir.insert(map_dir.clone(), maps);
            }
            let footprints = vehicle.fit_with(&heights, &aircraft::FitOptions::default())?;
            let exact = aircraft::exact::ExactModel::from_fit(&footprints);
            f.probe = probe::probe_all(
                &maps_by_dir[&map_dir],
                &model,
                &exact,
                opts.poses,
                campaign.seed,
                config.autonomy.avoider_safety_m as f64,
            )?;
        }
        out.push(f);
        progress(setting + 1, n);
    }
    mark_front(&mut out);
    Ok(out)
}

/// Relative tolerance of each objective: differences within it are no difference. Runs are
/// counted exactly; a false-alarm rate from a few thousand poses carries a sampling error of
/// about a fifth of itself (1.4 % of 2300 clear poses: +-0.25 points); lap times vary by a
/// fraction of a percent between equivalent runs; timings drift by 10-40 % on this kind of
/// machine, so a check must be 25 % cheaper to count.
const TOLERANCE: [f64; 5] = [0.0, 0.0, 0.2, 0.01, 0.25];

/// `a` no worse than `b` on objective `k`.
fn no_worse(a: f64, b: f64, k: usize) -> bool {
    a <= b * (1.0 + TOLERANCE[k]) + 1e-12
}

/// `a` better than `b` on objective `k`, beyond its tolerance.
fn better(a: f64, b: f64, k: usize) -> bool {
    a < b * (1.0 - TOLERANCE[k]) - 1e-12
}

/// Marks the settings no other dominates (no worse on every objective and better on one, each
/// within its tolerance).
pub fn mark_front(figures: &mut [SettingFigures]) {
    let objectives: Vec<[f64; 5]> = figures.iter().map(|f| f.objectives()).collect();
    for (i, f) in figures.iter_mut().enumerate() {
        let me = &objectives[i];
        f.non_dominated = !objectives.iter().enumerate().any(|(j, o)| {
            j != i
                && (0..5).all(|k| no_worse(o[k], me[k], k))
                && (0..5).any(|k| better(o[k], me[k], k))
        });
    }
}

/// The recommended setting, by a cascade over the settings with runs: keep the safest (fewest
/// unsafe runs), of those the least conservative in the loop, then those within tolerance of the
/// fewest false alarms, of the fastest lap, of the cheapest check; then the fewest circles, the
/// least map memory, the lowest index. Each step keeps what is near the best of the step before
/// it, so the answer does not depend on the order of the settings.
pub fn recommend(figures: &[SettingFigures]) -> Option<usize> {
    let mut keep: Vec<&SettingFigures> = figures.iter().filter(|f| f.runs > 0).collect();
    for k in 0..5 {
        let best = keep
            .iter()
            .map(|f| f.objectives()[k])
            .fold(f64::INFINITY, f64::min);
        keep.retain(|f| no_worse(f.objectives()[k], best, k));
    }
    keep.into_iter()
        .min_by_key(|f| (f.circles, f.map_bytes, f.setting))
        .map(|f| f.setting)
}

fn csv_field(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| format!("{v:.3}"))
}

/// The figures as CSV, one line per setting.
pub fn to_csv(figures: &[&SettingFigures]) -> String {
    let mut s = String::from(
        "setting,parameters,circles,levels,heights_m,runs,unsafe_runs,contacts,min_clearance_m,false_stops,needless_deviations,failed_runs,mean_lap_s,poses,exact_collisions,false_alarms,false_alarm_rate,misses,misses_beyond_lookup,circle_ns_per_check,exact_ns_per_check,map_mb,non_dominated\n",
    );
    for f in figures {
        let c = &f.probe.comparison;
        let heights: Vec<String> = f.heights_m.iter().map(|h| format!("{h}")).collect();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.4},{},{},{:.1},{:.0},{:.1},{}",
            f.setting,
            csv_field(&f.label),
            f.circles,
            f.heights_m.len(),
            csv_field(&heights.join(" ")),
            f.runs,
            f.unsafe_runs,
            f.contacts,
            opt(f.min_clearance_m),
            f.false_stops,
            f.needless_deviations,
            f.failed_runs,
            opt(f.mean_lap_s),
            c.poses,
            c.exact_collisions,
            c.false_alarms,
            c.false_alarm_rate(),
            c.misses,
            c.misses_beyond_lookup,
            f.probe.circle_ns,
            f.probe.exact_ns,
            f.map_bytes as f64 / 1e6,
            f.non_dominated
        );
    }
    s
}

/// The table of the README and `tune.md`.
pub fn to_markdown(figures: &[SettingFigures], recommended: Option<usize>) -> String {
    let mut s = String::from(
        "| setting | circles | runs | unsafe | contacts | min clearance, m | safe failures | false stops | needless dev. | false alarms (exact) | misses (beyond lookup) | ns/check (exact) | front |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for f in figures {
        let c = &f.probe.comparison;
        let mark = match (Some(f.setting) == recommended, f.non_dominated) {
            (true, _) => "recommended",
            (false, true) => "yes",
            _ => "",
        };
        let _ = writeln!(
            s,
            "| {}: {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} % of {} | {} ({}) | {:.0} ({:.0}) | {} |",
            f.setting,
            f.label,
            f.circles,
            f.runs,
            f.unsafe_runs,
            f.contacts,
            f.min_clearance_m.map_or("-".into(), |v| format!("{v:.2}")),
            f.failed_runs.saturating_sub(f.unsafe_runs),
            f.false_stops,
            f.needless_deviations,
            100.0 * c.false_alarm_rate(),
            c.poses,
            c.misses,
            c.misses_beyond_lookup,
            f.probe.circle_ns,
            f.probe.exact_ns,
            mark
        );
    }
    s
}

/// Writes the outputs of a tuning run into `dir`: `settings.csv` (every setting), `pareto.csv`
/// (the non-dominated ones), `tune.md`, `pareto.svg` / `.png`, and for the recommended setting
/// `recommended/`: its run configuration, CARMEN collision file, fit options and the drawing of
/// its circles over the footprints per level.
pub fn write_outputs(
    campaign: &Campaign,
    dir: &Path,
    figures: &[SettingFigures],
) -> Result<Option<usize>> {
    let recommended = recommend(figures);
    let all: Vec<&SettingFigures> = figures.iter().collect();
    let front: Vec<&SettingFigures> = figures.iter().filter(|f| f.non_dominated).collect();
    mapper::write_atomically(&dir.join("settings.csv"), to_csv(&all).as_bytes())?;
    mapper::write_atomically(&dir.join("pareto.csv"), to_csv(&front).as_bytes())?;
    let mut md = format!(
        "# Tuning: {}\n\n{} settings, {} on the Pareto front. Objectives (all minimised): unsafe runs (a contact, or an obstacle passed inside the danger distance), safe failures per run (an expectation unmet without a contact: a false stop, a needless deviation, a pilot called where the run should complete), false alarms of the circle check against the exact reference (poses near obstacles of the setting's offline map, at the avoider's safety distance), mean lap time, ns per pose check.\n\n",
        campaign.name,
        figures.len(),
        front.len()
    );
    md += &to_markdown(figures, recommended);
    draw::pareto(dir, &campaign.name, figures, recommended)?;
    if let Some(r) = recommended {
        let _ = writeln!(
            md,
            "\nRecommended: setting {r} ({}); files in `recommended/`.",
            figures[r].label
        );
        write_recommended(campaign, dir, r)?;
    }
    mapper::write_atomically(&dir.join("tune.md"), md.as_bytes())?;
    Ok(recommended)
}

/// `dir/recommended/`: `config.toml` (the setting over the base's configuration: what
/// `taxi-sim run --config` takes), `model.carmen`, `fit.toml` (a sidecar `[fit]` table, when the
/// setting fits), `model.svg` / `.png`.
fn write_recommended(campaign: &Campaign, dir: &Path, setting: usize) -> Result<()> {
    let out = dir.join("recommended");
    std::fs::create_dir_all(&out).map_err(|source| Error::Io {
        what: "creating the recommended model's directory",
        path: out.clone(),
        source,
    })?;
    let config = campaign.config(setting)?;
    let vehicle = &campaign.base().vehicle.vehicle;
    let model = config.collision_model(vehicle)?;
    let heights = config.heights_of_interest_m(vehicle).to_vec();
    mapper::write_atomically(&out.join("config.toml"), config.to_toml().as_bytes())?;
    aircraft::carmen::write_carmen_file(&out.join("model.carmen"), &model)?;
    if let CollisionModelConfig::Fit { options } = &config.collision_model {
        let mut t = toml::Table::new();
        t.insert(
            "heights_of_interest_m".into(),
            toml::Value::try_from(&heights).map_err(|e| Error::Invalid(e.to_string()))?,
        );
        t.insert(
            "fit".into(),
            toml::Value::try_from(options).map_err(|e| Error::Invalid(e.to_string()))?,
        );
        let text = format!(
            "# The recommended fit of {} (setting {setting} of {}): paste into the vehicle's sidecar.\n{}",
            vehicle.spec.name,
            campaign.name,
            toml::to_string(&t).unwrap_or_default()
        );
        mapper::write_atomically(&out.join("fit.toml"), text.as_bytes())?;
    }
    let footprints = vehicle.fit_with(&heights, &aircraft::FitOptions::default())?;
    let title = format!(
        "{}: recommended model, {} circles",
        vehicle.spec.name,
        model.circles().len()
    );
    draw::model(&out, "model", &title, &footprints, &model)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig(setting: usize, unsafe_runs: usize, false_stops: usize, ns: f64) -> SettingFigures {
        let mut f = from_records(setting, &[], None);
        f.runs = 10;
        f.unsafe_runs = unsafe_runs;
        f.false_stops = false_stops;
        f.failed_runs = unsafe_runs + false_stops;
        f.mean_lap_s = Some(100.0);
        f.probe.circle_ns = ns;
        f
    }

    #[test]
    fn the_front_keeps_what_nothing_beats_and_the_recommendation_is_the_safest_least_conservative()
    {
        let mut figs = vec![
            fig(0, 0, 3, 100.0), // safe, conservative, cheap
            fig(1, 0, 1, 300.0), // safe, less conservative, dear
            fig(2, 2, 0, 50.0),  // unsafe, bold, cheapest
            fig(3, 0, 3, 150.0), // beaten by 0 on every objective
            fig(4, 2, 1, 60.0),  // beaten by 2
        ];
        mark_front(&mut figs);
        let front: Vec<usize> = figs
            .iter()
            .filter(|f| f.non_dominated)
            .map(|f| f.setting)
            .collect();
        assert_eq!(front, vec![0, 1, 2]);
        assert_eq!(recommend(&figs), Some(1));
        // Settings equal but for timings within the machine's drift do not knock each other
        // out, and the one with fewer circles is recommended.
        let mut twins = vec![fig(0, 0, 1, 95.0), fig(1, 0, 1, 80.0)];
        twins[0].circles = 10;
        twins[1].circles = 20;
        mark_front(&mut twins);
        assert!(twins.iter().all(|f| f.non_dominated));
        assert_eq!(recommend(&twins), Some(0));
        // The answer does not depend on the order of the settings: a chain of near ties (each
        // within tolerance of the next, the ends not) still picks the one near the best.
        let mut chain = vec![
            fig(0, 0, 0, 100.0),
            fig(1, 0, 0, 100.0),
            fig(2, 0, 0, 100.0),
        ];
        for (f, fa) in chain.iter_mut().zip([0.050, 0.045, 0.038]) {
            f.probe.comparison.poses = 1000;
            f.probe.comparison.false_alarms = (fa * 1000.0) as usize;
        }
        for (f, n) in chain.iter_mut().zip([30, 40, 50]) {
            f.circles = n;
        }
        // 0 is within tolerance of 1 but not of the best (2); of 1 and 2, 1 has fewer circles.
        let forward = recommend(&chain);
        chain.reverse();
        assert_eq!(forward, recommend(&chain));
        assert_eq!(forward, Some(1));
        // A setting with no run is never recommended.
        let mut empty = fig(0, 0, 0, 1.0);
        empty.runs = 0;
        assert_eq!(recommend(&[empty, fig(1, 1, 1, 9.0)]), Some(1));
    }

    #[test]
    fn the_csv_has_a_line_per_setting_and_quotes_its_labels() {
        let mut f = fig(7, 1, 2, 123.4);
        f.label = "collision_model = {source = \"fit\"}, x = 1".into();
        let csv = to_csv(&[&f]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2);
        let columns = lines[0].split(',').count();
        assert!(
            lines[1].starts_with("7,\"collision_model = {source = \"\"fit\"\"}, x = 1\","),
            "{}",
            lines[1]
        );
        // The label's one comma is inside quotes: one more raw comma than columns.
        assert_eq!(lines[1].matches(',').count(), columns);
    }
}
