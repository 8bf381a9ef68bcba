//! What the rules remember of movers from plan to plan: the streaks of tracks seen moving
//! (which make a track a mover), the movers at the vehicle's body, those that coasted out of
//! view towards it, and those lost from view while standing.

use mapper::TrackState;
use nalgebra::{Isometry2, Point2, Vector2};

use super::body::{box_gap_m, cell_m, hit_box};
use super::parts::{
    CARRIED_BACK_S, DRIVEN_THROUGH_M, LEFT_WITH_M_S, carried_part, driven_over,
    lost_on_a_standing_object, part_of_another, read_back, stood_in_its_body,
};
use super::rules::{AtBody, BodyHold, LostMover, MoverPath, MoverStreak, TrafficRules};
use super::{
    TrafficConfig, at_body, came_there, may_have_walked_to, may_reach_body,
    moved_beyond_its_extent, surely_moving,
};

/// A mover predicted out of view whose track drops while it may reach the standing vehicle's
/// body within this many seconds, at any speed up to its peak ([`may_reach_body`]), is waited
/// for as one lost there. Short: a static object's parts sliding out of view (a stale map,
/// heavy dropout) seem to move too, and over the whole horizon their predictions would reach
/// the body and call the pilot.
const DROPPED_AT_BODY_S: f64 = 2.0;

/// ... and only once it had been out of view this long, seconds: it coasted out of view. Under
/// heavy faults spurious returns make one-cell tracks that jump at 5-14 m/s and are dropped
/// within a second; a person lost under the wing was dropped 1.9 s after last seen (sample 757
/// of the falsifier on 308acd2), so 2 s let them go.
const COASTED_S: f64 = 1.5;

/// ... and only one seen and predicted on consecutive plans for at least this long, seconds
/// (three revolutions): one revolution's jump of a one-cell track is no evidence of a mover (a
/// parked car a stale map does not hold).
const SEEN_MOVING_S: f64 = 0.15;

/// A track seen and predicted as a mover without a break for this long, seconds ...
const MOVER_FOR_S: f64 = 1.0;
/// ... this lately, seconds, may arrive at the body (`arriving`): one that slowed as it
/// reached it, or walked out of view into it, is still one. A static object's sliding visible
/// part seems to move in bursts, not for a second on end (a row of parked cars a stale map
/// does not hold, on the parking lot).
const MOVER_LATELY_S: f64 = 6.0;
/// A mover lost from view while standing may have walked on at this speed, m/s (a brisk walk)
/// ...
const LOST_STANDING_WALK_M_S: f64 = 1.5;
/// ... for this long after it was last seen, seconds, if no larger than this, metres (a person;
/// a parked car a stale map does not hold, whose visible part slides, is larger).
const LOST_STANDING_FOR_S: f64 = 60.0;
pub(super) const LOST_STANDING_EXTENT_M: f64 = 2.0;
/// A mover lost standing walks no farther unseen than this, metres: the sensor's blind ground
/// round the airframe reaches 9.6 m from it (ahead of the nose, for a 0.7 m object; `taxi-sim
/// model coverage`), so one who walks up from farther is seen on the way and tracked afresh - a
/// person last seen standing 58 m behind, 22 m aside, held the jet standing for a van 34 s on
/// until it called a pilot (`tests/found/person_lost_standing_far_behind_holds_the_jet.toml`).
const LOST_STANDING_WALK_MAX_M: f64 = 20.0;

/// A mover lost at the body is the same mover as a track the tracker started within this many
/// seconds after it was last seen ...
const ELSEWHERE_WITHIN_S: f64 = 10.0;
/// ... where it could have gone by then at its own peak speed, or at least this, m/s (a brisk
/// walk).
const ELSEWHERE_M_S: f64 = 1.5;

/// A mover lost at the body going at [`LEFT_WITH_M_S`] or more has left with another going its
/// way at as much ([`TrafficRules::left_with_others`]) within this of its direction, radians (30
/// degrees), that drove through where it was last seen ([`DRIVEN_THROUGH_M`]) and on beyond it
/// by as much, or that carried it on (read back at most [`CARRIED_BACK_S`]) ...
const LEFT_WITH_RAD: f64 = 0.52;

