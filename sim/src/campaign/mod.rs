//! Campaigns: a family of scenarios run thousands of times, measured, and searched for failures.
//!
//! A campaign file (`scenarios/campaigns/*.toml`) names a base scenario and what varies: any
//! scenario field as a distribution ([`dist`]), obstacles placed along the base route
//! (`along_m`, `offset_m`, `crossing_m`), a pool of obstacles drawn in number, and run
//! configuration parameters swept as a grid. A variant is a pure function of the campaign and
//! its index: index `i` is sample `i / settings` under parameter setting `i % settings`; the
//! sample is a point of the unit cube chosen by the [`sampler`] and mapped through the
//! distributions into a plain scenario text ([`Campaign::variant`]) that `taxi-sim run` runs
//! alone. [`execute`] runs them in parallel into `results.jsonl`; [`summary`] reads that back.

pub mod compare;
pub mod dist;
mod execute;
mod map_cache;
pub mod merge;
mod record;
pub mod sampler;
pub mod select;
mod shard;
pub mod summary;

pub use execute::{
    ExternalStacks, Outcome, RunOptions, proposals_for, run_campaign, total_runs, variant,
};
pub use map_cache::{MapCache, static_world_key};
pub use record::{INVALID, ObstacleOutcome, RunRecord, failures_of, read_results, record};
pub use shard::Shard;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use autonomy::RoutePath;
use serde::Deserialize;
use toml::{Spanned, Table, Value};

use crate::toml_file::set_path;

use crate::scenario::RunConfig;
use crate::scenario::Scenario;
use crate::toml_file::LocatedError;
use dist::{Layout, Node};
pub use sampler::SamplerKind;

/// The cross-entropy search's settings (`[falsify]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FalsifySpec {
    /// Samples per generation. Default 40.
    pub batch: u64,
    /// Fraction of the runs so far, lowest score first, the next generation is fitted to.
    /// Default 0.2.
    pub elite_fraction: f64,
    /// Weight of the new fit against the previous distribution, 0..1. Default 0.7.
    pub smoothing: f64,
}

impl Default for FalsifySpec {
    fn default() -> Self {
        FalsifySpec {
            batch: 40,
            elite_fraction: 0.2,
            smoothing: 0.7,
        }
    }
}

/// `[pool]`: a number of obstacles drawn from templates.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PoolSpec {
    /// How many: an integer or `{ int = [lo, hi] }`.
    count: Value,
    /// The templates; each drawn obstacle is one of them, id `<template id>_<k>`.
    obstacles: Vec<Table>,
}

/// A campaign file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CampaignFile {
    name: String,
    description: Option<String>,
    /// The base scenario, relative to the campaign file.
    base: Spanned<String>,
    #[serde(default = "one")]
    seed: u64,
    /// Runs (variants) by default; `--runs` overrides.
    runs: Spanned<u64>,
    #[serde(default)]
    sampler: SamplerKind,
    /// Grid levels of each continuous variation. Default 3.
    grid_steps: Option<Spanned<u32>>,
    #[serde(default)]
    falsify: FalsifySpec,
    /// Remove the base scenario's run-time obstacles first. Default false.
    #[serde(default)]
    drop_base_obstacles: bool,
    /// Scenario fields set or varied, by dotted path (`laps`, `route.speed_m_s`, `seed`).
    scenario: Option<Spanned<Table>>,
    /// Obstacles: an id of the base scenario's is modified, another is added.
    #[serde(default)]
    obstacles: Vec<Spanned<Table>>,
    pool: Option<Spanned<PoolSpec>>,
    /// Run configuration parameters, dotted path to a list of values: the grid of settings.
    parameters: Option<Spanned<Table>>,
}

fn one() -> u64 {
    1
}

/// One setting of the swept parameters: dotted path and value, in the file's order.
pub type Setting = Vec<(String, Value)>;

