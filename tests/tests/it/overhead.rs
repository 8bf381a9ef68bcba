//! Overhead structures in the closed loop: every vehicle's map has a ceiling (its top plus its
//! sidecar's `overhead_clearance_m`); what is above it is no obstacle, what reaches below it is.
//! Each scenario of `scenarios/` about it, run after its mapping drive.

use sim::engine::RunReport;
use sim::scenario::{RunConfig, Scenario};

use crate::common::{run_with, scenario};

/// A run-time structure the vehicle must drive under: passed, no stop anywhere, no contact.
fn assert_passes_under(s: Scenario, id: &str) -> RunReport {
    let name = s.name.clone();
    let r = run_with(&s, RunConfig::default());
    assert!(r.expectations_met, "{name}: {r:#?}");
    assert_eq!(r.obstacles.len(), 1);
    let o = &r.obstacles[0];
    assert_eq!(o.id, id);
    assert_eq!(o.passes.len(), 1, "{name}: {o:#?}");
    assert_eq!(o.passes[0].outcome.as_str(), "passed", "{name}: {o:#?}");
    assert!(o.passes[0].max_offset_m < 0.5, "{name}: {o:#?}");
    assert!(r.stops.is_empty(), "{name}: no stop-and-go: {:?}", r.stops);
    assert!(r.contacts.is_empty(), "{name}: {:?}", r.contacts);
    r
}

#[test]
fn the_car_passes_under_a_canopy_2_8_m_up_without_stopping() {
    let r = assert_passes_under(scenario("canopy_car"), "canopy");
    // The canopy's underside is 0.58 m above the Velodyne's top (2.22 m).
    let d = r.obstacles[0].passes[0].min_clearance_m[0];
    assert!((d - 0.58).abs() < 0.02, "{d}");
}

#[test]
fn the_jet_passes_under_a_footbridge_9_m_up() {
    assert_passes_under(scenario("footbridge_jet"), "footbridge");
    // The jet passed under it before the ceiling too, only because its nose sensor stops seeing
    // the deck 40 m out. Now the deck is in no level: as a static object, the offline map holds
    // exactly what it holds without it.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(&scenario("footbridge_jet").path).unwrap();
    let (before, deck) = text.split_once("[[obstacles]]").unwrap();
    let deck = deck.replace("expect = \"pass_under\"\n", "");
    let occupied = |text: &str, name: &str| {
        let path = dir.path().join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let s = Scenario::from_file(&path).unwrap();
        sim::offline_map::map_drive(
            &s,
            &RunConfig::default(),
            &dir.path().join(name),
            &mut |_, _| {},
        )
        .unwrap()
        .occupied_cells
    };
    let with_deck = occupied(&format!("{before}[[objects]]{deck}"), "with");
    let without = occupied(before, "without");
    assert_eq!(with_deck, without);
}

#[test]
fn the_car_stops_short_of_a_bar_whose_underside_is_1_9_m_up() {
    let s = scenario("low_bar_car");
    let r = run_with(&s, RunConfig::default());
    assert!(r.expectations_met, "{r:#?}");
    let pass = &r.obstacles[0].passes[0];
    assert_eq!(pass.outcome.as_str(), "stopped", "{r:#?}");
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    // It stopped before the bar was swung away (40 s), short of it (route x = 60 m), with room.
    let stop = &r.stops[0];
    assert!(stop.start_s < 40.0, "{stop:?}");
    assert!(stop.route_s_m < 60.0, "{stop:?}");
    assert!(pass.min_clearance_m[0] > 0.5, "{pass:?}");
}

/// The jet under a bridge 6 m up - below its ceiling (7.00 m), so an obstacle in both levels -
/// stops short of it with its tail clear and stays stopped (the deck never goes; the run ends
/// timed out, or calling for a pilot if the nose sensor loses sight of the deck). It struck the
/// deck with its T-tail at 31 s before: the deck faded once unseen (time-based forgetting), and
/// beams passing under it cleared it from level 1.
#[test]
fn the_jet_stops_short_of_a_bridge_6_m_up_and_stays_stopped() {
    let s = scenario("low_bridge_jet");
    let r = run_with(&s, RunConfig::default());
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert!(r.expectations_met, "{r:#?}");
    assert_eq!(r.stops.len(), 1, "{:?}", r.stops);
    assert_eq!(r.stops[0].end_s, None);
    let pass = &r.obstacles[0].passes[0];
    assert_eq!(pass.outcome.as_str(), "stopped");
    // The tail (fin and stabiliser, level 1) kept well clear of the deck.
    assert!(pass.min_clearance_m[1] > 1.0, "{pass:?}");
}

/// A ramp's overhang (issue 37): the airliner's wing passes over a parked business jet's wing
/// (`kind = "parked_aircraft"`: the jet's URDF parts as static objects) with a metre between them.
#[test]
fn the_airliner_s_wing_passes_over_a_parked_jet_s_wing() {
    let s = scenario("airliner_wing_over_parked_jet");
    let r = run_with(&s, RunConfig::for_scenario(&s, None).unwrap());
    assert!(r.expectations_met && r.contacts.is_empty(), "{r:#?}");
    // Ground truth, level 2 (the airliner's wing and what is above 2.1 m): 1.24 m to the parked
    // jet's parts; the gear and engines (levels 0 and 1) stay 3.4 and 1.5 m away.
    let levels = &r.min_clearance_m;
    assert!(
        (1.1..1.4).contains(&levels[2]) && levels[1] > 1.3 && levels[0] > 3.0,
        "{levels:?}"
    );
    // The parked jet's wing, seen a slice at a time as the airliner closes in, made a track whose
    // centre slid 2.8 m in 2 s; predicted across the taxilane, it held the airliner for 5 s.
    // Since the slow-mover changes of 2026-11-28 the airliner passes without stopping (not read
    // run by run why).
    assert!(r.stops.is_empty(), "{:?}", r.stops);
}
