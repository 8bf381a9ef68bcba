//! Traffic (issue 36): movers predicted and yielded to in closed loop, on the shipped
//! `scenarios/traffic_*.toml` edited or with their figures checked (the files' own expectations,
//! such as the vans timed to meet the jet's and the airliner's noses being yielded to, are
//! `taxi-sim regress`'s). Each run says what
//! the stack did (no contact while it moved, who went first) by the judge's ground truth.

use sim::engine::{EndReason, RunReport};
use sim::scenario::{PoseSourceConfig, RunConfig, Scenario};

use crate::common::{run_with, scenario};

fn run_default(s: &Scenario) -> RunReport {
    let config = RunConfig::for_scenario(s, None).unwrap();
    run_with(s, config)
}

/// The scenario `name` with `from` replaced by `to` in its text (it must occur).
fn edited(name: &str, from: &str, to: &str) -> Scenario {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(from), "{name} has no {from:?}");
    Scenario::from_str(&text.replace(from, to), &path).unwrap_or_else(|e| panic!("{e}"))
}

fn mover<'a>(r: &'a RunReport, id: &str) -> &'a sim::engine::ObstacleReport {
    r.obstacles.iter().find(|o| o.id == id).unwrap()
}

/// The crossing car of `crossing_vehicle.toml` at 1.0 m/s instead of 1.5 (the known problem
/// before issue 36: it drove into the side of the jet, which had stopped across its path, and
/// the jet moved on into it): no contact, the car first.
#[test]
fn a_slow_car_crossing_ahead_is_let_past() {
    let s = edited("crossing_vehicle", "speed_m_s = 1.5", "speed_m_s = 1.0");
    let r = run_default(&s);
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert!(r.expectations_met, "{r:#?}");
    assert_eq!(mover(&r, "crossing_car").pet_mover_first, Some(true));
}

/// The jet at 10 m/s (its sidecar allows 10.3) needs 41.3 m to stop; the planner checked 30 m
/// and drove into a car parked across the taxiway in plain view. The horizon now grows with
/// speed: it stops short. (True pose: with the particle filter this road's first revolution
/// leaves a phantom the jet waits for - `tests/found/phantom_from_the_first_revolution.toml`.)
#[test]
fn a_fast_jet_stops_short_of_a_car_parked_across_the_taxiway() {
    let s = scenario("traffic_parked_car_at_speed");
    let mut config = RunConfig::for_scenario(&s, None).unwrap();
    config.pose_source = PoseSourceConfig::Truth;
    let r = run_with(&s, config);
    assert!(r.expectations_met, "{r:#?}");
    let pass = &mover(&r, "parked_car").passes[0];
    assert!(pass.min_clearance_m[0] > 1.0, "{pass:?}");
    assert!(r.lap_times_s.len() == 1);
}

/// Blocked: the same car parked across the taxiway for good. The jet stops short of it, stands
/// with the car in plain view, and a minute after its plans first commanded speed 0
/// (`blocked_call_after_s`; they slow it to a crawl first, so within half a second of coming to
/// rest) calls for a pilot - an aircraft never steers round. Before, it stood to the run's time limit. With the setting at
/// 20 s, it calls 40 s sooner.
#[test]
fn a_jet_blocked_by_a_car_parked_for_good_calls_a_pilot() {
    let s = edited("traffic_parked_car_at_speed", "disappears_s = 60.0", "");
    for after_s in [60.0, 20.0] {
        let mut config = RunConfig::for_scenario(&s, None).unwrap();
        config.pose_source = PoseSourceConfig::Truth;
        config.autonomy.blocked_call_after_s = after_s;
        let r = run_with(&s, config);
        assert!(r.contacts.is_empty(), "{:?}", r.contacts);
        assert_eq!(r.end, EndReason::Blocked, "{:?}", r.stops);
        assert_eq!(r.stops.len(), 1, "{:?}", r.stops);
        let stood_s = r.sim_time_s - r.stops[0].start_s;
        assert!(
            (after_s - 0.5..=after_s + 0.11).contains(&stood_s),
            "stood {stood_s} s, blocked after {after_s} s"
        );
        assert_eq!(
            mover(&r, "parked_car").passes[0].outcome.as_str(),
            "stopped"
        );
    }
}

/// A baggage cart (1.0 m) driving past under the left wing's path (its level starts at 1.1 m)
/// does not stop the jet; a fuel truck (3.2 m) on the same path does. Its driver does not react:
/// it drives on into the standing jet's wing - struck, not the stack's fault (a jet cannot back
/// away; `traffic_reactive_van.toml` has a driver who stops).
#[test]
fn a_cart_passes_under_the_wing_a_fuel_truck_does_not() {
    let cart = run_default(&scenario("traffic_cart_under_wing"));
    assert!(cart.expectations_met, "{cart:#?}");
    assert!(cart.contacts.is_empty(), "{:?}", cart.contacts);
    let truck = run_default(&edited(
        "traffic_cart_under_wing",
        "kind = \"baggage_cart\"",
        "kind = \"fuel_truck\"",
    ));
    assert_eq!(truck.contacts_at_fault, 0, "{:?}", truck.contacts_judged);
    let first_stop = truck.stops.first().expect("the jet stops for the truck");
    assert!(
        truck
            .contacts
            .iter()
            .all(|c| c.time_s > first_stop.start_s + 1.0),
        "stopped at {} s: {:?}",
        first_stop.start_s,
        truck.contacts
    );
    // FIXME (docs/known-problems.md): the cart should not stop the jet at all; the jet holds
    // short of it for about 9 s (the cart's predicted footprint, widened by what it may hide
    // and its uncertainty, reaches the gear's path; and until the cart is within 24 m the
    // sensor, 1.55 m up, cannot tell it from a 1.5 m van - its open top - and a fragment of it
    // tracked apart is never bounded below the wing level). 7 s before the open top. Asserted
    // as it is.
    let stood: f64 = cart
        .stops
        .iter()
        .map(|s| s.end_s.unwrap_or(cart.sim_time_s) - s.start_s)
        .sum();
    assert!(
        (7.0..11.0).contains(&stood),
        "FIXME fixed? {:?}",
        cart.stops
    );
}

/// A van whose driver obeys the ramp rule stops for the jet; the jet, seeing it stand, drives on
/// without stopping.
#[test]
fn a_van_that_yields_is_passed_without_stopping() {
    let r = run_default(&scenario("traffic_reactive_van"));
    assert!(r.expectations_met, "{r:#?}");
    assert!(r.stops.is_empty(), "{:?}", r.stops);
    assert_eq!(mover(&r, "van").pet_mover_first, Some(false));
}
