//! The judge's unit tests: contacts and who was at fault, and the `yield` rule on a sampled
//! crossing.

use nalgebra::{Isometry2, Point2, Vector2};

use super::contacts::judge_contacts;
use super::traffic::{Mover, Samples, mover_crossed_s, window_encroachment};
use super::yielding::{YieldFacts, yield_met};
use super::*;
use crate::engine::conflict::{Body, Hull};
use crate::world::ObjectKind;

fn contact(time_s: f64) -> Contact {
    Contact {
        time_s,
        object: "van".into(),
        kind: ObjectKind::Vehicle,
        part: "nose".into(),
    }
}

/// A truck strikes the standing jet's wing (struck) and halts against it; the jet then
/// moves while they touch: at fault, once while it lasts; touching anew later, judged anew.
#[test]
fn a_contact_lasting_while_the_vehicle_moves_is_at_fault_once() {
    let c = |t: f64| Contact {
        time_s: t,
        object: "truck".into(),
        kind: ObjectKind::FuelTruck,
        part: "wing_left".into(),
    };
    let mut pushing = contacts::Touching::default();
    let never = |_: &Contact| false;
    let judge = |p: &mut contacts::Touching, begun: &[Contact], touching: &[Contact], v: f64| {
        judge_contacts(p, begun, touching, v, &never)
    };
    let j = judge(&mut pushing, &[c(1.0)], &[c(1.0)], 0.0);
    assert_eq!(j.len(), 1);
    assert!(!j[0].at_fault);
    assert!(judge(&mut pushing, &[], &[c(2.0)], 0.0).is_empty());
    let j = judge(&mut pushing, &[], &[c(3.0)], 0.8);
    assert_eq!(j.len(), 1);
    assert!(j[0].at_fault && j[0].contact.time_s == 3.0);
    assert!(judge(&mut pushing, &[], &[c(3.1)], 0.9).is_empty());
    // Apart, then touching again while moving: a new contact, judged once.
    assert!(judge(&mut pushing, &[], &[], 0.9).is_empty());
    let j = judge(&mut pushing, &[c(5.0)], &[c(5.0)], 0.9);
    assert_eq!(j.len(), 1);
    assert!(j[0].at_fault);
    assert!(judge(&mut pushing, &[], &[c(5.1)], 0.9).is_empty());
}

/// A van drives into the side of the jet moving off at 0.3 m/s: it overlaps the jet as it stood
/// half a second before at least as deeply - struck while moving, not at fault, and asked again
/// while they touch: at fault once the jet's own motion deepens it. The same contact where the
/// jet's half second made it (the jet into the van) is at fault; standing, the pair is one
/// struck standing, at fault when driven into.
#[test]
fn a_mover_into_room_the_moving_vehicle_held_is_struck_while_moving() {
    let c = |t: f64| Contact {
        time_s: t,
        object: "van".into(),
        kind: ObjectKind::Vehicle,
        part: "tail_cone".into(),
    };
    let mut state = contacts::Touching::default();
    let held = |_: &Contact| true;
    let not_held = |_: &Contact| false;
    let j = judge_contacts(&mut state, &[c(1.0)], &[c(1.0)], 0.3, &held);
    assert_eq!(j.len(), 1);
    assert!(!j[0].at_fault && j[0].struck_while_moving, "{:?}", j[0]);
    assert!(judge_contacts(&mut state, &[], &[c(1.1)], 0.25, &held).is_empty());
    // The jet's own motion deepens it: at fault, once while it lasts.
    let j = judge_contacts(&mut state, &[], &[c(1.2)], 0.25, &not_held);
    assert!(j.len() == 1 && j[0].at_fault, "{j:?}");
    assert!(judge_contacts(&mut state, &[], &[c(1.3)], 0.25, &not_held).is_empty());
    // Apart, then touching anew where the jet's own motion made it: at fault.
    assert!(judge_contacts(&mut state, &[], &[], 0.2, &held).is_empty());
    let j = judge_contacts(&mut state, &[c(3.0)], &[c(3.0)], 0.3, &not_held);
    assert!(j[0].at_fault && !j[0].struck_while_moving, "{:?}", j[0]);
    // Struck while moving, the jet stands, then moves while they still touch: at fault.
    let mut state = contacts::Touching::default();
    let j = judge_contacts(&mut state, &[c(5.0)], &[c(5.0)], 0.3, &held);
    assert!(j[0].struck_while_moving, "{:?}", j[0]);
    assert!(judge_contacts(&mut state, &[], &[c(5.5)], 0.0, &held).is_empty());
    let j = judge_contacts(&mut state, &[], &[c(6.0)], 0.2, &held);
    assert!(j.len() == 1 && j[0].at_fault, "{j:?}");
    // Standing, the held room is not asked: struck, as before.
    let mut state = contacts::Touching::default();
    let j = judge_contacts(&mut state, &[c(7.0)], &[c(7.0)], 0.01, &held);
    assert!(!j[0].at_fault && !j[0].struck_while_moving, "{:?}", j[0]);
}

