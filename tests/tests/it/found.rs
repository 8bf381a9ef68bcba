//! Failures the campaigns found and the stack does not handle yet, kept as plain scenario files
//! in `tests/found/` and asserted as they are (FIXME), so a fix shows here first.

use std::path::PathBuf;

use sim::engine::{RunSetup, run};
use sim::scenario::{RunConfig, Scenario};

use crate::common::nearest_m;

/// Runs a found scenario after its mapping drive (with the configuration the campaign found it
/// with: the true pose - every one was found before the particle filter became the default).
fn run_found(s: &Scenario) -> sim::engine::RunReport {
    run_found_with(s, |c| {
        c.pose_source = sim::scenario::PoseSourceConfig::Truth
    })
}

/// [`run_found`] with the configuration changed by `change`.
fn run_found_with(s: &Scenario, change: impl FnOnce(&mut RunConfig)) -> sim::engine::RunReport {
    let dir = tempfile::tempdir().unwrap();
    let mut config = RunConfig::for_scenario(s, None).unwrap();
    change(&mut config);
    sim::offline_map::map_drive(s, &config, dir.path(), &mut |_, _| {}).unwrap();
    let setup = RunSetup {
        config,
        ..RunSetup::new(dir.path().to_path_buf())
    };
    run(s, &setup).unwrap()
}

/// The calibrated HDL-32E (issue 39: 4 mm of range noise, 1.3 % drop-off) in place of the
/// sensor a case was found with (its scenario's `[config.lidar]`).
fn calibrated_sensor(c: &mut RunConfig) {
    c.lidar = sim::world::LidarConfig::default();
}

/// Each judged contact as (object, vehicle part), in time order.
fn contact_parts(r: &sim::engine::RunReport) -> Vec<(&str, &str)> {
    r.contacts_judged
        .iter()
        .map(|c| (c.contact.object.as_str(), c.contact.part.as_str()))
        .collect()
}

/// The run's one contact: `object` struck `part` of the standing vehicle (none at fault), and
/// the vehicle stayed, calling a pilot for it.
fn assert_struck_and_held(r: &sim::engine::RunReport, object: &str, part: &str) {
    assert_eq!(contact_parts(r), [(object, part)]);
    assert_eq!(
        (r.contacts_struck, r.contacts_at_fault),
        (1, 0),
        "{:?}",
        r.contacts_judged
    );
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
}

