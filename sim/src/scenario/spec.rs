//! A scenario file as written: the serde structs ([`ScenarioFile`] and the `*Spec` structs),
//! every field's unit and default documented on it, unknown keys rejected everywhere. Numbers are
//! checked while they are read (validating newtypes such as [`Positive`]), so toml's error points
//! at the value; the cross-field checks are the resolver's, on the spans toml keeps
//! ([`toml::Spanned`]).

use serde::Deserialize;
use toml::Spanned;

use super::numbers::{Count, Finite, Laps, NonNegative, Positive, Remission};
use crate::world::ObjectKind;

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
    /// The ground. Required unless `[airport]` is given (then the airport's extent, on grass).
    pub world: Option<WorldSpec>,
    /// A real airport's ground and objects from an X-Plane apt.dat.
    pub airport: Option<Spanned<AirportSpec>>,
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
    /// How `taxi-sim regress` runs it (its quick tier). Default: as it is.
    #[serde(default)]
    pub regress: RegressSpec,
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
    /// vehicle calls for a pilot rather than guess it has gone), `waiting_for_walk_around` (it
    /// never moved off: ground it would sweep first is ground its LiDAR cannot see, and no
    /// walk-around confirmed it) or `stopped_for_good` (stopped
    /// before an obstacle that never goes, or never moved off for one, timed out or calling for
    /// a pilot: waiting for a hidden obstacle, or blocked) or `any` (only
    /// contacts and the obstacles' expectations count, and an obstacle never passed counts for
    /// nothing: a campaign's randomized obstacles, which may block the way or appear late).
    pub end: Option<ExpectedEnd>,
    /// True: a contact while the vehicle was moving (the stack's fault) fails the run, whatever
    /// the obstacles' `expect`; a contact while it stood (struck by a mover) does not by this
    /// rule. Default false.
    #[serde(default)]
    pub no_contact_at_fault: bool,
    /// At most this many stops over the whole run (stops for obstacles, real or not): a stack
    /// that stops again and again on a clear way fails it. Default none: not checked.
    pub max_stops: Option<usize>,
    /// The pose estimate's cross-track RMSE over the run, metres, > 0: at most this. Checked when
    /// the stack estimates its pose (the particle filter, noisy truth); default none.
    pub max_cross_track_rmse_m: Option<Positive>,
    /// The pose estimate's heading RMSE over the run, radians, > 0: at most this (as above).
    pub max_heading_rmse_rad: Option<Positive>,
    /// A known problem: the run does not meet the expectations above today, and this text says
    /// why. Given with `today` (the outcome as it is now), `taxi-sim regress` reports the case as
    /// an expected failure while it still ends as `today` states, and as a failure once it meets
    /// the expectations (the problem is fixed: remove the mark) or ends some other way. Default
    /// none.
    pub known_problem: Option<Spanned<String>>,
    /// The outcome as it is today, for a `known_problem`: every field given must hold.
    pub today: Option<Spanned<TodaySpec>>,
}

/// `[expectations.today]`: a known problem's outcome as it is now (each field optional; at
/// least one given).
#[derive(Debug, Default, Deserialize, serde::Serialize, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TodaySpec {
    /// How the run ends today: `completed`, `timed_out`, `waiting_for_hidden_obstacle`,
    /// `waiting_for_walk_around` or `blocked`.
    pub end: Option<TodayEnd>,
    /// Contacts in all.
    pub contacts: Option<usize>,
    /// Contacts that began while the vehicle moved (at fault).
    pub contacts_at_fault: Option<usize>,
    /// Contacts that began while it stood (struck by a mover).
    pub contacts_struck: Option<usize>,
    /// The objects touched, in the order first touched.
    pub contacts_with: Option<Vec<String>>,
}

/// How a run ends, as a known problem's `today.end` states it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TodayEnd {
    /// Every lap driven.
    Completed,
    /// Out of simulated time.
    TimedOut,
    /// Waiting for a hidden obstacle: a pilot called.
    WaitingForHiddenObstacle,
    /// Waiting for a walk-around at the start: a pilot called.
    WaitingForWalkAround,
    /// Blocked for good: a pilot called.
    Blocked,
    /// Struck: a pilot called to inspect the airframe.
    Struck,
}

impl TodayEnd {
    /// The name a run report gives this end.
    pub fn as_str(self) -> &'static str {
        match self {
            TodayEnd::Completed => "completed",
            TodayEnd::TimedOut => "timed_out",
            TodayEnd::WaitingForHiddenObstacle => "waiting_for_hidden_obstacle",
            TodayEnd::WaitingForWalkAround => "waiting_for_walk_around",
            TodayEnd::Blocked => "blocked",
            TodayEnd::Struck => "struck",
        }
    }
}

