//! Traffic: the movers the tracker follows ([`mapper::TrackState`]), predicted over the planning
//! horizon, and the space-time check of the planned path against them.
//!
//! - **Prediction**: constant velocity from the track's Kalman filter; each mover is a capsule
//!   along its velocity: half its length along the motion (the box of its hits measured along
//!   it, at least half its largest extent) and half its width across, each plus `hidden_m`
//!   (what of it the sensor may not see), widened by `sigmas` standard deviations of its
//!   predicted position, which grow with time. Over a stretch of time it sweeps a longer
//!   capsule, since it moves along its own length, stretched on to where the fastest speed it
//!   was seen at lately would take it (a mover going into a wing's shadow seems to slow as its
//!   visible part shrinks: [`mapper::TrackState::peak_speed_m_s`]). A mover occupies the levels it was hit in: a
//!   baggage cart lower than a wing's level is checked against the gear and fuselage only.
//! - **Space-time check**: the vehicle's arrival time at each pose of the chosen path (from its
//!   speed now, accelerating to the speed it wants), and each circle of a level the mover
//!   occupies against the stretch the mover is predicted to cover from `time_margin_s` before
//!   to `time_margin_s` after the vehicle is there. The first such pose is the conflict.
//! - **Where to stop**: before the conflict zone - the first pose of the path that any position
//!   the mover is predicted to reach within `horizon_s` touches - so a vehicle never stands in
//!   a mover's predicted path when it can stop short of it; when it cannot (too close, too
//!   fast), it drives on if it clears the mover by `committed_margin_s`, and stops before the
//!   conflict itself only if it does not. Wherever it stops - for a mover or for the map - it
//!   stops short of any other mover's predicted path when it can ([`stand_clear`]): a stop for
//!   one must not leave the tail across another's. A mover predicted to pass before the
//!   vehicle arrives (or after it has gone) is no conflict, so it does not stop the vehicle.
//!   While yielding, the margin after grows by `resume_margin_s`, so the vehicle does not creep
//!   off and stop again.
//! - Movers slower than `min_speed_m_s`, or than `sigmas` standard deviations of their speed,
//!   are left to the map (their cells are obstacles there) - but a mover known to move, in
//!   view, down to half that ([`predict_keeping`]: its visible part slows as the airframe hides
//!   the rest of it).
//! - **Caution**: a candidate mover - seen to travel a metre, not yet beyond what revealing a
//!   static object explains - checked the same way caps the speed at `caution_speed_m_s`
//!   instead of stopping the vehicle: slow for what may move, stop for what does.
//! - **A mover at the body** ([`at_body`]): one seen, or predicted while out of view, whose box
//!   of hits, grown by what of it may be hidden, comes within `at_body_m` of a circle of a level
//!   it occupies is where the map cannot hold it (returns within the map's self-hit margin of
//!   the vehicle are dropped as its own): the vehicle does
//!   not move until it is seen away from the body, and one lost there is waited for as a hidden
//!   obstacle (the pilot is called); so is one predicted out of view whose track drops while
//!   it is predicted to reach the standing vehicle's body within the horizon (a van lost into
//!   the blind zone behind a wing). A person who walked up to the fuselage, a truck that
//!   struck the nose: the vehicle moving on would meet them. Only a mover arrives there: a
//!   track predicted lately that has moved beyond its own extent
//!   ([`moved_beyond_its_extent`]) - not a parked car whose visible part slides.

use aircraft::footprint::segment_distance;
use mapper::{CollisionModel, TrackState};
use nalgebra::{Isometry2, Point2, Vector2};
use serde::{Deserialize, Serialize};

/// How the stack predicts movers and checks its path against them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrafficConfig {
    /// Predict movers and yield to them. Default true; false: the map alone (a mover stops the
    /// vehicle only once it stands in the path).
    pub enabled: bool,
    /// How far ahead movers are predicted, seconds. Default 8.
    pub horizon_s: f64,
    /// The vehicle keeps out of where a mover is predicted from this long before it is at a
    /// pose to this long after, seconds. Default 1.5.
    pub time_margin_s: f64,
    /// While yielding - stopped for a mover, or within `conflict_memory_s` of a plan that found
    /// a conflict - the margin after grows by this much, seconds. Default 1.
    pub resume_margin_s: f64,
    /// How long after a conflict was last found the vehicle counts as yielding, seconds.
    /// Default 2.
    pub conflict_memory_s: f64,
    /// The margin of a vehicle too close to stop short of a mover's path: it drives on when it
    /// clears the mover by this much (standing in the path would be worse), seconds. Default 0.5.
    pub committed_margin_s: f64,
    /// A mover's disc is widened by this many standard deviations of its predicted position.
    /// Default 2.
    pub sigmas: f64,
    /// Clearance kept from a predicted mover beyond the radii, metres. Default 0.5.
    pub margin_m: f64,
    /// What may lie of a mover beyond the box of its hits, along and across its motion (the far
    /// side of a van seen from one side, its back seen from the front), metres. Default 1.
    pub hidden_m: f64,
    /// Movers slower than this are left to the map, m/s. Default 0.8 (a static object's visible
    /// part, sliding as it is hidden or revealed, seldom seems faster).
    pub min_speed_m_s: f64,
    /// A tracked mover whose box of hits, grown by what of it may be hidden (`hidden_m` or
    /// more), comes this close to the vehicle's body (beyond a circle's radius, on a level it
    /// occupies) holds the vehicle ([`at_body`]), metres. Default 1 (the map drops returns
    /// within 0.8 m of a circle as the vehicle's own).
    pub at_body_m: f64,
    /// A mover not yet predictable - one the tracker has seen travel a metre but not yet
    /// beyond what revealing a static object's parts explains
    /// ([`mapper::Tracker::candidate_movers`]) - whose motion so far would meet the path caps
    /// the speed at this, m/s, until `conflict_memory_s` after it was last found: by the time
    /// it is confirmed, the vehicle can stop short of it. Default 3 (a long truck crossing at
    /// 1.3 m/s takes 4.4 s to confirm, 35 m at 8 m/s).
    pub caution_speed_m_s: f64,
    /// A mover standing (a known mover not [`surely_moving`]) may walk or drive on without
    /// warning: the vehicle passes within this much of it (beyond `margin_m` and its
    /// footprint) no faster than `caution_speed_m_s` ([`passes_standing`]), does not stop
    /// within it when it can stop short ([`stand_clear`]) and, standing within it, does not
    /// move off, metres. Default 3 (two seconds of a brisk walk; a van from rest at 1.5
    /// m/s^2).
    pub standing_reach_m: f64,
}