/// ... or, it and the other this extent or more, metres (a fuel truck, a train: what the
/// tracker follows as two tracks of its parts; a van is 5.6 m, a cart 2), that was the same
/// object tracked twice and has gone on whole ([`TrafficRules::gone_as_one`]).
const TRACKED_TWICE_M: f64 = 8.0;

/// A held mover whose box steps away from the body by this much more than its speed explains,
/// metres, is seen away only in part ([`TrafficRules::still_at_body`]): a box's near edge
/// wanders a cell or two as hits come and go; a train's went 2.2 m in a revolution as its tug
/// went out of view (variant 238 of `traffic_jet_speed_profiles.toml`).
const STEPPED_AWAY_M: f64 = 1.0;

/// How long the rules keep where each mover was seen, seconds: longer than a track coasts out
/// of view before the tracker drops it.
const PATH_KEPT_S: f64 = 15.0;

/// How long the rules keep where the vehicle was, seconds (longer than [`HIDDEN_IN_PLACE_S`]).
const VEHICLE_KEPT_S: f64 = 3.0;

/// A track whose box now lies within its box this long or longer before, seconds ...
const HIDDEN_IN_PLACE_S: f64 = 1.0;
/// ... and smaller, while the vehicle travelled this far, metres, shows less of itself where
/// it stood ([`TrafficRules::hidden_in_place`]).
const HIDDEN_IN_PLACE_M: f64 = 1.0;

impl TrafficRules {
    /// Notes where each of `movers` was last seen, and forgets what is older than
    /// [`PATH_KEPT_S`] or of tracks not among them.
    fn note_paths(&mut self, movers: &[TrackState], now_s: f64) {
        self.paths.retain(|p| movers.iter().any(|t| t.id == p.id));
        for t in movers {
            let i = match self.paths.iter().position(|p| p.id == t.id) {
                Some(i) => i,
                None => {
                    let (seen, boxes) = (Vec::new(), Vec::new());
                    self.paths.push(MoverPath {
                        id: t.id,
                        seen,
                        boxes,
                    });
                    self.paths.len() - 1
                }
            };
            let path = &mut self.paths[i];
            if path.seen.last().is_none_or(|&(s, _)| t.t_s > s) {
                path.seen.push((t.t_s, t.position));
                path.boxes.push((t.t_s, hit_box(t)));
            }
            path.seen.retain(|&(s, _)| now_s - s <= PATH_KEPT_S);
            // Only what `hidden_in_place` can use: the vehicle's positions go back no further.
            path.boxes.retain(|&(s, _)| now_s - s <= VEHICLE_KEPT_S);
        }
    }

    /// Notes where the vehicle is at the plan of `now_s`, and forgets where it was more than
    /// [`VEHICLE_KEPT_S`] before.
    fn note_vehicle(&mut self, pose: &Isometry2<f64>, now_s: f64) {
        self.vehicle_seen
            .push((now_s, Point2::from(pose.translation.vector)));
        self.vehicle_seen
            .retain(|&(s, _)| now_s - s <= VEHICLE_KEPT_S);
    }

    /// The rearmost and foremost points of the vehicle's centreline at `pose`: where its
    /// circles reach along its length.
    fn centreline_ends(&self, pose: &Isometry2<f64>) -> [Point2<f64>; 2] {
        let circles = self.model.circles();
        let rear = circles
            .iter()
            .map(|c| c.x_m - c.radius_m)
            .fold(0.0, f64::min);
        let front = circles
            .iter()
            .map(|c| c.x_m + c.radius_m)
            .fold(0.0, f64::max);
        [rear, front].map(|x| pose * Point2::new(x, 0.0))
    }

