//! Every pilot call says why, as data (`RunReport::pilot_call`): the rule that called, what held
//! the vehicle as the stack believed it and where, and - from ground truth - whether an object
//! stood there. A phantom that holds the car is a needless call; the cone a low LiDAR stops the
//! jet for, the cone under the nose of a jet without a walk-around, and a person who walked on
//! into the standing jet out of view, or a train that stopped at its nose out of view, are not;
//! a van standing in the path for good is a blocked way.

use std::path::PathBuf;

use sim::engine::Hold;
use sim::scenario::{RunConfig, Scenario};

fn file(path: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path);
    Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn run(s: &Scenario) -> sim::engine::RunReport {
    crate::common::run_with(s, RunConfig::for_scenario(s, None).unwrap())
}

/// The pilot call of the run of `path`, one for a mover the stack lost at its body.
fn waits_for_a_mover_at_its_body(path: &str) -> sim::engine::PilotCallReport {
    let call = run(&file(path)).pilot_call.expect("a pilot call");
    assert_eq!(call.call, "hidden_obstacle");
    assert!(
        matches!(
            call.hold,
            Some(Hold::LostObstacle {
                mover: Some(autonomy::traffic::LostMover::AtBody),
                ..
            })
        ),
        "{call:?}"
    );
    call
}

/// The degraded LiDAR's phantom at the start, as it was before beams with no echo cleared it.
#[test]
fn a_phantom_that_holds_the_car_is_a_needless_pilot_call() {
    let s = file("found/degraded_lidar_phantom_at_the_start_holds_the_car.toml");
    let mut config = RunConfig::for_scenario(&s, None).unwrap();
    config.mapping.map.no_echo_clears_within_m = 0.0;
    let r = crate::common::run_with(&s, config);
    let call = r.pilot_call.expect("a pilot call");
    assert_eq!(call.call, "hidden_obstacle");
    assert!(
        matches!(call.hold, Some(Hold::LostObstacle { mover: None, .. })),
        "map cells, not a mover: {call:?}"
    );
    let [x, _] = call.at_m.unwrap();
    assert!(x < 12.0, "held near its start: {call:?}");
    // Nothing within a metre of where the car believed it was: the nearest object is a lamp.
    assert!(call.needless, "{call:?}");
    assert!(
        call.nearest_object.as_ref().is_some_and(|(_, d)| *d > 5.0),
        "{call:?}"
    );
}

#[test]
fn a_cone_seen_in_the_path_or_in_the_unseen_ground_makes_a_call_that_was_needed() {
    let s = file("../scenarios/jet_with_a_low_lidar_sees_the_cone_at_its_nose.toml");
    let call = run(&s).pilot_call.expect("a pilot call");
    assert_eq!(call.call, "blocked");
    assert!(matches!(call.hold, Some(Hold::Obstacle { .. })), "{call:?}");
    let (id, d) = call.nearest_object.clone().unwrap();
    assert_eq!(id, "cone_left_at_the_nose");
    assert!(d < 0.3 && !call.needless, "{call:?}");
    let s = file("../scenarios/jet_waits_for_a_walk_around.toml");
    let call = run(&s).pilot_call.expect("a pilot call");
    assert_eq!(call.call, "walk_around");
    assert!(matches!(call.hold, Some(Hold::UnseenGround { unseen_m2 }) if unseen_m2 > 10.0));
    assert_eq!(
        call.nearest_object.as_ref().map(|o| o.0.as_str()),
        Some("cone_left_at_the_nose")
    );
    assert!(!call.needless);
    // The same stand without the cone: the wait was needless.
    let mut empty = s.clone();
    empty.obstacles.clear();
    let call = run(&empty).pilot_call.expect("a pilot call");
    assert_eq!(call.call, "walk_around");
    assert!(call.needless, "{call:?}");
}

/// The person of `person_walks_into_the_standing_jet.toml`, last seen a step short of the
/// fuselage, walked on into it out of view and stands against it: the stack waits for a mover
/// lost at its body, and the call was needed - the person is within centimetres of the
/// airframe, though over a metre from where the stack last saw them.
#[test]
fn a_person_who_walked_into_the_standing_jet_out_of_view_makes_a_call_that_was_needed() {
    let call = waits_for_a_mover_at_its_body("found/person_walks_into_the_standing_jet.toml");
    let (id, d) = call.nearest_object.clone().unwrap();
    assert_eq!(id, "person_1");
    assert!(d < 0.1 && !call.needless, "{call:?}");
}

/// A tug train gives way to the standing jet and stops 1.7 m from its nose, in the blind zone
/// (`found/tug_train_stops_at_the_nose_out_of_view.toml`): the stack waits for the train lost
/// at its body, last seen 3.4 m from where its nearest cart stands. More than a metre from
/// that point, yet within `AT_BODY_WITHIN_M` of the airframe: the call was needed.
#[test]
fn a_train_standing_at_the_nose_out_of_view_makes_a_call_that_was_needed() {
    let call = waits_for_a_mover_at_its_body("found/tug_train_stops_at_the_nose_out_of_view.toml");
    let (id, d) = call.nearest_object.clone().unwrap();
    assert!(id.starts_with("tug_2"), "{call:?}");
    assert!(
        d > sim::engine::REAL_WITHIN_M && d <= sim::engine::AT_BODY_WITHIN_M,
        "{call:?}"
    );
    assert!(!call.needless, "{call:?}");
}

/// A careful van standing in the path for good (variant 38 of `traffic_jet.toml`, without the
/// `makes_room_m` its careful vans have since: they clear the way now): the jet
/// stands short of its reach, stood for as an obstacle - a minute of it is a blocked way and a
/// pilot is called, with the van there - not yielding to no conflict, silent to the time limit.
#[test]
fn a_van_standing_in_the_path_is_a_blocked_way_not_a_silent_yield() {
    let r = run(&file(
        "found/careful_van_standing_in_the_path_blocks_the_jet.toml",
    ));
    let call = r.pilot_call.expect("a pilot call, not the time limit");
    assert_eq!(call.call, "blocked");
    assert!(matches!(call.hold, Some(Hold::Obstacle { .. })), "{call:?}");
    assert!(!call.needless, "{call:?}");
}

/// A tug towing three carts drives into the standing nose, under the LiDAR's lowest beam
/// (variant 826 of `traffic_jet_speed_profiles.toml`; the jet moved off against it before the
/// strike sensor): the airframe feels the strike, the jet stands and calls a pilot at once -
/// the call names the strike and, from ground truth, the tug against the nose - and never moves
/// while the tug touches it.
#[test]
fn a_tug_run_into_the_standing_nose_is_a_strike_the_jet_stands_for() {
    let r = run(&file(
        "found/tug_train_against_the_nose_the_jet_moves_off.toml",
    ));
    assert_eq!(r.end, sim::engine::EndReason::Struck);
    assert_eq!((r.contacts_at_fault, r.contacts_struck), (0, 1));
    let call = r.pilot_call.expect("a pilot call");
    assert_eq!(call.call, "struck");
    let Some(Hold::Struck { at_s }) = call.hold else {
        panic!("{call:?}");
    };
    // Called as soon as it stood: the tug struck the already standing jet.
    assert!((call.t_s - at_s).abs() < 0.05, "{call:?}");
    assert_eq!(r.contacts[0].time_s, at_s, "{:?}", r.contacts);
    let (id, d) = call.nearest_object.clone().unwrap();
    assert!(id == "tug_1" && d < 0.1, "{call:?}");
    assert!(!call.needless, "{call:?}");
}