/// A read and validated campaign.
#[derive(Debug)]
pub struct Campaign {
    /// The campaign file.
    pub path: PathBuf,
    /// Its name.
    pub name: String,
    /// Its description.
    pub description: Option<String>,
    /// Its seed: every draw of every variant derives from it and the variant's index.
    pub seed: u64,
    /// Runs by default.
    pub runs: u64,
    /// How samples are chosen.
    pub sampler: SamplerKind,
    /// Grid levels per continuous variation.
    pub grid_steps: u32,
    /// The cross-entropy search's settings.
    pub falsify: FalsifySpec,
    /// Parameter settings (at least one, possibly empty).
    pub settings: Vec<Setting>,
    /// The random dimensions.
    pub layout: Layout,
    /// A digest of the campaign and base texts: results of another campaign are never mixed in.
    pub digest: String,
    base: Scenario,
    base_doc: Table,
    drop_base_obstacles: bool,
    scenario: Option<Node>,
    /// Fields set in every variant over the file's draws ([`Campaign::set_field`]).
    set: Vec<(String, Value)>,
    obstacles: Vec<Node>,
    pool: Option<(Node, usize, Vec<Node>)>,
}

/// One variant: its scenario text and what was drawn.
#[derive(Clone, Debug)]
pub struct Variant {
    /// Its index.
    pub index: u64,
    /// Its sample (`index / settings`).
    pub sample: u64,
    /// Its parameter setting (`index % settings`).
    pub setting: usize,
    /// The point of the unit cube it was drawn at.
    pub u: Vec<f64>,
    /// Each draw by label.
    pub drawn: BTreeMap<String, Value>,
    /// The scenario file's text (with the setting as its `[config]`).
    pub text: String,
}

/// An error at the span of a campaign file.
fn at(
    file: &str,
    text: &str,
    span: std::ops::Range<usize>,
    field: &str,
    m: String,
) -> LocatedError {
    LocatedError::at(file, text, span, field, m)
}

impl Campaign {
    /// Reads and validates a campaign file (and its base scenario).
    pub fn from_file(path: &Path) -> crate::Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| crate::Error::Io {
            what: "reading the campaign",
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_str(&text, path)
    }

    /// Validates a campaign text; `path` labels errors and anchors the base scenario's path.
    pub fn from_str(text: &str, path: &Path) -> crate::Result<Self> {
        let file = path.display().to_string();
        let spec: CampaignFile =
            toml::from_str(text).map_err(|e| LocatedError::toml(&file, text, &e))?;
        let base_path = path
            .parent()
            .unwrap_or_else(|| Path::new(""))
            .join(spec.base.get_ref());
        let base_text = std::fs::read_to_string(&base_path).map_err(|e| {
            at(
                &file,
                text,
                spec.base.span(),
                "base",
                format!("cannot read {}: {e}", base_path.display()),
            )
        })?;
        let base = Scenario::from_str(&base_text, &base_path)?;
        let base_doc: Table = toml::from_str(&base_text)
            .map_err(|e| LocatedError::toml(&base_path.display().to_string(), &base_text, &e))?;
        let grid_steps = checked_counts(&spec, &file, text)?;
        let mut layout = Layout::default();
        let e = |span: std::ops::Range<usize>, field: &str, m: String| -> crate::Error {
            at(&file, text, span, field, m).into()
        };
        let scenario = match &spec.scenario {
            Some(t) => Some(
                layout
                    .compile("scenario", &Value::Table(t.get_ref().clone()))
                    .map_err(|m| e(t.span(), "scenario", m))?,
            ),
            None => None,
        };
        let mut obstacles = Vec::new();
        for (i, o) in spec.obstacles.iter().enumerate() {
            let field = format!("obstacles[{i}]");
            let Some(id) = o.get_ref().get("id").and_then(Value::as_str) else {
                let m = "needs an `id` (a base obstacle's, to modify it, or a new one)";
                return Err(e(o.span(), &field, m.into()));
            };
            let node = layout
                .compile(
                    &format!("obstacles.{id}"),
                    &Value::Table(o.get_ref().clone()),
                )
                .map_err(|m| e(o.span(), &field, m))?;
            obstacles.push(node);
        }
        let pool = match &spec.pool {
            Some(p) => {
                Some(compile_pool(&mut layout, p.get_ref()).map_err(|m| e(p.span(), "pool", m))?)
            }
            None => None,
        };
        let (settings, span) = match &spec.parameters {
            Some(p) => (
                settings_of(p.get_ref()).map_err(|m| e(p.span(), "parameters", m))?,
                p.span(),
            ),
            None => (vec![Vec::new()], 0..0),
        };
        // Every setting must make a valid run configuration over the base's, and a circle
        // model of the base's vehicle.
        for s in &settings {
            let config = config_of(&base_doc, s).map_err(|m| e(span.clone(), "parameters", m))?;
            config.collision_model(&base.vehicle.vehicle).map_err(|m| {
                let shown: Vec<String> = s.iter().map(|(k, v)| format!("{k} = {v}")).collect();
                e(
                    span.clone(),
                    "parameters",
                    format!("the setting {{ {} }}: {m}", shown.join(", ")),
                )
            })?;
        }
        let mut h = crc32fast::Hasher::new();
        h.update(text.as_bytes());
        h.update(base_text.as_bytes());
        let campaign = Campaign {
            path: path.to_path_buf(),
            name: spec.name,
            description: spec.description,
            seed: spec.seed,
            runs: *spec.runs.get_ref(),
            sampler: spec.sampler,
            grid_steps,
            falsify: spec.falsify,
            settings,
            layout,
            digest: format!("{:08x}", h.finalize()),
            base,
            base_doc,
            drop_base_obstacles: spec.drop_base_obstacles,
            scenario,
            set: Vec::new(),
            obstacles,
            pool,
        };
        // The variant at the centre of every draw must be a valid scenario: a mistake in the
        // file shows now, not after the first run.
        let v = campaign.variant_at(0, &vec![0.5; campaign.layout.dims.len()]);
        Scenario::from_str(&v.text, &campaign.variant_path(0)).map_err(|e| {
            crate::Error::Invalid(format!(
                "{file}: the variant at the centre of the draws is not a valid scenario: {e}"
            ))
        })?;
        Ok(campaign)
    }

