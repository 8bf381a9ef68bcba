//! The speed caps of `speed_cap` - a map obstacle closing on the vehicle (`closing`), a small
//! object seen only standing - through [`TrafficRules::decide`](super::TrafficRules::decide),
//! on a straight route.

use super::rules_tests::{inputs, rules, straight, track};
use super::{MoverDecision, MoverInputs, TrafficConfig};
use crate::planner::{AutonomyConfig, stopping_distance_m};
use mapper::TrackState;

/// The decisions of plans every 0.2 s for 1.6 s, the vehicle at 3 m/s, the first collision
/// at route position `at(t)`: the last one.
fn decide_closing(at: impl Fn(f64) -> f64) -> (MoverDecision, f64) {
    let config = AutonomyConfig::default();
    let poses = straight();
    let mut r = rules();
    let mut last = None;
    for k in 0..=8 {
        let t = 0.2 * k as f64;
        let s = 3.0 * t;
        // (The planner's collisions fall on its poses, 0.5 m apart: the jitter this gives
        // is `a_static_object_met_on_jittering_poses_is_not_closing`'s.)
        let stop = at(t) - s;
        let i = MoverInputs {
            s_m: s,
            stop_at_m: Some(stop),
            ..inputs(&poses, &[], &[], t, 3.0, &config)
        };
        last = Some((r.decide(&i), stop));
    }
    last.expect("plans")
}

/// A tug train seen as a mover only in flashes meets the slowing nose
/// (`tests/found/tug_train_meets_the_slowing_nose.toml`): its cells, static to the map,
/// close on the path at 1.7 m/s; the vehicle slows so that the two close at the caution
/// speed, and stops short of where the train will be when it stands.
#[test]
fn a_map_obstacle_closing_slows_the_vehicle_and_moves_its_stop_short() {
    let (d, stop) = decide_closing(|t| 40.0 - 1.7 * t);
    let cfg = TrafficConfig::default();
    let together = cfg.caution_speed_m_s - 1.7;
    assert!((d.wanted_m_s - together).abs() < 1e-9, "{d:?}");
    // Short by 1.7 m/s times the time to stand from 3 m/s (its stopping distance without the
    // buffer at half the speed: 2 s with these rules' 3 m/s^2).
    let config = AutonomyConfig::default();
    let to_stand_s = 2.0 * (stopping_distance_m(3.0, 3.0, &config) - config.stop_buffer_m) / 3.0;
    let moved = stop - d.stop_at_m.expect("a stop");
    assert!((moved - 1.7 * to_stand_s).abs() < 1e-9, "{moved} {d:?}");
    // A static object met the same way: the speed wanted, the stop where the map has it.
    let (d, stop) = decide_closing(|_| 40.0);
    assert_eq!(d.wanted_m_s, 5.0);
    assert_eq!(d.stop_at_m, Some(stop));
}

/// A person who stood beside the path walks on into the nose
/// (`tests/found/person_walks_on_into_the_slowing_nose.toml`): a small object seen only
/// standing, hit on both levels, within its reach of the path caps the speed at the caution
/// speed; a little farther off, on the ground level alone (a cone), or with the rule off, it
/// does not.
#[test]
fn a_small_object_seen_only_standing_beside_the_path_caps_the_speed() {
    let poses = straight();
    let config = AutonomyConfig::default();
    let cfg = &config.traffic;
    let object = |y: f64, levels: u32| {
        let mut t = track(3, 0.0, (30.0, y), (0.0, 0.0), levels);
        (t.confirmed, t.travel_m, t.extent_m) = (false, 0.0, 0.8);
        t
    };
    let person = |y: f64| object(y, 0b11);
    // The test model's ground circles are 1 m in radius on the route's line; the reach is 6 m
    // beyond half the person's footprint (0.5 m and 1 m hidden) and the 0.5 m margin.
    let edge_m = 1.0 + 1.5 + cfg.standing_object_reach_m + cfg.margin_m;
    assert_eq!(edge_m, 9.0);
    let wanted_for = |t: TrackState, config: &AutonomyConfig| {
        let standing = [t];
        let i = MoverInputs {
            standing: &standing,
            ..inputs(&poses, &[], &[], 0.0, 5.0, config)
        };
        rules().decide(&i).wanted_m_s
    };
    let wanted = |y: f64, config: &AutonomyConfig| wanted_for(person(y), config);
    assert_eq!(wanted(-(edge_m - 0.1), &config), cfg.caution_speed_m_s);
    assert_eq!(wanted(-(edge_m + 0.1), &config), 5.0);
    assert_eq!(wanted_for(object(-(edge_m - 0.1), 0b01), &config), 5.0);
    let mut off = config.clone();
    off.traffic.standing_object_max_m = 0.0;
    assert_eq!(wanted(-(edge_m - 0.1), &off), 5.0);
}
