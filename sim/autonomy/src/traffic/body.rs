//! Movers at the vehicle's body: where the map cannot hold them (returns within its self-hit
//! margin are dropped as the vehicle's own), seen, predicted, or lost there.

use mapper::{CollisionModel, TrackState};
use nalgebra::{Isometry2, Point2, Vector2};

use super::TrafficConfig;
use super::conflict::touches;
use super::predict::{Footprint, reach};
use super::rules::HitBox;

/// Whether a known mover lost while standing, `t`, may have walked from where it was last seen
/// to the body of the vehicle `model` at `pose` by `now_s`: within its footprint and
/// `walk_m_s` times the time since, no more than `walk_max_m`, of a circle of a level it
/// occupies.
pub fn may_have_walked_to(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    t: &TrackState,
    now_s: f64,
    (walk_m_s, walk_max_m): (f64, f64),
    cfg: &TrafficConfig,
) -> bool {
    let f = Footprint::of(t, cfg);
    let walked_m = (walk_m_s * (now_s - t.t_s).max(0.0)).min(walk_max_m);
    let reach = f.half_length_m.max(f.half_width_m) + walked_m;
    touches(model, pose, t.levels, &t.position, &t.position, reach)
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
    let (lo, hi) = hit_box(t);
    // What of it may lie beyond the box: `hidden_m`, or what it is seen smaller than its
    // largest extent (a truck whose front a wing hides).
    let hidden_m = cfg.hidden_m.max(t.extent_m - (hi - lo).norm());
    box_gap_m(model, pose, t, shift) <= hidden_m + cfg.at_body_m
}

/// How far the box of the hits of `t` when last seen, moved by `shift`, lies from the body of
/// the vehicle `model` at `pose`: from the nearest circle of a level it occupies, metres
/// (negative within one; infinite when it occupies none of the model's levels).
pub(super) fn box_gap_m(
    model: &CollisionModel,
    pose: &Isometry2<f64>,
    t: &TrackState,
    shift: &Vector2<f64>,
) -> f64 {
    let (lo, hi) = hit_box(t);
    let (lo, hi) = (lo + shift, hi + shift);
    (model.circles().iter())
        .filter(|c| t.levels & (1u32 << c.level.min(31)) != 0)
        .map(|c| {
            let p = pose * Point2::new(c.x_m, c.y_m);
            let out = (lo - p.coords).sup(&(p.coords - hi)).sup(&Vector2::zeros());
            out.norm() - c.radius_m
        })
        .fold(f64::INFINITY, f64::min)
}

/// The corners of the box of the hits of `t` when last seen, metres.
pub(super) fn hit_box(t: &TrackState) -> HitBox {
    let ((x0, y0), (x1, y1)) = t.bbox;
    let r = cell_m(t);
    let lo = Vector2::new(x0 as f64 * r, y0 as f64 * r);
    let hi = Vector2::new((x1 + 1) as f64 * r, (y1 + 1) as f64 * r);
    (lo, hi)
}

/// The side of the map cells the box of `t` is counted in, metres.
pub(super) fn cell_m(t: &TrackState) -> f64 {
    let ((x0, _), (x1, _)) = t.bbox;
    t.size_m[0] / (x1 - x0 + 1).max(1) as f64
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