fn found(name: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("found")
        .join(format!("{name}.toml"));
    Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Fixed by issue 36 (prediction of movers): a van crossing the taxiway at 2.8 m/s from 35 m
/// right of it reaches the centreline as the Praetor-like jet's nose does. Before, the jet
/// planned against where things were and met the van's side while still moving (34.5 s); now
/// it yields: no contact, the van first.
#[test]
fn the_jet_yields_to_a_van_crossing_its_path() {
    let s = found("jet_meets_crossing_vehicle");
    let r = run_found(&s);
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    let van = r
        .obstacles
        .iter()
        .find(|o| o.id == "crossing_vehicle_1")
        .unwrap();
    assert_eq!(van.pet_mover_first, Some(true), "{van:?}");
    // The jet stood before the van crossed: its first stop began before the van's nearest
    // approach (the TTC was never under a second).
    assert!(van.min_ttc_s.is_none_or(|t| t > 1.0), "{van:?}");
}

/// Once a FIXME, now a regression: on a 320 m road with the particle filter, the first
/// revolution is taken at the fix (0.147 rad off with this seed): mapped, it left an obstacle at
/// (81.9, -2.7) m, at the height of the wings, that no later beam cleared, and the jet stopped
/// 14 m short of it and called a pilot. Mapping now starts once the estimate trusts a
/// revolution out to 70 m within `mapping.max_return_error_m` (1 m, 2 sigma), and the filter's
/// particles spread twice the fix's sigma (drawn with one, they collapsed 0.048 rad off): the
/// lap completes, and the parked car on it still stops the jet. With the bound lifted the
/// phantom is back - the bound is what mends it.
#[test]
fn a_revolution_taken_before_the_filter_settled_leaves_no_phantom() {
    let s = found("phantom_from_the_first_revolution");
    let run_with = |max_return_error_m: f64| {
        run_found_with(&s, |c| c.mapping.max_return_error_m = max_return_error_m)
    };
    let r = run_with(1.0);
    assert!(
        matches!(
            r.config.pose_source,
            sim::scenario::PoseSourceConfig::ParticleFilter(_)
        ),
        "the particle filter is this scenario's default"
    );
    assert_eq!(
        r.end,
        sim::engine::EndReason::Completed,
        "{:?}",
        r.waiting_for
    );
    assert!(r.expectations_met && r.contacts.is_empty());
    assert_eq!(
        r.obstacles[0].passes[0].outcome,
        sim::engine::PassOutcome::Stopped
    );

    let r = run_with(1e6);
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
    let w = r.waiting_for.expect("waiting for the phantom");
    assert!(
        (w.x_m - 81.9).abs() < 1.0 && (w.y_m + 2.7).abs() < 1.0,
        "{w:?}"
    );
    assert!(w.last_seen_s.is_some_and(|t| t < 0.5), "{w:?}");
}

/// Fixed: a fuel truck crossing 82 m along at 2.4 m/s passes 0.5 m from a lamp post. The stack
/// dropped every track whose hits touched an offline-map obstacle, lost the truck for 4.6 s and
/// met it again 5 m ahead (its nose LiDAR touched the truck at 0.35 m/s, at fault). Now hits on
/// and beside the offline map's obstacles are no mover's: the jet yields, the truck first.
/// Found by the traffic campaign (variant 60).
#[test]
fn the_jet_yields_to_a_fuel_truck_passing_a_lamp_post() {
    let r = run_found_with(&found("fuel_truck_meets_the_stopping_nose"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    let truck = r.obstacles.iter().find(|o| o.id == "fuel_truck_1").unwrap();
    assert_eq!(truck.pet_mover_first, Some(true), "{truck:?}");
    assert!(truck.pet_s.is_some_and(|t| t > 2.0), "{truck:?}");
    let pass = &truck.passes[0];
    assert!(pass.min_clearance_m.iter().all(|&c| c > 5.0), "{pass:?}");
}

/// Fixed: a person who does not react walks into the standing jet's fuselage (struck while
/// standing). Before, they walked on through the airframe and out under a wing, which met them
/// as the jet drove on (at fault). Now a mover that touches the vehicle halts there, and the
/// stack holds the jet for a mover at its body - where its map cannot hold it - and, the
/// person lost there, calls the pilot. Found by the traffic campaign (variant 187).
#[test]
fn a_person_at_the_standing_jets_body_holds_it_until_the_pilot_is_called() {
    let r = run_found_with(&found("person_walks_into_the_standing_jet"), |_| {});
    assert_eq!(r.contacts_at_fault, 0, "{:?}", r.contacts_judged);
    assert_eq!(r.contacts_struck, 1, "{:?}", r.contacts_judged);
    assert_eq!(r.contacts_judged[0].contact.object, "person_1");
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
}

/// Fixed: a fuel truck whose driver does not react strikes the standing jet's nose. Before, the
/// truck's track seemed to stop as the nose hid its front and its side came into view, and the
/// jet drove on into it (at fault). Now the truck halts where it struck and the jet is held
/// while the box of the truck's hits is at its body: after a minute standing for it, the jet
/// calls a pilot (blocked), the truck in view. Found by the traffic campaign (variant 192).
#[test]
fn a_truck_that_struck_the_standing_nose_holds_the_jet() {
    let r = run_found_with(&found("fuel_truck_strikes_the_standing_nose"), |_| {});
    assert_eq!(r.contacts_at_fault, 0, "{:?}", r.contacts_judged);
    let c = &r.contacts_judged;
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].contact.object, "fuel_truck_1");
    assert_eq!(c[0].vehicle_speed_m_s, 0.0, "{c:?}");
    assert_eq!(r.end, sim::engine::EndReason::Blocked);
}

/// Fixed: a 9 m fuel truck crossing at 1.3 m/s along its own length is offered for prediction
/// only once it has travelled 0.6 times its extent - 4.4 s, 35 m of the jet's at 8 m/s - and
/// the jet, 18.5 m short of where its wing would meet the truck, could not stop. Now a
/// candidate mover whose motion so far would meet the path caps the speed at 3 m/s until it is
/// confirmed or gone: the jet yields, the truck first. Without the cap (as it was) its left
/// wing tip touches the truck while moving. Found by the traffic campaign (variant 428).
#[test]
fn a_slow_truck_not_yet_confirmed_slows_the_jet_in_time() {
    let s = found("slow_fuel_truck_meets_the_wing_tip");
    let r = run_found_with(&s, |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    let truck = r.obstacles.iter().find(|o| o.id == "fuel_truck_1").unwrap();
    assert_eq!(truck.pet_mover_first, Some(true), "{truck:?}");
    let was = run_found_with(&s, |c| c.autonomy.traffic.caution_speed_m_s = 100.0);
    assert_eq!(was.contacts_at_fault, 1, "{:?}", was.contacts_judged);
    assert_eq!(was.contacts_judged[0].contact.part, "wing_left");
}

/// Changed, not mended at its root: the jet stops for one fuel truck ahead (2.8 m/s) with its
/// tail across the path of a slower one (1.08 m/s), which it never predicts (read at 0.55 m/s,
/// under the floor of prediction). Before, a ghost's track expired and the jet moved off as the
/// slow truck reached its nacelle (at fault, 0.13 m/s); with the calibrated sensor it crept into
/// it at 0.055 m/s after being struck. Now a mover known to move stays predicted below the floor
/// while in view: the slow truck strikes the standing nacelle and the jet stands for it (README,
/// Known problems); with the calibrated sensor the jet stays clear of it. Found by the traffic
/// campaign (variant 560 of 1000 on 8c04d85).
#[test]
fn a_truck_lost_toward_the_standing_jet_is_waited_for() {
    let r = run_found_with(&found("fuel_truck_meets_the_stopping_jets_nacelle"), |_| {});
    assert_eq!(r.contacts_at_fault, 0, "{:?}", r.contacts_judged);
    assert_eq!(contact_parts(&r), [("fuel_truck_1", "wing_left")]);
    assert_eq!(r.end, sim::engine::EndReason::Blocked);
    let r = run_found_with(
        &found("fuel_truck_meets_the_stopping_jets_nacelle"),
        calibrated_sensor,
    );
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
}

/// Fixed: found by the traffic campaign on the calibrated LiDAR (variant 559 of 1000 on
/// aa8261c): a van crossing diagonally at 4.5 m/s met the left wing tip of the jet moving off at
/// 1.07 m/s (at fault). Its speed seemed to fall to 1.7 m/s as it went into the shadow of the
/// wing, and it was lost at that speed: predicted 13 m short of the wing line, the jet resumed.
/// Now a mover's footprint reaches to where the fastest speed it was seen at lately would take
/// it: the jet stays stopped, the van strikes the standing wing, the pilot is called.
#[test]
fn a_van_lost_in_the_wings_shadow_finds_the_jet_standing() {
    let r = run_found_with(&found("van_crosses_under_the_braking_jets_wing"), |_| {});
    assert_struck_and_held(&r, "van_1", "wing_left");
}

/// Fixed: found by the traffic campaign on the calibrated LiDAR (variant 592 of 1000 on
/// aa8261c): a fuel truck crossing square to the route at 1.23 m/s was met by the creeping jet
/// (0.82 m/s: fuselage, then right wing). A long truck close by seems to slow as the airframe
/// hides its front and fell under the floor of prediction. Now a mover known to move stays
/// predicted down to half the floor while in view: the jet stands, the truck strikes its nose.
#[test]
fn a_slow_fuel_truck_finds_the_jet_standing() {
    let r = run_found_with(
        &found("slow_fuel_truck_meets_the_creeping_fuselage"),
        |_| {},
    );
    assert_eq!(contact_parts(&r), [("fuel_truck_2", "nose")]);
    assert_eq!(r.contacts_at_fault, 0, "{:?}", r.contacts_judged);
}

/// Fixed: found by the traffic campaign on the calibrated LiDAR (variant 886 of 1000 on
/// aa8261c): the jet stopped 20 s for a fuel truck crossing square at 1.34 m/s (a ghost track of
/// it read at 5 m/s stopped the jet with its nose in the truck's lane), moved off as the truck,
/// now read at 0.65 m/s (its front hidden), fell under the floor of prediction, and met it with
/// its left wing at 1.13 m/s. Now the known mover stays predicted: the jet stands and the truck
/// strikes its fuselage (it stands there, as a mover touching the vehicle does in the
/// simulator, and after a minute the jet calls a pilot: blocked). Stopping in the lane at all is the needless part (README, Known
/// problems).
#[test]
fn the_jet_does_not_move_off_into_a_slow_fuel_truck() {
    let r = run_found_with(&found("jet_moves_off_into_a_slow_fuel_truck"), |_| {});
    assert_eq!(contact_parts(&r), [("fuel_truck_1", "fuselage")]);
    assert_eq!(r.contacts_at_fault, 0, "{:?}", r.contacts_judged);
    assert_eq!(r.end, sim::engine::EndReason::Blocked);
}

/// Fixed: found by the random traffic campaign on b324193 (variant 2): a van (1.5 m) crossing
/// diagonally at 4.6 m/s struck the standing jet's right wing, and the jet then moved off while
/// it touched (at fault). Its track was lost 28 m off with its speed read at 1.4 m/s and in the
/// ground level only: the jet's sensor, 1.55 m up, hits it there only below 1.1 m, its 0-degree
/// beam passing over the roof. Now the beam above says the van may reach 1.55 m (its open top,
/// `mapper::TrackState::open_top_m`), so it counts against the wings: the jet stands, the van
/// crosses first, 7 m clear.
#[test]
fn a_van_seen_only_low_is_waited_for_at_the_wing() {
    let r = run_found_with(&found("van_touching_the_wing_is_not_held_for"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    let van = r.obstacles.iter().find(|o| o.id == "van_2").unwrap();
    assert_eq!(van.pet_mover_first, Some(true), "{van:?}");
    let clearance = nearest_m(&van.passes[0]);
    assert!(clearance > 5.0, "{van:?}");
}

/// Fixed: a person walking toward the taxiway stands 14 s 4.7 m left of the centreline, inside
/// the wings' sweep, then walks on across. The jet (8 m/s) stopped for them at its wing, its
/// nose and fuselage drawing up beside them, and the person walking on met the fuselage's side
/// while the jet still braked (0.75 m/s, at fault). Now a known mover standing may walk on
/// without warning: the jet passes within `standing_reach_m` (3 m) of one at the caution speed
/// and stops short of that reach - here 7.8 m from them, and they cross first. Found by the
/// falsifier on the traffic campaign with movers that stop (variant 13 on c4fdc01).
#[test]
fn a_person_standing_beside_the_nose_is_stopped_short_of() {
    let r = run_found_with(&found("person_standing_beside_the_nose_walks_on"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    assert_eq!(
        r.end,
        sim::engine::EndReason::Completed,
        "{:?}",
        r.waiting_for
    );
    let person = &r.obstacles[0];
    assert_eq!(person.pet_mover_first, Some(true), "{person:?}");
    // Stopped short of the 3 m reach beyond the person's footprint (1.25 m from its centre)
    // and the margin (0.5 m), on every level: the circles 4.75 m from their centre, their body
    // (0.25 m) 4.5 m from the circles, which cover the airframe.
    let clearance = nearest_m(&person.passes[0]);
    assert!(clearance > 4.4, "{person:?}");
}

/// Fixed: a tug towing three baggage carts (14 m) crosses square at 1.18 m/s ahead of the jet
/// at 3 m/s. Seen as fragments, none confirmed as a mover, the train only capped the speed; the
/// jet planned to stop with its wing short of the tug, its nose across the tug's way, and the
/// tug met the nose at 1.9 m/s (at fault). Now where a candidate mover's motion meets the path
/// is held for 2 s (the caution line) and a stop is moved short of it when the vehicle can
/// stop before it: the whole train crosses first, none nearer than 3 m. The run ends calling a
/// pilot for a cart lost 8 m beyond the wing tip (the train's merged box reached it): safe, not
/// needed (Known problems). Found by the random campaign with towed trains (variant 80 on
/// c4fdc01).
#[test]
fn a_tug_train_crosses_before_the_jet_stopping_for_it() {
    let r = run_found_with(&found("tug_train_crosses_the_stopping_nose"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    assert_eq!(r.obstacles.len(), 4, "the tug and its three carts");
    for o in &r.obstacles {
        assert_eq!(o.pet_mover_first, Some(true), "{o:?}");
        let clearance = nearest_m(&o.passes[0]);
        assert!(clearance > 3.0, "{o:?}");
    }
    // FIXME: a cart lost beyond the wing tip is waited for (a needless pilot call).
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
}

/// Fixed: a van that does not react stands by the road 3 m left of the nose's path, then speeds
/// up across it. The jet stopped beside it, the van drove into the nose (struck) and the jet
/// moved off while it touched (at fault). Now a known mover that arrived lately and stands
/// within its reach of the standing vehicle holds it: the van still strikes the standing nose
/// (it does not react), and the jet stays, calling a pilot. Found by the random campaign with
/// movers that stop (variant 84 on c4fdc01).
#[test]
fn a_van_standing_at_the_nose_holds_the_jet() {
    let r = run_found_with(&found("van_stopped_by_the_road_goes_on"), |_| {});
    assert_struck_and_held(&r, "stop_and_go_van_1", "nose");
}

/// FIXME: a van that does not react stops with its front 1.2 m from the jet's path and goes on
/// 8 s later. The jet's stop for it is moved short of the standing van's reach; creeping toward
/// that line the jet drops it as too late to stop short of (its stopping distance counts the 3 m
/// stop buffer), drives on at 3 m/s, and the van goes on into its nose (at fault). Counting
/// braking alone mends this run but lets a van strike the standing wing in another (the
/// scenario file says which): not landed. Found by the speed-profile campaign (variant 105 on
/// 308acd2). Asserted as it is.
#[test]
fn a_van_stopping_at_the_edge_of_the_path_goes_on_into_the_nose_as_it_is() {
    let r = run_found_with(
        &found("van_stopping_at_the_edge_goes_on_into_the_nose"),
        |_| {},
    );
    let first = r.contacts_judged.first().expect("a contact");
    assert_eq!(
        (first.contact.object.as_str(), first.contact.part.as_str()),
        ("stop_and_go_van_1", "nose")
    );
    assert!(first.at_fault && first.vehicle_speed_m_s > 1.0, "{first:?}");
}

/// Fixed: a person stands 16 s 15 m right of the taxiway, hidden from the nose sensor by the
/// approaching airframe, then walks on unseen across behind the wing into the standing jet's
/// tail cone (struck) and stays there; the jet moved off after the fuel truck it stood for had
/// passed, while they touched it (at fault). Nothing the stack saw says they moved, and the
/// sensor does not see the tail: now a small known mover lost while standing may have walked
/// on (1.5 m/s since it was last seen), and one that may have reached the standing vehicle's
/// body is waited for - the pilot is called (since the jet stops short of people standing, the
/// person walks into its standing fuselage instead: struck, the jet stays). Found by the random campaign with movers that stop
/// (variant 61 on c4fdc01).
#[test]
fn a_person_lost_standing_is_waited_for_at_the_tail() {
    let r = run_found_with(&found("person_lost_standing_walks_into_the_tail"), |_| {});
    assert_eq!(r.contacts_at_fault, 0, "{:?}", r.contacts_judged);
    assert!(r.contacts_struck <= 1, "{:?}", r.contacts_judged);
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
}

/// Fixed: the jet at 3 m/s passed a person standing about 2 m beyond its right wing tip's path,
/// at the caution speed for passing within reach of a mover standing; the person walked on
/// across and the right wing met them (at fault): from 2 m they reach the path before the
/// tracker sees them move and the jet can stop. Now the jet stops short of a person's reach
/// (a small mover once seen walking, standing: `Driver::short_of_walkers`) and waits. The run
/// ends calling a pilot for the other person, lost standing at the end of their way 28 m off
/// (safe, not needed). Found by the speed-profile campaign (variant 28 on fe2aa19).
#[test]
fn a_person_standing_by_the_wing_tip_is_stopped_short_of() {
    let r = run_found_with(&found("person_standing_by_the_wing_tip_walks_on"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    assert!(!r.stops.is_empty());
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
}

/// FIXME: the jet at 8 m/s slows for a tug towing two carts; a person who stood 16 s 7.7 m from
/// the centreline walks on into the taxiway and the nose meets them at 2.7-3.0 m/s (at fault).
/// The stack only ever saw them standing (a post, to it); they walk on with the nose about 25 m
/// off, are predicted 0.8 s later, and reach the path in 3-4 s - the jet needs 5.3 s to stop
/// from 8 m/s. Found by the speed-profile campaign (variant 66 on fe2aa19). Asserted as it is.
#[test]
fn a_person_walks_on_into_the_slowing_nose_as_it_is() {
    let r = run_found_with(&found("person_walks_on_into_the_slowing_nose"), |_| {});
    let first = r.contacts_judged.first().expect("a contact");
    assert_eq!(
        (first.contact.object.as_str(), first.contact.part.as_str()),
        ("standing_person_2", "nose")
    );
    assert!(first.at_fault && first.vehicle_speed_m_s > 2.0, "{first:?}");
}

/// FIXME: the jet at 5 m/s; a tug towing four carts crosses at 1.66 m/s, 120 degrees to the
/// route, and the slowing jet meets it with its nose (1.53 m/s, at fault). The train is a
/// candidate mover only in flashes, never confirmed; the caution speed lapses 2 s after the
/// last flash and the jet speeds up toward its cells, closing on the path in the map, until
/// they cross into it 5 m ahead (the scenario file has the times). Found by the speed-profile
/// campaign (variant 87 on 308acd2). Asserted as it is.
#[test]
fn a_tug_train_meets_the_slowing_nose_as_it_is() {
    let r = run_found_with(&found("tug_train_meets_the_slowing_nose"), |_| {});
    let first = r.contacts_judged.first().expect("a contact");
    assert_eq!(
        (first.contact.object.as_str(), first.contact.part.as_str()),
        ("tug_2", "nose")
    );
    assert!(first.at_fault && first.vehicle_speed_m_s > 1.0, "{first:?}");
}

/// Fixed: the van of `van_strikes_the_tail_of_the_standing_jet` with the calibrated sensor and
/// a follow-me car appearing earlier: lost behind the right wing, read at 4.2 m/s (it drives
/// 6.3, and was seen at 6.5), it strikes the standing wing. Its track dropped with its
/// prediction at the read speed not yet at the body, and the jet moved off while it touched (at
/// fault). Now a dropped mover is waited for if it may be at the body at any speed up to its
/// peak: struck while standing, the pilot called. Found by the random campaign (variant 963 of
/// 1000 on 308acd2).
#[test]
fn a_van_lost_behind_the_wing_holds_the_jet_it_struck() {
    let r = run_found_with(&found("van_lost_behind_the_wing_strikes_it"), |_| {});
    assert_eq!(contact_parts(&r), [("van_1", "wing_right")]);
    assert_eq!((r.contacts_struck, r.contacts_at_fault), (1, 0));
    assert_eq!(r.contacts_judged[0].vehicle_speed_m_s, 0.0);
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
}

/// Fixed: a person walking toward the standing jet's right wing, confirmed, is lost under it
/// while walking and strikes the standing wing. Their track dropped 1.9 s after they were last
/// seen, under the 2 s a track had to coast before its drop was checked at the body; once the
/// van the jet stood for had passed it drove on into them (wing, then right main gear, at
/// fault). Now 1.5 s: struck while standing, the pilot called. Found by the falsifier (sample
/// 757 of 1000 on 308acd2).
#[test]
fn a_person_lost_under_the_wing_holds_the_jet() {
    let r = run_found_with(&found("person_lost_walking_under_the_wing"), |_| {});
    assert_eq!(contact_parts(&r), [("person_2", "wing_right")]);
    assert_eq!((r.contacts_struck, r.contacts_at_fault), (1, 0));
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
}

/// Not a case any stack can pass, kept as the evidence for the campaign's change: a follow-me car
/// appeared (`appears_s` 29.6 s) 3.2 m left of the centreline ahead of the jet at 8 m/s - inside
/// its stopping distance - and drove toward it. The stack braked at once (from the speed at the
/// first contact, braking at the jet's 1.5 m/s^2 began within 0.3 s of the appearance), and the
/// left wing still met the car. The traffic campaign now has follow-me cars turn onto the
/// taxiway in the first 8 s, at least 85 m ahead. Found by the traffic campaign (variant 880 of
/// 1000 on 8c04d85).
#[test]
fn a_follow_me_car_appearing_at_the_wing_cannot_be_avoided() {
    let s = found("follow_me_car_appears_at_the_wing");
    let appears_s = s.obstacles[0].appears_s;
    let r = run_found_with(&s, |_| {});
    let first = r.contacts_judged.first().expect("a contact");
    assert_eq!(first.contact.part, "wing_left", "{:?}", r.contacts_judged);
    // 8 m/s down to the contact's speed at 1.5 m/s^2 at most: braking began by this time.
    let braking_by_s = first.contact.time_s - (8.0 - first.vehicle_speed_m_s) / 1.5;
    assert!(
        braking_by_s - appears_s < 0.3,
        "braking by {braking_by_s:.2} s, the car appeared at {appears_s:.2} s"
    );
}

/// Fixed: a van crossing at 6.3 m/s, predicted, then lost into the blind zone behind the
/// standing jet's wing, strikes its tail cone (struck while standing). Before, its track
/// expired 6 s after it was last seen - a second before it arrived - and the jet moved off while
/// the van still touched the tail (at fault). Now a mover whose track drops while it is
/// predicted to reach the standing vehicle's body is waited for as one lost there: the pilot is
/// called. Found by the traffic campaign (variant 963 of 1000 on 8c04d85). Since the open top
/// (a confirmed mover counts in the levels its unseen top may reach) the jet stands elsewhere
/// and the van strikes its right wing rather than its tail cone (not read why).
#[test]
fn a_van_lost_behind_the_wing_holds_the_standing_jet() {
    let r = run_found_with(&found("van_strikes_the_tail_of_the_standing_jet"), |_| {});
    assert_eq!(
        (r.contacts_struck, r.contacts_at_fault),
        (1, 0),
        "{:?}",
        r.contacts_judged
    );
    let c = &r.contacts_judged[0].contact;
    assert_eq!(
        (c.object.as_str(), c.part.as_str()),
        ("van_1", "wing_right")
    );
    assert_eq!(r.contacts_judged[0].vehicle_speed_m_s, 0.0);
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
    // With the calibrated sensor the van never touches the jet.
    let r = run_found_with(
        &found("van_strikes_the_tail_of_the_standing_jet"),
        calibrated_sensor,
    );
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
}

/// Fixed: a one-cell ghost at a crossing fuel truck's far end, 53 m off the road, seemed to
/// move toward it at 7.7 m/s (never confirmed); its track dropped after 6 s out of view while
/// its prediction put it at the standing jet's body, and the jet waited for it as a mover lost
/// there - the pilot was called where the lap used to complete. Now only confirmed movers are
/// waited for. Found by the traffic campaign (variant 19 on ff63a25).
#[test]
fn a_ghost_track_lost_far_off_does_not_call_the_pilot() {
    let r = run_found_with(&found("ghost_of_a_fuel_truck_lost_far_off"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    assert_eq!(r.end, sim::engine::EndReason::Completed, "{:?}", r.stops);
}

/// Fixed (issue 37): on KSYR's taxiway W the file's network runs 9-14 m off the painted
/// centreline near the runway 10/28 crossing; following it, the jet's left main gear struck an
/// elevated edge light at 5 m/s (the light is too small for the LiDAR to resolve in time). Routes
/// now follow the painted centreline where the network strays (`airport::paint`): the jet taxis
/// W on its paint and touches nothing. Needs `../shared/data` (run with `--ignored`, as CI does).
/// Found on a 3.4 km route.
#[test]
#[ignore = "reads ../shared/data"]
fn shared_data_the_jet_taxis_w_on_its_paint_clear_of_the_edge_lights() {
    let r = run_found_with(&found("ksyr_gear_meets_an_edge_light_on_w"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts_judged);
    assert_eq!(r.end, sim::engine::EndReason::Completed, "{:?}", r.stops);
    // The nearest static objects are W's edge lights, 1.39 m from the airframe at their closest
    // (the gear had met one).
    let nearest = &r.closest_static[0];
    assert_eq!(
        nearest.kind,
        sim::world::ObjectKind::EdgeLight,
        "{nearest:?}"
    );
    assert!(nearest.min_clearance_m > 1.0, "{:?}", r.closest_static);
}

/// FIXME (README, Known problems): a 0.104 m piece of debris 0.39 m left of the car's
/// centreline, just over the obstacle height (0.1 m): the car starts round it too late, stops
/// 0.15 m short of it, and with the debris hidden under its nose waits and calls for a pilot
/// rather than drive on. Found by the falsifier on the debris family (variant 258).
#[test]
fn fixme_the_car_stops_short_of_low_debris_and_calls_a_pilot() {
    let s = found("car_stops_short_of_low_debris");
    let r = run_found(&s);
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
    let pass = &r.obstacles[0].passes[0];
    assert_eq!(pass.outcome, sim::engine::PassOutcome::Stopped);
    assert!((0.1..0.2).contains(&pass.min_clearance_m[0]), "{pass:?}");
}

/// FIXME (README, Known problems): in about one in two hundred passes of the parking-lot
/// campaign the car goes round a cone under its wing's path that it should pass under; here a
/// 0.48 m cone 1.69 m right of the route (the wing is at 0.70 m) on the first aisle. Found by
/// the parking-lot campaign (variant 487); not yet explained.
#[test]
fn fixme_the_car_goes_round_a_cone_it_should_pass_under() {
    let r = run_found(&found("parking_lot_variant_487"));
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    let cone = r.obstacles.iter().find(|o| o.id == "cone_wing_1").unwrap();
    assert_eq!(cone.passes[0].outcome, sim::engine::PassOutcome::Deviated);
    assert!(!cone.passes[0].met);
    let others_met = r
        .obstacles
        .iter()
        .filter(|o| o.id != "cone_wing_1")
        .all(|o| o.passes.iter().all(|p| p.met));
    assert!(others_met, "{:?}", r.obstacles);
}

/// Variant 505's container pass, with no contact in the run and the car deviating round it, and
/// its smallest clearance over the levels.
fn container_pass(r: &sim::engine::RunReport) -> (&sim::engine::Pass, f64) {
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    let o = r.obstacles.iter().find(|o| o.id == "cone_path_1").unwrap();
    let p = &o.passes[0];
    assert_eq!(p.outcome, sim::engine::PassOutcome::Deviated);
    let closest = nearest_m(p);
    (p, closest)
}

/// FIXME (README, Known problems): the car goes round a 0.98 m container 0.11 m right of the
/// route 0.19 m from it, inside the danger distance (0.2 m). Found by the parking-lot campaign
/// (variant 505).
#[test]
fn fixme_the_car_passes_a_container_inside_the_danger_distance() {
    let r = run_found(&found("parking_lot_variant_505"));
    let (p, closest) = container_pass(&r);
    assert!((0.15..0.2).contains(&closest), "{p:?}");
    assert!(!p.met);
    // With the calibrated sensor (and still the true pose) it passes 0.62 m from it: the cause is
    // not found, the 2-cm range noise brought it out.
    let r = run_found_with(&found("parking_lot_variant_505"), |c| {
        c.pose_source = sim::scenario::PoseSourceConfig::Truth;
        calibrated_sensor(c);
    });
    let (p, closest) = container_pass(&r);
    assert!(closest > 0.4 && p.met, "{p:?}");
}

/// With the particle filter (the default since issue #24) the same variant passes the container
/// outside the danger distance: the estimate's uncertainty widens the margins (0.68 m off when
/// the particles spread as the fix; 0.49 m since they spread twice as far and the estimate is
/// better). The cause above is not found yet; this only shows the default hides it.
#[test]
fn with_the_particle_filter_the_container_is_passed_outside_the_danger_distance() {
    let r = run_found_with(&found("parking_lot_variant_505"), |_| {});
    let (p, closest) = container_pass(&r);
    assert!(closest > 0.4 && p.met, "{p:?}");
}

/// FIXME (issue 37; README, Known problems): the Praetor-like jet taxis under a parked
/// airliner's wing, 2.9 to 3.5 m up, a metre above its own wing (ground truth: 1.24 m at level 1,
/// with the particle filter). Its map has two levels (0 and 1.1 m, cumulative), so the airliner's
/// wing is an obstacle to its wing circles: it stops short (about 71 m along), the wing goes out of
/// its nose sensor's view, and it calls a pilot. What a third height of interest (or banded
/// levels) would change is issue 40's question.
#[test]
fn fixme_the_jet_stops_under_a_parked_airliners_wing_a_metre_above_its_own() {
    let r = run_found_with(&found("jet_under_parked_airliner_wing"), |_| {});
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert_eq!(r.end, sim::engine::EndReason::WaitingForHiddenObstacle);
    assert_eq!(r.stops.len(), 1, "{:?}", r.stops);
    assert!(
        (60.0..75.0).contains(&r.stops[0].route_s_m),
        "{:?}",
        r.stops
    );
    assert!(r.min_clearance_m[1] > 1.0, "{:?}", r.min_clearance_m);
}
