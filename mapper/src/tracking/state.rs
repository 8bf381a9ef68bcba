//! What the tracker offers of its tracks: [`TrackState`] (for prediction), [`MovingObject`],
//! and which tracks are movers or candidate movers.

use nalgebra::{Matrix4, Point2, Vector2};

use super::Tracker;
use super::track::Track;
use crate::map::WorldCell;

/// A moving object as the tracker sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingObject {
    /// Track id.
    pub id: u32,
    /// Centre of its hits, metres.
    pub position: Point2<f64>,
    /// Distance travelled since first seen, metres.
    pub travel_m: f64,
}

/// A tracked object's state: what [`Tracker::movers`], [`Tracker::candidate_movers`] and
/// [`Tracker::standing_objects`] give.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackState {
    /// Track id.
    pub id: u32,
    /// When it was last seen, seconds.
    pub t_s: f64,
    /// Where the filter puts the centre of its hits at `t_s`, metres.
    pub position: Point2<f64>,
    /// Its velocity, m/s.
    pub velocity: Vector2<f64>,
    /// Covariance of `[x, y, vx, vy]`.
    pub covariance: Matrix4<f64>,
    /// Largest extent (bounding-box diagonal) it was seen with, metres: every part of the
    /// object lies within this of the centre of its hits.
    pub extent_m: f64,
    /// The levels it was hit in (bit `l`: level `l`): the height span of the object.
    pub levels: u32,
    /// How high above the ground it may reach where the sensor has not seen it, metres: the
    /// lowest height at which a revolution's beams passed over all of it they hit (infinity:
    /// never all; `None`: no revolution told, as with [`Tracker::update_with_levels`]). A
    /// nose sensor 1.55 m up sees a 1.5 m van's side only below 1.1 m from 19 m out.
    pub open_top_m: Option<f64>,
    /// Confirmed moving by the stricter rule that lets it clear what it left.
    pub confirmed: bool,
    /// How far its centre is from where it was first seen, metres: beyond its extent, it moved
    /// (the centre of a static object's hits stays within its extent however it is hidden).
    pub travel_m: f64,
    /// The bounding box of its hits this revolution (world cells, lower and upper corners).
    pub bbox: (WorldCell, WorldCell),
    /// That box's size along x and y, metres.
    pub size_m: [f64; 2],
    /// The fastest its velocity was over about the last [`PEAK_SPEED_S`](super::PEAK_SPEED_S)
    /// seconds it was seen moving steadily, going the way it goes now (within
    /// [`PEAK_HEADING_RAD`](super::PEAK_HEADING_RAD); at least its speed now), m/s: a mover going into the shadow of a
    /// wing seems to slow as its visible part shrinks, and is lost at that lower speed. Not a
    /// speed it had going another way: a train's cars bunching up as it stops seem to push
    /// its centre back, and it would be read as about to come back at its cruising speed.
    pub peak_speed_m_s: f64,
    /// When the tracker first saw it under this id, seconds.
    pub born_s: f64,
    /// Where it was then (the centre of its hits), metres.
    pub origin: Point2<f64>,
}

impl TrackState {
    /// The centre predicted `dt_s` after `t_s` at constant velocity, and the standard deviation
    /// of its position then (the larger axis), metres.
    pub fn predict(&self, dt_s: f64) -> (Point2<f64>, f64) {
        let at = self.position + self.velocity * dt_s;
        let c = &self.covariance;
        let var =
            |i: usize| c[(i, i)] + 2.0 * dt_s * c[(i, i + 2)] + dt_s * dt_s * c[(i + 2, i + 2)];
        (at, var(0).max(var(1)).max(0.0).sqrt())
    }
}

impl Tracker {
    /// Marks the tracks seen this revolution whose motion can be predicted: seen steadily for
    /// `predict_after_revolutions`, no larger than `max_object_m`, and travelled more than
    /// `predict_extent_factor` times their extent (at least `predict_min_travel_m`) - or
    /// confirmed moving. A track seen again after a step its motion did not explain starts
    /// over.
    pub(super) fn mark_predictable(&mut self) {
        let low_below_m = self.low_below_m();
        let cfg = &self.config;
        for t in &mut self.tracks {
            if t.bbox.is_none() {
                continue;
            }
            let travel = t.travel_m(low_below_m);
            t.predictable = t.moving
                || (t.steady >= cfg.predict_after_revolutions
                    && t.max_extent_m <= cfg.max_object_m
                    && travel
                        >= cfg
                            .predict_min_travel_m
                            .max(cfg.predict_extent_factor * t.max_extent_m));
        }
    }

