//! Caution: slow for what may move, stop for what does. A candidate mover's motion meeting the
//! path, the path passing near a known mover standing or a person-sized object seen only
//! standing, caps the speed at the caution speed; a map obstacle closing on the vehicle
//! (`closing`) caps it lower and moves the stop short.

use super::conflict::{first_within, reach_of};
use super::rules::{MoverInputs, TrafficRules};
use super::{TimedPath, first_conflict, first_within_standing_reach, predict, surely_moving};

impl TrafficRules {
    /// The wanted speed of `i` capped at the caution speed while the motion so far of a
    /// candidate mover (one not yet predictable, [`mapper::Tracker::candidate_movers`]) would
    /// meet its path, or the path passes near a known mover standing
    /// ([`super::passes_standing`]) or a person-sized object seen only standing
    /// (`passes_standing_object`), and for `conflict_memory_s` after: by the time a candidate
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
            || self.passes_standing_object(i)
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

    /// Whether the path of `i` passes within `standing_object_reach_m` of a small object seen
    /// only standing (`standing_object_max_m`) and hit above the lowest level (a person; a cone
    /// too where that level starts low): one who stood beside the path and walks on is
    /// predicted only after a second or so of walking, by when a vehicle at 8 m/s could no
    /// longer stop short of them (variant 66 of `traffic_jet_speed_profiles.toml`).
    fn passes_standing_object(&self, i: &MoverInputs<'_>) -> bool {
        let cfg = i.traffic;
        cfg.standing_object_max_m > 0.0
            && i.standing.iter().filter(|t| t.levels > 1).any(|t| {
                let reach = reach_of(t, cfg.standing_object_reach_m, cfg);
                first_within(&self.model, i.poses, t, reach).is_some()
            })
    }

    /// The speed cap and how far short to move the map's stop for a map obstacle closing on
    /// the vehicle of plan `i` ([`super::closing`]): no faster than the caution speed together
    /// (a third of it at least), stopping short of where it will be by the time the vehicle
    /// stands; (infinite, 0) when none closes, or with traffic off. Closing also holds the
    /// caution speed for `conflict_memory_s`, like a candidate mover meeting the path.
    pub(super) fn closing_obstacle(&mut self, i: &MoverInputs<'_>) -> (f64, f64) {
        let cfg = i.traffic;
        if !cfg.enabled {
            return (f64::INFINITY, 0.0);
        }
        let at = i.stop_at_m.map(|a| i.s_m + a);
        let closing_m_s =
            self.closing
                .observe(i.now_s, at, cfg.closing_speed_m_s, cfg.conflict_memory_s);
        if self.closing.found_at(i.now_s) {
            self.last_caution_s = Some(i.now_s);
        }
        if closing_m_s <= 0.0 {
            return (f64::INFINITY, 0.0);
        }
        let together = (cfg.caution_speed_m_s - closing_m_s).max(cfg.caution_speed_m_s / 3.0);
        (together, closing_m_s * time_to_stop_s(i))
    }
}

/// How long the vehicle of `i` takes to stand from its speed now, seconds (0 standing): its
/// stopping distance without the buffer at the mean speed of a steady braking - an upper bound,
/// since the reaction's distance, driven at full speed, is counted at half of it too.
fn time_to_stop_s(i: &MoverInputs<'_>) -> f64 {
    if i.speed_m_s < 0.05 {
        return 0.0;
    }
    2.0 * (i.stopping_m - i.stop_buffer_m).max(0.0) / i.speed_m_s
}
