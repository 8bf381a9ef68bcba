//! The contacts and who was at fault: judged when they begin, and again, once, if the vehicle
//! moves while they last.

use super::Judge;
use crate::engine::outcome::{AT_FAULT_SPEED_M_S, Event, JudgedContact};
use crate::world::{Contact, World};

impl Judge {
    /// The contacts begun since the last step and those lasting while the vehicle moves,
    /// judged ([`judge_contacts`]).
    pub(super) fn judge_contacts(&mut self, speed_m_s: f64, world: &World) {
        let begun = &world.contacts()[self.contacts_seen..];
        self.contacts_seen = world.contacts().len();
        let judged = judge_contacts(&mut self.pushing, begun, &world.touching_now(), speed_m_s);
        for j in judged {
            self.events
                .push((j.contact.time_s, Event::Contact(j.clone())));
            self.contacts.push(j);
        }
    }
}

/// The contacts `begun` since the last step, judged by the vehicle's speed now; and each
/// (object, part) pair `touching` now while the vehicle moves - a mover that struck it standing
/// and halted against it, then driven into - judged at fault, once while it lasts. `pushing`
/// holds the pairs touching and already judged at fault.
pub(super) fn judge_contacts(
    pushing: &mut Vec<(String, String)>,
    begun: &[Contact],
    touching: &[Contact],
    speed_m_s: f64,
) -> Vec<JudgedContact> {
    let key = |c: &Contact| (c.object.clone(), c.part.clone());
    pushing.retain(|k| touching.iter().any(|c| key(c) == *k));
    let moving = speed_m_s.abs() > AT_FAULT_SPEED_M_S;
    let pushed = touching
        .iter()
        .filter(|c| moving && !begun.iter().any(|b| key(b) == key(c)));
    let mut judged = Vec::new();
    for c in begun.iter().chain(pushed) {
        if pushing.contains(&key(c)) {
            continue;
        }
        let j = JudgedContact::new(c.clone(), speed_m_s);
        if j.at_fault {
            pushing.push(key(c));
        }
        judged.push(j);
    }
    judged
}
