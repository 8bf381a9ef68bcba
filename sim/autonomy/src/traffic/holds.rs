//! The lines the vehicle stops short of for movers: the hold line of a conflict, the caution
//! line of a candidate mover, clear of other movers' paths, short of a person standing; and
//! the known mover standing within reach of a standing vehicle.

use mapper::TrackState;
use nalgebra::{Isometry2, Point2, Vector2};

use super::body::box_gap_m;
use super::memory::LOST_STANDING_EXTENT_M;
use super::rules::{BodyHold, MoverInputs, MoverPath, TrafficRules};
use super::{
    Conflict, StandStop, TimedPath, TrafficConfig, came_there, first_within_standing_reach,
    stand_clear_why, surely_moving,
};

/// The vehicle stands where it stood while it stays within this of it, metres.
const STOOD_M: f64 = 0.5;
/// A mover whose box came nearer the standing vehicle's body by more than this came to it,
/// metres: more than a standing car's box wanders as hits come and go.
const CAME_M: f64 = 1.0;
/// Where a mover was this long before the vehicle came to stand is where it was then, seconds:
/// a van that stopped as the vehicle braked for it came to it; a follow-me car that made room
/// stood 6.2 s before the jet came to stand beside it (traffic_jet's variant 175).
const STOOD_GRACE_S: f64 = 3.0;

impl TrafficRules {
    /// A known mover of `movers` - arriving lately (seen predicted for a second within the last
    /// six, beyond its own extent: not a static object's sliding parts), a person standing
    /// (`is_walker`), or one that drove up longer ago (`drove_up`: a van that stood at the nose
    /// longer than six seconds, variant 6 of `traffic_jet_speed_profiles.toml`) to the vehicle
    /// standing (`came_to_the_standing_vehicle`: not a car that made room and stood before the
    /// vehicle came beside it, `follow_me_car_made_room_beside_the_jet_holds_it.toml`; one
    /// that drove up and stands at the body itself is held there whenever it came,
    /// `movers_at_body`) - standing now
    /// (not [`surely_moving`]) within its reach of the vehicle at `pose`
    /// ([`first_within_standing_reach`]), as what stops the vehicle; `None` with traffic off.
    pub(super) fn standing_at(
        &self,
        movers: &[TrackState],
        pose: &Isometry2<f64>,
        now_s: f64,
        cfg: &TrafficConfig,
    ) -> Option<BodyHold> {
        if !cfg.enabled {
            return None;
        }
        movers
            .iter()
            .filter(|t| {
                self.arriving(t, now_s, cfg)
                    || self.is_walker(t, cfg)
                    || (self.drove_up(t) && self.came_to_the_standing_vehicle(t, pose))
            })
            .find(|t| self.standing_within_reach(t, pose, cfg))
            .map(|t| BodyHold::Seen {
                at: t.position,
                last_seen_s: t.t_s,
            })
    }

    /// Whether `t`, a track, stands (not [`surely_moving`]) within its reach of the vehicle at
    /// `pose` ([`first_within_standing_reach`]).
    pub(super) fn standing_within_reach(
        &self,
        t: &TrackState,
        pose: &Isometry2<f64>,
        cfg: &TrafficConfig,
    ) -> bool {
        !surely_moving(t, cfg)
            && first_within_standing_reach(&self.model, std::slice::from_ref(pose), t, cfg)
                .is_some()
    }

    /// Whether `t` is a known mover that came where it stands: seen moving as a mover for
    /// `MOVER_FOR_S` on end at some time and [`came_there`], as one lost standing must have
    /// (`note_lost_standing`).
    pub(super) fn drove_up(&self, t: &TrackState) -> bool {
        self.walked.contains(&t.id) && came_there(t)
    }