/// `[regress]`: how `taxi-sim regress` runs this file.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegressSpec {
    /// Laps in the quick tier (without `--full`); a file with fewer `laps` (a campaign's
    /// variant) runs them all. Default: all of them.
    pub quick_laps: Option<Laps>,
    /// Run only in the full tier (`--full`): a case too long to shorten. Default false.
    #[serde(default)]
    pub full_only: bool,
    /// The quick tier's golden numbers, a `.json` file relative to this one (written by `regress
    /// --bless`): the case fails when its run's summary differs.
    pub golden: Option<Spanned<String>>,
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
    /// Never moved off, waiting for a walk-around, calling for a pilot.
    WaitingForWalkAround,
    /// Stopped for good before an obstacle that never goes: the run ends timed out or calling
    /// for a pilot (waiting for a hidden obstacle, blocked, or struck), the vehicle still standing - or
    /// never having moved off.
    StoppedForGood,
    /// The airframe felt a strike, stood and called for a pilot to inspect it.
    Struck,
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
    /// The crew's walk-around, which confirms the ground round the vehicle that its LiDAR cannot
    /// see from the start (the stack's start-up rule): `"before_start"` (the default: confirmed
    /// before the run starts), `"none"` (never: a vehicle whose first plan sweeps blind ground
    /// waits and calls for a pilot), or a time in seconds (it waits until then).
    pub walk_around: Option<Spanned<WalkAroundSpec>>,
}

/// `[vehicle] walk_around`: a word or a time.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum WalkAroundSpec {
    /// `"before_start"` or `"none"`.
    Word(String),
    /// Seconds of simulated time.
    At(f64),
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

/// `[airport]`: an apt.dat airport as the world: its pavement, runways and painted lines on the
/// ground, its signs and lights, parked aircraft at its stands.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AirportSpec {
    /// The apt.dat file, relative to the scenario file's directory. Required.
    pub file: Spanned<String>,
    /// The airport's code, when the file holds several.
    pub code: Option<String>,
    /// Its signs as objects. Default true.
    #[serde(default = "yes")]
    pub signs: bool,
    /// Its light units, windsocks and taxiway edge lights as objects. Default true.
    #[serde(default = "yes")]
    pub lights: bool,
    /// A tug and a baggage cart beside each parked aircraft. Default false.
    #[serde(default)]
    pub ground_equipment: bool,
    /// Aircraft parked at stands.
    #[serde(default)]
    pub parked: Vec<Spanned<ParkedSpec>>,
    /// The share of the other stands occupied, drawn with the scenario's seed: each by the
    /// largest shipped aircraft its size class takes (code C and up an A320, B a Praetor; A or
    /// none stays empty). Never the route's own stands. Default 0.
    pub occupancy: Option<Spanned<Remission>>,
    /// The stands as the prior map's survey found them. Default `as_run`.
    #[serde(default)]
    pub surveyed_stands: SurveyedStands,
}

/// `[airport] surveyed_stands`: what the offline map holds of the stands. A surveyed map is
/// driven once per route and vehicle, whatever the run's seed, speed and stand occupancy, so a
/// campaign's variants share it; what the run parks after the survey is news to the stack.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurveyedStands {
    /// The map is driven through the run's own static world, with its seed and speed: every
    /// parked aircraft and its equipment in it (a map made the day of the run).
    #[default]
    AsRun,
    /// Surveyed with the `parked` aircraft (and their equipment) at their stands; the stands
    /// `occupancy` fills were empty.
    Parked,
    /// Surveyed with every stand empty.
    Empty,
}

fn yes() -> bool {
    true
}

/// `[[airport.parked]]`: an aircraft parked at a stand.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParkedSpec {
    /// The stand's name, as the file has it. Required.
    pub stand: Spanned<String>,
    /// A vehicle description (shipped name or sidecar path). Required.
    pub vehicle: Spanned<String>,
}

/// `route.taxi`: a route on the airport's taxi network.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaxiSpec {
    /// A stand's name, `node <id>` or `runway <number>` (vacating it). Required.
    pub from: String,
    /// `runway <number>` (its hold point), a stand's name or `node <id>`. Required.
    pub to: String,
    /// Taxiways to follow in order. Default none.
    #[serde(default)]
    pub via: Vec<String>,
}