    /// Whether track `t` only shows less of itself where it stood as the vehicle moves by: the
    /// box of its hits is smaller than the box it was seen with [`HIDDEN_IN_PLACE_S`] or more
    /// before and lies within it (a cell more), on each axis one of its edges where it was
    /// then (within a cell: the object's own end, standing), while the vehicle travelled
    /// [`HIDDEN_IN_PLACE_M`] or more since (the other edge is where the airframe or the
    /// sensor's blind ground, moving with it, cuts the object off). Its centre slides: no
    /// motion of its own. A follow-me car that had pulled aside and stood, its front hidden as
    /// the jet passed at 3 m/s, seemed to move at 1.4 m/s for a second, became a mover
    /// arriving at the body again and held the jet until it called a pilot
    /// (`tests/found/traffic_follow_me_car_head_on.toml`). A mover driving into the shadow
    /// of a moving airframe is cut off too, but its own far end moves with it; under a
    /// standing airframe the vehicle does not move.
    fn hidden_in_place(&self, t: &TrackState) -> bool {
        let Some(path) = self.paths.iter().find(|p| p.id == t.id) else {
            return false;
        };
        let then_s = t.t_s - HIDDEN_IN_PLACE_S;
        let Some((s, (lo0, hi0))) = path.box_by(then_s) else {
            return false;
        };
        let at = |s: f64| {
            (self.vehicle_seen.iter().rev())
                .find(|&&(v, _)| v <= s)
                .map(|&(_, p)| p)
        };
        let moved = match (at(s), at(t.t_s)) {
            (Some(a), Some(b)) => (b - a).norm() >= HIDDEN_IN_PLACE_M,
            _ => false,
        };
        let (lo, hi) = hit_box(t);
        let cell = cell_m(t);
        let area = |lo: Vector2<f64>, hi: Vector2<f64>| (hi - lo).product();
        let within = (0..2).all(|k| lo[k] >= lo0[k] - cell && hi[k] <= hi0[k] + cell);
        let an_end_stood =
            (0..2).all(|k| (lo[k] - lo0[k]).abs() <= cell || (hi[k] - hi0[k]).abs() <= cell);
        moved && within && an_end_stood && area(lo, hi) < area(lo0, hi0)
    }