#[test]
fn a_contact_while_standing_is_struck_and_while_moving_at_fault() {
    let standing = JudgedContact::new(contact(3.0), 0.01);
    assert!(!standing.at_fault);
    let reversing = JudgedContact::new(contact(3.0), -0.5);
    assert!(reversing.at_fault);
    let moving = JudgedContact::new(contact(3.0), 2.0);
    assert!(moving.at_fault);
    // The event and the report carry the contact's fields flat, and the attribution.
    let json = serde_json::to_value(Event::Contact(standing)).unwrap();
    assert_eq!(json["event"], "contact");
    assert_eq!(json["object"], "van");
    assert_eq!(json["at_fault"], false);
    assert_eq!(json["vehicle_speed_m_s"], 0.01);
}

/// A crossing sampled every 0.1 s for 30 s: the vehicle (a disc of 1 m) along +x towards
/// the crossing at x = 0, the mover (a disc of 1 m) along +y through it at 2 m/s, nearest
/// the route at `mover_at_s`. The vehicle drives at 2 m/s, standing from `stop_s` to
/// `go_s` at x = `stop_x`, and its front (1 m ahead) reaches x = 0 when it gets to -1 m.
fn judged_crossing(mover_at_s: f64, stop: Option<(f64, f64)>) -> (YieldFacts, YieldFacts) {
    let mut samples = Samples::default();
    let mut mover = Mover {
        solid_index: 0,
        id: "van".into(),
        body: Body::new(vec![Hull::disc(Point2::origin(), 1.0)]),
        vehicle: Body::new(vec![Hull::disc(Point2::origin(), 1.0)]),
        last: None,
        velocity: Vector2::zeros(),
        min_ttc_s: None,
        touched: false,
        armed: true,
        poses: Vec::new(),
    };
    let mut x = -30.0;
    let mut front_reached_s = None;
    for k in 0..=300 {
        let t = 0.1 * k as f64;
        let standing = stop.is_some_and(|(from, to)| (from..to).contains(&t));
        if k > 0 && !standing {
            x += 0.2;
        }
        if front_reached_s.is_none() && x + 1.0 >= 0.0 {
            front_reached_s = Some(t);
        }
        samples.t_s.push(t);
        samples
            .vehicle
            .push(Isometry2::new(Vector2::new(x, 0.0), 0.0));
        samples.joined.push(k > 0);
        mover.poses.push(Some(Isometry2::new(
            Vector2::new(0.0, 2.0 * (t - mover_at_s)),
            0.0,
        )));
    }
    let range = 0..samples.t_s.len();
    let facts = YieldFacts {
        contact: false,
        encroachment: window_encroachment(&samples, &mover, range.clone()),
        mover_crossed_s: mover_crossed_s(&samples, &mover, range, &Point2::origin()),
        front_reached_s,
        drove_on: true,
    };
    (
        facts,
        YieldFacts {
            drove_on: false,
            ..facts
        },
    )
}

#[test]
fn yield_is_met_when_the_mover_goes_first_and_the_vehicle_drives_on() {
    // The vehicle reaches x = -8 at 11 s and stands there until 20 s; the mover crosses
    // at 15 s. Mover first, PET > 0.
    let (facts, stuck) = judged_crossing(15.0, Some((11.0, 20.0)));
    let e = facts.encroachment.expect("their paths cross");
    assert_eq!(e.mover_first, Some(true), "{facts:?}");
    assert!(e.pet_s > 0.0, "{facts:?}");
    assert!(yield_met(&facts), "{facts:?}");
    // Still standing there when the run ended (not by time): not met.
    assert!(!yield_met(&stuck), "{stuck:?}");
    // A contact: not met.
    assert!(!yield_met(&YieldFacts {
        contact: true,
        ..facts
    }));
}

#[test]
fn yield_is_not_met_when_the_vehicle_goes_first() {
    // No stop: the vehicle crosses x = 0 at 15 s, the mover at 20 s.
    let (facts, _) = judged_crossing(20.0, None);
    assert_eq!(facts.encroachment.and_then(|e| e.mover_first), Some(false));
    assert!(!yield_met(&facts), "{facts:?}");
    // Together: not met either.
    let (facts, _) = judged_crossing(15.0, None);
    assert!(!yield_met(&facts), "{facts:?}");
}
