//! Scenario files: the TOML format (world, vehicle, route, static objects and rows of them,
//! painted patches, run-time obstacles with expectations, laps, seed), its validation and its
//! conversion into a [`Scene`].
//!
//! The serde structs ([`ScenarioFile`] and the `*Spec` structs) are the file as written; every
//! field's unit and default is documented on it, unknown keys are rejected everywhere. Numbers
//! are checked while they are read (validating newtypes such as [`Positive`]), so toml's error
//! points at the value; cross-field checks (one route source, duplicate ids, the start overlap...)
//! use the spans toml keeps ([`toml::Spanned`]). Every mistake becomes a [`ScenarioError`] naming
//! the file, the line, the column and the field, with the offending line quoted.
//!
//! [`Scenario::from_str`] reads a scenario text; it loads the files the text names (a vehicle
//! sidecar, a pose file) relative to the scenario's directory. [`Scenario::from_file`] reads the
//! scenario file first. World frame: x east, y north, z up, metres, radians.

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use aircraft::footprint::{ConvexPolygon, Disc, Footprint};
use nalgebra::{Isometry2, Point2, Vector2};
use serde::Deserialize;
use toml::Spanned;

use crate::scene::{ObjectKind, Patch, Scene, Solid, SolidShape};

// ---------------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------------

/// A mistake in a scenario (or in a file it names).
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The scenario file itself could not be read.
    #[error("{}: cannot read the scenario: {error}", path.display())]
    Io {
        /// The scenario file.
        path: PathBuf,
        /// The underlying error (in the message, not repeated as a source).
        error: std::io::Error,
    },
    /// A located mistake: syntax, unknown key, wrong type, bad value, inconsistent fields, a
    /// named file that cannot be read or parsed.
    #[error("{file}:{line}:{column}: `{field}`: {message}{snippet}")]
    Invalid {
        /// The file at fault (the scenario, or the pose file it names).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (characters).
        column: usize,
        /// The field, e.g. `obstacles[1].radius_m` (`(file)` for a top-level syntax error).
        field: String,
        /// What is wrong.
        message: String,
        /// The offending line quoted, with a caret under the column (starts with a newline).
        snippet: String,
    },
}

impl ScenarioError {
    /// An error located at byte `span` of `text`, with the field given.
    pub(crate) fn at(
        file: &str,
        text: &str,
        span: Range<usize>,
        field: &str,
        message: String,
    ) -> Self {
        let (line, column, line_text) = locate(text, span.start);
        let width = text.get(span.clone()).map_or(1, |s| {
            s.lines().next().map_or(1, |l| l.chars().count().max(1))
        });
        let gutter = line.to_string().len();
        let snippet = format!(
            "\n {line} | {line_text}\n {:gutter$} | {:pad$}{}",
            "",
            "",
            "^".repeat(width.min(line_text.chars().count().saturating_sub(column - 1).max(1))),
            pad = column - 1
        );
        ScenarioError::Invalid {
            file: file.to_string(),
            line,
            column,
            field: field.to_string(),
            message,
            snippet,
        }
    }

    /// An error from toml's deserializer: the field is read off the text around the span.
    pub(crate) fn toml(file: &str, text: &str, err: &toml::de::Error) -> Self {
        let span = err.span().unwrap_or(0..0);
        let start = floor_boundary(text, span.start);
        let field = field_at(text, start);
        ScenarioError::at(
            file,
            text,
            start..span.end.max(start),
            &field,
            err.message().to_string(),
        )
    }
}

fn floor_boundary(text: &str, offset: usize) -> usize {
    let mut o = offset.min(text.len());
    while !text.is_char_boundary(o) {
        o -= 1;
    }
    o
}

/// 1-based line and column (in characters) of byte `offset`, and the text of that line.
fn locate(text: &str, offset: usize) -> (usize, usize, &str) {
    let offset = floor_boundary(text, offset);
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let line = text[..offset].matches('\n').count() + 1;
    let column = text[line_start..offset].chars().count() + 1;
    (
        line,
        column,
        text[line_start..line_end].trim_end_matches('\r'),
    )
}

fn is_key_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.'
}

/// The dotted path of the field at byte `offset` of a TOML text, as `table[index].key`: the last
/// table header before it, and the key on its line (or the last key of a multi-line value).
/// A reading of the text for error messages, not a TOML parser.
fn field_at(text: &str, offset: usize) -> String {
    let mut header = String::new();
    let mut counts: HashMap<String, usize> = HashMap::new();
    let mut key: Option<String> = None;
    let mut line_start = 0;
    for raw in text.split_inclusive('\n') {
        if line_start > offset {
            break;
        }
        let line = raw.trim_end_matches(['\n', '\r']);
        let trimmed = line.trim_start();
        let on_error_line = offset < line_start + raw.len() || line_start + raw.len() == text.len();
        if let Some(name) = table_header(trimmed, "[[", "]]") {
            let n = counts.entry(name.clone()).or_insert(0);
            header = format!("{name}[{n}]");
            *n += 1;
            key = None;
        } else if let Some(name) = table_header(trimmed, "[", "]") {
            header = name;
            key = None;
        } else if on_error_line {
            let col = (offset - line_start).min(line.len());
            // A key starting at the offset (an unknown key's span starts there) counts too.
            let rest = &line[col..];
            let word_end = rest.find(|c: char| !is_key_char(c)).unwrap_or(rest.len());
            let prefix = if word_end > 0 && rest[word_end..].trim_start().starts_with('=') {
                format!("{}{} =", &line[..col], &rest[..word_end])
            } else {
                line[..col].to_string()
            };
            if let Some(k) = keys_before(&prefix) {
                key = Some(k);
            }
        } else if let Some(k) = keys_before(line) {
            // A key opening a line (its value may continue on the following lines).
            if line.starts_with(|c: char| is_key_char(c) || c == ' ') {
                key = Some(k.split('.').next().unwrap_or(&k).to_string());
            }
        }
        line_start += raw.len();
    }
    match (header.is_empty(), key) {
        (true, None) => "(file)".to_string(),
        (true, Some(k)) => k,
        (false, None) => header,
        (false, Some(k)) => format!("{header}.{k}"),
    }
}

/// The table name of a header line `[name]` or `[[name]]` (not of a line of an array value).
fn table_header(line: &str, open: &str, close: &str) -> Option<String> {
    let rest = line.strip_prefix(open)?;
    let (name, after) = rest.split_once(close)?;
    let after = after.trim_start();
    let name_ok = !name.trim().is_empty()
        && name
            .chars()
            .all(|c| is_key_char(c) || c == ' ' || c == '"' || c == '\'');
    (name_ok && (after.is_empty() || after.starts_with('#'))).then(|| name.trim().to_string())
}

/// The key path at the end of `prefix` (one line): inline-table keys joined with dots.
fn keys_before(prefix: &str) -> Option<String> {
    let mut stack: Vec<String> = Vec::new();
    let mut last: Option<String> = None;
    let mut word = String::new();
    let mut in_string: Option<char> = None;
    for c in prefix.chars() {
        if let Some(q) = in_string {
            if c == q {
                in_string = None;
            }
            continue;
        }
        match c {
            '"' | '\'' => in_string = Some(c),
            '#' => break,
            '=' => {
                if !word.is_empty() {
                    last = Some(std::mem::take(&mut word));
                }
            }
            '{' => {
                stack.push(last.take().unwrap_or_default());
                word.clear();
            }
            '}' => {
                last = stack.pop();
                word.clear();
            }
            c if is_key_char(c) => word.push(c),
            ' ' | '\t' => {}
            _ => word.clear(),
        }
    }
    let mut parts: Vec<String> = stack.into_iter().filter(|s| !s.is_empty()).collect();
    parts.extend(last);
    (!parts.is_empty()).then(|| parts.join("."))
}

// ---------------------------------------------------------------------------------------------
// Validating numbers
// ---------------------------------------------------------------------------------------------

/// A finite number (no NaN, no infinity).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct Finite(pub f64);

impl TryFrom<f64> for Finite {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() {
            Ok(Finite(v))
        } else {
            Err(format!("must be a finite number, got {v}"))
        }
    }
}

/// A finite number > 0 (sizes, radii, heights, speeds).
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct Positive(pub f64);

impl TryFrom<f64> for Positive {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() && v > 0.0 {
            Ok(Positive(v))
        } else {
            Err(format!("must be finite and > 0, got {v}"))
        }
    }
}

/// A finite number >= 0 (times, heights above the ground).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct NonNegative(pub f64);

