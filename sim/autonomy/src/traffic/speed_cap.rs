//! Caution: slow for what may move, stop for what does. A candidate mover's motion meeting the
//! path, or the path passing near a known mover standing, caps the speed at the caution speed.

use super::rules::{MoverInputs, TrafficRules};
use super::{TimedPath, first_conflict, first_within_standing_reach, predict, surely_moving};

impl TrafficRules {
    /// The wanted speed of `i` capped at the caution speed while the motion so far of a
    /// candidate mover (one not yet predictable, [`mapper::Tracker::candidate_movers`]) would
    /// meet its path, or the path passes near a known mover standing
    /// ([`super::passes_standing`]), and for `conflict_memory_s` after: by the time a candidate
    /// is confirmed, or the one standing has walked on, the vehicle can stop short of it; if it
    /// was a static object's parts coming into view, it only slowed. Where the candidate's
    /// motion meets the path is kept as the caution line (`short_of_caution_line`).
    pub(super) fn caution(&mut self, i: &MoverInputs<'_>) -> f64 {
        let (s, candidates, movers, wanted, now_s) =
            (i.s_m, i.candidates, i.movers, i.wanted_m_s, i.now_s);
        let traffic = i.traffic;
        if !traffic.enabled {
            return wanted;
        }
        let predictions = predict(candidates, now_s, traffic);
        if !predictions.is_empty() {
            let path = TimedPath {
                poses: i.poses,
                step_m: i.step_m,
                profile: self.profile(i.speed_m_s, wanted),
                now_s,
                yielding: false,
            };
            if let Some(c) = first_conflict(&path, &self.model, &predictions, traffic) {
                self.last_caution_s = Some(now_s);
                let line = match self.caution_line {
                    Some((held, t)) if now_s - t < traffic.conflict_memory_s => {
                        held.min(s + c.zone_m)
                    }
                    _ => s + c.zone_m,
                };
                self.caution_line = Some((line, now_s));
            }
        }
        let poses = i.poses;
        if movers
            .iter()
            .filter(|t| !surely_moving(t, traffic))
            .any(|t| first_within_standing_reach(&self.model, poses, t, traffic).is_some())
        {
            self.last_caution_s = Some(now_s);
        }
        if self
            .last_caution_s
            .is_some_and(|t| now_s - t < traffic.conflict_memory_s)
        {
            wanted.min(traffic.caution_speed_m_s)
        } else {
            wanted
        }
    }
}