impl Default for TrafficConfig {
    fn default() -> Self {
        TrafficConfig {
            enabled: true,
            horizon_s: 8.0,
            time_margin_s: 1.5,
            resume_margin_s: 1.0,
            conflict_memory_s: 2.0,
            committed_margin_s: 0.5,
            sigmas: 2.0,
            margin_m: 0.5,
            hidden_m: 1.0,
            min_speed_m_s: 0.8,
            at_body_m: 1.0,
            caution_speed_m_s: 3.0,
            standing_reach_m: 3.0,
        }
    }
}

impl TrafficConfig {
    /// The first field out of range, as (name, value).
    pub fn invalid_field(&self) -> Option<(&'static str, f64)> {
        let positive = [("horizon_s", self.horizon_s)];
        let non_negative = [
            ("time_margin_s", self.time_margin_s),
            ("resume_margin_s", self.resume_margin_s),
            ("conflict_memory_s", self.conflict_memory_s),
            ("committed_margin_s", self.committed_margin_s),
            ("sigmas", self.sigmas),
            ("margin_m", self.margin_m),
            ("hidden_m", self.hidden_m),
            ("min_speed_m_s", self.min_speed_m_s),
            ("at_body_m", self.at_body_m),
            ("caution_speed_m_s", self.caution_speed_m_s),
            ("standing_reach_m", self.standing_reach_m),
        ];
        positive
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v > 0.0))
            .or_else(|| {
                non_negative
                    .into_iter()
                    .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
            })
    }
}

/// How the vehicle is expected to move along its path: from `speed_m_s` now towards
/// `target_m_s` at `acceleration_m_s2` (a profile that only speeds up or holds: a slower
/// vehicle arrives later, which the check sees as it slows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedProfile {
    /// Speed now, m/s.
    pub speed_m_s: f64,
    /// Speed it drives up to, m/s.
    pub target_m_s: f64,
    /// Acceleration, m/s^2.
    pub acceleration_m_s2: f64,
}

impl SpeedProfile {
    /// Seconds to cover `s_m` metres (infinite if it never gets there).
    pub fn time_to(&self, s_m: f64) -> f64 {
        let (v0, a) = (self.speed_m_s.max(0.0), self.acceleration_m_s2.max(1e-6));
        let v1 = self.target_m_s.max(v0);
        if v1 <= 1e-9 {
            return if s_m <= 0.0 { 0.0 } else { f64::INFINITY };
        }
        let ramp_m = (v1 * v1 - v0 * v0) / (2.0 * a);
        if s_m <= ramp_m {
            // s = v0 t + a t^2 / 2.
            (-v0 + (v0 * v0 + 2.0 * a * s_m).sqrt()) / a
        } else {
            (v1 - v0) / a + (s_m - ramp_m) / v1
        }
    }
}

/// A mover's predicted footprint at one time: a capsule along its motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PredictedDisc {
    /// Seconds from now.
    pub dt_s: f64,
    /// Centre, metres.
    pub center: Point2<f64>,
    /// Radius across its motion (half width, hidden part and uncertainty), metres.
    pub radius_m: f64,
    /// Half the length of the capsule's axis, along its motion, metres.
    pub half_length_m: f64,
    /// Heading of its motion, radians.
    pub heading_rad: f64,
}

/// A mover the stack predicts: its track and its discs over the horizon.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The track.
    pub track: TrackState,
    /// Its discs every half second over the horizon, from now.
    pub discs: Vec<PredictedDisc>,
}

/// What the space-time check found on the path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conflict {
    /// The mover's track id.
    pub track_id: u32,
    /// Distance along the path to the first pose where the vehicle would meet the mover, metres.
    pub at_m: f64,
    /// Distance along the path to the first pose any predicted position of the mover touches
    /// (the conflict zone's start), metres; at most `at_m`.
    pub zone_m: f64,
    /// When the vehicle would be at the conflict, seconds from now.
    pub in_s: f64,
    /// Where the mover would be then, metres.
    pub mover_at: Point2<f64>,
}

/// The predictable movers of `tracks` seen at `now_s`, with their discs over the horizon.
pub fn predict(tracks: &[TrackState], now_s: f64, cfg: &TrafficConfig) -> Vec<Prediction> {
    predict_keeping(tracks, now_s, cfg, &[])
}