    /// Samples the same family another way (the digest follows: results of the two samplers
    /// never share a directory).
    pub fn set_sampler(&mut self, kind: SamplerKind) {
        if kind != self.sampler {
            self.sampler = kind;
            self.digest = format!("{}-{}", self.digest, kind.as_str());
        }
    }

    /// Sets scenario field `path` (dotted, as in `[scenario]`) to `value` in every variant, over
    /// what the file sets or draws (`campaign run --set`): the same variants with one thing
    /// changed. The digest follows (their results never share a directory with the file's own),
    /// and the variant at the centre of the draws must still be a valid scenario.
    pub fn set_field(&mut self, path: &str, value: Value) -> crate::Result<()> {
        self.digest = format!(
            "{}-set{:08x}",
            self.digest,
            crc32fast::hash(format!("{path}={value}").as_bytes())
        );
        self.set.push((path.to_string(), value));
        let v = self.variant_at(0, &vec![0.5; self.layout.dims.len()]);
        Scenario::from_str(&v.text, &self.variant_path(0)).map_err(|e| {
            crate::Error::Invalid(format!("--set {path}: the variants are not valid: {e}"))
        })?;
        Ok(())
    }

    /// The base scenario.
    pub fn base(&self) -> &Scenario {
        &self.base
    }

    /// Where variant `index`'s scenario is taken to be (beside the base: relative paths in it
    /// resolve as in the base).
    pub fn variant_path(&self, index: u64) -> PathBuf {
        let dir = self.base.path.parent().unwrap_or_else(|| Path::new(""));
        dir.join(format!("variant-{index}.toml"))
    }

    /// The route of a variant whose `[route]`, `[airport]` or `[vehicle]` differ from the base's
    /// (resolved without its obstacles); `None` when they do not, or it does not resolve (the
    /// variant is refused then anyway).
    fn variant_route(&self, doc: &Table) -> Option<RoutePath> {
        let same = ["route", "airport", "vehicle"]
            .iter()
            .all(|k| doc.get(*k) == self.base_doc.get(*k));
        if same {
            return None;
        }
        let mut probe = doc.clone();
        probe.remove("obstacles");
        absolutize(
            &mut probe,
            self.base.path.parent().unwrap_or_else(|| Path::new("")),
        );
        let text = toml::to_string(&probe).ok()?;
        let s = Scenario::from_str(&text, &self.variant_path(0)).ok()?;
        Some(RoutePath::new(&s.route.waypoints_m, s.route.closed))
    }

