//! The space-time check: the vehicle's path, timed, against the movers' swept footprints; where
//! a stopping vehicle stands clear of their paths and of movers standing.

use aircraft::footprint::segment_distance;
use mapper::{CollisionModel, TrackState};
use nalgebra::{Isometry2, Point2};

use super::predict::{Footprint, came_there, swept};
use super::{Conflict, Prediction, TimedPath, TrafficConfig};

/// How near a known mover standing, `t`, the vehicle's circles may not come: its footprint's
/// larger half, `cfg.standing_reach_m` (how far it may walk or drive on without warning) and
/// `cfg.margin_m`, metres from its centre beyond a circle's radius.
pub(super) fn standing_reach(t: &TrackState, cfg: &TrafficConfig) -> f64 {
    reach_of(t, cfg.standing_reach_m, cfg)
}

/// Its footprint's larger half, `reach_m` and `cfg.margin_m`: how near `t` the vehicle's
/// circles may come, metres from its centre beyond a circle's radius.
pub(super) fn reach_of(t: &TrackState, reach_m: f64, cfg: &TrafficConfig) -> f64 {
    let f = Footprint::of(t, cfg);
    f.half_length_m.max(f.half_width_m) + reach_m + cfg.margin_m
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
    first_within(model, poses, t, standing_reach(t, cfg))
}

/// The first of `poses` whose circles, on a level `t` occupies, come within `reach_m` of its
/// centre beyond their radii.
pub(super) fn first_within(
    model: &CollisionModel,
    poses: &[Isometry2<f64>],
    t: &TrackState,
    reach_m: f64,
) -> Option<usize> {
    poses
        .iter()
        .position(|pose| touches(model, pose, t.levels, &t.position, &t.position, reach_m))
}

/// Whether any circle of `model` at `pose` on a level in `levels` comes within `reach_m` (plus
/// its radius) of the segment `a`-`b`.
pub(super) fn touches(
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

/// Where a mover may be, for [`stand_clear`]: a capsule.
struct Zone {
    /// Its axis's ends, metres.
    axis: (Point2<f64>, Point2<f64>),
    /// Its reach beyond the circles' radii, metres.
    reach_m: f64,
    /// The levels it occupies.
    levels: u32,
    /// A predicted mover's sweep over the horizon.
    predicted: bool,
    /// The reach of a standing mover that came where it stands ([`came_there`]), not a
    /// predicted one's sweep nor a static object's sliding parts.
    came_there: bool,
}

impl Zone {
    /// Whether the circles of `model` at `pose` on its levels come within its reach.
    fn touches(&self, model: &CollisionModel, pose: &Isometry2<f64>) -> bool {
        let (a, b) = &self.axis;
        touches(model, pose, self.levels, a, b, self.reach_m)
    }
}

/// Where the vehicle about to stop `stop_at_m` along `path` (it stands `stand_back_m` before
/// that) should stop instead, so that it does not stand where a mover is predicted to pass
/// within the horizon, nor within `cfg.standing_reach_m` of a known mover standing
/// (`standing`: it may walk on into the airframe, as a person waiting beside the nose did):
/// before the first pose such a zone touches, when that lies beyond `stopping_m` (the vehicle
/// can still stop short of it). A stop for one mover, or for an obstacle in the map, must not
/// leave the tail across another's path. Too late to stop short of the reach of a standing
/// mover that came there ([`came_there`]), it stops as short as it can (`stopping_m`, when that
/// is over a pose step short of the stop and not in a predicted mover's sweep), not deeper
/// within the reach: a van standing at the path's edge may drive on into the nose going by
/// (`tests/found/van_stopping_at_the_edge_goes_on_into_the_nose.toml`). Standing, that is where
/// it stands (the stop buffer): it does not creep on within the reach. `None`: standing there
/// is clear of every mover, or it is too late to stop short of a predicted one.
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
    let stop = StandStop {
        stop_at_m,
        stand_back_m,
        stopping_m,
    };
    stand_clear_why(path, model, predictions, standing, stop, cfg).map(|(at_m, _)| at_m)
}

/// Where the vehicle is about to stop, for [`stand_clear_why`].
#[derive(Clone, Copy, Debug)]
pub struct StandStop {
    /// The stop, ahead along the path.
    pub stop_at_m: f64,
    /// How far before its stop the vehicle stands.
    pub stand_back_m: f64,
    /// Its stopping distance.
    pub stopping_m: f64,
}

/// [`stand_clear`], and whether the place is the stopping distance, taken because it is too
/// late to stop short of a standing mover's reach (`true`) - a place that moves on with the
/// vehicle if taken afresh each plan - rather than the start of a mover's zone.
pub fn stand_clear_why(
    path: &TimedPath<'_>,
    model: &CollisionModel,
    predictions: &[Prediction],
    standing: &[TrackState],
    stop: StandStop,
    cfg: &TrafficConfig,
) -> Option<(f64, bool)> {
    let StandStop {
        stop_at_m,
        stand_back_m,
        stopping_m,
    } = stop;
    let last = path.poses.len().checked_sub(1)?;
    let zones: Vec<Zone> = predictions
        .iter()
        .map(|p| {
            let (a, b, radius) = swept(&p.track, path.now_s, path.now_s + cfg.horizon_s, cfg);
            Zone {
                axis: (a, b),
                reach_m: radius + cfg.margin_m,
                levels: p.track.levels,
                predicted: true,
                came_there: false,
            }
        })
        .chain(standing.iter().map(|t| Zone {
            axis: (t.position, t.position),
            reach_m: standing_reach(t, cfg),
            levels: t.levels,
            predicted: false,
            came_there: came_there(t),
        }))
        .collect();
    // The pose the vehicle stands at, stopping `at_m` ahead.
    let stand_at =
        |at_m: f64| (((at_m - stand_back_m) / path.step_m).floor().max(0.0) as usize).min(last);
    let in_a_sweep = |at_m: f64| {
        let pose = &path.poses[stand_at(at_m)];
        zones.iter().any(|z| z.predicted && z.touches(model, pose))
    };
    let mut at_m = stop_at_m;
    let mut moved = false;
    let mut too_late = false;
    // Each earlier line may stand in a third mover's path: at most one step per zone.
    for _ in 0..zones.len() {
        let stand = stand_at(at_m);
        let earliest = zones
            .iter()
            .filter(|z| z.touches(model, &path.poses[stand]))
            .map(|z| {
                let zone_m = path.poses[..=stand]
                    .iter()
                    .position(|pose| z.touches(model, pose))
                    .unwrap_or(stand) as f64
                    * path.step_m;
                (zone_m, z.came_there)
            })
            // The earliest; of two as early, the one of a mover that came there.
            .reduce(|a, b| if (b.0, !b.1) < (a.0, !a.1) { b } else { a });
        match earliest {
            Some((zone_m, _)) if zone_m > stopping_m && zone_m < at_m => {
                (at_m, too_late) = (zone_m, false)
            }
            Some((_, true)) if stopping_m < at_m - path.step_m && !in_a_sweep(stopping_m) => {
                (at_m, too_late) = (stopping_m, true)
            }
            _ => break,
        }
        moved = true;
    }
    moved.then_some((at_m, too_late))
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