    /// The movers at the body now ([`at_body`]: arriving, or - the vehicle standing - driven up
    /// and standing within reach), those held there before and not seen away
    /// ([`Self::still_at_body`]), joined to those lost there before; what holds
    /// the vehicle for them (`None`: nothing at the body): stopped for the one seen last, if
    /// seen within `hidden_after_s`, else waiting for one lost there, as for a hidden obstacle.
    pub(super) fn movers_at_body(
        &mut self,
        movers: &[TrackState],
        pose: &Isometry2<f64>,
        now_s: f64,
        stopped: bool,
        cfg: &TrafficConfig,
        hidden_after_s: f64,
    ) -> Option<BodyHold> {
        if !cfg.enabled {
            self.at_body.clear();
            self.coasting.clear();
            return None;
        }
        self.note_vehicle(pose, now_s);
        self.note_streaks(now_s);
        self.note_lost_standing(movers, now_s, cfg);
        self.claimed.retain(|id| movers.iter().any(|t| t.id == *id));
        // The movers, and the candidates that were movers lately (their paths kept): what
        // tells where a lost track went.
        let others: Vec<TrackState> = (movers.iter())
            .chain((self.candidates.iter()).filter(|c| self.paths.iter().any(|p| p.id == c.id)))
            .cloned()
            .collect();
        self.note_paths(&others, now_s);
        // One lost standing that was a part of another mover carried on (`carried_part`: a
        // fuel truck's corner tracked apart, a follow-me car's front), driven over by it
        // (`driven_over`: a follow-me car's corner) or standing where its body was
        // (`stood_in_its_body`: a fuel truck's side) is forgotten while it stays out of view.
        // Kept, it held the jet 25 m off as its walk-to reach grew (variants 284 and 814 of
        // `traffic_jet.toml`: needless pilot calls; 399).
        let ends = self.centreline_ends(pose);
        for l in &self.lost_standing {
            let taken = carried_part(l, &others, &self.paths, now_s)
                || driven_over(l, &others, &self.paths)
                || stood_in_its_body(l, &others, &self.paths, (now_s, ends));
            if !self.parts.contains(&l.id) && taken {
                self.parts.push(l.id);
            }
        }
        let parts = &self.parts;
        self.lost_standing.retain(|l| !parts.contains(&l.id));
        // A mover arriving at the body (or, the vehicle standing, one that drove up and stands
        // within its reach: a train seen in flashes as it crawls to the nose makes no streak),
        // or one held there before and not seen away (`still_at_body`).
        let mut body: Vec<AtBody> = (movers.iter())
            .filter_map(|t| match self.at_body.iter().find(|r| r.id == t.id) {
                Some(r) => self.still_at_body(r, t, pose, now_s, cfg),
                None => ((self.arriving(t, now_s, cfg)
                    || (stopped && self.drove_up(t) && self.standing_within_reach(t, pose, cfg)))
                    && at_body(&self.model, pose, t, now_s, cfg))
                .then(|| self.at_body_now(t, pose, None)),
            })
            .collect();
        // One lost (its track gone) is waited for for good, as a hidden obstacle: the pilot is
        // called. Its cells reading free would prove nothing - within the map's self-hit margin
        // of the body nothing is ever mapped. Unless it is seen elsewhere under a new number
        // (`seen_elsewhere`): it walked or drove on out of the blind zone; or it left with
        // others (`left_with_others`: not claimed - the other track is not the lost one). Not
        // one seen away only in part (`still_at_body`).
        let lost: Vec<AtBody> = (self.at_body.iter())
            .filter(|r| !movers.iter().any(|t| t.id == r.id))
            .copied()
            .collect();
        for r in lost {
            // Seen away only in part: what else is seen tells nothing of the part hidden.
            if r.stepped_at.is_some() {
                body.push(r);
                continue;
            }
            let seen = self.seen_elsewhere(&r, movers, pose, now_s, cfg);
            if let Some(id) = seen {
                self.claimed.push(id);
            }
            if seen.is_some() || self.left_with_others(&r, &others, now_s, cfg) {
                self.lost_standing.retain(|l| l.id != r.id);
                self.coasting.retain(|l| l.id != r.id);
            } else {
                body.push(r);
            }
        }
        // A mover that coasted out of view toward a standing vehicle and whose track was then
        // dropped: if it may reach the body within `DROPPED_AT_BODY_S`, it is waited for as
        // one lost there (a van that drove into the blind zone behind the wing has not gone) -
        // unless it never moved as a mover and the sensor saw its way empty since
        // (`no_mover_gone`).
        if stopped {
            let window = (now_s, now_s + DROPPED_AT_BODY_S);
            let dropped = self
                .coasting
                .iter()
                .filter(|t| !movers.iter().any(|m| m.id == t.id))
                .filter(|t| !body.iter().any(|r| r.id == t.id) && now_s - t.t_s >= COASTED_S)
                .filter(|t| {
                    let reaches =
                        |o: &TrackState| may_reach_body(&self.model, pose, o, window, cfg);
                    !part_of_another(t, &others, &self.paths, now_s, reaches)
                        && !lost_on_a_standing_object(t, &others, now_s, cfg)
                        && !self.no_mover_gone(t)
                })
                .filter(|t| may_reach_body(&self.model, pose, t, window, cfg))
                .map(|t| AtBody::of(t, LostMover::Coasting))
                .collect::<Vec<_>>();
            body.extend(dropped);
            let lost = self.lost_standing_at(pose, now_s, &body, cfg);
            body.extend(lost);
        }
        // Movers predicted out of view now, confirmed - or that drove up (`drove_up`: a van
        // seen in fragments is never confirmed by the stricter rule, and one that went out of
        // view behind the wing at a third of its speed struck the fuselage unseen, variant 426
        // of `traffic_jet_speed_profiles.toml`) - beyond what revealing a static object
        // explains, and seen predicted on a few revolutions on end: checked again if their
        // track drops (seen too briefly for a streak, maybe: a van seen in fragments for under
        // a second each). Others are not: a one-cell track jumping at 7 m/s at the edge of
        // view, lost for 6 s, would be predicted onto the body from 50 m away (one seen longer
        // still is: docs/known-problems.md).
        self.coasting = movers
            .iter()
            .filter(|t| {
                now_s - t.t_s > 0.25
                    && (t.confirmed || self.drove_up(t))
                    && moved_beyond_its_extent(t, cfg)
                    && self.predictions.iter().any(|p| p.track.id == t.id)
                    && self
                        .streaks
                        .iter()
                        .any(|r| r.id == t.id && r.last_s - r.since_s >= SEEN_MOVING_S)
            })
            .cloned()
            .collect();
        self.at_body = body;
        let seen = self
            .at_body
            .iter()
            .filter(|r| now_s - r.seen_s <= hidden_after_s);
        if let Some(r) = seen.max_by(|a, b| a.seen_s.total_cmp(&b.seen_s)) {
            return Some(BodyHold::Seen {
                at: r.at,
                last_seen_s: r.seen_s,
            });
        }
        let r = self.at_body.first()?;
        Some(BodyHold::Lost {
            at: r.at,
            last_seen_s: r.seen_s,
            why: r.why,
        })
    }