    /// The tracks whose motion can be predicted (see `mark_predictable`): those seen this
    /// revolution, and those out of view for up to `coast_s` (from where they were last seen:
    /// a hidden mover is not gone). Their velocity may be small: a mover that stopped stays one.
    pub fn movers(&self) -> Vec<TrackState> {
        self.tracks
            .iter()
            .filter(|t| t.predictable)
            .map(|t| self.state(t))
            .collect()
    }

    /// The tracks seen this revolution that may be moving but are not yet predictable: seen
    /// steadily for `predict_after_revolutions`, no larger than `max_object_m`, their centre
    /// `predict_min_travel_m` from where it was first seen - not yet beyond what hiding or
    /// revealing a static object's parts explains. A long truck crossing slowly along its own
    /// length takes seconds to get there; what may move is worth slowing for meanwhile.
    pub fn candidate_movers(&self) -> Vec<TrackState> {
        self.steady_unpredictable(self.config.max_object_m, true)
    }

    /// The tracks seen this revolution, steadily for `predict_after_revolutions`, no larger
    /// than `max_extent_m`, that are neither predictable nor candidate movers: small objects
    /// standing - with an offline map, ones it does not hold (a person waiting beside the
    /// path, a cone left out). Nothing says they will not walk on.
    pub fn standing_objects(&self, max_extent_m: f64) -> Vec<TrackState> {
        self.steady_unpredictable(max_extent_m, false)
    }

    /// The tracks seen this revolution, steadily for `predict_after_revolutions`, no larger
    /// than `max_extent_m`, not predictable, whose centre is (`travelled`) or is not yet
    /// `predict_min_travel_m` from where it was first seen, over the ground (a low object
    /// keeping pace with the vehicle is one to be cautious of: `Track::travel_m`).
    fn steady_unpredictable(&self, max_extent_m: f64, travelled: bool) -> Vec<TrackState> {
        let cfg = &self.config;
        self.tracks
            .iter()
            .filter(|t| {
                !t.predictable
                    && t.bbox.is_some()
                    && t.steady >= cfg.predict_after_revolutions
                    && t.max_extent_m <= max_extent_m
                    && (t.ground_travel_m() >= cfg.predict_min_travel_m) == travelled
            })
            .map(|t| self.state(t))
            .collect()
    }

    fn state(&self, t: &Track) -> TrackState {
        let bbox = t.last_bbox;
        TrackState {
            bbox,
            size_m: [
                (bbox.1.0 - bbox.0.0 + 1) as f64 * self.resolution_m,
                (bbox.1.1 - bbox.0.1 + 1) as f64 * self.resolution_m,
            ],
            id: t.id,
            t_s: t.last_t_s,
            position: Point2::new(t.motion.x[0], t.motion.x[1]),
            velocity: t.motion.velocity(),
            covariance: t.motion.p,
            extent_m: t.max_extent_m,
            levels: t.levels,
            open_top_m: t.open_top_m.map(f64::from),
            confirmed: t.moving,
            travel_m: (t.last - t.origin).norm(),
            born_s: t.born_s,
            origin: t.origin,
            peak_speed_m_s: peak_speed_m_s(t.motion.velocity(), &t.recent_velocities),
        }
    }
}

/// The fastest of `recent` velocities within [`PEAK_HEADING_RAD`](super::PEAK_HEADING_RAD) of `now`, and at least
/// `now`'s speed, m/s.
fn peak_speed_m_s(
    now: Vector2<f64>,
    recent: &std::collections::VecDeque<(f64, Vector2<f64>)>,
) -> f64 {
    (recent.iter())
        .filter(|(_, v)| {
            now.norm() > 0.0 && v.norm() > 0.0 && v.angle(&now) <= super::PEAK_HEADING_RAD
        })
        .map(|(_, v)| v.norm())
        .fold(now.norm(), f64::max)
}
