//! The rules about movers, with the memory they keep from plan to plan: [`TrafficRules`] takes
//! one plan's inputs ([`MoverInputs`]: the chosen path, the tracker's movers, the vehicle's
//! speed) and gives one decision ([`MoverDecision`]: the speed cap, where to stop, and why).
//!
//! In the order [`TrafficRules::decide`] applies them:
//! 1. caution ([`speed_cap`](super::speed_cap)): a candidate mover's motion meeting the path,
//!    or a known mover standing near it, caps the speed; so does a map obstacle closing on the
//!    vehicle ([`closing`](super::closing)), whose stop is moved short of where it will be;
//! 2. the space-time check against the predicted movers (here): the conflict, dropped when the
//!    vehicle is too close to stop short and clears the mover with the committed margin;
//! 3. the stop lines ([`holds`](super::holds)): the hold line for the conflict, short of the
//!    caution line, clear of other movers' paths, short of a person standing;
//! 4. the body hold ([`memory`](super::memory)): a mover at the body, or lost there, or a
//!    known mover standing within its reach of a standing vehicle: the vehicle does not move.

use mapper::{CollisionModel, TrackState};
use nalgebra::{Isometry2, Point2, Vector2};
use serde::Serialize;

use super::closing::Closing;
use super::predict::predict_keeping;
use super::{Conflict, Prediction, SpeedProfile, TimedPath, TrafficConfig, first_conflict};

/// What the rules decide from at one plan.
#[derive(Clone, Copy, Debug)]
pub struct MoverInputs<'a> {
    /// The chosen candidate's poses, `step_m` apart, the first where the vehicle is.
    pub poses: &'a [Isometry2<f64>],
    /// The route progress of the estimate, metres.
    pub s_m: f64,
    /// Where the plan stops for the map's obstacles, metres ahead (the chosen candidate's
    /// first collision; `None`: nothing in the map stops it).
    pub stop_at_m: Option<f64>,
    /// The tracker's movers.
    pub movers: &'a [TrackState],
    /// The tracker's candidate movers (seen to travel, not yet predictable).
    pub candidates: &'a [TrackState],
    /// The small objects the tracker has seen only standing
    /// (`crate::OnlineMap::standing_objects`).
    pub standing: &'a [TrackState],
    /// The speed the vehicle wants before the movers are counted, m/s.
    pub wanted_m_s: f64,
    /// The vehicle's estimated pose.
    pub pose: Isometry2<f64>,
    /// Now (the estimate's time), seconds.
    pub now_s: f64,
    /// The vehicle's speed now (odometry, not below zero), m/s.
    pub speed_m_s: f64,
    /// How far the vehicle needs to stop from its speed now, metres (reaction, braking and
    /// `stop_buffer_m`: the planner's `stopping_distance_m`).
    pub stopping_m: f64,
    /// The spacing of `poses`, metres (the planner's `step_m`).
    pub step_m: f64,
    /// What the vehicle stands back from where it stops, metres (the planner's
    /// `stop_buffer_m`).
    pub stop_buffer_m: f64,
    /// A mover at the body not seen for longer than this is waited for as lost there, seconds
    /// (the planner's `hidden_after_s`).
    pub hidden_after_s: f64,
    /// The vehicle was yielding to a mover at the last plan.
    pub yielding: bool,
    /// How the movers are predicted and checked (the plan's `traffic`).
    pub traffic: &'a TrafficConfig,
    /// The tracks lost from view whose way the sensor has seen empty since, and when, seconds
    /// (`crate::OnlineMap::ways_seen_empty`): a mover lost coasting that neither went on its
    /// way nor stopped on it is not waited for.
    pub ways_seen_empty: &'a [(u32, f64)],
}

/// A mover at, or within reach of, the standing vehicle's body: it does not move off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BodyHold {
    /// The mover was seen within `hidden_after_s`: the vehicle stands for it.
    Seen {
        /// Where it was last seen, metres.
        at: Point2<f64>,
        /// When it was last seen, seconds.
        last_seen_s: f64,
    },
    /// None seen lately: one lost there is waited for, as a hidden obstacle.
    Lost {
        /// Where it was last seen, metres.
        at: Point2<f64>,
        /// When it was last seen, seconds.
        last_seen_s: f64,
        /// Why it is believed at the body.
        why: LostMover,
    },
}