/// `[route]`: the path the vehicle follows. Exactly one of `waypoints_m`, `pose_file` and `taxi`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RouteSpec {
    /// A taxi route on the `[airport]`'s network: from, to, via.
    pub taxi: Option<Spanned<TaxiSpec>>,
    /// With `taxi`: the radius of a turn where the legs leave room, metres. Default 30.
    pub turn_radius_m: Option<Positive>,
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
/// round kinds (`cone`, `marker`, `lamp_post`, `cylinder`, `person`) take `radius_m` and
/// `height_m`, the others (`container`, `parked_car`, `vehicle`, `debris`, `building`, `box`,
/// `tug`, `baggage_cart`, `fuel_truck`) take `size_m`.
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
/// | person | cylinder | radius 0.25, height 1.75 | 0.3 |
/// | tug | box | 3.0 x 1.8 x 1.5 | 0.3 |
/// | baggage_cart | box | 2.6 x 1.4 x 1.0 (under a business jet's 1.1 m wing) | 0.4 |
/// | fuel_truck | box | 9.0 x 2.5 x 3.2 | 0.3 |
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
    /// `parked_aircraft` only: the vehicle description whose collision parts it places (a shipped
    /// name or a sidecar path). Required for that kind, refused for the others.
    pub vehicle: Option<Spanned<String>>,
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
    /// A mover crossing the route: stop or slow so that it passes first, without contact, then
    /// drive on.
    Yield,
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
            Expectation::Yield => "yield",
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
    /// What the vehicle must do: `pass_under`, `deviate`, `stop`, `no_contact` or (a mover)
    /// `yield`. Required.
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
    /// How fast it speeds up and brakes, m/s^2, > 0. Only with `path_m`. Default none: speed
    /// changes are instant (it moves at `speed_m_s` from its appearance and stands at once at a
    /// stop or at the path's end), except for a driver that yields (`yields_to_vehicle_m`), whose
    /// every speed change is at 2.0 m/s^2 then.
    pub acceleration_m_s2: Option<Spanned<Positive>>,
    /// Where it stops along `path_m` and how long it waits there,
    /// `[{ at_m = 20.0, wait_s = 4.0 }, ...]`: arc lengths increasing, within the path's length.
    /// Only with `path_m`. Default none.
    pub stops: Option<Spanned<Vec<StopSpec>>>,
    /// A driver that yields to the vehicle, metres, > 0: while any part of the vehicle comes
    /// within this distance of the stretch of its path ahead of its front (its braking distance
    /// plus its own length), it brakes to a stop and waits; it drives on once the stretch is
    /// clear. Only with `path_m`. Default none: it does not react.
    pub yields_to_vehicle_m: Option<Spanned<Positive>>,
    /// A driver that yields and makes room for the vehicle, metres, > 0 (the ramp rule: a
    /// vehicle meeting an aircraft head-on gives way and pulls aside): once it has stood 3 s
    /// for the vehicle coming towards it (headings within 45 degrees of opposite) with its
    /// near side less than this beyond the vehicle's widest part (measured from the vehicle's
    /// centre line), it backs along its path and pulls aside, away from that line, until it
    /// is; from there it yields beside its path as before and drives on once the vehicle has
    /// passed. Not head-on (crossing), standing 3 s for the vehicle with some of its body
    /// ahead of the vehicle and less than this beyond its widest part, it clears the way: it
    /// moves on along its path (or back, if that is shorter) until all of it is, and yields
    /// there. Only with `yields_to_vehicle_m`, not with `train`. Default none: it stands where
    /// it stopped.
    pub makes_room_m: Option<Spanned<Positive>>,
    /// A towed train: this mover is the lead (a tug) and `cars` cars follow it along `path_m`,
    /// each an obstacle `<id>_car1`, `<id>_car2`, ... Only with `path_m`. Default none.
    pub train: Option<Spanned<TrainSpec>>,
}

/// One stop of a moving obstacle, `{ at_m = .., wait_s = .. }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StopSpec {
    /// Where it stands, the arc length along `path_m` (of its centre), metres, >= 0; greater
    /// than the previous stop's, at most the path's length. Required.
    pub at_m: Spanned<NonNegative>,
    /// How long it waits there, seconds, > 0. Required.
    pub wait_s: Positive,
}

/// `train = { cars = .., kind = .., gap_m = .. }`: the cars a moving obstacle tows.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainSpec {
    /// How many cars, an integer from 1 to [`MAX_TRAIN_CARS`]. Required.
    pub cars: Spanned<Count>,
    /// What each car is (snake_case [`ObjectKind`], at the kind's default size and remission;
    /// `building`, `box` and `cylinder`, which have none, are refused). Default `baggage_cart`.
    pub kind: Option<Spanned<ObjectKind>>,
    /// Free distance between consecutive vehicles of the train (the lead and the first car, a
    /// car and the next), measured along the path, metres, >= 0. Default 1.0.
    pub gap_m: Option<NonNegative>,
}

/// The most cars one train may tow.
pub const MAX_TRAIN_CARS: u32 = 50;