    /// Notes where the vehicle came to stand (slower than 0.05 m/s) and where each mover was
    /// then - [`STOOD_GRACE_S`] before, by its kept path: a van that stopped as the vehicle
    /// braked for it came to it - or, one first seen since, where first seen; forgets both once
    /// the vehicle is more than [`STOOD_M`] from there.
    pub(super) fn note_stood(&mut self, i: &MoverInputs<'_>) {
        let here = Point2::from(i.pose.translation.vector);
        if (self.stood.as_ref()).is_some_and(|(at, _)| (at - here).norm() > STOOD_M) {
            self.stood = None;
        }
        if self.stood.is_none() && i.speed_m_s < 0.05 {
            let then_s = i.now_s - STOOD_GRACE_S;
            let then = |p: &MoverPath| {
                let (first, last) = (p.seen.first()?, p.seen.last()?);
                Some(
                    p.at(then_s)
                        .unwrap_or(if then_s < first.0 { first.1 } else { last.1 }),
                )
            };
            let seen = (self.paths.iter())
                .filter_map(|p| Some((p.id, then(p)?)))
                .collect();
            self.stood = Some((here, seen));
        }
        if let Some((_, seen)) = &mut self.stood {
            for t in i.movers {
                if !seen.iter().any(|(id, _)| *id == t.id) {
                    seen.push((t.id, t.position));
                }
            }
        }
    }

    /// Whether mover `t` came to the vehicle standing at `pose` ([`Self::note_stood`]): the box
    /// of its hits is nearer the body by more than [`CAME_M`] than it was where the mover was
    /// when the vehicle came to stand. One that stood where it stands before (a car that made
    /// room), or crept along the body or away from it, did not.
    pub(super) fn came_to_the_standing_vehicle(
        &self,
        t: &TrackState,
        pose: &Isometry2<f64>,
    ) -> bool {
        let Some((_, seen)) = &self.stood else {
            return false;
        };
        seen.iter()
            .find(|(id, _)| *id == t.id)
            .is_some_and(|(_, p)| {
                let gap = |shift: Vector2<f64>| box_gap_m(&self.model, pose, t, &shift);
                gap(p - t.position) - gap(Vector2::zeros()) > CAME_M
            })
    }

    /// Whether `t` is a person standing: a small known mover (up to
    /// [`LOST_STANDING_EXTENT_M`]) seen moving for `MOVER_FOR_S` on end at some time, not
    /// moving now.
    pub(super) fn is_walker(&self, t: &TrackState, cfg: &TrafficConfig) -> bool {
        t.confirmed
            && t.extent_m <= LOST_STANDING_EXTENT_M
            && !surely_moving(t, cfg)
            && self.walked.contains(&t.id)
    }

    /// Where to stop instead of `at_m` ahead (`None`: nothing stops the vehicle) so as not to
    /// pass within reach ([`first_within_standing_reach`]) of a person standing (`is_walker`):
    /// walking on from 2 m off the path, they reach it before the tracker sees them move and
    /// the vehicle can stop - passing slowly is not enough. When the vehicle can stop before the reach;
    /// already inside it, the caution speed applies. The person stopped for is kept as
    /// `walker_stop` (what the stopped vehicle says it stands for).
    pub(super) fn short_of_walkers(
        &mut self,
        i: &MoverInputs<'_>,
        at_m: Option<f64>,
    ) -> Option<f64> {
        let movers = i.movers;
        self.walker_stop = None;
        let cfg = i.traffic;
        if !cfg.enabled {
            return at_m;
        }
        let braking_m = i.stopping_m - i.stop_buffer_m;
        let poses = i.poses;
        let mut at_m = at_m;
        let walkers: Vec<&TrackState> = movers.iter().filter(|t| self.is_walker(t, cfg)).collect();
        for t in walkers {
            let reached = first_within_standing_reach(&self.model, poses, t, cfg);
            let Some(k) = reached else { continue };
            let zone_m = k as f64 * i.step_m;
            if zone_m > braking_m && at_m.is_none_or(|a| zone_m < a) {
                at_m = Some(zone_m);
                self.walker_stop = Some((t.position, t.t_s));
            }
        }
        at_m
    }

    /// Where to stop instead of `at_m` ahead of route progress `i.s_m`: short of the caution line
    /// while it holds (found within `conflict_memory_s`) and the vehicle can stop before it -
    /// a vehicle stopping anyway (for a tug under its wing) must not stop with its nose across
    /// the way a candidate mover is heading (the tug's train, not yet confirmed); `at_m` else.
    pub(super) fn short_of_caution_line(&mut self, at_m: f64, i: &MoverInputs<'_>) -> f64 {
        let (s, now_s) = (i.s_m, i.now_s);
        let Some((line, t)) = self.caution_line else {
            return at_m;
        };
        if now_s - t >= i.traffic.conflict_memory_s || line - s < -1.0 {
            self.caution_line = None;
            return at_m;
        }
        // Short of the line itself, if not by the whole stop buffer: braking now, it stops
        // before the mover's way.
        let ahead = line - s;
        let braking_m = i.stopping_m - i.stop_buffer_m;
        if ahead > braking_m && ahead < at_m {
            ahead
        } else {
            at_m
        }
    }