    /// Variant `index` at point `u` of the unit cube.
    pub fn variant_at(&self, index: u64, u: &[f64]) -> Variant {
        let n = self.settings.len() as u64;
        let (sample, setting) = (index / n, (index % n) as usize);
        let mut drawn = BTreeMap::new();
        let mut doc = self.base_doc.clone();
        if self.drop_base_obstacles {
            doc.remove("obstacles");
        }
        if let Some(node) = &self.scenario
            && let Value::Table(t) = node.sample(u, &self.layout, &mut drawn)
        {
            for (path, v) in t {
                set_path(&mut doc, &path, v);
            }
        }
        for (path, v) in &self.set {
            set_path(&mut doc, path, v.clone());
        }
        // Obstacles are placed along the variant's own route when its route or airport is drawn
        // (a taxi route from a drawn stand), else along the base's.
        let route = self.variant_route(&doc).unwrap_or_else(|| {
            RoutePath::new(&self.base.route.waypoints_m, self.base.route.closed)
        });
        let mut added = Vec::new();
        for node in &self.obstacles {
            if let Value::Table(o) = node.sample(u, &self.layout, &mut drawn) {
                added.push(o);
            }
        }
        if let Some((count, _, slots)) = &self.pool {
            let n = count
                .sample(u, &self.layout, &mut drawn)
                .as_integer()
                .unwrap_or(0)
                .max(0) as usize;
            for (k, slot) in slots.iter().take(n).enumerate() {
                if let Value::Table(mut o) = slot.sample(u, &self.layout, &mut drawn) {
                    let id = o
                        .get("id")
                        .and_then(Value::as_str)
                        .unwrap_or("pool")
                        .to_string();
                    o.insert("id".into(), Value::String(format!("{id}_{}", k + 1)));
                    added.push(o);
                }
            }
        }
        for o in added {
            put_obstacle(&mut doc, o, &route);
        }
        doc.insert(
            "name".into(),
            Value::String(format!("{} - variant {index}", self.name)),
        );
        doc.insert(
            "description".into(),
            Value::String(format!(
                "Variant {index} of the campaign {:?} (base: {:?}).",
                self.name, self.base.name
            )),
        );
        absolutize(
            &mut doc,
            self.base.path.parent().unwrap_or_else(|| Path::new("")),
        );
        let setting_table = self.settings[setting].clone();
        if !setting_table.is_empty() {
            let config = doc
                .entry("config")
                .or_insert_with(|| Value::Table(Table::new()));
            if let Value::Table(c) = config {
                for (path, v) in setting_table {
                    set_path(c, &path, v);
                }
            }
        }
        let text = self.header(index, sample, setting, &drawn)
            + &toml::to_string(&doc).unwrap_or_default();
        Variant {
            index,
            sample,
            setting,
            u: u.to_vec(),
            drawn,
            text,
        }
    }

    fn header(
        &self,
        index: u64,
        sample: u64,
        setting: usize,
        drawn: &BTreeMap<String, Value>,
    ) -> String {
        let mut h = format!(
            "# Variant {index} (sample {sample}, setting {setting}) of campaign \"{}\" ({}), seed {}.\n# Run it alone: taxi-sim run <this file>\n",
            self.name,
            self.path.display(),
            self.seed
        );
        for (k, v) in drawn {
            h += &format!("#   {k} = {v}\n");
        }
        h
    }

    /// The run configuration of a setting over the base scenario's `[config]`.
    pub fn config(&self, setting: usize) -> crate::Result<RunConfig> {
        config_of(&self.base_doc, &self.settings[setting]).map_err(crate::Error::Invalid)
    }
}