    /// Whether `t`, lost from view, was no mover and is gone: never seen moving as a mover for
    /// [`MOVER_FOR_S`] on end (`walked`), and its way seen empty after it was last seen
    /// ([`super::MoverInputs::ways_seen_empty`]: low beams passed through every place on it
    /// from where it was lost to past where its peak speed takes it) - it neither went on that way
    /// nor stopped on it. The visible side of the tail cone of an aircraft parked at a stand
    /// the survey never held slid along it for 0.8 s, was lost 58 m off where nothing stands
    /// and, its straight-line prediction reaching the standing airliner, held it until a pilot
    /// call (`tests/found/ksyr_survey_parked_tail_cone_held_as_a_mover_lost_coasting.toml`).
    /// Not one seen walking, which may have turned off its way: with that condition or the way
    /// checked as wide as the track, a person lost walking under the wing a little off the line
    /// read is waited for; with neither, they were struck as the jet moved off
    /// (`tests/found/person_lost_walking_under_the_wing.toml`).
    fn no_mover_gone(&self, t: &TrackState) -> bool {
        !self.walked.contains(&t.id)
            && (self.ways_seen_empty.iter()).any(|&(id, s)| id == t.id && s > t.t_s)
    }

    /// The track of `movers` that is `lost` - a mover held at the body of the vehicle at `pose`
    /// and lost there, or lost standing near enough to have walked to it, not one that coasted
    /// out of view - seen again under a new number, if any: seen now, away from the body
    /// ([`at_body`]), moved beyond its own extent, hit in a level `lost` was, no smaller than
    /// half its extent nor larger by 2 m, started by the tracker within [`ELSEWHERE_WITHIN_S`]
    /// after `lost` was last seen (or a second before: a track may split as it is renumbered)
    /// where `lost` could have gone by then at its peak speed (at least [`ELSEWHERE_M_S`]), and
    /// not already taken for another (`claimed`). The nearest to where `lost` was, when several
    /// are.
    fn seen_elsewhere(
        &self,
        lost: &AtBody,
        movers: &[TrackState],
        pose: &Isometry2<f64>,
        now_s: f64,
        cfg: &TrafficConfig,
    ) -> Option<u32> {
        if lost.why == LostMover::Coasting {
            return None;
        }
        let started_where_it_went = |t: &TrackState| {
            let dt = t.born_s - lost.seen_s;
            let speed = lost.peak_m_s.max(ELSEWHERE_M_S);
            (-1.0..=ELSEWHERE_WITHIN_S).contains(&dt)
                && (t.origin - lost.at).norm() <= lost.extent_m + t.extent_m + speed * dt.max(0.0)
        };
        movers
            .iter()
            .filter(|t| t.id != lost.id && !self.claimed.contains(&t.id))
            .filter(|t| {
                now_s - t.t_s <= 0.25
                    && t.levels & lost.levels != 0
                    && t.extent_m >= 0.5 * lost.extent_m
                    && t.extent_m <= lost.extent_m + 2.0
                    && moved_beyond_its_extent(t, cfg)
                    && !at_body(&self.model, pose, t, now_s, cfg)
                    && started_where_it_went(t)
            })
            .min_by(|a, b| {
                let d = |t: &TrackState| (t.position - lost.at).norm();
                d(a).total_cmp(&d(b))
            })
            .map(|t| t.id)
    }

