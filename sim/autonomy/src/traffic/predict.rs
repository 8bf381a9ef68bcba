//! Prediction: each mover's footprint over the horizon, a capsule along its motion swept from
//! where its speed now puts it to where its peak speed would; which tracks are predicted.

use mapper::TrackState;
use nalgebra::{Point2, Vector2};

use super::{PredictedDisc, Prediction, TrafficConfig};

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

/// Whether the tracked mover `t` has moved beyond its own extent plus `cfg.hidden_m` since it
/// was first seen: the centre of a static object's hits stays within its extent, however it is
/// hidden or revealed (a row of parked cars merged into one track can still slide further).
pub fn moved_beyond_its_extent(t: &TrackState, cfg: &TrafficConfig) -> bool {
    t.travel_m > t.extent_m + cfg.hidden_m
}

/// Whether the tracked mover `t` came where it is: travelled more than twice its extent and
/// 3 m since first seen (any size: a person, a van). A parked car the offline map does not hold,
/// whose visible part slides as the vehicle drives by, seems to travel a few metres only
/// (`parking_lot_on_a_stale_map_movers_predicted`).
pub fn came_there(t: &TrackState) -> bool {
    t.travel_m > 2.0 * t.extent_m + 3.0
}

/// A mover's shape as the check uses it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Footprint {
    /// Unit vector of its motion.
    pub(super) along: Vector2<f64>,
    /// Half its length along its motion, hidden part included, metres.
    pub(super) half_length_m: f64,
    /// Half its width across its motion, hidden part included, metres.
    pub(super) half_width_m: f64,
}

impl Footprint {
    /// The footprint of `t`.
    pub(super) fn of(t: &TrackState, cfg: &TrafficConfig) -> Self {
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
pub(crate) fn reach(t: &TrackState, dt_s: f64) -> (Point2<f64>, Point2<f64>, f64) {
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
pub(super) fn swept(
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