impl TryFrom<f64> for NonNegative {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() && v >= 0.0 {
            Ok(NonNegative(v))
        } else {
            Err(format!("must be finite and >= 0, got {v}"))
        }
    }
}

/// A LiDAR remission (reflectivity) in [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct Remission(pub f32);

impl TryFrom<f64> for Remission {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if (0.0..=1.0).contains(&v) {
            Ok(Remission(v as f32))
        } else {
            Err(format!("remission must be in [0, 1], got {v}"))
        }
    }
}

/// A number of laps, >= 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(try_from = "i64")]
pub struct Laps(pub u32);

impl Default for Laps {
    fn default() -> Self {
        Laps(1)
    }
}

impl TryFrom<i64> for Laps {
    type Error = String;
    fn try_from(v: i64) -> Result<Self, String> {
        match u32::try_from(v) {
            Ok(n) if n >= 1 => Ok(Laps(n)),
            _ => Err(format!("laps must be an integer >= 1, got {v}")),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The file as written
// ---------------------------------------------------------------------------------------------

fn default_seed() -> u64 {
    1
}

fn default_pavement_texture() -> Remission {
    Remission(0.05)
}

fn default_ground_remission() -> Remission {
    Remission(0.2)
}

/// A scenario file as written. See `scenarios/README.md` for a commented example.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// Short human name (reports, replay). Required.
    pub name: String,
    /// Free text. Optional.
    pub description: Option<String>,
    /// Seed of every random draw of a run (sensor noise, dropout). Default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// How many times the route is driven (a closed route loops). Integer >= 1, default 1.
    #[serde(default)]
    pub laps: Laps,
    /// The ground. Required.
    pub world: WorldSpec,
    /// The vehicle and its start pose. Required.
    pub vehicle: VehicleEntry,
    /// The route to follow. Required.
    pub route: Spanned<RouteSpec>,
    /// Static objects: in the world from the start, and in the offline map. Default none.
    #[serde(default)]
    pub objects: Vec<Spanned<ObjectSpec>>,
    /// Rows of static objects along a line (edge markers, parked cars): each expands into
    /// ordinary static objects. Default none.
    #[serde(default)]
    pub rows: Vec<Spanned<RowSpec>>,
    /// Painted markings on the ground (remission texture). Default none.
    #[serde(default)]
    pub patches: Vec<Spanned<PatchSpec>>,
    /// Run-time obstacles: absent from the mapping drive and the offline map. Default none.
    #[serde(default)]
    pub obstacles: Vec<Spanned<ObstacleSpec>>,
    /// Expectations about the whole run, beyond each obstacle's `expect`. Default none.
    #[serde(default)]
    pub expectations: ExpectationsSpec,
    /// The run configuration this scenario runs with, as in a `--config` file (only what
    /// differs from the defaults). A campaign's failure file carries its setting here. Default
    /// none: the defaults.
    pub config: Option<Spanned<toml::Table>>,
}

/// `[expectations]`: what must hold over the whole run, beside each obstacle's `expect`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectationsSpec {
    /// The danger distance, metres, > 0: the smallest ground-truth clearance between any part of
    /// the vehicle and any run-time obstacle must never fall under it (the thesis' tall
    /// obstacles were passed inside the safety distance but never closer than the danger
    /// distance). Default none: only a contact fails.
    pub danger_distance_m: Option<Positive>,
    /// How the run must end: `completed` (every lap driven; the default),
    /// `waiting_for_hidden_obstacle` (stopped for an obstacle the sensor can no longer see, the
    /// vehicle calls for a pilot rather than guess it has gone) or `stopped_for_good` (stopped
    /// before an obstacle that never goes, timed out or calling for a pilot) or `any` (only
    /// contacts and the obstacles' expectations count, and an obstacle never passed counts for
    /// nothing: a campaign's randomized obstacles, which may block the way or appear late).
    pub end: Option<ExpectedEnd>,
}

/// How a scenario's run must end (`[expectations] end`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExpectedEnd {
    /// Every lap driven.
    #[default]
    Completed,
    /// Waiting for a hidden obstacle, calling for a pilot.
    WaitingForHiddenObstacle,
    /// Stopped for good before an obstacle that never goes: the run ends timed out or calling
    /// for a pilot, the vehicle still standing.
    StoppedForGood,
    /// However it ends: only contacts and the obstacles' expectations count.
    Any,
}

/// `[world]`: the ground, a rectangle of the plane z = 0.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Lower corner `[x, y]` of the ground, metres. Required.
    pub min_m: [Finite; 2],
    /// Upper corner `[x, y]` of the ground, metres; each coordinate > the lower one. Required.
    pub max_m: Spanned<[Finite; 2]>,
    /// Remission of bare ground, in [0, 1]. Default 0.2 (asphalt, concrete).
    #[serde(default = "default_ground_remission")]
    pub ground_remission: Remission,
    /// Texture of the pavement: each 0.5 m square's remission (bare ground or a patch) is off by
    /// up to this much, in [0, 1] (what a remission map of real asphalt or concrete shows, and
    /// what a remission localizer reads). Default 0.05; 0 makes a featureless ground.
    #[serde(default = "default_pavement_texture")]
    pub pavement_texture: Remission,
}

/// `[vehicle]`: which vehicle, and where it starts.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleEntry {
    /// A shipped vehicle (`praetor600`, `iara_car`, `iara_car_fake_wing`) or the path of a
    /// vehicle sidecar TOML, relative to the scenario file's directory. Required.
    pub description: Spanned<String>,
    /// Start pose of the vehicle frame (origin on the ground under the rear axle / main gear).
    /// Default: on the first route point, heading to the second.
    pub start: Option<Spanned<StartPose>>,
}

/// A start pose, `{ x_m = .., y_m = .., yaw_rad = .. }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartPose {
    /// Position, metres. Required.
    pub x_m: Finite,
    /// Position, metres. Required.
    pub y_m: Finite,
    /// Heading, radians counter-clockwise from x. Default 0.
    #[serde(default)]
    pub yaw_rad: Finite,
}

/// `[route]`: the path the vehicle follows. Exactly one of `waypoints_m` and `pose_file`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RouteSpec {
    /// Waypoints `[[x, y], ...]`, metres; at least 2 (3 when closed), no two consecutive equal.
    pub waypoints_m: Option<Spanned<Vec<[Finite; 2]>>>,
    /// A pose file, relative to the scenario file's directory: one pose a line,
    /// `x_m,y_m[,yaw_rad]`; blank lines and `#` comments are skipped.
    pub pose_file: Option<Spanned<String>>,
    /// True when the last point joins the first (do not repeat the first point). Default false.
    #[serde(default)]
    pub closed: bool,
    /// Target speed along the route, m/s, > 0. Required.
    pub speed_m_s: Positive,
}

/// `[[objects]]`: a static object. Shape fields depend on the kind:
/// round kinds (`cone`, `marker`, `lamp_post`, `cylinder`) take `radius_m` and `height_m`,
/// the others (`container`, `parked_car`, `vehicle`, `debris`, `building`, `box`) take `size_m`.
///
/// | kind | shape | default size | default remission |
/// | --- | --- | --- | --- |
/// | cone | cone | radius 0.18, height 0.45 | 0.5 |
/// | marker | cylinder | radius 0.10, height 0.35 | 0.7 |
/// | lamp_post | cylinder | radius 0.12, height 6.0 | 0.3 |
/// | cylinder | cylinder | required | 0.3 |
/// | container | box | 0.8 x 0.6 x 1.1 | 0.4 |
/// | parked_car, vehicle | box | 4.5 x 1.8 x 1.5 | 0.3 |
/// | debris | box | 0.3 x 0.3 x 0.15 | 0.2 |
/// | building | box | required | 0.2 |
/// | box | box | required | 0.3 |
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Unique name across objects, rows, patches and obstacles. Required.
    pub id: Spanned<String>,
    /// What it is (snake_case [`ObjectKind`]). Required.
    pub kind: ObjectKind,
    /// Position of its axis (box: its centre), metres. Required.
    pub x_m: Finite,
    /// Position of its axis (box: its centre), metres. Required.
    pub y_m: Finite,
    /// Heading, radians counter-clockwise from x (box: its x extent runs along it). Default 0.
    #[serde(default)]
    pub yaw_rad: Finite,
    /// Height of its base above the ground, metres, >= 0. Default 0 (standing on the ground).
    #[serde(default)]
    pub z_min_m: NonNegative,
    /// Box kinds: full extents `[x, y, z]`, metres, each > 0. Default per kind (table above).
    pub size_m: Option<Spanned<[Positive; 3]>>,
    /// Round kinds: base radius, metres, > 0. Default per kind.
    pub radius_m: Option<Spanned<Positive>>,
    /// Round kinds: height, metres, > 0. Default per kind.
    pub height_m: Option<Spanned<Positive>>,
    /// LiDAR remission in [0, 1]. Default per kind.
    pub remission: Option<Remission>,
}