    /// Whether `lost` - a mover lost at the body itself, going at [`LEFT_WITH_M_S`] or more when
    /// last seen (not one standing, nor one that coasted out of view, nor one lost standing
    /// elsewhere) - has left where it was last seen, as another of `others` (the movers, and the
    /// candidates that were movers lately) shows: one seen now, hit in a level `lost` was, moved
    /// beyond its own extent, going the way `lost` went (within [`LEFT_WITH_RAD`]) at
    /// [`LEFT_WITH_M_S`] or more, that since `lost` was last seen
    /// - drove through that place and on: its centre came within [`DRIVEN_THROUGH_M`] of it and
    ///   is now beyond it by more than that, the way `lost` went (a train's next cart, where the
    ///   lost one would have been driven into had it stopped there);
    /// - or carried it on: as large or larger, tracked since before `lost` was last seen, its
    ///   centre then within half its extent of that place (on its kept path, or within
    ///   [`CARRIED_BACK_S`] as its motion says: a candidate then) - the carts of a train the
    ///   tracker takes for one object, one of them lost as its hits join the train's track;
    /// - or, going at [`LEFT_WITH_M_S`] or more whatever its extent's travel and its way, was
    ///   one long object with `lost`, tracked twice, that has gone on whole
    ///   ([`Self::gone_as_one`]).
    fn left_with_others(
        &self,
        lost: &AtBody,
        others: &[TrackState],
        now_s: f64,
        cfg: &TrafficConfig,
    ) -> bool {
        if lost.why != LostMover::AtBody || lost.velocity.norm() < LEFT_WITH_M_S {
            return false;
        }
        let way = lost.velocity.normalize();
        let near = |at: &Point2<f64>| (at - lost.at).norm() <= DRIVEN_THROUGH_M;
        others
            .iter()
            .filter(|o| o.id != lost.id && now_s - o.t_s <= 0.25 && o.levels & lost.levels != 0)
            .filter(|o| o.velocity.norm() >= LEFT_WITH_M_S)
            .any(|o| {
                let its_way = moved_beyond_its_extent(o, cfg)
                    && o.velocity.angle(&lost.velocity) <= LEFT_WITH_RAD;
                let path = self.paths.iter().find(|p| p.id == o.id);
                let drove_through = its_way
                    && (o.position - lost.at).dot(&way) > DRIVEN_THROUGH_M
                    && path.is_some_and(|p| {
                        (p.seen.iter()).any(|(s, at)| *s > lost.seen_s && near(at))
                    });
                let then =
                    (path.and_then(|p| p.at(lost.seen_s))).or_else(|| read_back(o, lost.seen_s));
                let carried_on = its_way
                    && o.extent_m >= lost.extent_m
                    && o.born_s <= lost.seen_s
                    && then.is_some_and(|p| (p - lost.at).norm() <= 0.5 * o.extent_m);
                let gone_as_one = path.is_some_and(|p| self.gone_as_one(lost, o, p));
                drove_through || carried_on || gone_as_one
            })
    }

    /// Whether `lost` (a mover lost at the body going, see [`Self::left_with_others`]) and `o`,
    /// kept on `path`, were one long object tracked twice that has gone on whole: both
    /// [`TRACKED_TWICE_M`] across or more (a fuel truck, a train; not a van, 5.6 m), `o` tracked
    /// since before `lost` was last seen; its sighting nearest then, within [`CARRIED_BACK_S`]
    /// (a candidate till then, maybe), within `e` (the larger extent) of that place; since moved
    /// beyond `e` from there (no static object's hits do), along a line that passes within a
    /// quarter of `e` of that place (not a vehicle in the next lane), the way `lost` went, and
    /// now beyond that place by more than `e` - all of it gone from there, whatever part `lost`
    /// was. Its own line, not `lost`'s way: a jump as the other took its hits turns that 40
    /// degrees (variants 439 and 930 of `traffic_jet.toml`, a fuel truck's rear lost at the nose).
    fn gone_as_one(&self, lost: &AtBody, o: &TrackState, path: &MoverPath) -> bool {
        let e = o.extent_m.max(lost.extent_m);
        if o.extent_m.min(lost.extent_m) < TRACKED_TWICE_M || o.born_s > lost.seen_s {
            return false;
        }
        let nearest_then = (path.seen.iter())
            .filter(|(s, _)| (s - lost.seen_s).abs() <= CARRIED_BACK_S)
            .min_by(|a, b| {
                (a.0 - lost.seen_s)
                    .abs()
                    .total_cmp(&(b.0 - lost.seen_s).abs())
            });
        let Some(&(_, from)) = nearest_then else {
            return false;
        };
        let moved = o.position - from;
        if (from - lost.at).norm() > e || moved.norm() <= e {
            return false;
        }
        let line = moved.normalize();
        let off = lost.at - from;
        let aside = (off - line * off.dot(&line)).norm();
        aside <= 0.25 * e
            && lost.velocity.dot(&line) > 0.0
            && (o.position - lost.at).dot(&line) > e + DRIVEN_THROUGH_M
    }

