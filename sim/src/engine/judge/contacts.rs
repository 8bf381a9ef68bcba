//! The contacts and who was at fault: judged when they begin, and again while the vehicle
//! moves as they last.
//!
//! Who came into whose room: a contact that begins while the vehicle moves is at fault unless
//! the object, where it is now, overlaps the touching part placed where the vehicle was
//! [`HELD_ROOM_S`] before at least as deeply as it overlaps it now (less [`DEEPER_M`]): then the
//! vehicle's own motion did not bring them together - the object came into room the vehicle
//! held - and the contact is struck while moving. Such a pair is asked again each step the
//! vehicle moves while it lasts, and is at fault once the vehicle's motion deepens it; once the
//! vehicle stands, the pair is one struck standing (driven into later: at fault). An object
//! that appeared within [`HELD_ROOM_S`] held no room: at fault, as before the rule.

use nalgebra::Isometry2;

use super::Judge;
use crate::engine::outcome::{AT_FAULT_SPEED_M_S, Event, HELD_ROOM_S, JudgedContact};
use crate::world::{Contact, World};

/// How much deeper (metres) the overlap may be now than with the vehicle where it was: the
/// physics' own contact margin and the penetration query's rounding.
pub(super) const DEEPER_M: f64 = 0.005;

/// An (object, vehicle part) pair.
type Pair = (String, String);

/// The pairs touching now that were judged, and how.
#[derive(Debug, Default)]
pub(super) struct Touching {
    /// Judged at fault while they touch.
    pushing: Vec<Pair>,
    /// Struck while moving: asked again each step the vehicle moves while they touch.
    came_in: Vec<Pair>,
}

impl Judge {
    /// Records the vehicle's true pose at `t_s`: the poses of the last [`HELD_ROOM_S`] are
    /// kept, and the latest one at least that old.
    pub(super) fn remember_pose(&mut self, t_s: f64, pose: Isometry2<f64>) {
        self.recent_poses.push_back((t_s, pose));
        while self
            .recent_poses
            .get(1)
            .is_some_and(|(t, _)| *t <= t_s - HELD_ROOM_S)
        {
            self.recent_poses.pop_front();
        }
    }

    /// The contacts begun since the last step and those lasting while the vehicle moves,
    /// judged ([`judge_contacts`]) against the vehicle as it stood [`HELD_ROOM_S`] before.
    pub(super) fn judge_contacts(
        &mut self,
        t_s: f64,
        now: &Isometry2<f64>,
        speed_m_s: f64,
        world: &World,
    ) {
        let begun = &world.contacts()[self.contacts_seen..];
        self.contacts_seen = world.contacts().len();
        // Less than HELD_ROOM_S of history (the run's first steps): no room held yet.
        let then = self
            .recent_poses
            .front()
            .filter(|(t, _)| *t <= t_s - HELD_ROOM_S + 1e-9)
            .map(|(_, pose)| *pose);
        let held = |c: &Contact| {
            let Some(then) = then else {
                return false;
            };
            let solids = &world.scene().solids;
            let Some(i) = solids.iter().position(|s| s.id == c.object) else {
                return false;
            };
            if world.object_active_since_s(i) > t_s - HELD_ROOM_S {
                return false;
            }
            let was = world.part_separation_at_m(i, &c.part, &then);
            was.is_finite() && was <= world.part_separation_at_m(i, &c.part, now) + DEEPER_M
        };
        let judged = judge_contacts(
            &mut self.touching,
            begun,
            &world.touching_now(),
            speed_m_s,
            &held,
        );
        for j in judged {
            self.events
                .push((j.contact.time_s, Event::Contact(j.clone())));
            self.contacts.push(j);
        }
    }

    /// Forgets the poses (a new lap of an open route starts elsewhere).
    pub(super) fn forget_poses(&mut self) {
        self.recent_poses.clear();
    }
}

/// The contacts `begun` since the last step, judged by the vehicle's speed now and, when it
/// moves, by whether the object came into room the vehicle held (`into_held_room`); and each
/// (object, part) pair `touching` now while the vehicle moves: one struck standing, or struck
/// while moving and now driven into (no longer `into_held_room`), judged at fault, once while
/// it lasts.
pub(super) fn judge_contacts(
    state: &mut Touching,
    begun: &[Contact],
    touching: &[Contact],
    speed_m_s: f64,
    into_held_room: &dyn Fn(&Contact) -> bool,
) -> Vec<JudgedContact> {
    let key = |c: &Contact| (c.object.clone(), c.part.clone());
    let lasts = |k: &Pair| touching.iter().any(|c| key(c) == *k);
    state.pushing.retain(lasts);
    state.came_in.retain(lasts);
    let moving = speed_m_s.abs() > AT_FAULT_SPEED_M_S;
    if !moving {
        // Standing, a pair struck while moving is one struck standing from now on.
        state.came_in.clear();
    }
    let mut judged = Vec::new();
    for c in begun {
        let k = key(c);
        if state.pushing.contains(&k) {
            continue;
        }
        state.came_in.retain(|p| *p != k);
        let j = JudgedContact::judged(c.clone(), speed_m_s, moving && into_held_room(c));
        if j.at_fault {
            state.pushing.push(k);
        } else if j.struck_while_moving {
            state.came_in.push(k);
        }
        judged.push(j);
    }
    if !moving {
        return judged;
    }
    for c in touching {
        let k = key(c);
        if begun.iter().any(|b| key(b) == k) || state.pushing.contains(&k) {
            continue;
        }
        if state.came_in.contains(&k) {
            if into_held_room(c) {
                continue;
            }
            state.came_in.retain(|p| *p != k);
        }
        state.pushing.push(k);
        judged.push(JudgedContact::new(c.clone(), speed_m_s));
    }
    judged
}
