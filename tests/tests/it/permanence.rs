//! Object permanence in the closed loop: a cell fades only on evidence (a beam through it, or
//! the tracked object that painted it seen elsewhere), so an obstacle the airframe hides after
//! the vehicle stopped for it holds the vehicle until a pilot comes; what a moving object left
//! is still cleared (`closed_loop.rs`, the crossing vehicle).

use autonomy::ForgettingRule;
use sim::engine::{EndReason, RunReport};
use sim::scenario::RunConfig;

use crate::common::{run_with, scenario};

/// The A320-like airliner and the cart towed away from its engine's path (a known problem).
fn towed_cart() -> sim::scenario::Scenario {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("found/a320_cart_towed_from_under_the_fuselage.toml");
    sim::scenario::Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Stopped for a unit its airframe then hides, the jet waits and calls for a pilot: no contact,
/// the pass closes as a stop, and the report names where the hidden obstacle is.
fn assert_waits_for_hidden(name: &str, id: &str, at: (f64, f64)) -> RunReport {
    let r = run_with(&scenario(name), RunConfig::default());
    assert!(r.contacts.is_empty(), "{name}: {:?}", r.contacts);
    assert!(r.expectations_met, "{name}: {r:#?}");
    assert_eq!(r.end, EndReason::WaitingForHiddenObstacle);
    assert_eq!(r.obstacles[0].id, id);
    assert_eq!(r.obstacles[0].passes.len(), 1);
    assert_eq!(r.obstacles[0].passes[0].outcome.as_str(), "stopped");
    assert_eq!(r.stops.len(), 1, "{:?}", r.stops);
    assert_eq!(r.stops[0].end_s, None, "it never moves on");
    let w = r.waiting_for.as_ref().expect("says what it waits for");
    assert!(
        (w.x_m - at.0).abs() < 1.5 && (w.y_m - at.1).abs() < 1.5,
        "{name}: waits for ({:.1}, {:.1}), the unit is at {at:?}",
        w.x_m,
        w.y_m
    );
    let last = w.last_seen_s.expect("seen live before it was hidden");
    assert!(last < w.since_s, "{w:?}");
    r
}

#[test]
fn the_jet_waits_for_a_unit_its_wing_would_strike_once_its_airframe_hides_it() {
    assert_waits_for_hidden("unit_in_wing_path_jet", "gpu_under_wing", (80.0, 5.0));
}

/// The hazard the evidence rule removes, kept as an assertion: with time-based forgetting the
/// jet forgets the hidden unit after its stop, drives on and strikes it with the left wing.
#[test]
fn with_time_based_forgetting_the_jet_strikes_the_unit_it_stopped_for() {
    let mut config = RunConfig::default();
    config.mapping.forgetting.rule = ForgettingRule::TimeDecay;
    let r = run_with(&scenario("unit_in_wing_path_jet"), config);
    assert_eq!(r.stops.len(), 1, "{:?}", r.stops);
    let stop = &r.stops[0];
    assert!(stop.end_s.is_some(), "it went on: {stop:?}");
    assert!(
        r.contacts
            .iter()
            .any(|c| c.object == "gpu_under_wing" && c.part == "wing_left"),
        "{:?}",
        r.contacts
    );
    assert!(!r.expectations_met);
}

/// The A320-like airliner (three levels: gear, nacelles, wings) stops short of a cart in its
/// left engine's path, which its nose pod still sees under the fuselage; it waits while it sees
/// the cart and drives on only once it has seen it towed away (60 s), without contact - with the
/// sensor as it was before its calibration on a real HDL-32E (2 cm of range noise, no drop-off).
/// With the calibrated sensor (4 mm, 1.3 %) the cart's top near its front corner, at (99.7,
/// 5.5), is last hit 1.5 s before the stop and hidden from then on; when the cart vanishes at
/// 60 s (the scenario's tow, `disappears_s`) the rest of it is seen gone, but no beam can pass
/// through that cell (unseen is not gone), and the airliner waits for it until the pilot is
/// called: a known problem, in its file (`tests/found/a320_cart_towed_from_under_the_fuselage`,
/// which `taxi-sim regress` holds to it and to its golden numbers: where it waits, since when).
#[test]
fn the_airliner_waits_for_a_cart_in_its_engines_path_until_it_sees_it_towed_away() {
    let mut config = RunConfig::default();
    config.lidar.noise_stddev_m = 0.02;
    config.lidar.dropoff_general_rate = 0.0;
    let r = run_with(&towed_cart(), config);
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert!(r.expectations_met, "{r:#?}");
    assert_eq!(r.end, EndReason::Completed);
    // FIXME (docs/known-problems.md): as it starts, the airliner stops once more for 0.6 s
    // within its first metre while the particle filter settles again (its wingtips, 17 m out,
    // turn the heading's uncertainty into lateral uncertainty past the stop threshold).
    let (start_up, stops): (Vec<_>, Vec<_>) = r
        .stops
        .iter()
        .partition(|s| s.route_s_m < 1.0 && s.end_s.is_some_and(|e| e - s.start_s < 1.0));
    assert!(start_up.len() <= 1, "{:?}", r.stops);
    assert_eq!(stops.len(), 1, "{:?}", r.stops);
    let resumed = stops[0].end_s.expect("it drives on");
    assert!((60.0..63.0).contains(&resumed), "{:?}", r.stops);
    let pass = &r.obstacles[0].passes[0];
    assert_eq!(pass.outcome.as_str(), "stopped");
    // Three levels; the nacelles' (level 1) came nearest and stayed clear.
    assert_eq!(pass.min_clearance_m.len(), 3);
    assert!(pass.min_clearance_m[1] > 1.0, "{pass:?}");
}