/// [`predict`], and the tracks of `kept` (movers already known to move) down to half the speed
/// floor: a truck near the vehicle whose front the airframe hides seems to slow to half its
/// speed as only its back stays in view, and left to the map it would be a photograph. One
/// that stopped is the map's again (a parked car a stale map does not hold, once merged into a
/// track that jumped, would stand predicted by the path for ever).
pub fn predict_keeping(
    tracks: &[TrackState],
    now_s: f64,
    cfg: &TrafficConfig,
    kept: &[u32],
) -> Vec<Prediction> {
    tracks
        .iter()
        .filter(|t| {
            if kept.contains(&t.id) {
                t.velocity.norm() >= 0.5 * cfg.min_speed_m_s
            } else {
                surely_moving(t, cfg)
            }
        })
        .map(|t| {
            let steps = (cfg.horizon_s / 0.5).ceil() as usize;
            let discs = (0..=steps)
                .map(|k| {
                    let dt_s = k as f64 * 0.5;
                    let (slow, fast, sigma) = reach(t, (now_s + dt_s - t.t_s).max(0.0));
                    let f = Footprint::of(t, cfg);
                    PredictedDisc {
                        dt_s,
                        center: nalgebra::center(&slow, &fast),
                        radius_m: f.half_width_m + cfg.sigmas * sigma,
                        half_length_m: f.half_length_m + 0.5 * (fast - slow).norm(),
                        heading_rad: f.along.y.atan2(f.along.x),
                    }
                })
                .collect();
            Prediction {
                track: t.clone(),
                discs,
            }
        })
        .collect()
}

/// Whether the track `t` moves, and surely: faster than `cfg.min_speed_m_s` and than
/// `cfg.sigmas` standard deviations of its speed.
pub fn surely_moving(t: &TrackState, cfg: &TrafficConfig) -> bool {
    let c = &t.covariance;
    let speed_sigma = c[(2, 2)].max(c[(3, 3)]).max(0.0).sqrt();
    t.velocity.norm() >= cfg.min_speed_m_s.max(cfg.sigmas * speed_sigma)
}

/// How near a known mover standing, `t`, the vehicle's circles may not come: its footprint's
/// larger half, `cfg.standing_reach_m` (how far it may walk or drive on without warning) and
/// `cfg.margin_m`, metres from its centre beyond a circle's radius.
fn standing_reach(t: &TrackState, cfg: &TrafficConfig) -> f64 {
    let f = Footprint::of(t, cfg);
    f.half_length_m.max(f.half_width_m) + cfg.standing_reach_m + cfg.margin_m
}

/// Whether any of `poses` comes within [`standing_reach`] of a known mover standing in
/// `standing`, on a level it occupies: the vehicle passes it slowly (the caution speed), as it
/// may step into the path without warning (a person waiting beside the nose walked into the
/// fuselage's side).
pub fn passes_standing(
    model: &CollisionModel,
    poses: &[Isometry2<f64>],
    standing: &[TrackState],
    cfg: &TrafficConfig,
) -> bool {
    standing
        .iter()
        .any(|t| first_within_standing_reach(model, poses, t, cfg).is_some())
}

/// The first of `poses` that comes within [`standing_reach`] of the mover standing `t`, on a
/// level it occupies.
pub fn first_within_standing_reach(
    model: &CollisionModel,
    poses: &[Isometry2<f64>],
    t: &TrackState,
    cfg: &TrafficConfig,
) -> Option<usize> {
    let reach = standing_reach(t, cfg);
    poses
        .iter()
        .position(|pose| touches(model, pose, t.levels, &t.position, &t.position, reach))
}

/// Whether a known mover lost while standing, `t`, may have walked from where it was last seen
/// to the body of the vehicle `model` at `pose` by `now_s`: within its footprint and
/// `walk_m_s` times the time since, of a circle of a level it occupies.
pub fn may_have_walked_to(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    t: &TrackState,
    now_s: f64,
    walk_m_s: f64,
    cfg: &TrafficConfig,
) -> bool {
    let f = Footprint::of(t, cfg);
    let reach = f.half_length_m.max(f.half_width_m) + walk_m_s * (now_s - t.t_s).max(0.0);
    touches(model, pose, t.levels, &t.position, &t.position, reach)
}

/// Whether the tracked mover `t` has moved beyond its own extent plus `cfg.hidden_m` since it
/// was first seen: the centre of a static object's hits stays within its extent, however it is
/// hidden or revealed (a row of parked cars merged into one track can still slide further).
pub fn moved_beyond_its_extent(t: &TrackState, cfg: &TrafficConfig) -> bool {
    t.travel_m > t.extent_m + cfg.hidden_m
}

/// Whether the tracked object `t` is at the body of the vehicle `model` standing at `pose` at
/// `now_s`: the box of its hits when it was last seen, moved to where its motion puts it now
/// (not at all when it was seen now), comes within what of it the sensor may not see
/// (`cfg.hidden_m`, or more: what its box is smaller than the largest extent it was seen with)
/// plus `cfg.at_body_m` of a circle of a level it occupies. Seen or not, moving or not: a mover predicted to walk on through the airframe
/// stopped at it. The box, not the centre of the hits: the centre of a truck whose front
/// touches the nose and whose side comes into view slides away from the nose.
pub fn at_body(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    t: &TrackState,
    now_s: f64,
    cfg: &TrafficConfig,
) -> bool {
    // Where its motion puts the box now (where it was seen, when seen now): checked every plan,
    // a mover walking on out of view cannot step over the body unnoticed.
    let (now_at, _) = t.predict((now_s - t.t_s).max(0.0));
    box_at_body(model, pose, t, &(now_at - t.position), cfg)
}

/// Whether the box of the hits of `t` when last seen, moved by `shift`, is at the body of the
/// vehicle `model` standing at `pose` ([`at_body`]).
fn box_at_body(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    t: &TrackState,
    shift: &Vector2<f64>,
    cfg: &TrafficConfig,
) -> bool {
    let ((x0, y0), (x1, y1)) = t.bbox;
    let r = t.size_m[0] / (x1 - x0 + 1).max(1) as f64;
    let lo = Vector2::new(x0 as f64 * r, y0 as f64 * r);
    let hi = Vector2::new((x1 + 1) as f64 * r, (y1 + 1) as f64 * r);
    // What of it may lie beyond the box: `hidden_m`, or what it is seen smaller than its
    // largest extent (a truck whose front a wing hides).
    let hidden_m = cfg.hidden_m.max(t.extent_m - (hi - lo).norm());
    let (lo, hi) = (lo + shift, hi + shift);
    model.circles().iter().any(|c| {
        let p = pose * Point2::new(c.x_m, c.y_m);
        let out = (lo - p.coords).sup(&(p.coords - hi)).sup(&Vector2::zeros());
        t.levels & (1u32 << c.level.min(31)) != 0
            && out.norm() <= c.radius_m + hidden_m + cfg.at_body_m
    })
}