/// Why a mover none sees is believed at the standing vehicle's body (what a pilot call for it
/// says).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LostMover {
    /// Held at the body, then its track dropped without it being seen away.
    AtBody,
    /// Predicted out of view towards the standing vehicle when its track dropped.
    Coasting,
    /// Lost from view standing, near enough to have walked to the body since.
    Standing,
}

/// The rules' decision about movers for one plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoverDecision {
    /// The speed wanted, capped at the caution speed while caution holds, m/s.
    pub wanted_m_s: f64,
    /// Where to stop, metres ahead: the plan's own stop moved for movers (`None`: nothing
    /// stops the vehicle).
    pub stop_at_m: Option<f64>,
    /// The conflict with a predicted mover found on the path.
    pub conflict: Option<Conflict>,
    /// The track of the mover whose hold line is held, if any.
    pub held_for: Option<u32>,
    /// The person standing the vehicle stops short of: where, and when last seen, seconds.
    pub walker: Option<(Point2<f64>, f64)>,
    /// A mover at the body: the vehicle does not move.
    pub body: Option<BodyHold>,
}

/// A mover at the vehicle's body.
#[derive(Clone, Copy, Debug)]
pub(super) struct AtBody {
    /// Its track.
    pub(super) id: u32,
    /// Where it was last seen (the centre of its hits), metres.
    pub(super) at: Point2<f64>,
    /// When it was last seen, seconds.
    pub(super) seen_s: f64,
    /// Its largest extent, metres.
    pub(super) extent_m: f64,
    /// The levels it was hit in (bit `l`: level `l`).
    pub(super) levels: u32,
    /// The fastest it was seen moving lately, m/s.
    pub(super) peak_m_s: f64,
    /// Its velocity when last seen, m/s (held at the body: over its kept path's last second).
    pub(super) velocity: Vector2<f64>,
    /// Why it is held once lost.
    pub(super) why: LostMover,
    /// The nearest its box came to the body while held, metres (infinite: not known), when,
    /// seconds, and its speed then, m/s.
    pub(super) nearest_gap: (f64, f64, f64),
    /// Where its track was when its box stepped away from the body further than its speed
    /// explains (its near part gone out of view), if it did: seen away only in part, held as it
    /// was until its track has moved beyond its extent from there.
    pub(super) stepped_at: Option<Point2<f64>>,
}

impl AtBody {
    /// Track `t` at the body, held for `why` once lost.
    pub(super) fn of(t: &TrackState, why: LostMover) -> Self {
        AtBody {
            id: t.id,
            at: t.position,
            seen_s: t.t_s,
            extent_m: t.extent_m,
            levels: t.levels,
            peak_m_s: t.peak_speed_m_s,
            velocity: t.velocity,
            why,
            nearest_gap: (f64::INFINITY, t.t_s, 0.0),
            stepped_at: None,
        }
    }
}

/// A track seen and predicted as a mover on consecutive plans.
#[derive(Clone, Copy, Debug)]
pub(super) struct MoverStreak {
    /// Its track.
    pub(super) id: u32,
    /// The last plan that saw and predicted it, seconds.
    pub(super) last_s: f64,
    /// Since when without a break, seconds.
    pub(super) since_s: f64,
    /// The last plan of its last streak, once that lasted `MOVER_FOR_S` (`None`: it has not).
    pub(super) mover_s: Option<f64>,
}

/// Where one mover was seen over the last `PATH_KEPT_S` (`memory.rs`): (when, its centre), oldest first.
#[derive(Clone, Debug)]
pub(super) struct MoverPath {
    /// Its track.
    pub(super) id: u32,
    /// When and where it was seen.
    pub(super) seen: Vec<(f64, Point2<f64>)>,
    /// When it was seen, and the corners of the box of its hits then, metres (the last few
    /// seconds only: what `hidden_in_place` reads).
    pub(super) boxes: Vec<(f64, HitBox)>,
}