/// `[[patches]]`: a painted rectangle on the ground with its own remission (lines, patches).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatchSpec {
    /// Unique name across objects, rows, patches and obstacles. Required.
    pub id: Spanned<String>,
    /// Centre, metres. Required.
    pub x_m: Finite,
    /// Centre, metres. Required.
    pub y_m: Finite,
    /// Heading of its length, radians. Default 0.
    #[serde(default)]
    pub yaw_rad: Finite,
    /// Extent along its heading, metres, > 0. Required.
    pub length_m: Positive,
    /// Extent across, metres, > 0. Required.
    pub width_m: Positive,
    /// LiDAR remission in [0, 1]. Default 0.8 (white paint).
    pub remission: Option<Remission>,
}

/// The line a row follows when it is not given as `along_m`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RowLine {
    /// The scenario's route (closed or not, as the route is).
    Route,
}

/// `[[rows]]`: a row of identical static objects at a regular spacing along a line, repeated at
/// lateral offsets from it; it expands into ordinary static objects with ids `<id>_<n>`
/// (`n` from 1, along the line first, then in the order of `offsets_m` at each station). The
/// shape fields are those of [`ObjectSpec`], with the same per-kind defaults.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowSpec {
    /// Prefix of the objects' ids; unique across objects, rows, patches and obstacles, and so
    /// are the ids it makes. Required.
    pub id: Spanned<String>,
    /// What its objects are (snake_case [`ObjectKind`]). Required.
    pub kind: ObjectKind,
    /// The line, `[[x, y], ...]`, metres: at least 2 points, no two consecutive equal.
    /// Exactly one of `along_m` and `along`.
    pub along_m: Option<Spanned<Vec<[Finite; 2]>>>,
    /// `"route"`: the line is the route (with its closing segment when it is closed).
    pub along: Option<Spanned<RowLine>>,
    /// Distance between stations, measured along the line, metres, > 0. Required.
    pub spacing_m: Spanned<Positive>,
    /// Lateral offsets from the line, metres, left of its direction positive; one object per
    /// offset at each station (`[-11.5, 11.5]`: both edges). No repeats. Default `[0.0]`.
    pub offsets_m: Option<Spanned<Vec<Finite>>>,
    /// Arc length of the first station, metres, >= 0. Default 0.
    pub start_m: Option<Spanned<NonNegative>>,
    /// Arc length the stations stop at (inclusive), metres, > `start_m`, at most the line's
    /// length. Default the line's end (on a closed route the station that would repeat the
    /// first is left out).
    pub end_m: Option<Spanned<NonNegative>>,
    /// Heading of each object relative to the line's direction where it stands, radians
    /// (a box's x extent runs along the line at 0; `1.5708` turns parked cars across it).
    /// Default 0.
    #[serde(default)]
    pub yaw_rad: Finite,
    /// Height of the objects' base above the ground, metres, >= 0. Default 0.
    #[serde(default)]
    pub z_min_m: NonNegative,
    /// Box kinds: full extents `[x, y, z]`, metres, each > 0. Default per kind.
    pub size_m: Option<Spanned<[Positive; 3]>>,
    /// Round kinds: base radius, metres, > 0. Default per kind.
    pub radius_m: Option<Spanned<Positive>>,
    /// Round kinds: height, metres, > 0. Default per kind.
    pub height_m: Option<Spanned<Positive>>,
    /// LiDAR remission in [0, 1]. Default per kind.
    pub remission: Option<Remission>,
}

/// The most objects one row may make (a guard against a spacing typed in the wrong unit).
pub const MAX_ROW_OBJECTS: usize = 10_000;

/// What the vehicle must do about a run-time obstacle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Expectation {
    /// Drive on with a part passing over it (a short cone under a wing), without contact.
    PassUnder,
    /// Leave the route around it, without contact, and rejoin.
    Deviate,
    /// Stop short of it without contact (and resume if it goes away).
    Stop,
    /// Anything, as long as nothing touches it.
    NoContact,
}

impl std::fmt::Display for Expectation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

impl Expectation {
    /// The name used in files.
    pub fn as_str(self) -> &'static str {
        match self {
            Expectation::PassUnder => "pass_under",
            Expectation::Deviate => "deviate",
            Expectation::Stop => "stop",
            Expectation::NoContact => "no_contact",
        }
    }
}

/// `[[obstacles]]`: a run-time obstacle (not in the offline map). The object fields of
/// [`ObjectSpec`] (with the same per-kind defaults), plus the expectation and optional timing
/// and motion.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// Unique name across objects, rows, patches and obstacles. Required.
    pub id: Spanned<String>,
    /// What it is (snake_case [`ObjectKind`]). Required.
    pub kind: ObjectKind,
    /// Position, metres. Required unless `path_m` is given (then not allowed).
    pub x_m: Option<Finite>,
    /// Position, metres. Required unless `path_m` is given (then not allowed).
    pub y_m: Option<Finite>,
    /// Heading, radians; for a moving obstacle, an offset to the heading of its path. Default 0.
    #[serde(default)]
    pub yaw_rad: Finite,
    /// Height of its base above the ground, metres, >= 0. Default 0.
    #[serde(default)]
    pub z_min_m: NonNegative,
    /// Box kinds: full extents `[x, y, z]`, metres. Default per kind.
    pub size_m: Option<Spanned<[Positive; 3]>>,
    /// Round kinds: base radius, metres. Default per kind.
    pub radius_m: Option<Spanned<Positive>>,
    /// Round kinds: height, metres. Default per kind.
    pub height_m: Option<Spanned<Positive>>,
    /// LiDAR remission in [0, 1]. Default per kind.
    pub remission: Option<Remission>,
    /// What the vehicle must do: `pass_under`, `deviate`, `stop` or `no_contact`. Required.
    pub expect: Expectation,
    /// When it appears, seconds from the start, >= 0. Default 0 (there from the start).
    pub appears_s: Option<Spanned<NonNegative>>,
    /// When it disappears, seconds, > `appears_s`. Default never.
    pub disappears_s: Option<Spanned<NonNegative>>,
    /// A moving obstacle: the polyline `[[x, y], ...]` it follows from its appearance, metres,
    /// at least 2 points, no two consecutive equal; it stays at the last point. Default static.
    pub path_m: Option<Spanned<Vec<[Finite; 2]>>>,
    /// Its speed along `path_m`, m/s, > 0. Required with `path_m`, not allowed without.
    pub speed_m_s: Option<Spanned<Positive>>,
}

// ---------------------------------------------------------------------------------------------
// The scenario, resolved
// ---------------------------------------------------------------------------------------------

/// The ground.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// Lower corner (x, y), metres.
    pub min_m: [f64; 2],
    /// Upper corner (x, y), metres.
    pub max_m: [f64; 2],
    /// Remission of bare ground in [0, 1].
    pub ground_remission: f32,
    /// Amplitude of the pavement's texture (`[world] pavement_texture`).
    pub pavement_texture: f32,
}

/// The vehicle of a scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioVehicle {
    /// The description as written (a shipped name or a sidecar path).
    pub description: String,
    /// The vehicle: sidecar spec and collision parts.
    pub vehicle: aircraft::Vehicle,
    /// Start pose of the vehicle frame in the world.
    pub world_from_start: Isometry2<f64>,
}

/// The route.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// Waypoints in the world, metres (the first is not repeated at the end of a closed route).
    pub waypoints_m: Vec<Point2<f64>>,
    /// Headings given by a pose file, one per waypoint (`None` where not given).
    pub yaws_rad: Vec<Option<f64>>,
    /// True when the last waypoint joins the first.
    pub closed: bool,
    /// Target speed, m/s.
    pub speed_m_s: f64,
}

impl Route {
    /// Length of one lap, metres (with the closing segment of a closed route).
    pub fn length_m(&self) -> f64 {
        let open: f64 = self
            .waypoints_m
            .windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .sum();
        match (
            self.closed,
            self.waypoints_m.first(),
            self.waypoints_m.last(),
        ) {
            (true, Some(first), Some(last)) => open + (first - last).norm(),
            _ => open,
        }
    }
}