/// Whether mover `t`, gone out of view, may be at the body of the vehicle standing at `pose`
/// at some time from `now_s` to `until_s`: anywhere along its motion from where its speed now
/// puts it then to where its peak speed would ([`reach`]), sampled every [`SWEEP_STEP_M`]
/// (within what [`box_at_body`] allows around a box). A van going behind a wing was read at
/// two thirds of its speed as its visible part shrank (variant 963 of the random traffic
/// campaign on 308acd2). Along its heading as read only: a cone of 5 degrees either side took
/// the slide of a parked car's visible part, on a stale map, onto the car 35 m away.
pub fn may_reach_body(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    t: &TrackState,
    (now_s, until_s): (f64, f64),
    cfg: &TrafficConfig,
) -> bool {
    let (near, _, _) = reach(t, (now_s - t.t_s).max(0.0));
    let (_, far, _) = reach(t, (until_s - t.t_s).max(0.0));
    let steps = ((far - near).norm() / SWEEP_STEP_M).ceil().max(1.0) as usize;
    (0..=steps).any(|i| {
        let at = near + (far - near) * (i as f64 / steps as f64);
        box_at_body(model, pose, t, &(at - t.position), cfg)
    })
}

/// How far apart [`may_reach_body`] samples, metres.
const SWEEP_STEP_M: f64 = 0.5;

/// A mover's shape as the check uses it.
#[derive(Clone, Copy, Debug)]
struct Footprint {
    /// Unit vector of its motion.
    along: Vector2<f64>,
    half_length_m: f64,
    half_width_m: f64,
}

impl Footprint {
    fn of(t: &TrackState, cfg: &TrafficConfig) -> Self {
        let speed = t.velocity.norm();
        let along = if speed > 1e-9 {
            t.velocity / speed
        } else {
            Vector2::x()
        };
        let [dx, dy] = t.size_m;
        let length = dx * along.x.abs() + dy * along.y.abs();
        let width = dx * along.y.abs() + dy * along.x.abs();
        Footprint {
            along,
            half_length_m: (0.5 * length).max(0.5 * t.extent_m) + cfg.hidden_m,
            half_width_m: 0.5 * width + cfg.hidden_m,
        }
    }
}

/// Where the centre of mover `t` may be `dt_s` after it was last seen, along its motion: from
/// where its velocity now puts it (`slow`) to where it would be at the peak speed it was seen
/// with lately (`fast`; [`TrackState::peak_speed_m_s`]: one that seemed to slow as it went into
/// the shadow of a wing may not have), and the standard deviation of its position then.
fn reach(t: &TrackState, dt_s: f64) -> (Point2<f64>, Point2<f64>, f64) {
    let (slow, sigma) = t.predict(dt_s);
    let speed = t.velocity.norm();
    if speed < 1e-9 {
        return (slow, slow, sigma);
    }
    let faster = (t.peak_speed_m_s - speed).max(0.0);
    (slow, slow + t.velocity / speed * faster * dt_s, sigma)
}

/// The capsule the mover sweeps from `from_s` to `to_s` (absolute times): its axis' ends and
/// its radius.
fn swept(
    t: &TrackState,
    from_s: f64,
    to_s: f64,
    cfg: &TrafficConfig,
) -> (Point2<f64>, Point2<f64>, f64) {
    let f = Footprint::of(t, cfg);
    let (a, _, _) = reach(t, (from_s - t.t_s).max(0.0));
    let (_, b, sigma) = reach(t, (to_s - t.t_s).max(0.0));
    (
        a - f.along * f.half_length_m,
        b + f.along * f.half_length_m,
        f.half_width_m + cfg.sigmas * sigma,
    )
}

/// Whether any circle of `model` at `pose` on a level in `levels` comes within `reach_m` (plus
/// its radius) of the segment `a`-`b`.
fn touches(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    levels: u32,
    a: &Point2<f64>,
    b: &Point2<f64>,
    reach_m: f64,
) -> bool {
    let bound = model.bounding_circle();
    if segment_distance(&(pose * bound.center), a, b) > bound.radius_m + reach_m {
        return false;
    }
    touches_every_circle(model, pose, levels, a, b, reach_m)
}

/// [`touches`] without the bounding circle's early out: every circle of the mover's levels
/// (the straightforward way, the baseline of `taxi-sim bench loop`).
fn touches_every_circle(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    levels: u32,
    a: &Point2<f64>,
    b: &Point2<f64>,
    reach_m: f64,
) -> bool {
    model.circles().iter().any(|c| {
        levels & (1u32 << c.level.min(31)) != 0
            && segment_distance(&(pose * Point2::new(c.x_m, c.y_m)), a, b) <= c.radius_m + reach_m
    })
}

/// The vehicle's path with its timing: what the space-time check checks.
#[derive(Clone, Copy, Debug)]
pub struct TimedPath<'a> {
    /// The poses, `step_m` apart, the first where the vehicle is now.
    pub poses: &'a [Isometry2<f64>],
    /// Their spacing, metres.
    pub step_m: f64,
    /// How the vehicle is expected to move along them.
    pub profile: SpeedProfile,
    /// Now, seconds.
    pub now_s: f64,
    /// The vehicle is already stopped for a mover.
    pub yielding: bool,
}