/// The lower and upper corners of the box of a track's hits, metres.
pub(super) type HitBox = (Vector2<f64>, Vector2<f64>);

impl MoverPath {
    /// Where it was at `t_s`: between the sightings around it, linearly (`None` before the
    /// first kept or after the last).
    pub(super) fn at(&self, t_s: f64) -> Option<Point2<f64>> {
        let i = self.seen.partition_point(|&(s, _)| s <= t_s);
        let &(s0, p0) = self.seen.get(i.checked_sub(1)?)?;
        if s0 == t_s {
            return Some(p0);
        }
        let &(s1, p1) = self.seen.get(i)?;
        Some(p0 + (p1 - p0) * ((t_s - s0) / (s1 - s0)))
    }

    /// The last box of its hits kept at or before `t_s`, and when it was seen.
    pub(super) fn box_by(&self, t_s: f64) -> Option<(f64, HitBox)> {
        self.boxes.iter().rev().find(|&&(s, _)| s <= t_s).copied()
    }
}

/// The rules about movers and their memory: lines held, movers seen at the body, lost
/// standing, or seen moving lately.
pub struct TrafficRules {
    /// The vehicle's collision model.
    pub(super) model: CollisionModel,
    /// Acceleration the space-time check expects of the vehicle, m/s^2.
    pub(super) acceleration_m_s2: f64,
    /// The movers predicted at the last plan.
    pub(super) predictions: Vec<Prediction>,
    /// The conflict with a mover the last plan found on the chosen path.
    pub(super) conflict: Option<Conflict>,
    /// When a plan last found a conflict with a mover, seconds.
    pub(super) last_conflict_s: Option<f64>,
    /// When a plan last found a candidate mover's motion meeting the path, seconds.
    pub(super) last_caution_s: Option<f64>,
    /// Where, on the route, the nearest candidate mover's motion found lately meets the path
    /// (the start of its zone, metres of route progress), and when it was last found, seconds:
    /// a vehicle stopping anyway stops short of it.
    pub(super) caution_line: Option<(f64, f64)>,
    /// The line the vehicle holds short of for a mover: its track, the route arc length,
    /// when the conflict was last found.
    pub(super) hold: Option<(u32, f64, f64)>,
    /// The movers at the vehicle's body ([`super::at_body`]): released once seen away from the
    /// body; once lost, kept until seen elsewhere under a new number (not one lost coasting).
    pub(super) at_body: Vec<AtBody>,
    /// Movers predicted out of view at the last plan (see `movers_at_body`): one whose track
    /// drops while predicted to reach the standing vehicle's body is waited for.
    pub(super) coasting: Vec<TrackState>,
    /// The tracks seen and predicted as movers lately.
    pub(super) streaks: Vec<MoverStreak>,
    /// Movers that went out of view standing, as last seen (see `lost_standing_at`), kept
    /// for `LOST_STANDING_FOR_S` after.
    pub(super) lost_standing: Vec<TrackState>,
    /// The tracks seen moving as movers for `MOVER_FOR_S` on end at some time.
    pub(super) walked: Vec<u32>,
    /// The tracks lost standing that were parts of another mover carried on, driven over or
    /// standing where its body was (see `carried_part`, `driven_over`, `stood_in_its_body`):
    /// not kept as lost standing while they stay out of view.
    pub(super) parts: Vec<u32>,
    /// The tracks taken for movers lost at the body seen again (see `seen_elsewhere`): each
    /// lets go of one only.
    pub(super) claimed: Vec<u32>,
    /// The person standing the last plan stopped short of (see `short_of_walkers`): where, and
    /// when last seen, seconds.
    pub(super) walker_stop: Option<(Point2<f64>, f64)>,
    /// Where each mover was seen lately (see `part_of_another`), and a mover since demoted to a
    /// candidate (a car that stood, then backs slowly).
    pub(super) paths: Vec<MoverPath>,
    /// The candidate movers of the last plan: one that was a mover lately (it has a kept
    /// path) tells of a track lost that was part of it, as a mover does.
    pub(super) candidates: Vec<TrackState>,
    /// The plans' first collisions with the map, to find one closing on the vehicle.
    pub(super) closing: Closing,
    /// Where, on the route, the vehicle stops as short as it can when it is too late to stop
    /// short of a standing mover's reach (`stand_clear`), kept while the plans go on moving
    /// their stop for movers: a place, not a distance ahead.
    pub(super) stand_line: Option<f64>,
    /// Where the vehicle came to stand (`None` once it is away from there), and where each
    /// mover was then or first seen since (see `note_stood`): one whose box came nearer the
    /// body since came to it.
    pub(super) stood: Option<(Point2<f64>, Vec<Sighting>)>,
    /// Where the vehicle was at each plan of the last few seconds (see `note_vehicle`).
    pub(super) vehicle_seen: Vec<(f64, Point2<f64>)>,
    /// The plan's tracks lost whose way was seen empty ([`MoverInputs::ways_seen_empty`]).
    pub(super) ways_seen_empty: Vec<(u32, f64)>,
}