/// How a run-time obstacle moves.
#[derive(Clone, Debug, PartialEq)]
pub struct ObstacleMotion {
    /// The polyline followed from its appearance, metres.
    pub path_m: Vec<Point2<f64>>,
    /// Speed along it, m/s.
    pub speed_m_s: f64,
    /// Offset of the obstacle's heading to the heading of the path, radians.
    pub yaw_offset_rad: f64,
}

/// A run-time obstacle.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Its solid at its initial pose (`runtime` is true).
    pub solid: Solid,
    /// What the vehicle must do.
    pub expect: Expectation,
    /// When it appears, seconds.
    pub appears_s: f64,
    /// When it disappears, seconds (`None`: never).
    pub disappears_s: Option<f64>,
    /// Its motion (`None`: static).
    pub motion: Option<ObstacleMotion>,
}

impl Obstacle {
    /// Its pose `(x_m, y_m, yaw_rad)` at time `t_s`, or `None` when it is absent then.
    pub fn pose_at(&self, t_s: f64) -> Option<(f64, f64, f64)> {
        if t_s < self.appears_s || self.disappears_s.is_some_and(|d| t_s >= d) {
            return None;
        }
        let Some(motion) = &self.motion else {
            return Some((self.solid.x_m, self.solid.y_m, self.solid.yaw_rad));
        };
        let mut left_m = motion.speed_m_s * (t_s - self.appears_s);
        let mut last = (self.solid.x_m, self.solid.y_m, self.solid.yaw_rad);
        for w in motion.path_m.windows(2) {
            let d = w[1] - w[0];
            let len = d.norm();
            let yaw = d.y.atan2(d.x) + motion.yaw_offset_rad;
            if left_m <= len {
                let p = w[0] + d * (left_m / len);
                return Some((p.x, p.y, yaw));
            }
            left_m -= len;
            last = (w[1].x, w[1].y, yaw);
        }
        Some(last)
    }
}

/// A validated scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// The file it was read from (or the label given to [`Scenario::from_str`]).
    pub path: PathBuf,
    /// Short human name.
    pub name: String,
    /// Free text.
    pub description: Option<String>,
    /// Seed of every random draw of a run.
    pub seed: u64,
    /// Laps of the route, >= 1.
    pub laps: u32,
    /// The ground.
    pub world: World,
    /// The vehicle and its start pose.
    pub vehicle: ScenarioVehicle,
    /// The route.
    pub route: Route,
    /// Static objects (`runtime` false): the `[[objects]]` in file order, then the objects of
    /// each `[[rows]]` in file order.
    pub objects: Vec<Solid>,
    /// Painted patches.
    pub patches: Vec<Patch>,
    /// Run-time obstacles.
    pub obstacles: Vec<Obstacle>,
    /// The danger distance (`[expectations] danger_distance_m`), metres: the smallest
    /// ground-truth clearance between the vehicle and any run-time obstacle must stay at or
    /// above it. `None`: not checked (only a contact fails).
    pub danger_distance_m: Option<f64>,
    /// How the run must end (`[expectations] end`).
    pub expected_end: ExpectedEnd,
    /// The `[config]` table (validated): the run configuration over the defaults.
    pub config: Option<toml::Table>,
}

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn from_file(path: &Path) -> Result<Self, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|error| ScenarioError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        Scenario::from_str(&text, path)
    }

    /// Validates a scenario text; `path` labels errors and anchors the relative paths of the
    /// files it names (vehicle sidecar, pose file), which are read here.
    pub fn from_str(text: &str, path: &Path) -> Result<Self, ScenarioError> {
        let file = path.display().to_string();
        let spec: ScenarioFile =
            toml::from_str(text).map_err(|e| ScenarioError::toml(&file, text, &e))?;
        Resolver {
            text,
            file: &file,
            dir: path.parent().unwrap_or_else(|| Path::new("")),
        }
        .resolve(spec, path)
    }

    /// The world as a [`Scene`]: ground, static objects, patches, and with `include_runtime`
    /// the run-time obstacles at their initial poses (`Solid::runtime` true).
    pub fn scene(&self, include_runtime: bool) -> Scene {
        let mut solids = self.objects.clone();
        if include_runtime {
            solids.extend(self.obstacles.iter().map(|o| o.solid.clone()));
        }
        Scene {
            min_m: self.world.min_m,
            max_m: self.world.max_m,
            ground_remission: self.world.ground_remission,
            pavement_texture: self.world.pavement_texture,
            solids,
            patches: self.patches.clone(),
        }
    }
}

/// Turns the file as written into a [`Scenario`], with the cross-field checks.
struct Resolver<'a> {
    text: &'a str,
    file: &'a str,
    dir: &'a Path,
}