fn compile_pool(layout: &mut Layout, p: &PoolSpec) -> Result<(Node, usize, Vec<Node>), String> {
    let count = layout.compile("pool.count", &p.count)?;
    let max = match &count {
        Node::Fixed(Value::Integer(n)) if *n >= 0 => *n as usize,
        Node::Int { lo, hi, .. } if *lo >= 0 => *hi as usize,
        _ => return Err("count: an integer >= 0 or { int = [lo, hi] } with lo >= 0".into()),
    };
    if p.obstacles.is_empty() || max > 100 {
        return Err(
            "needs at least one template in [[pool.obstacles]] and a count of at most 100".into(),
        );
    }
    if let Some(i) = p
        .obstacles
        .iter()
        .position(|o| o.get("id").and_then(Value::as_str).is_none())
    {
        return Err(format!("obstacles[{i}]: a template needs an `id`"));
    }
    let templates = Value::Array(p.obstacles.iter().cloned().map(Value::Table).collect());
    let slots = (0..max)
        .map(|k| {
            let mut choice = Table::new();
            choice.insert("choice".into(), templates.clone());
            layout.compile(&format!("pool[{k}]"), &Value::Table(choice))
        })
        .collect::<Result<_, _>>()?;
    Ok((count, max, slots))
}

fn settings_of(p: &Table) -> Result<Vec<Setting>, String> {
    let mut settings: Vec<Setting> = vec![Vec::new()];
    for (path, values) in p {
        let values = values
            .as_array()
            .filter(|a| !a.is_empty())
            .ok_or_else(|| format!("{path}: a parameter takes a non-empty list of values"))?;
        settings = settings
            .iter()
            .flat_map(|s| {
                values.iter().map(move |v| {
                    let mut s = s.clone();
                    s.push((path.clone(), v.clone()));
                    s
                })
            })
            .collect();
    }
    Ok(settings)
}

/// The base's `[config]` with a setting applied, as a run configuration.
fn config_of(base_doc: &Table, setting: &Setting) -> Result<RunConfig, String> {
    let mut t = match base_doc.get("config") {
        Some(Value::Table(t)) => t.clone(),
        _ => Table::new(),
    };
    for (path, v) in setting {
        set_path(&mut t, path, v.clone());
    }
    RunConfig::from_table(t).map_err(|m| {
        let shown: Vec<String> = setting.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        format!("the setting {{ {} }}: {m}", shown.join(", "))
    })
}

/// Shape keys a new `kind` replaces.
const SHAPE_KEYS: [&str; 3] = ["size_m", "radius_m", "height_m"];

/// Merges a drawn obstacle into the document: into the base obstacle of its id, or as a new
/// one; `with` merges a drawn table in; `along_m` / `offset_m` place it from the route
/// (`yaw_rad` then relative to the route's heading), `crossing_m = [from, to]` makes it cross
/// the route at `along_m` between those offsets along a line at `crossing_angle_deg` (default
/// 90) from the route's heading, reaching the route at `arrives_s` when given.
fn put_obstacle(doc: &mut Table, mut o: Table, route: &RoutePath) {
    if let Some(Value::Table(with)) = o.remove("with") {
        for (k, v) in with {
            o.insert(k, v);
        }
    }
    let num = |v: Option<Value>| {
        v.and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
    };
    if let Some(s) = num(o.remove("along_m")) {
        let d = num(o.remove("offset_m")).unwrap_or(0.0);
        let (p, heading) = route.at(s);
        let left = nalgebra::Vector2::new(-heading.sin(), heading.cos());
        let at = |d: f64| p + left * d;
        if let Some(Value::Array(c)) = o.remove("crossing_m") {
            let (a, b) = (
                num(c.first().cloned()).unwrap_or(-5.0),
                num(c.get(1).cloned()).unwrap_or(5.0),
            );
            // The crossing line through the crossing point, at `crossing_angle_deg` from the
            // route's heading (90: square across it, left-bound from `a < 0`).
            let angle = num(o.remove("crossing_angle_deg")).map_or(90.0, f64::to_radians);
            let dir = nalgebra::Vector2::new((heading + angle).cos(), (heading + angle).sin());
            let cross = at(d);
            let mut from = cross + dir * a;
            // `arrives_s`: the mover reaches the crossing point then (at its speed), so it
            // appears that much earlier - or, when that would be before the start, appears at
            // the start that much nearer.
            if let (Some(arrives), Some(speed)) =
                (num(o.remove("arrives_s")), num(o.get("speed_m_s").cloned()))
            {
                let lead = (cross - from).norm();
                let appears = arrives - lead / speed.max(1e-9);
                if appears >= 0.0 {
                    o.insert("appears_s".into(), Value::Float(round_mm(appears)));
                } else {
                    from = cross - dir * (speed * arrives.max(0.0)).min(lead);
                    o.insert("appears_s".into(), Value::Float(0.0));
                }
            }
            let path = [from, cross + dir * b].map(|q| {
                Value::Array(vec![
                    Value::Float(round_mm(q.x)),
                    Value::Float(round_mm(q.y)),
                ])
            });
            o.insert("path_m".into(), Value::Array(path.to_vec()));
            o.remove("x_m");
            o.remove("y_m");
        } else {
            let q = at(d);
            o.insert("x_m".into(), Value::Float(round_mm(q.x)));
            o.insert("y_m".into(), Value::Float(round_mm(q.y)));
            let yaw = num(o.remove("yaw_rad")).unwrap_or(0.0);
            o.insert("yaw_rad".into(), Value::Float(round_mm(heading + yaw)));
        }
    }
    let id = o
        .get("id")
        .and_then(Value::as_str)
        .unwrap_or_default()
        .to_string();
    let list = doc
        .entry("obstacles")
        .or_insert_with(|| Value::Array(Vec::new()));
    let Value::Array(list) = list else { return };
    let existing = list.iter_mut().find_map(|v| match v {
        Value::Table(t) if t.get("id").and_then(Value::as_str) == Some(id.as_str()) => Some(t),
        _ => None,
    });
    match existing {
        Some(old) => {
            if o.contains_key("kind") {
                for k in SHAPE_KEYS {
                    old.remove(k);
                }
            }
            if o.contains_key("path_m") {
                old.remove("x_m");
                old.remove("y_m");
            }
            if o.contains_key("x_m") {
                old.remove("path_m");
            }
            for (k, v) in o {
                old.insert(k, v);
            }
        }
        None => list.push(Value::Table(o)),
    }
}