/// A track, and where it was seen.
pub(super) type Sighting = (u32, Point2<f64>);

impl TrafficRules {
    /// The rules for a vehicle of collision model `model` that accelerates at
    /// `acceleration_m_s2`, with nothing remembered.
    pub fn new(model: CollisionModel, acceleration_m_s2: f64) -> Self {
        TrafficRules {
            model,
            acceleration_m_s2,
            predictions: Vec::new(),
            conflict: None,
            last_conflict_s: None,
            last_caution_s: None,
            caution_line: None,
            hold: None,
            at_body: Vec::new(),
            coasting: Vec::new(),
            streaks: Vec::new(),
            lost_standing: Vec::new(),
            walked: Vec::new(),
            parts: Vec::new(),
            claimed: Vec::new(),
            walker_stop: None,
            paths: Vec::new(),
            candidates: Vec::new(),
            closing: Closing::default(),
            stand_line: None,
            stood: None,
            vehicle_seen: Vec::new(),
            ways_seen_empty: Vec::new(),
        }
    }

    /// The vehicle was put back at the start of an open route (a new lap): the lines and the
    /// movers remembered are forgotten (the last plan's predictions and conflict stay).
    pub fn restart(&mut self) {
        self.last_conflict_s = None;
        self.last_caution_s = None;
        self.caution_line = None;
        self.at_body.clear();
        self.coasting.clear();
        self.streaks.clear();
        self.lost_standing.clear();
        self.walked.clear();
        self.parts.clear();
        self.claimed.clear();
        self.paths.clear();
        self.candidates.clear();
        self.closing.clear();
        self.hold = None;
        self.stand_line = None;
        self.stood = None;
        self.vehicle_seen.clear();
        self.ways_seen_empty.clear();
    }