impl Resolver<'_> {
    fn err(&self, span: Range<usize>, field: &str, message: impl Into<String>) -> ScenarioError {
        ScenarioError::at(self.file, self.text, span, field, message.into())
    }

    fn resolve(&self, spec: ScenarioFile, path: &Path) -> Result<Scenario, ScenarioError> {
        let world = self.world(&spec.world)?;
        let route = self.route(&spec.route, &world)?;
        let vehicle = self.vehicle(&spec.vehicle, &route, &world)?;
        // Every id, with who uses it (as error messages name it).
        let mut ids: HashMap<String, String> = HashMap::new();
        let mut objects = self.objects(&spec.objects, &world, &vehicle, &mut ids)?;
        self.rows(&spec.rows, &world, &route, &vehicle, &mut ids, &mut objects)?;
        let patches = self.patches(&spec.patches, &world, &mut ids)?;
        let obstacles = self.obstacles(&spec.obstacles, &world, &vehicle, &mut ids)?;
        if let Some(c) = &spec.config {
            crate::config::RunConfig::from_table(c.get_ref().clone())
                .map_err(|m| ScenarioError::at(self.file, self.text, c.span(), "config", m))?;
        }
        Ok(Scenario {
            path: path.to_path_buf(),
            name: spec.name,
            description: spec.description,
            seed: spec.seed,
            laps: spec.laps.0,
            world,
            vehicle,
            route,
            objects,
            patches,
            obstacles,
            danger_distance_m: spec.expectations.danger_distance_m.map(|d| d.0),
            expected_end: spec.expectations.end.unwrap_or_default(),
            config: spec.config.map(Spanned::into_inner),
        })
    }

    /// Claims `id` in `ids` for `owner` (as error messages name it): an empty id or one
    /// already claimed is refused at `span` under `field`, the message starting with `made`.
    fn claim(
        &self,
        ids: &mut HashMap<String, String>,
        id: &str,
        span: Range<usize>,
        field: &str,
        owner: String,
        made: &str,
    ) -> Result<(), ScenarioError> {
        if id.is_empty() {
            return Err(self.err(span, field, "an id must not be empty"));
        }
        if let Some(first) = ids.insert(id.to_string(), owner) {
            return Err(self.err(
                span,
                field,
                format!("{made}duplicate id `{id}` (already used by {first})"),
            ));
        }
        Ok(())
    }

    /// Claims the id of table `field` (`objects[3]`), named `<field>.id` as field and owner.
    fn claim_id(
        &self,
        ids: &mut HashMap<String, String>,
        id: &Spanned<String>,
        field: &str,
    ) -> Result<(), ScenarioError> {
        let field = format!("{field}.id");
        self.claim(
            ids,
            id.get_ref(),
            id.span(),
            &field,
            format!("`{field}`"),
            "",
        )
    }

    /// The `[[objects]]` as solids, in file order: ids claimed, shapes checked, each inside the
    /// world and clear of the vehicle at its start.
    fn objects(
        &self,
        specs: &[Spanned<ObjectSpec>],
        world: &World,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
    ) -> Result<Vec<Solid>, ScenarioError> {
        let mut objects = Vec::with_capacity(specs.len());
        for (i, o) in specs.iter().enumerate() {
            let field = format!("objects[{i}]");
            let o_ref = o.get_ref();
            self.claim_id(ids, &o_ref.id, &field)?;
            let shape = self.shape(
                &field,
                o.span(),
                o_ref.kind,
                &o_ref.size_m,
                &o_ref.radius_m,
                &o_ref.height_m,
            )?;
            let solid = Solid {
                id: o_ref.id.get_ref().clone(),
                kind: o_ref.kind,
                shape,
                x_m: o_ref.x_m.0,
                y_m: o_ref.y_m.0,
                z_min_m: o_ref.z_min_m.0,
                yaw_rad: o_ref.yaw_rad.0,
                remission: o_ref
                    .remission
                    .map_or_else(|| default_remission(o_ref.kind), |r| r.0),
                runtime: false,
            };
            self.inside_world(world, &field, o_ref.id.span(), solid.x_m, solid.y_m)?;
            self.no_start_overlap(vehicle, &solid, &field, o_ref.id.span())?;
            objects.push(solid);
        }
        Ok(objects)
    }

    /// Appends the objects of each `[[rows]]`, in file order, to `objects`: the row's id and
    /// each object's id claimed, each object inside the world and clear of the vehicle at its
    /// start.
    fn rows(
        &self,
        specs: &[Spanned<RowSpec>],
        world: &World,
        route: &Route,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
        objects: &mut Vec<Solid>,
    ) -> Result<(), ScenarioError> {
        for (i, r) in specs.iter().enumerate() {
            let field = format!("rows[{i}]");
            let id = &r.get_ref().id;
            self.claim_id(ids, id, &field)?;
            for (n, made) in self.row(r, &field, route)?.into_iter().enumerate() {
                let solid = made.solid;
                let what = format!(
                    "object {} (arc length {:.2} m, offset {} m)",
                    n + 1,
                    made.s_m,
                    made.offset_m
                );
                self.claim(
                    ids,
                    &solid.id,
                    id.span(),
                    &format!("{field}.id"),
                    format!("`{field}`, its {what}"),
                    &format!("its {what} is `{}`: ", solid.id),
                )?;
                if !(world.min_m[0]..=world.max_m[0]).contains(&solid.x_m)
                    || !(world.min_m[1]..=world.max_m[1]).contains(&solid.y_m)
                {
                    return Err(self.err(
                        id.span(),
                        &field,
                        format!(
                            "its {what}, `{}` at ({:.3}, {:.3}), lies outside the world [{}, {}] .. [{}, {}]",
                            solid.id,
                            solid.x_m,
                            solid.y_m,
                            world.min_m[0],
                            world.min_m[1],
                            world.max_m[0],
                            world.max_m[1]
                        ),
                    ));
                }
                self.no_start_overlap(vehicle, &solid, &field, id.span())?;
                objects.push(solid);
            }
        }
        Ok(())
    }

    /// The `[[patches]]`, in file order: ids claimed, each inside the world.
    fn patches(
        &self,
        specs: &[Spanned<PatchSpec>],
        world: &World,
        ids: &mut HashMap<String, String>,
    ) -> Result<Vec<Patch>, ScenarioError> {
        let mut patches = Vec::with_capacity(specs.len());
        for (i, p) in specs.iter().enumerate() {
            let field = format!("patches[{i}]");
            let p = p.get_ref();
            self.claim_id(ids, &p.id, &field)?;
            self.inside_world(world, &field, p.id.span(), p.x_m.0, p.y_m.0)?;
            patches.push(Patch {
                id: p.id.get_ref().clone(),
                x_m: p.x_m.0,
                y_m: p.y_m.0,
                yaw_rad: p.yaw_rad.0,
                length_m: p.length_m.0,
                width_m: p.width_m.0,
                remission: p.remission.map_or(0.8, |r| r.0),
            });
        }
        Ok(patches)
    }

    /// The `[[obstacles]]`, in file order: ids claimed, each (and its path) inside the world,
    /// and one present at the start clear of the vehicle there.
    fn obstacles(
        &self,
        specs: &[Spanned<ObstacleSpec>],
        world: &World,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
    ) -> Result<Vec<Obstacle>, ScenarioError> {
        let mut obstacles = Vec::with_capacity(specs.len());
        for (i, o) in specs.iter().enumerate() {
            let field = format!("obstacles[{i}]");
            self.claim_id(ids, &o.get_ref().id, &field)?;
            let obstacle = self.obstacle(o, &field)?;
            let id_span = o.get_ref().id.span();
            self.inside_world(
                world,
                &field,
                id_span.clone(),
                obstacle.solid.x_m,
                obstacle.solid.y_m,
            )?;
            if let (Some(m), Some(path)) = (&obstacle.motion, &o.get_ref().path_m) {
                for p in &m.path_m {
                    self.inside_world(world, &format!("{field}.path_m"), path.span(), p.x, p.y)?;
                }
            }
            if obstacle.appears_s <= 0.0 {
                self.no_start_overlap(vehicle, &obstacle.solid, &field, id_span)?;
            }
            obstacles.push(obstacle);
        }
        Ok(obstacles)
    }

    fn world(&self, w: &WorldSpec) -> Result<World, ScenarioError> {
        let min_m = [w.min_m[0].0, w.min_m[1].0];
        let max_m = [w.max_m.get_ref()[0].0, w.max_m.get_ref()[1].0];
        if max_m[0] <= min_m[0] || max_m[1] <= min_m[1] {
            return Err(self.err(
                w.max_m.span(),
                "world.max_m",
                format!(
                    "the upper corner {max_m:?} must be above the lower corner {min_m:?} in x and y"
                ),
            ));
        }
        Ok(World {
            min_m,
            max_m,
            ground_remission: w.ground_remission.0,
            pavement_texture: w.pavement_texture.0,
        })
    }

    fn inside_world(
        &self,
        world: &World,
        field: &str,
        span: Range<usize>,
        x: f64,
        y: f64,
    ) -> Result<(), ScenarioError> {
        if x < world.min_m[0] || x > world.max_m[0] || y < world.min_m[1] || y > world.max_m[1] {
            return Err(self.err(
                span,
                field,
                format!(
                    "({x}, {y}) lies outside the world [{}, {}] .. [{}, {}]",
                    world.min_m[0], world.min_m[1], world.max_m[0], world.max_m[1]
                ),
            ));
        }
        Ok(())
    }

    /// Checks a polyline: at least `min` points, no two consecutive equal (nor, when `closed`,
    /// the last and the first).
    #[allow(clippy::too_many_arguments)]
    fn polyline(
        &self,
        points: &[Point2<f64>],
        min: usize,
        closed: bool,
        span: Range<usize>,
        field: &str,
        what: &str,
    ) -> Result<(), ScenarioError> {
        if points.len() < min {
            return Err(self.err(
                span,
                field,
                format!(
                    "{} point(s): {}{what} needs at least {min}",
                    points.len(),
                    if closed { "closed, " } else { "" }
                ),
            ));
        }
        for (k, w) in points.windows(2).enumerate() {
            if w[0] == w[1] {
                return Err(self.err(
                    span,
                    field,
                    format!(
                        "points {k} and {} are the same ({}, {})",
                        k + 1,
                        w[0].x,
                        w[0].y
                    ),
                ));
            }
        }
        if closed && points.first() == points.last() {
            return Err(self.err(
                span,
                field,
                "the last point repeats the first: a closed route joins them itself, drop the last",
            ));
        }
        Ok(())
    }

    fn route(&self, r: &Spanned<RouteSpec>, world: &World) -> Result<Route, ScenarioError> {
        let spec = r.get_ref();
        let min = if spec.closed { 3 } else { 2 };
        let (waypoints_m, yaws_rad, span, field) = match (&spec.waypoints_m, &spec.pose_file) {
            (Some(_), Some(p)) => {
                return Err(self.err(
                    p.span(),
                    "route.pose_file",
                    "give either waypoints_m or pose_file, not both",
                ));
            }
            (None, None) => {
                return Err(self.err(
                    r.span(),
                    "route",
                    "missing the route: give waypoints_m = [[x, y], ...] or pose_file = \"...\"",
                ));
            }
            (Some(w), None) => {
                let pts: Vec<Point2<f64>> = w
                    .get_ref()
                    .iter()
                    .map(|p| Point2::new(p[0].0, p[1].0))
                    .collect();
                let n = pts.len();
                (pts, vec![None; n], w.span(), "route.waypoints_m")
            }
            (None, Some(p)) => {
                let (pts, yaws) = self.pose_file(p)?;
                (pts, yaws, p.span(), "route.pose_file")
            }
        };
        self.polyline(
            &waypoints_m,
            min,
            spec.closed,
            span.clone(),
            field,
            "a route",
        )?;
        for (k, p) in waypoints_m.iter().enumerate() {
            if p.x < world.min_m[0]
                || p.x > world.max_m[0]
                || p.y < world.min_m[1]
                || p.y > world.max_m[1]
            {
                return Err(self.err(
                    span,
                    field,
                    format!("point {k} ({}, {}) lies outside the world", p.x, p.y),
                ));
            }
        }
        Ok(Route {
            waypoints_m,
            yaws_rad,
            closed: spec.closed,
            speed_m_s: spec.speed_m_s.0,
        })
    }

    /// Reads a pose file: `x_m,y_m[,yaw_rad]` a line, `#` comments.
    #[allow(clippy::type_complexity)]
    fn pose_file(
        &self,
        name: &Spanned<String>,
    ) -> Result<(Vec<Point2<f64>>, Vec<Option<f64>>), ScenarioError> {
        let path = self.dir.join(name.get_ref());
        let text = std::fs::read_to_string(&path).map_err(|e| {
            self.err(
                name.span(),
                "route.pose_file",
                format!("cannot read the pose file {}: {e}", path.display()),
            )
        })?;
        let label = path.display().to_string();
        let mut points = Vec::new();
        let mut yaws = Vec::new();
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let start = offset;
            offset += line.len();
            let content = line.split('#').next().unwrap_or("").trim_end();
            if content.trim().is_empty() {
                continue;
            }
            let mut values = Vec::with_capacity(3);
            let mut col = start;
            for field in content.split(',') {
                let lead = field.len() - field.trim_start().len();
                let token = field.trim();
                let at = col + lead;
                let v: f64 = token
                    .parse()
                    .ok()
                    .filter(|v: &f64| v.is_finite())
                    .ok_or_else(|| {
                        ScenarioError::at(
                            &label,
                            &text,
                            at..at + token.len().max(1),
                            "route.pose_file",
                            format!(
                                "`{token}` is not a finite number (a line is x_m,y_m[,yaw_rad])"
                            ),
                        )
                    })?;
                values.push(v);
                col += field.len() + 1;
            }
            if !(2..=3).contains(&values.len()) {
                return Err(ScenarioError::at(
                    &label,
                    &text,
                    start..start + content.len(),
                    "route.pose_file",
                    format!("{} values: a line is x_m,y_m[,yaw_rad]", values.len()),
                ));
            }
            points.push(Point2::new(values[0], values[1]));
            yaws.push(values.get(2).copied());
        }
        Ok((points, yaws))
    }

    fn vehicle(
        &self,
        v: &VehicleEntry,
        route: &Route,
        world: &World,
    ) -> Result<ScenarioVehicle, ScenarioError> {
        let name = v.description.get_ref();
        let as_path = self.dir.join(name);
        let loaded = if aircraft::SHIPPED_VEHICLES.contains(&name.as_str())
            || (!as_path.exists() && Path::new(name).extension().is_none())
        {
            // A shipped name, or neither a name nor a file: the error lists the shipped names.
            aircraft::Vehicle::shipped(name)
        } else {
            aircraft::Vehicle::from_file(&as_path)
        };
        let vehicle = loaded.map_err(|e| {
            self.err(
                v.description.span(),
                "vehicle.description",
                format!("cannot load the vehicle: {e}"),
            )
        })?;
        let world_from_start = match &v.start {
            Some(s) => {
                let p = s.get_ref();
                if p.x_m.0 < world.min_m[0]
                    || p.x_m.0 > world.max_m[0]
                    || p.y_m.0 < world.min_m[1]
                    || p.y_m.0 > world.max_m[1]
                {
                    return Err(self.err(
                        s.span(),
                        "vehicle.start",
                        format!("({}, {}) lies outside the world", p.x_m.0, p.y_m.0),
                    ));
                }
                Isometry2::new(Vector2::new(p.x_m.0, p.y_m.0), p.yaw_rad.0)
            }
            None => {
                let (a, b) = (route.waypoints_m[0], route.waypoints_m[1]);
                let d = b - a;
                Isometry2::new(a.coords, route.yaws_rad[0].unwrap_or(d.y.atan2(d.x)))
            }
        };
        Ok(ScenarioVehicle {
            description: name.clone(),
            vehicle,
            world_from_start,
        })
    }

    fn shape(
        &self,
        field: &str,
        table_span: Range<usize>,
        kind: ObjectKind,
        size: &Option<Spanned<[Positive; 3]>>,
        radius: &Option<Spanned<Positive>>,
        height: &Option<Spanned<Positive>>,
    ) -> Result<SolidShape, ScenarioError> {
        let name = kind_name(kind);
        let round = matches!(
            kind,
            ObjectKind::Cone | ObjectKind::Marker | ObjectKind::LampPost | ObjectKind::Cylinder
        );
        if round {
            if let Some(s) = size {
                return Err(self.err(
                    s.span(),
                    &format!("{field}.size_m"),
                    format!("a {name} is round: give radius_m and height_m, not size_m"),
                ));
            }
            let (r0, h0) = match kind {
                ObjectKind::Cone => (Some(0.18), Some(0.45)),
                ObjectKind::Marker => (Some(0.10), Some(0.35)),
                ObjectKind::LampPost => (Some(0.12), Some(6.0)),
                _ => (None, None),
            };
            let r = radius.as_ref().map(|r| r.get_ref().0).or(r0);
            let h = height.as_ref().map(|h| h.get_ref().0).or(h0);
            let (Some(radius_m), Some(height_m)) = (r, h) else {
                let missing = if r.is_none() { "radius_m" } else { "height_m" };
                return Err(self.err(
                    table_span,
                    &format!("{field}.{missing}"),
                    format!("a {name} needs radius_m and height_m (metres)"),
                ));
            };
            Ok(if kind == ObjectKind::Cone {
                SolidShape::Cone { radius_m, height_m }
            } else {
                SolidShape::Cylinder { radius_m, height_m }
            })
        } else {
            for (v, key) in [(radius, "radius_m"), (height, "height_m")] {
                if let Some(v) = v {
                    return Err(self.err(
                        v.span(),
                        &format!("{field}.{key}"),
                        format!("a {name} is box-like: give size_m = [x, y, z], not {key}"),
                    ));
                }
            }
            let default = match kind {
                ObjectKind::Container => Some([0.8, 0.6, 1.1]),
                ObjectKind::ParkedCar | ObjectKind::Vehicle => Some([4.5, 1.8, 1.5]),
                ObjectKind::Debris => Some([0.3, 0.3, 0.15]),
                _ => None,
            };
            let size_m = size
                .as_ref()
                .map(|s| {
                    let s = s.get_ref();
                    [s[0].0, s[1].0, s[2].0]
                })
                .or(default)
                .ok_or_else(|| {
                    self.err(
                        table_span,
                        &format!("{field}.size_m"),
                        format!("a {name} needs size_m = [x, y, z] (metres)"),
                    )
                })?;
            Ok(SolidShape::Box { size_m })
        }
    }

    /// Expands a row into its objects (ids, shapes, poses), with the checks that need only the
    /// row and the route; ids, the world and the start overlap are checked by the caller.
    fn row(
        &self,
        r: &Spanned<RowSpec>,
        field: &str,
        route: &Route,
    ) -> Result<Vec<RowObject>, ScenarioError> {
        let spec = r.get_ref();
        let shape = self.shape(
            field,
            r.span(),
            spec.kind,
            &spec.size_m,
            &spec.radius_m,
            &spec.height_m,
        )?;
        let line = self.row_line(r, field, route)?;
        let length = line.length_m();
        let offsets = self.row_offsets(spec, field)?;
        let stations = self.row_stations(spec, field, &line, length, offsets.len())?;
        self.place_row(r, field, shape, &line, &offsets, &stations)
    }

    /// A row's line: its own `along_m` (checked as a polyline) or the route (`along = "route"`),
    /// exactly one of them.
    fn row_line(
        &self,
        r: &Spanned<RowSpec>,
        field: &str,
        route: &Route,
    ) -> Result<Polyline, ScenarioError> {
        let spec = r.get_ref();
        Ok(match (&spec.along_m, &spec.along) {
            (Some(_), Some(a)) => {
                return Err(self.err(
                    a.span(),
                    &format!("{field}.along"),
                    "give either along_m or along, not both",
                ));
            }
            (None, None) => {
                return Err(self.err(
                    r.span(),
                    field,
                    "missing the row's line: give along_m = [[x, y], ...] or along = \"route\"",
                ));
            }
            (Some(a), None) => {
                let pts: Vec<Point2<f64>> = a
                    .get_ref()
                    .iter()
                    .map(|p| Point2::new(p[0].0, p[1].0))
                    .collect();
                self.polyline(
                    &pts,
                    2,
                    false,
                    a.span(),
                    &format!("{field}.along_m"),
                    "a row's line",
                )?;
                Polyline::new(&pts, false)
            }
            (None, Some(a)) => match a.get_ref() {
                RowLine::Route => Polyline::new(&route.waypoints_m, route.closed),
            },
        })
    }

    /// A row's lateral offsets, metres (default: on the line): at least one, none twice.
    fn row_offsets(&self, spec: &RowSpec, field: &str) -> Result<Vec<f64>, ScenarioError> {
        Ok(match &spec.offsets_m {
            None => vec![0.0],
            Some(o) => {
                let v: Vec<f64> = o.get_ref().iter().map(|x| x.0).collect();
                if v.is_empty() {
                    return Err(self.err(
                        o.span(),
                        &format!("{field}.offsets_m"),
                        "no offsets: give at least one, e.g. [0.0] (on the line)",
                    ));
                }
                for (k, a) in v.iter().enumerate() {
                    if v[..k].contains(a) {
                        return Err(self.err(
                            o.span(),
                            &format!("{field}.offsets_m"),
                            format!("offset {a} m is given twice"),
                        ));
                    }
                }
                v
            }
        })
    }

    /// Where along its line (`length` metres long) a row's stations run, checking `end_m`
    /// against `start_m` and the line, `start_m` against the line, and the number of objects
    /// (`offset_count` a station) against [`MAX_ROW_OBJECTS`].
    fn row_stations(
        &self,
        spec: &RowSpec,
        field: &str,
        line: &Polyline,
        length: f64,
        offset_count: usize,
    ) -> Result<RowStations, ScenarioError> {
        let start = spec.start_m.as_ref().map_or(0.0, |s| s.get_ref().0);
        // On a closed line without end_m, the station at the full length would repeat s = 0.
        let (end, open_end) = match &spec.end_m {
            Some(e) => {
                let end = e.get_ref().0;
                if end <= start {
                    return Err(self.err(
                        e.span(),
                        &format!("{field}.end_m"),
                        format!("{end} m is not after start_m ({start} m)"),
                    ));
                }
                if end > length + 1e-9 {
                    return Err(self.err(
                        e.span(),
                        &format!("{field}.end_m"),
                        format!("{end} m lies beyond the end of the line ({length:.3} m long)"),
                    ));
                }
                (end, false)
            }
            None => {
                if let Some(s) = &spec.start_m
                    && start >= length
                {
                    return Err(self.err(
                        s.span(),
                        &format!("{field}.start_m"),
                        format!(
                            "{start} m lies at or beyond the end of the line ({length:.3} m long)"
                        ),
                    ));
                }
                (length, line.closed)
            }
        };
        let spacing = spec.spacing_m.get_ref().0;
        let stations = ((end - start) / spacing + 1e-9).floor() + 1.0;
        let count = stations * offset_count as f64;
        if count > MAX_ROW_OBJECTS as f64 {
            return Err(self.err(
                spec.spacing_m.span(),
                &format!("{field}.spacing_m"),
                format!(
                    "{spacing} m over {:.1} m with {} offset(s) makes {count:.0} objects, more than {MAX_ROW_OBJECTS}",
                    end - start,
                    offset_count
                ),
            ));
        }
        Ok(RowStations {
            start,
            end,
            open_end,
            length,
            spacing,
            stations,
            count,
        })
    }

    /// Places a row's objects, station by station and, at each, offset by offset (ids
    /// `<row id>_<n>` from 1), refusing an offset object a sharp turn puts near the line.
    fn place_row(
        &self,
        r: &Spanned<RowSpec>,
        field: &str,
        shape: SolidShape,
        line: &Polyline,
        offsets: &[f64],
        stations: &RowStations,
    ) -> Result<Vec<RowObject>, ScenarioError> {
        let spec = r.get_ref();
        let RowStations {
            start,
            end,
            open_end,
            length,
            spacing,
            stations,
            count,
        } = *stations;
        let remission = spec
            .remission
            .map_or_else(|| default_remission(spec.kind), |r| r.0);
        let prefix = spec.id.get_ref();
        let mut made = Vec::with_capacity(count as usize);
        for k in 0..stations as usize {
            let s_m = start + k as f64 * spacing;
            if s_m > end + 1e-9 || (open_end && s_m >= length - 1e-9) {
                break;
            }
            let (p, heading) = line.at(s_m);
            let normal = Vector2::new(-heading.sin(), heading.cos());
            for &offset_m in offsets {
                let q = p + normal * offset_m;
                // A sharp turn of the line puts an offset object of one segment over another:
                // refuse it rather than place an object where the line runs.
                let d = line.distance(&q);
                if d < 0.9 * offset_m.abs() - 1e-9 {
                    let span = spec
                        .offsets_m
                        .as_ref()
                        .map_or_else(|| r.span(), |o| o.span());
                    return Err(self.err(
                        span,
                        &format!("{field}.offsets_m"),
                        format!(
                            "the object at arc length {s_m:.2} m, offset {offset_m} m, ({:.2}, {:.2}) lies {d:.2} m from the line: it turns too sharply there for this offset (round the corner with more points, or limit the row with start_m/end_m)",
                            q.x, q.y
                        ),
                    ));
                }
                made.push(RowObject {
                    solid: Solid {
                        id: format!("{prefix}_{}", made.len() + 1),
                        kind: spec.kind,
                        shape,
                        x_m: q.x,
                        y_m: q.y,
                        z_min_m: spec.z_min_m.0,
                        yaw_rad: crate::motion::wrap_angle(heading + spec.yaw_rad.0),
                        remission,
                        runtime: false,
                    },
                    s_m,
                    offset_m,
                });
            }
        }
        Ok(made)
    }

    fn obstacle(&self, o: &Spanned<ObstacleSpec>, field: &str) -> Result<Obstacle, ScenarioError> {
        let s = o.get_ref();
        let shape = self.shape(field, o.span(), s.kind, &s.size_m, &s.radius_m, &s.height_m)?;
        let appears_s = s.appears_s.as_ref().map_or(0.0, |a| a.get_ref().0);
        if let Some(d) = &s.disappears_s
            && d.get_ref().0 <= appears_s
        {
            return Err(self.err(
                d.span(),
                &format!("{field}.disappears_s"),
                format!("{} s is not after appears_s ({appears_s} s)", d.get_ref().0),
            ));
        }
        let (x_m, y_m, yaw_rad, motion) = match (&s.path_m, &s.speed_m_s) {
            (Some(path), Some(speed)) => {
                if s.x_m.is_some() || s.y_m.is_some() {
                    return Err(self.err(
                        path.span(),
                        &format!("{field}.path_m"),
                        "a moving obstacle starts at the first point of path_m: drop x_m and y_m",
                    ));
                }
                let pts: Vec<Point2<f64>> = path
                    .get_ref()
                    .iter()
                    .map(|p| Point2::new(p[0].0, p[1].0))
                    .collect();
                self.polyline(
                    &pts,
                    2,
                    false,
                    path.span(),
                    &format!("{field}.path_m"),
                    "a path",
                )?;
                let d = pts[1] - pts[0];
                let motion = ObstacleMotion {
                    path_m: pts.clone(),
                    speed_m_s: speed.get_ref().0,
                    yaw_offset_rad: s.yaw_rad.0,
                };
                (
                    pts[0].x,
                    pts[0].y,
                    d.y.atan2(d.x) + s.yaw_rad.0,
                    Some(motion),
                )
            }
            (Some(path), None) => {
                return Err(self.err(
                    path.span(),
                    &format!("{field}.speed_m_s"),
                    "a moving obstacle (path_m) needs speed_m_s (m/s)",
                ));
            }
            (None, Some(speed)) => {
                return Err(self.err(
                    speed.span(),
                    &format!("{field}.speed_m_s"),
                    "speed_m_s is only for a moving obstacle: give path_m too",
                ));
            }
            (None, None) => match (s.x_m, s.y_m) {
                (Some(x), Some(y)) => (x.0, y.0, s.yaw_rad.0, None),
                (x, _) => {
                    let missing = if x.is_none() { "x_m" } else { "y_m" };
                    return Err(self.err(
                        o.span(),
                        &format!("{field}.{missing}"),
                        format!("missing field `{missing}` (or give path_m and speed_m_s)"),
                    ));
                }
            },
        };
        Ok(Obstacle {
            solid: Solid {
                id: s.id.get_ref().clone(),
                kind: s.kind,
                shape,
                x_m,
                y_m,
                z_min_m: s.z_min_m.0,
                yaw_rad,
                remission: s
                    .remission
                    .map_or_else(|| default_remission(s.kind), |r| r.0),
                runtime: true,
            },
            expect: s.expect,
            appears_s,
            disappears_s: s.disappears_s.as_ref().map(|d| d.get_ref().0),
            motion,
        })
    }

    fn no_start_overlap(
        &self,
        vehicle: &ScenarioVehicle,
        solid: &Solid,
        field: &str,
        span: Range<usize>,
    ) -> Result<(), ScenarioError> {
        if let Some(hit) = start_overlap(&vehicle.vehicle, &vehicle.world_from_start, solid) {
            let t = vehicle.world_from_start.translation.vector;
            return Err(self.err(
                span,
                field,
                format!(
                    "`{}` ({}, z {:.2}..{:.2} m) overlaps the vehicle at its start pose ({:.2}, {:.2}) m, yaw {:.3} rad: {hit}",
                    solid.id,
                    kind_name(solid.kind),
                    solid.z_min_m,
                    solid.z_min_m + solid.shape.height_m(),
                    t.x,
                    t.y,
                    vehicle.world_from_start.rotation.angle(),
                ),
            ));
        }
        Ok(())
    }
}