fn round_mm(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// Makes the vehicle and pose-file paths that exist relative to `dir` absolute, so the variant
/// runs from anywhere (a failure file in the campaign's output directory); drops the base's
/// `[regress] golden`, whose numbers are the base's run, not a variant's.
fn absolutize(doc: &mut Table, dir: &Path) {
    if let Some(Value::Table(r)) = doc.get_mut("regress") {
        r.remove("golden");
    }
    for (table, key) in [
        ("vehicle", "description"),
        ("route", "pose_file"),
        ("airport", "file"),
    ] {
        if let Some(Value::Table(t)) = doc.get_mut(table)
            && let Some(Value::String(s)) = t.get_mut(key)
        {
            let p = dir.join(&*s);
            if Path::new(s).is_relative() && p.exists() {
                *s = std::path::absolute(&p).unwrap_or(p).display().to_string();
            }
        }
    }
}

/// The file's counts checked (`runs`, `grid_steps`, `[falsify]`); the grid's steps per
/// dimension (3 unless given).
fn checked_counts(spec: &CampaignFile, file: &str, text: &str) -> crate::Result<u32> {
    if *spec.runs.get_ref() == 0 {
        return Err(at(
            file,
            text,
            spec.runs.span(),
            "runs",
            "must be at least 1".into(),
        )
        .into());
    }
    let grid_steps = spec.grid_steps.as_ref().map_or(3, |g| *g.get_ref());
    if let Some(g) = &spec.grid_steps
        && *g.get_ref() == 0
    {
        return Err(at(
            file,
            text,
            g.span(),
            "grid_steps",
            "must be at least 1".into(),
        )
        .into());
    }
    let f = &spec.falsify;
    if f.batch == 0
        || !(f.elite_fraction > 0.0 && f.elite_fraction <= 1.0)
        || !(0.0..=1.0).contains(&f.smoothing)
    {
        return Err(crate::Error::Config {
            origin: format!("{file}: [falsify]"),
            message: format!(
                "batch = {} must be >= 1, elite_fraction = {} in (0, 1], smoothing = {} in [0, 1]",
                f.batch, f.elite_fraction, f.smoothing
            ),
        });
    }
    Ok(grid_steps)
}