    /// Mover `t` at the body of the vehicle at `pose`, as held there: its velocity over its
    /// kept path's last second, the nearest its box came to the body while held (`held`, if
    /// it was).
    fn at_body_now(&self, t: &TrackState, pose: &Isometry2<f64>, held: Option<&AtBody>) -> AtBody {
        let velocity = self.path_velocity(t);
        let gap_m = box_gap_m(&self.model, pose, t, &Vector2::zeros());
        let nearest_gap = match held {
            Some(h) if h.stepped_at.is_none() && h.nearest_gap.0 < gap_m => h.nearest_gap,
            _ => (gap_m, t.t_s, velocity.norm()),
        };
        AtBody {
            velocity,
            nearest_gap,
            ..AtBody::of(t, LostMover::AtBody)
        }
    }

    /// What holds mover `t`, held at the body as `held`, now (`None`: it is let go): released
    /// once seen away from the body ([`at_body`]; a prediction carrying it on through the
    /// airframe is no evidence that it left) - unless its box stepped away from the nearest it
    /// came further than [`STEPPED_AWAY_M`] plus what its speed explains since: its near part
    /// went out of view (a tug gone into the blind zone under the nose, its carts still seen,
    /// their track's box 2.2 m back in a revolution). Held then as it was until its track has
    /// moved beyond its extent from where it stepped to, or is seen at the body again.
    fn still_at_body(
        &self,
        held: &AtBody,
        t: &TrackState,
        pose: &Isometry2<f64>,
        now_s: f64,
        cfg: &TrafficConfig,
    ) -> Option<AtBody> {
        let seen_now = now_s - t.t_s <= 0.25;
        if (seen_now && at_body(&self.model, pose, t, now_s, cfg))
            || (!seen_now && held.stepped_at.is_none())
        {
            return Some(self.at_body_now(t, pose, Some(held)));
        }
        if let Some(stepped_at) = held.stepped_at {
            let moved_on = seen_now && (t.position - stepped_at).norm() > held.extent_m;
            return (!moved_on).then_some(*held);
        }
        // Its speed as it was nearest: a step read as motion makes the track's own fast.
        let (nearest_m, nearest_s, speed_then) = held.nearest_gap;
        let gap_m = box_gap_m(&self.model, pose, t, &Vector2::zeros());
        let speed = speed_then.max(ELSEWHERE_M_S);
        let stepped = gap_m - nearest_m > STEPPED_AWAY_M + speed * (t.t_s - nearest_s).max(0.0);
        stepped.then_some(AtBody {
            stepped_at: Some(t.position),
            ..*held
        })
    }

    /// The velocity of mover `t` over its kept path's last second, m/s (its filter's velocity
    /// when the path is shorter): a track's velocity as it is lost can be far off (a train's
    /// cart whose hits join the next one's seemed to go sideways at 1 m/s).
    fn path_velocity(&self, t: &TrackState) -> Vector2<f64> {
        (self.paths.iter().find(|p| p.id == t.id))
            .and_then(|p| p.at(t.t_s - 1.0))
            .map_or(t.velocity, |then| t.position - then)
    }

    /// Whether track `t` is a mover that may arrive at the body: one predicted on a streak
    /// lately that has moved beyond its own extent.
    pub(super) fn arriving(&self, t: &TrackState, now_s: f64, cfg: &TrafficConfig) -> bool {
        self.mover_lately(t.id, now_s) && moved_beyond_its_extent(t, cfg)
    }

    /// Whether track `id` was a mover (its streak's `mover_s`) within [`MOVER_LATELY_S`].
    fn mover_lately(&self, id: u32, now_s: f64) -> bool {
        (self.streaks.iter())
            .any(|r| r.id == id && r.mover_s.is_some_and(|m| now_s - m <= MOVER_LATELY_S))
    }