/// An object a row made, with where along its line it stands.
struct RowObject {
    solid: Solid,
    /// Arc length along the row's line, metres.
    s_m: f64,
    /// Lateral offset from the line, metres, left positive.
    offset_m: f64,
}

/// Where along its line a row's stations run (see [`Resolver::row_stations`]).
#[derive(Clone, Copy)]
struct RowStations {
    /// Arc length of the first station, metres.
    start: f64,
    /// Arc length no station goes beyond, metres.
    end: f64,
    /// A closed line without `end_m`: no station at the full length (it would repeat s = 0).
    open_end: bool,
    /// Length of the line, metres.
    length: f64,
    /// Distance between stations, metres.
    spacing: f64,
    /// Number of stations (a whole number).
    stations: f64,
    /// Number of objects: stations times offsets.
    count: f64,
}

/// A row's line: a polyline with arc lengths (closed: back to its first point).
struct Polyline {
    points: Vec<Point2<f64>>,
    s: Vec<f64>,
    closed: bool,
}

impl Polyline {
    fn new(points: &[Point2<f64>], closed: bool) -> Self {
        let mut points = points.to_vec();
        if closed && let Some(first) = points.first().copied() {
            points.push(first);
        }
        let mut s = vec![0.0];
        for w in points.windows(2) {
            s.push(s[s.len() - 1] + (w[1] - w[0]).norm());
        }
        Polyline { points, s, closed }
    }

