//! An obstacle of the map closing on the vehicle: the route position of the chosen path's first
//! collision falling from plan to plan faster than `closing_speed_m_s` is something moving
//! towards the vehicle that the tracker does not follow as a mover - a towed train whose carts
//! merge and split, seen as a candidate only in flashes (`tests/found/tug_train_meets_the_slowing_nose.toml`).
//! The map holds it as static cells; the rules count it as moving on
//! (`TrafficRules::closing_obstacle`, in `speed_cap`): the vehicle closes on it no faster than
//! the caution speed together and stops short of where it will be by the time it stands.

/// How long a plan's first collision is remembered to find the closing speed, seconds.
const WINDOW_S: f64 = 1.5;
/// The shortest stretch of plans a closing speed is found over, seconds.
const MIN_SPAN_S: f64 = 1.0;
/// Fewest plans a closing speed is found from.
const MIN_PLANS: usize = 5;
/// The least the first collision must have come nearer over the window, metres: more than the
/// path's pose spacing makes the collision's route position jitter by (0.5 m), so a static
/// object met on a replanned path is not taken for one closing.
const MIN_FALL_M: f64 = 1.0;
/// A first collision that moves more than this between two plans is another obstacle (one
/// revealed nearer, the path replanned past one), metres: the history starts over from it.
const JUMP_M: f64 = 1.5;

/// The first collision's route positions over the last plans, and the closing speed found.
#[derive(Clone, Debug, Default)]
pub(super) struct Closing {
    /// (when, the first collision's route position), seconds and metres, oldest first.
    seen: Vec<(f64, f64)>,
    /// The closing speeds found and when, m/s and seconds, within the memory, oldest first.
    found: Vec<(f64, f64)>,
}

impl Closing {
    /// Forgets every plan (a new lap).
    pub(super) fn clear(&mut self) {
        self.seen.clear();
        self.found.clear();
    }

    /// Whether the last plan taken, at `now_s`, found a closing speed itself (not one held).
    pub(super) fn found_at(&self, now_s: f64) -> bool {
        self.found.last().is_some_and(|&(_, t)| t == now_s)
    }

    /// Takes the plan at `now_s` whose first collision is at route position `at_m` (`None`:
    /// nothing stops the path) and gives the speed it closes at, m/s (0 when not closing
    /// faster than `min_m_s`), the fastest found within `memory_s` before.
    pub(super) fn observe(
        &mut self,
        now_s: f64,
        at_m: Option<f64>,
        min_m_s: f64,
        memory_s: f64,
    ) -> f64 {
        match at_m {
            None => self.seen.clear(),
            Some(at) => {
                let restart = self
                    .seen
                    .last()
                    .is_some_and(|&(t, a)| now_s <= t || (at - a).abs() > JUMP_M);
                if restart {
                    self.seen.clear();
                }
                self.seen.push((now_s, at));
                self.seen.retain(|&(t, _)| now_s - t <= WINDOW_S);
            }
        }
        if let Some(c) = closing_speed(&self.seen).filter(|&c| c > min_m_s) {
            self.found.push((c, now_s));
        }
        self.found.retain(|&(_, t)| now_s - t < memory_s);
        self.found.iter().map(|&(c, _)| c).fold(0.0, f64::max)
    }
}

/// The speed the route positions `seen` (when, where; oldest first) fall at, m/s: the least
/// squares slope, negated, when they span `MIN_SPAN_S` over `MIN_PLANS` plans and fell
/// `MIN_FALL_M` from the first half to the second (`None` otherwise).
fn closing_speed(seen: &[(f64, f64)]) -> Option<f64> {
    let (&(t0, _), &(t1, _)) = (seen.first()?, seen.last()?);
    if seen.len() < MIN_PLANS || t1 - t0 < MIN_SPAN_S {
        return None;
    }
    let n = seen.len() as f64;
    let (mt, ma) = seen
        .iter()
        .fold((0.0, 0.0), |(st, sa), &(t, a)| (st + t / n, sa + a / n));
    let (sta, stt) = seen.iter().fold((0.0, 0.0), |(sta, stt), &(t, a)| {
        (sta + (t - mt) * (a - ma), stt + (t - mt) * (t - mt))
    });
    let half = seen.len() / 2;
    let mean = |s: &[(f64, f64)]| s.iter().map(|&(_, a)| a).sum::<f64>() / s.len() as f64;
    let fell = mean(&seen[..half]) - mean(&seen[seen.len() - half..]);
    (fell >= MIN_FALL_M && stt > 0.0).then(|| -sta / stt)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plans every 0.2 s from `t0` with first collisions `at(t)`.
    fn observe_all(c: &mut Closing, t0: f64, n: usize, at: impl Fn(f64) -> Option<f64>) -> f64 {
        (0..n)
            .map(|k| t0 + 0.2 * k as f64)
            .map(|t| c.observe(t, at(t), 0.8, 2.0))
            .last()
            .unwrap_or(0.0)
    }

    #[test]
    fn a_train_closing_at_1_7_m_s_is_found_and_held_after() {
        // The tug train's first collision as the plans saw it: 1.7 m/s nearer, on 0.5 m poses.
        let mut c = Closing::default();
        let at = |t: f64| {
            Some(
                178.6 - 1.7 * t
                    + if (t * 5.0) as i64 % 2 == 0 {
                        0.25
                    } else {
                        -0.2
                    },
            )
        };
        let found = observe_all(&mut c, 0.0, 10, at);
        assert!((found - 1.7).abs() < 0.2, "{found}");
        // Nothing in the path 0.6 s later: still held (memory 2 s); then let go.
        assert!(c.observe(2.4, None, 0.8, 2.0) > 1.5);
        assert_eq!(c.observe(4.0, None, 0.8, 2.0), 0.0);
    }

    #[test]
    fn a_faster_closing_is_held_only_for_the_memory() {
        // 3 m/s for 1.6 s, then 1.5 m/s for 4 s: the fastest found within the last 2 s.
        let mut c = Closing::default();
        let at = |t: f64| {
            Some(if t < 1.6 {
                200.0 - 3.0 * t
            } else {
                195.2 - 1.5 * (t - 1.6)
            })
        };
        assert!((observe_all(&mut c, 0.0, 9, at) - 3.0).abs() < 1e-9);
        let found = observe_all(&mut c, 1.8, 20, at);
        assert!((found - 1.5).abs() < 1e-9, "{found}");
        assert!(c.found_at(1.8 + 0.2 * 19.0));
    }

    #[test]
    fn a_static_object_met_on_jittering_poses_is_not_closing() {
        // The collision's route position s + k * 0.5 of an object at 150 m: within half a metre.
        let mut c = Closing::default();
        let at = |t: f64| {
            let s = 120.0 + 4.6 * t;
            Some(s + ((150.0 - s) / 0.5).ceil() * 0.5)
        };
        assert_eq!(observe_all(&mut c, 0.0, 30, at), 0.0);
    }

    #[test]
    fn another_obstacle_revealed_nearer_is_not_closing() {
        // 30 m ahead, then a box revealed at 24 m, then standing there.
        let mut c = Closing::default();
        let at = |t: f64| Some(if t < 1.0 { 180.0 } else { 174.0 });
        assert_eq!(observe_all(&mut c, 0.0, 20, at), 0.0);
    }

    #[test]
    fn a_slow_creep_of_the_map_is_not_closing() {
        // An object whose cells grow towards the path at 0.4 m/s (revealed as the vehicle comes).
        let mut c = Closing::default();
        assert_eq!(observe_all(&mut c, 0.0, 20, |t| Some(150.0 - 0.4 * t)), 0.0);
    }
}