/// The first conflict on `path` with the movers `predictions`.
pub fn first_conflict(
    path: &TimedPath<'_>,
    model: &CollisionModel,
    predictions: &[Prediction],
    cfg: &TrafficConfig,
) -> Option<Conflict> {
    conflict_with(path, model, predictions, cfg, touches)
}

/// [`first_conflict`] checking every circle at every pose (no bounding-circle early out): the
/// straightforward way, the same answer (`taxi-sim bench loop` times both).
pub fn first_conflict_straightforward(
    path: &TimedPath<'_>,
    model: &CollisionModel,
    predictions: &[Prediction],
    cfg: &TrafficConfig,
) -> Option<Conflict> {
    conflict_with(path, model, predictions, cfg, touches_every_circle)
}

/// How a pose is tested against a swept mover.
type Touches = fn(&CollisionModel, &Isometry2<f64>, u32, &Point2<f64>, &Point2<f64>, f64) -> bool;

fn conflict_with(
    path: &TimedPath<'_>,
    model: &CollisionModel,
    predictions: &[Prediction],
    cfg: &TrafficConfig,
    touches: Touches,
) -> Option<Conflict> {
    let TimedPath {
        poses,
        step_m,
        profile,
        now_s,
        yielding,
    } = *path;
    let after_s = cfg.time_margin_s + if yielding { cfg.resume_margin_s } else { 0.0 };
    let mut best: Option<Conflict> = None;
    for p in predictions {
        let t = &p.track;
        let horizon_end = now_s + cfg.horizon_s;
        for (k, pose) in poses.iter().enumerate() {
            let at_m = k as f64 * step_m;
            if best.is_some_and(|b| b.at_m <= at_m) {
                break;
            }
            let in_s = profile.time_to(at_m);
            let (lo, hi) = (
                now_s + (in_s - cfg.time_margin_s).max(0.0),
                now_s + in_s + after_s,
            );
            if lo > horizon_end {
                break;
            }
            let (a, b, radius) = swept(t, lo, hi.min(horizon_end), cfg);
            if touches(model, pose, t.levels, &a, &b, radius + cfg.margin_m) {
                let zone_m = conflict_zone(path, model, t, k, cfg, touches);
                best = Some(Conflict {
                    track_id: t.id,
                    at_m,
                    zone_m,
                    in_s,
                    mover_at: t.predict((now_s + in_s - t.t_s).max(0.0)).0,
                });
                break;
            }
        }
    }
    best
}

/// Where the vehicle about to stop `stop_at_m` along `path` (it stands `stand_back_m` before
/// that) should stop instead, so that it does not stand where a mover is predicted to pass
/// within the horizon, nor within `cfg.standing_reach_m` of a known mover standing
/// (`standing`: it may walk on into the airframe, as a person waiting beside the nose did):
/// before the first pose such a zone touches, when that lies beyond `stopping_m` (the vehicle
/// can still stop short of it). A stop for one mover, or for an obstacle in the map, must not
/// leave the tail across another's path. `None`: standing there is clear of every mover, or it
/// is too late to stop short.
#[allow(clippy::too_many_arguments)]
pub fn stand_clear(
    path: &TimedPath<'_>,
    model: &CollisionModel,
    predictions: &[Prediction],
    standing: &[TrackState],
    stop_at_m: f64,
    stand_back_m: f64,
    stopping_m: f64,
    cfg: &TrafficConfig,
) -> Option<f64> {
    let last = path.poses.len().checked_sub(1)?;
    // Each zone: its capsule's axis, its reach beyond the circles' radii, its levels.
    let zones: Vec<(Point2<f64>, Point2<f64>, f64, u32)> = predictions
        .iter()
        .map(|p| {
            let (a, b, radius) = swept(&p.track, path.now_s, path.now_s + cfg.horizon_s, cfg);
            (a, b, radius + cfg.margin_m, p.track.levels)
        })
        .chain(standing.iter().map(|t| {
            let reach = standing_reach(t, cfg);
            (t.position, t.position, reach, t.levels)
        }))
        .collect();
    let mut at_m = stop_at_m;
    let mut moved = false;
    // Each earlier line may stand in a third mover's path: at most one step per zone.
    for _ in 0..zones.len() {
        let stand = (((at_m - stand_back_m) / path.step_m).floor().max(0.0) as usize).min(last);
        let earliest = zones
            .iter()
            .filter(|(a, b, reach, levels)| {
                touches(model, &path.poses[stand], *levels, a, b, *reach)
            })
            .map(|(a, b, reach, levels)| {
                path.poses[..=stand]
                    .iter()
                    .position(|pose| touches(model, pose, *levels, a, b, *reach))
                    .unwrap_or(stand) as f64
                    * path.step_m
            })
            .reduce(f64::min);
        match earliest {
            Some(zone_m) if zone_m > stopping_m && zone_m < at_m => {
                at_m = zone_m;
                moved = true;
            }
            _ => break,
        }
    }
    moved.then_some(at_m)
}

/// The first pose (up to `up_to`) that any position the mover is predicted to reach within the
/// horizon touches, as a distance along the path.
fn conflict_zone(
    path: &TimedPath<'_>,
    model: &CollisionModel,
    track: &TrackState,
    up_to: usize,
    cfg: &TrafficConfig,
    touches: Touches,
) -> f64 {
    let (a, b, radius) = swept(track, path.now_s, path.now_s + cfg.horizon_s, cfg);
    path.poses[..up_to]
        .iter()
        .position(|pose| touches(model, pose, track.levels, &a, &b, radius + cfg.margin_m))
        .unwrap_or(up_to) as f64
        * path.step_m
}