    fn length_m(&self) -> f64 {
        self.s[self.s.len() - 1]
    }

    /// Point and heading at arc length `s` in [0, length]; on a vertex, the heading of the
    /// segment leaving it (of the last segment at the end).
    fn at(&self, s: f64) -> (Point2<f64>, f64) {
        let i = self
            .s
            .partition_point(|&x| x <= s)
            .saturating_sub(1)
            .min(self.points.len() - 2);
        let (a, b) = (self.points[i], self.points[i + 1]);
        let d = b - a;
        let len = d.norm();
        (a + d * ((s - self.s[i]) / len), d.y.atan2(d.x))
    }

    /// Distance from `p` to the nearest point of the line.
    fn distance(&self, p: &Point2<f64>) -> f64 {
        self.points
            .windows(2)
            .map(|w| {
                let ab = w[1] - w[0];
                let t = ((p - w[0]).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                (p - (w[0] + ab * t)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// The snake_case name of a kind, as in files.
pub fn kind_name(kind: ObjectKind) -> &'static str {
    match kind {
        ObjectKind::Cone => "cone",
        ObjectKind::Container => "container",
        ObjectKind::Marker => "marker",
        ObjectKind::Building => "building",
        ObjectKind::LampPost => "lamp_post",
        ObjectKind::ParkedCar => "parked_car",
        ObjectKind::Vehicle => "vehicle",
        ObjectKind::Debris => "debris",
        ObjectKind::Box => "box",
        ObjectKind::Cylinder => "cylinder",
    }
}

/// Default remission of a kind.
pub fn default_remission(kind: ObjectKind) -> f32 {
    match kind {
        ObjectKind::Cone => 0.5,
        ObjectKind::Marker => 0.7,
        ObjectKind::Container => 0.4,
        ObjectKind::Debris | ObjectKind::Building => 0.2,
        ObjectKind::LampPost
        | ObjectKind::ParkedCar
        | ObjectKind::Vehicle
        | ObjectKind::Box
        | ObjectKind::Cylinder => 0.3,
    }
}

// ---------------------------------------------------------------------------------------------
// Start overlap
// ---------------------------------------------------------------------------------------------

/// Gap under which two footprints touch, metres.
const TOUCH_M: f64 = 1e-9;

/// The first vehicle part a solid overlaps with the vehicle at `world_from_vehicle`, described.
///
/// A part and a solid overlap when their ground footprints intersect and their height ranges
/// intersect (open intervals: touching is not overlapping). Footprints: a part's exact projection
/// ([`aircraft::Part::footprint`]); a box's rectangle; a cone's or cylinder's base disc (a cone
/// is treated as its bounding cylinder, which is conservative).
pub fn start_overlap(
    vehicle: &aircraft::Vehicle,
    world_from_vehicle: &Isometry2<f64>,
    solid: &Solid,
) -> Option<String> {
    let (lo, hi) = (solid.z_min_m, solid.z_min_m + solid.shape.height_m());
    let footprint = solid_footprint_in_vehicle(solid, world_from_vehicle);
    vehicle.parts.iter().find_map(|part| {
        let (under, top) = (part.underside_m(), part.top_m());
        let heights = lo < top && under < hi;
        (heights && footprints_intersect(&footprint, &part.footprint())).then(|| {
            format!(
                "it meets link `{}` collision {} (z {:.2}..{:.2} m)",
                part.link, part.collision_index, under, top
            )
        })
    })
}

/// A solid's ground footprint in the vehicle frame.
fn solid_footprint_in_vehicle(solid: &Solid, world_from_vehicle: &Isometry2<f64>) -> Footprint {
    let vehicle_from_world = world_from_vehicle.inverse();
    let center = vehicle_from_world * Point2::new(solid.x_m, solid.y_m);
    match solid.shape {
        SolidShape::Cone { radius_m, .. } | SolidShape::Cylinder { radius_m, .. } => {
            Footprint::Disc(Disc { center, radius_m })
        }
        SolidShape::Box { size_m } => {
            let yaw = solid.yaw_rad - world_from_vehicle.rotation.angle();
            let (s, c) = yaw.sin_cos();
            let (u, v) = (
                Vector2::new(c, s) * (0.5 * size_m[0]),
                Vector2::new(-s, c) * (0.5 * size_m[1]),
            );
            let corners = [
                center + u + v,
                center - u + v,
                center - u - v,
                center + u - v,
            ];
            match ConvexPolygon::hull(&corners) {
                Some(p) => Footprint::Polygon(p),
                None => Footprint::Disc(Disc {
                    center,
                    radius_m: 0.5 * size_m[0].hypot(size_m[1]),
                }),
            }
        }
    }
}

fn project(points: &[Point2<f64>], axis: &Vector2<f64>) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let d = axis.dot(&p.coords);
            (lo.min(d), hi.max(d))
        })
}

/// True when two convex footprints overlap by more than [`TOUCH_M`] (separating axes).
fn footprints_intersect(a: &Footprint, b: &Footprint) -> bool {
    match (a, b) {
        (Footprint::Disc(p), Footprint::Disc(q)) => {
            (p.center - q.center).norm() < p.radius_m + q.radius_m - TOUCH_M
        }
        (Footprint::Polygon(poly), Footprint::Disc(d))
        | (Footprint::Disc(d), Footprint::Polygon(poly)) => {
            poly.distance(&d.center) < d.radius_m - TOUCH_M
        }
        (Footprint::Polygon(p), Footprint::Polygon(q)) => {
            let axes = [p, q].into_iter().flat_map(|poly| {
                let v = poly.vertices();
                (0..v.len()).map(move |i| {
                    let e = v[(i + 1) % v.len()] - v[i];
                    Vector2::new(-e.y, e.x).normalize()
                })
            });
            for axis in axes {
                let (p_lo, p_hi) = project(p.vertices(), &axis);
                let (q_lo, q_hi) = project(q.vertices(), &axis);
                if p_hi <= q_lo + TOUCH_M || q_hi <= p_lo + TOUCH_M {
                    return false;
                }
            }
            true
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_paths_read_off_the_text() {
        let text = "name = \"a\"\n[vehicle]\nstart = { x_m = 1, y_m = \"b\" }\n[[objects]]\nid = \"x\"\n[[objects]]\nradius_m = -1\n[route]\nwaypoints_m = [\n  [0, 0],\n  [1, nan],\n]\n";
        let at = |s: &str| field_at(text, text.find(s).expect("in text"));
        assert_eq!(at("\"b\""), "vehicle.start.y_m");
        assert_eq!(at("-1"), "objects[1].radius_m");
        assert_eq!(at("[1, nan]"), "route.waypoints_m");
        assert_eq!(at("\"a\""), "name");
    }
}