    /// Where the vehicle must stop for movers, as a distance ahead of route progress `s`: before
    /// the conflict zone when it can stop short of it (it stops within `stopping_m`), before
    /// the conflict itself otherwise.
    /// Once two plans in a row find the conflict, the line is held on the route - never moved
    /// further on while the conflict lasts, nor for `conflict_memory_s` after it was last
    /// found - so a prediction that flickers or a zone that shifts does not let the vehicle
    /// creep into the mover's path.
    pub(super) fn hold_line(
        &mut self,
        conflict: Option<&Conflict>,
        s: f64,
        stopping_m: f64,
        now_s: f64,
        cfg: &TrafficConfig,
    ) -> Option<f64> {
        let previous = self.conflict.map(|c| c.track_id);
        if let Some(c) = conflict {
            let short_of_zone = stopping_m < c.zone_m;
            let line = s + if short_of_zone { c.zone_m } else { c.at_m };
            let held = match self.hold {
                Some((id, held, _)) if id == c.track_id => held.min(line),
                _ => line,
            };
            if previous != Some(c.track_id) && self.hold.is_none() {
                // Found on one plan only (a prediction may flicker): this plan stops short of
                // it; the line is held once the next plan finds it again.
                return Some(line - s);
            }
            self.hold = Some((c.track_id, held, now_s));
        } else if self
            .hold
            .is_some_and(|(_, _, t)| now_s - t >= cfg.conflict_memory_s)
        {
            self.hold = None;
        }
        // A line well behind the vehicle (a closed route's lap started over, or it went on
        // committed) holds nothing.
        if self.hold.is_some_and(|(_, line, _)| line - s < -1.0) {
            self.hold = None;
        }
        self.hold.map(|(_, line, _)| (line - s).max(0.0))
    }

    /// Where to stop instead of `at_m` ahead so as not to stand in a predicted mover's path,
    /// nor beside one of `movers` not predicted now - standing, or too slow to predict
    /// ([`super::stand_clear`]); `at_m` when it is clear or too late. Too late to stop short of
    /// a standing mover's reach, the stop is the stopping distance, and taken afresh each plan
    /// it would move ahead with the vehicle, which would never brake (it drove on at 2.2 m/s
    /// for two seconds, its stop 5.7 m ahead, until the van beside its path drove on into the
    /// nose: variant 590 of `traffic_jet_speed_profiles.toml`): that place is kept on the
    /// route (`stand_line`), never moved further on, while the plans go on moving the stop,
    /// and bounds the stops they move for other causes (the start of a mover's zone, which
    /// moves on as the mover does, is not kept). A line more than a metre behind the vehicle
    /// (it went on, or a lap started over) holds nothing.
    pub(super) fn stand_clear(&mut self, i: &MoverInputs<'_>, at_m: f64) -> f64 {
        let (movers, v0, now_s, cfg) = (i.movers, i.speed_m_s, i.now_s, i.traffic);
        let standing: Vec<TrackState> = movers
            .iter()
            .filter(|t| !self.predictions.iter().any(|q| q.track.id == t.id))
            .cloned()
            .collect();
        if !cfg.enabled || (self.predictions.is_empty() && standing.is_empty()) {
            self.stand_line = None;
            return at_m;
        }
        let path = TimedPath {
            poses: i.poses,
            step_m: i.step_m,
            profile: self.profile(v0, 0.0),
            now_s,
            yielding: false,
        };
        let stop = StandStop {
            stop_at_m: at_m,
            stand_back_m: i.stop_buffer_m,
            stopping_m: i.stopping_m,
        };
        let moved = stand_clear_why(&path, &self.model, &self.predictions, &standing, stop, cfg);
        let Some((clear_m, too_late)) = moved else {
            self.stand_line = None;
            return at_m;
        };
        if self.stand_line.is_some_and(|l| l - i.s_m < -1.0) {
            self.stand_line = None;
        }
        let line = self
            .stand_line
            .map_or(i.s_m + clear_m, |l| l.min(i.s_m + clear_m));
        if too_late {
            self.stand_line = Some(line);
        }
        (line - i.s_m).max(0.0).min(at_m)
    }
}