#[cfg(test)]
mod tests {
    use super::*;
    use mapper::Circle;
    use nalgebra::Matrix4;

    /// A 10 m vehicle on level 0 (gear, fuselage) with a 1 m circle on level 1 far out left
    /// (a wing tip).
    fn model() -> CollisionModel {
        let mut circles: Vec<Circle> = (0..6)
            .map(|i| Circle {
                x_m: i as f64 * 2.0,
                y_m: 0.0,
                radius_m: 1.0,
                level: 0,
            })
            .collect();
        circles.push(Circle {
            x_m: 4.0,
            y_m: 8.0,
            radius_m: 1.0,
            level: 1,
        });
        CollisionModel::new(circles, vec![0.0, 1.1]).unwrap()
    }

    fn straight(n: usize) -> Vec<Isometry2<f64>> {
        (0..n)
            .map(|k| Isometry2::new(Vector2::new(k as f64 * 0.5, 0.0), 0.0))
            .collect()
    }

    fn mover(x: f64, y: f64, vx: f64, vy: f64, levels: u32) -> TrackState {
        TrackState {
            id: 7,
            t_s: 0.0,
            position: Point2::new(x, y),
            velocity: Vector2::new(vx, vy),
            covariance: Matrix4::from_diagonal(&nalgebra::Vector4::new(0.01, 0.01, 0.01, 0.01)),
            extent_m: 2.0,
            levels,
            open_top_m: None,
            confirmed: true,
            travel_m: 10.0,
            // Its hits: the 1 m cell it stands in.
            bbox: (
                (x.floor() as i64, y.floor() as i64),
                (x.floor() as i64, y.floor() as i64),
            ),
            size_m: [1.0, 1.0],
            peak_speed_m_s: vx.hypot(vy),
        }
    }