    /// The decision about movers for the plan `i`: the caution cap, the conflict, the stop
    /// lines (the plan's own stop moved short of movers), and the body hold.
    pub fn decide(&mut self, i: &MoverInputs<'_>) -> MoverDecision {
        let (s, v0, now_s, cfg) = (i.s_m, i.speed_m_s, i.now_s, i.traffic);
        let (closing_cap_m_s, closing_short_m) = self.closing_obstacle(i);
        let wanted = self.caution(i).min(closing_cap_m_s);
        let mut conflict = self.traffic_conflict(i, wanted, false);
        if conflict.is_some_and(|c| i.stopping_m >= c.zone_m) {
            // Too late to stop short of the mover's path: standing in it is the worst choice.
            // Drive on if the vehicle clears the mover with the tighter committed margin.
            let committed = self.traffic_conflict(i, wanted, true);
            if committed.is_none() {
                conflict = None;
            }
        }
        // A map obstacle closing on the vehicle: stop short of where it will be by the time
        // the vehicle stands.
        let mut stop_at_m = i.stop_at_m.map(|at| (at - closing_short_m).max(0.0));
        if let Some(stop_at) = self.hold_line(conflict.as_ref(), s, i.stopping_m, now_s, cfg) {
            stop_at_m = Some(stop_at_m.map_or(stop_at, |c| c.min(stop_at)));
        }
        if let Some(at) = stop_at_m {
            stop_at_m = Some(self.short_of_caution_line(at, i));
        }
        // Stopping - for a mover or the map - never where another mover is predicted to pass,
        // when the vehicle can stop short of its path.
        stop_at_m = stop_at_m.map(|at| self.stand_clear(i, at));
        if stop_at_m.is_none() {
            self.stand_line = None;
        }
        stop_at_m = self.short_of_walkers(i, stop_at_m);
        self.candidates = i.candidates.to_vec();
        self.ways_seen_empty = i.ways_seen_empty.to_vec();
        let body = self.movers_at_body(i.movers, &i.pose, now_s, v0 < 0.05, cfg, i.hidden_after_s);
        // Standing beside a known mover standing within its reach: it may walk or drive on
        // into the airframe (or it touches it already): the vehicle does not move off.
        self.note_stood(i);
        let body = body.or_else(|| {
            (v0 < 0.05)
                .then(|| self.standing_at(i.movers, &i.pose, now_s, cfg))
                .flatten()
        });
        if conflict.is_some() {
            self.last_conflict_s = Some(now_s);
        }
        self.conflict = conflict;
        MoverDecision {
            wanted_m_s: wanted,
            stop_at_m,
            conflict,
            held_for: self.hold.map(|h| h.0),
            walker: self.walker_stop,
            body,
        }
    }

    /// The movers predicted at the last plan, with their discs over the horizon.
    pub fn predictions(&self) -> &[Prediction] {
        &self.predictions
    }

    /// The conflict with a mover found on the chosen path at the last plan.
    pub fn conflict(&self) -> Option<&Conflict> {
        self.conflict.as_ref()
    }

    /// How the vehicle is expected to move: from its speed now, `speed_m_s`, to `wanted` m/s.
    pub(super) fn profile(&self, speed_m_s: f64, wanted: f64) -> SpeedProfile {
        SpeedProfile {
            speed_m_s,
            target_m_s: wanted,
            acceleration_m_s2: self.acceleration_m_s2,
        }
    }

    /// The movers of `i` predicted, and the first conflict on its path for a vehicle going
    /// from its speed now to `wanted` m/s (`None` with traffic off); `committed`: with the time
    /// margin of a vehicle that can no longer stop short.
    pub(super) fn traffic_conflict(
        &mut self,
        i: &MoverInputs<'_>,
        wanted: f64,
        committed: bool,
    ) -> Option<Conflict> {
        let (movers, now_s) = (i.movers, i.now_s);
        let mut traffic = i.traffic.clone();
        if committed {
            traffic.time_margin_s = traffic.committed_margin_s;
            traffic.resume_margin_s = 0.0;
        }
        let traffic = &traffic;
        if !traffic.enabled {
            self.predictions.clear();
            return None;
        }
        // A mover known to move (by the body hold's evidence) and in view stays predicted
        // slower than the floor: its visible part slows as the airframe hides the rest of it.
        let kept: Vec<u32> = movers
            .iter()
            .filter(|t| now_s - t.t_s <= 0.25 && self.arriving(t, now_s, traffic))
            .map(|t| t.id)
            .collect();
        self.predictions = predict_keeping(movers, now_s, traffic, &kept);
        if self.predictions.is_empty() {
            return None;
        }
        let path = TimedPath {
            poses: i.poses,
            step_m: i.step_m,
            profile: self.profile(i.speed_m_s, wanted),
            now_s,
            // Yielding, or slowing for a conflict found lately: the margin after grows, so a
            // prediction that flickers does not let the vehicle creep into the mover's path.
            yielding: i.yielding
                || self
                    .last_conflict_s
                    .is_some_and(|t| now_s - t < traffic.conflict_memory_s),
        };
        first_conflict(&path, &self.model, &self.predictions, traffic)
    }
}