    /// Keeps the known movers out of view while standing (the tracker's confirmed movers, no
    /// larger than [`LOST_STANDING_EXTENT_M`], that were seen moving for [`MOVER_FOR_S`] on end
    /// and travelled more than twice their extent and 3 m: a person who walked up and stopped,
    /// not a static object's sliding parts, which seem to move in bursts), as last seen, after
    /// their tracks drop; forgets one seen again, or lost [`LOST_STANDING_FOR_S`] ago.
    pub(super) fn note_lost_standing(
        &mut self,
        movers: &[TrackState],
        now_s: f64,
        cfg: &TrafficConfig,
    ) {
        for r in self.streaks.iter().filter(|r| r.mover_s.is_some()) {
            if !self.walked.contains(&r.id) {
                self.walked.push(r.id);
            }
        }
        // Those neither tracked nor kept (lost standing, or coasting at the last plan: a
        // dropped one is judged by it, `no_mover_gone`) are forgotten.
        let (lost, coasting) = (&self.lost_standing, &self.coasting);
        self.walked.retain(|id| {
            (movers.iter().any(|t| t.id == *id) || lost.iter().any(|l| l.id == *id))
                || coasting.iter().any(|c| c.id == *id)
        });
        // A part seen again is a track like any other: judged afresh if lost again.
        self.parts
            .retain(|id| movers.iter().any(|t| t.id == *id && now_s - t.t_s > 0.25));
        self.lost_standing.retain(|l| {
            now_s - l.t_s < LOST_STANDING_FOR_S
                && !movers.iter().any(|t| t.id == l.id && now_s - t.t_s <= 0.25)
        });
        for t in movers.iter().filter(|t| {
            now_s - t.t_s > 0.25
                && t.confirmed
                && self.walked.contains(&t.id)
                && t.extent_m <= LOST_STANDING_EXTENT_M
                && came_there(t)
                && !surely_moving(t, cfg)
        }) {
            match self.lost_standing.iter_mut().find(|l| l.id == t.id) {
                Some(l) => *l = t.clone(),
                None => self.lost_standing.push(t.clone()),
            }
        }
    }

    /// The movers lost standing (see `note_lost_standing`) that may have walked to the body of
    /// the standing vehicle at `pose` since they were last seen, as movers at its body (waited
    /// for, the pilot called): a person the airframe hid may have walked on into the blind zone
    /// at the tail. Not those already in `body`.
    pub(super) fn lost_standing_at(
        &self,
        pose: &Isometry2<f64>,
        now_s: f64,
        body: &[AtBody],
        cfg: &TrafficConfig,
    ) -> Vec<AtBody> {
        self.lost_standing
            .iter()
            .filter(|l| !body.iter().any(|r| r.id == l.id))
            .filter(|l| {
                let walk = (LOST_STANDING_WALK_M_S, LOST_STANDING_WALK_MAX_M);
                may_have_walked_to(&self.model, pose, l, now_s, walk, cfg)
            })
            .map(|l| AtBody::of(l, LostMover::Standing))
            .collect()
    }

    /// Each track seen (this revolution or the last, 0.25 s) and predicted now continues its
    /// streak, or starts one; its last streak, once it lasted [`MOVER_FOR_S`], makes it a mover
    /// as of the streak's last plan. Streaks not continued are kept for [`MOVER_LATELY_S`]. A
    /// track that is not a mover lately and only shows less of itself where it stood
    /// ([`Self::hidden_in_place`]) continues nothing: a break over 0.25 s starts a new streak.
    pub(super) fn note_streaks(&mut self, now_s: f64) {
        for p in self
            .predictions
            .iter()
            .filter(|p| now_s - p.track.t_s <= 0.25)
        {
            // Less of it seen where it stood, as the vehicle goes by: no motion of its own -
            // unless it is a mover lately (a streak it has is not broken by this).
            let id = p.track.id;
            if !self.mover_lately(id, now_s) && self.hidden_in_place(&p.track) {
                continue;
            }
            let r = match self.streaks.iter_mut().find(|r| r.id == id) {
                Some(r) => r,
                None => {
                    self.streaks.push(MoverStreak {
                        id,
                        last_s: now_s,
                        since_s: now_s,
                        mover_s: None,
                    });
                    self.streaks.last_mut().expect("just pushed")
                }
            };
            if now_s - r.last_s > 0.25 {
                // A new streak: an earlier one does not count (a row of parked cars the map
                // does not hold, merged into one track, seems to move in bursts).
                r.since_s = now_s;
                r.mover_s = None;
            }
            r.last_s = now_s;
            if now_s - r.since_s >= MOVER_FOR_S {
                r.mover_s = Some(now_s);
            }
        }
        self.streaks.retain(|r| now_s - r.last_s <= MOVER_LATELY_S);
    }
}