    /// `poses` driven at 2 m/s from now.
    fn at_2_m_s(poses: &[Isometry2<f64>]) -> TimedPath<'_> {
        TimedPath {
            poses,
            step_m: 0.5,
            profile: at_speed(2.0),
            now_s: 0.0,
            yielding: false,
        }
    }

    fn at_speed(v: f64) -> SpeedProfile {
        SpeedProfile {
            speed_m_s: v,
            target_m_s: v,
            acceleration_m_s2: 0.5,
        }
    }

    fn check(m: &TrackState, profile: &SpeedProfile, yielding: bool) -> Option<Conflict> {
        let cfg = TrafficConfig::default();
        let p = predict(std::slice::from_ref(m), 0.0, &cfg);
        let poses = straight(121);
        let path = TimedPath {
            poses: &poses,
            step_m: 0.5,
            profile: *profile,
            now_s: 0.0,
            yielding,
        };
        first_conflict(&path, &model(), &p, &cfg)
    }

    /// The vehicle about to stop 20 m ahead (standing 3 m before that: its circles over 17-27
    /// m) for something further on, with a slow mover crossing there from the right: it stops
    /// short of the mover's predicted path when it can, its circles then clear of every
    /// position the mover is predicted to reach; too late to stop short, or the mover far off,
    /// the line stays.
    #[test]
    fn a_stop_is_moved_short_of_another_movers_path() {
        let cfg = TrafficConfig::default();
        let poses = straight(121);
        let path = at_2_m_s(&poses);
        let clear = |m: &TrackState, stopping_m: f64| {
            let p = predict(std::slice::from_ref(m), 0.0, &cfg);
            stand_clear(&path, &model(), &p, &[], 20.0, 3.0, stopping_m, &cfg)
        };
        let truck = mover(22.0, -9.0, 0.0, 1.1, 0b11);
        let at = clear(&truck, 2.0).expect("moved short of the truck's path");
        assert!(at > 2.0 && at < 17.0, "{at}");
        // Standing there (3 m before the line), no circle meets the truck's 8-s sweep; half a
        // metre further on, one does (the line is the zone's start, not earlier).
        let (a, b, r) = swept(&truck, 0.0, cfg.horizon_s, &cfg);
        let touches_at = |x: f64| {
            let pose = Isometry2::new(Vector2::new(x, 0.0), 0.0);
            touches(&model(), &pose, truck.levels, &a, &b, r + cfg.margin_m)
        };
        assert!(!touches_at(at - 3.0));
        assert!(touches_at(at));
        // Too late to stop short of it: the line stays (driving on is the avoider's call).
        assert_eq!(clear(&truck, at + 0.5), None);
        // A mover predicted to stay 30 m off: standing at the line is clear.
        assert_eq!(clear(&mover(22.0, -40.0, 0.0, 1.1, 0b11), 2.0), None);
    }

    /// A known mover standing - a person waiting by the taxiway - may walk on without warning:
    /// the path passing within `standing_reach_m` (3 m) beyond its footprint (2 m from its
    /// centre here) and the margin (0.5 m) of a circle on a level it occupies slows the vehicle,
    /// and a stop is moved short of that reach while the vehicle can still stop short of it.
    #[test]
    fn a_mover_standing_is_kept_at_its_reach() {
        let cfg = TrafficConfig::default();
        let poses = straight(121);
        let passes = |t: TrackState| passes_standing(&model(), &poses, &[t], &cfg);
        // The body's circles (radius 1) along y = 0: 6.5 m from the centre reaches them.
        assert!(passes(mover(30.0, -6.0, 0.0, 0.0, 0b01)));
        assert!(!passes(mover(30.0, -7.0, 0.0, 0.0, 0b01)));
        // 7.5 m left, under the wing tip's circle (y = 8, level 1): a cart on the ground level
        // is clear of the body, a person (both levels) is not.
        assert!(!passes(mover(30.0, 7.5, 0.0, 0.0, 0b01)));
        assert!(passes(mover(30.0, 7.5, 0.0, 0.0, 0b11)));
        // Walking, it is predicted instead.
        assert!(surely_moving(&mover(30.0, -6.0, 0.0, 1.4, 0b11), &cfg));
        assert!(!surely_moving(&mover(30.0, -6.0, 0.0, 0.1, 0b11), &cfg));

        // About to stop 40 m ahead (standing 3 m back, its circles over 37-47 m) beside a
        // person 5 m right at 44 m: the front circle (x + 10) first comes within 6.5 m of them
        // at 44 - (6.5^2 - 5^2)^0.5 = 39.85 m, so the vehicle stops with its origin at 30 m.
        let path = at_2_m_s(&poses);
        let person = [mover(44.0, -5.0, 0.0, 0.0, 0b11)];
        let clear = |stopping_m: f64| {
            stand_clear(&path, &model(), &[], &person, 40.0, 3.0, stopping_m, &cfg)
        };
        assert_eq!(clear(5.0), Some(30.0));
        // Too late to stop short of the reach: the line stays.
        assert_eq!(clear(31.0), None);
    }

    #[test]
    fn the_profile_accelerates_then_holds() {
        let p = SpeedProfile {
            speed_m_s: 0.0,
            target_m_s: 2.0,
            acceleration_m_s2: 0.5,
        };
        // 4 s to reach 2 m/s over 4 m, then 2 m/s.
        assert!((p.time_to(4.0) - 4.0).abs() < 1e-9);
        assert!((p.time_to(1.0) - 2.0).abs() < 1e-9);
        assert!((p.time_to(10.0) - 7.0).abs() < 1e-9);
        assert_eq!(at_speed(0.0).time_to(1.0), f64::INFINITY);
    }

    /// A van crossing from the right at 3 m/s, timed to be on the path 30 m ahead when the
    /// vehicle (5 m/s) gets there in 6 s: a conflict, and the zone starts before it.
    #[test]
    fn a_mover_timed_to_meet_the_vehicle_is_a_conflict() {
        let van = mover(30.0, -18.0, 0.0, 3.0, 1);
        let c = check(&van, &at_speed(5.0), false).expect("a conflict");
        assert_eq!(c.track_id, 7);
        // The nose (x = 10 m ahead of the origin plus 1 m) meets the van's disc (2 m + 0.5 m
        // margin + 2 sigma) when the van, at 3 m/s, is there: a few metres before 30 - 11.
        assert!(c.at_m > 10.0 && c.at_m < 19.5, "{c:?}");
        assert!(c.zone_m <= c.at_m, "{c:?}");
    }

    /// The same van, 10 s early (gone by the time the vehicle arrives) or 10 s late (the vehicle
    /// long past), is no conflict; one far off the path's stretch is none either.
    #[test]
    fn a_mover_passing_before_or_after_the_vehicle_does_not_stop_it() {
        assert_eq!(
            check(&mover(30.0, 12.0, 0.0, 3.0, 1), &at_speed(5.0), false),
            None
        );
        assert_eq!(
            check(&mover(30.0, -48.0, 0.0, 3.0, 1), &at_speed(5.0), false),
            None
        );
        assert_eq!(
            check(&mover(30.0, -30.0, 3.0, 0.0, 1), &at_speed(5.0), false),
            None
        );
    }

    /// A baggage cart (level 0 only) crossing under the wing tip's path clears the wing; a
    /// fuel truck (levels 0 and 1) on the same path does not.
    #[test]
    fn a_mover_under_a_wing_level_passes_under_it() {
        // The wing tip sweeps y = 8 +- 1; the fuselage y = 0 +- 1. A mover moving along x at
        // y = 8, level 0 only: only the wing tip's level could touch it.
        let cart = mover(40.0, 8.0, -2.0, 0.0, 0b01);
        assert_eq!(check(&cart, &at_speed(5.0), false), None);
        let truck = mover(40.0, 8.0, -2.0, 0.0, 0b11);
        assert!(check(&truck, &at_speed(5.0), false).is_some());
    }

    /// A standing vehicle yields to a mover about to cross in front of it, and drives on once
    /// it has passed: the margin after grows while yielding.
    #[test]
    fn a_yielding_vehicle_waits_for_the_mover_to_pass() {
        let still = SpeedProfile {
            speed_m_s: 0.0,
            target_m_s: 5.0,
            acceleration_m_s2: 0.5,
        };
        // 20 m ahead, crossing from the right, 3 s away from the path.
        assert!(check(&mover(20.0, -9.0, 0.0, 3.0, 1), &still, true).is_some());
        // Past the path by 12 m: clear.
        assert_eq!(check(&mover(20.0, 12.0, 0.0, 3.0, 1), &still, true), None);
    }

    /// A mover beside the fuselage, seen there or predicted there while out of view, is at the
    /// body; one 3 m off it, or on a level the near circles do not occupy, is not.
    #[test]
    fn a_mover_at_the_body_is_found_seen_or_predicted() {
        let cfg = TrafficConfig::default();
        let pose = Isometry2::identity();
        // The fuselage's circles: y = 0 +- 1 on level 0, x 0..10.
        let beside = mover(4.0, 1.8, 0.0, 0.0, 0b01);
        assert!(at_body(&model(), &pose, &beside, 0.0, &cfg));
        let off = mover(4.0, 5.0, 0.0, 0.0, 0b01);
        assert!(!at_body(&model(), &pose, &off, 0.0, &cfg));
        // Only the wing tip's level (1) there: the fuselage's level-0 circles do not count.
        let high = mover(4.0, 1.8, 0.0, 0.0, 0b10);
        assert!(!at_body(&model(), &pose, &high, 0.0, &cfg));
        // Last seen 5 m off walking towards it at 1.4 m/s: 3 s later its motion puts it there,
        // 10 s later through and 8 m beyond (the plans between found it at the body).
        let walking = mover(4.0, -6.0, 0.0, 1.4, 0b01);
        assert!(!at_body(&model(), &pose, &walking, 0.0, &cfg));
        assert!(at_body(&model(), &pose, &walking, 3.0, &cfg));
        assert!(!at_body(&model(), &pose, &walking, 10.0, &cfg));
        // A 9 m truck seen as its last metre 5 m off: its hidden front may touch the body.
        let hidden_front = TrackState {
            extent_m: 9.0,
            travel_m: 40.0,
            ..mover(4.0, 5.0, 0.0, 0.0, 0b01)
        };
        assert!(at_body(&model(), &pose, &hidden_front, 0.0, &cfg));
        // Never moved beyond its extent (plus what it may hide): perhaps a static object.
        assert!(moved_beyond_its_extent(&beside, &cfg));
        let sliding = TrackState {
            travel_m: 2.5,
            ..beside.clone()
        };
        assert!(!moved_beyond_its_extent(&sliding, &cfg));
    }

    /// A mover lost 24 m off walking toward the fuselage, read at 2 m/s with a peak of 4 m/s:
    /// from 6 s to 8 s after it was last seen it may be at the body at its peak (24-32 m on), not
    /// at its read speed alone (12-16 m on: its box still 4 m short of touching); one read
    /// moving away, or along the fuselage's axis, may not.
    #[test]
    fn a_lost_mover_may_reach_the_body_at_its_peak_speed() {
        let cfg = TrafficConfig::default();
        let pose = Isometry2::identity();
        let window = (6.0, 8.0);
        let toward = TrackState {
            peak_speed_m_s: 4.0,
            ..mover(4.0, -24.0, 0.0, 2.0, 0b01)
        };
        assert!(may_reach_body(&model(), &pose, &toward, window, &cfg));
        let read_speed = TrackState {
            peak_speed_m_s: 2.0,
            ..toward.clone()
        };
        assert!(!may_reach_body(&model(), &pose, &read_speed, window, &cfg));
        // At its read speed it is there 10 s after it was last seen.
        assert!(may_reach_body(
            &model(),
            &pose,
            &read_speed,
            (9.0, 11.0),
            &cfg
        ));
        let away = TrackState {
            velocity: Vector2::new(0.0, -2.0),
            ..toward.clone()
        };
        assert!(!may_reach_body(&model(), &pose, &away, window, &cfg));
        let alongside = TrackState {
            velocity: Vector2::new(2.0, 0.0),
            ..toward.clone()
        };
        assert!(!may_reach_body(&model(), &pose, &alongside, window, &cfg));
    }

    /// A slow mover is left to the map.
    #[test]
    fn a_standing_mover_is_not_predicted() {
        let cfg = TrafficConfig::default();
        assert!(predict(&[mover(5.0, 0.0, 0.1, 0.0, 1)], 0.0, &cfg).is_empty());
        assert_eq!(predict(&[mover(5.0, 0.0, 1.0, 0.0, 1)], 0.0, &cfg).len(), 1);
    }

    /// A mover known to move stays predicted down to half the speed floor (a truck whose front
    /// the airframe hides seems to slow to half its speed); an unknown one that slow does not.
    #[test]
    fn a_known_mover_that_seems_to_slow_stays_predicted() {
        let cfg = TrafficConfig::default();
        let slow = mover(5.0, 0.0, 0.0, -0.6, 1);
        assert!(predict_keeping(std::slice::from_ref(&slow), 0.0, &cfg, &[8]).is_empty());
        let p = predict_keeping(std::slice::from_ref(&slow), 0.0, &cfg, &[7]);
        assert_eq!(p.len(), 1);
        assert!(
            (p[0].discs[4].center.y - -1.2).abs() < 1e-9,
            "{:?}",
            p[0].discs[4]
        );
        // Stopped (under half the floor): the map's again.
        let stopped = mover(5.0, 0.0, 0.0, -0.3, 1);
        assert!(predict_keeping(std::slice::from_ref(&stopped), 0.0, &cfg, &[7]).is_empty());
    }

    /// A van last seen at 1.5 m/s, having been seen at 4.5 m/s: its predicted footprint reaches
    /// from where its speed now puts it to where the peak would; with no peak above its speed,
    /// the footprint is where its speed puts it.
    #[test]
    fn a_movers_footprint_stretches_to_where_its_peak_speed_would_take_it() {
        let cfg = TrafficConfig::default();
        let van = TrackState {
            peak_speed_m_s: 4.5,
            ..mover(0.0, 20.0, 0.0, -1.5, 1)
        };
        let p = &predict(std::slice::from_ref(&van), 0.0, &cfg)[0];
        let d = p.discs.iter().find(|d| d.dt_s == 4.0).unwrap();
        let f = Footprint::of(&van, &cfg);
        // 4 s on: 6 m (its speed) to 18 m (its peak) towards -y.
        assert!((d.center.y - 8.0).abs() < 1e-9, "{d:?}");
        assert!(
            (d.half_length_m - (f.half_length_m + 6.0)).abs() < 1e-9,
            "{d:?}"
        );
        let (_, b, _) = swept(&van, 0.0, 4.0, &cfg);
        assert!((b.y - (2.0 - f.half_length_m)).abs() < 1e-9, "{b:?}");
        let steady = mover(0.0, 20.0, 0.0, -1.5, 1);
        let p = &predict(std::slice::from_ref(&steady), 0.0, &cfg)[0];
        let d = p.discs.iter().find(|d| d.dt_s == 4.0).unwrap();
        assert!(
            (d.center.y - 14.0).abs() < 1e-9 && (d.half_length_m - f.half_length_m).abs() < 1e-9
        );
    }
}
