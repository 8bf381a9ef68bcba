//! What the rules remember of a track that only shows less of itself where it stood as the
//! vehicle goes by (`TrafficRules::hidden_in_place`, `memory.rs`), on made-up tracks.

use mapper::TrackState;
use nalgebra::Isometry2;

use super::rules_tests::{rules, track};
use super::*;
use crate::planner::AutonomyConfig;

/// A track of the box of cells `x0..=x1` by `y0..=y1` (0.2 m cells) moving at (`vx`, 0), as
/// the tracker gives it.
fn boxed(t_s: f64, (x0, x1): (i64, i64), (y0, y1): (i64, i64), vx: f64) -> TrackState {
    let size_m = [(x1 - x0 + 1) as f64 * 0.2, (y1 - y0 + 1) as f64 * 0.2];
    let centre = ((x0 + x1 + 1) as f64 * 0.1, (y0 + y1 + 1) as f64 * 0.1);
    TrackState {
        bbox: ((x0, y0), (x1, y1)),
        size_m,
        extent_m: size_m[0].hypot(size_m[1]),
        ..track(3, t_s, centre, (vx, 0.0), 0b11)
    }
}

/// Whether the rules make a mover of the track `seen` gives at each plan of 4 s (0.1 s
/// apart), seen by a jet driving along y = 0 at `jet_m_s`.
fn a_mover_after(jet_m_s: f64, seen: impl Fn(f64) -> TrackState) -> bool {
    let config = AutonomyConfig::default();
    let (cfg, hidden_after_s) = (&config.traffic, config.hidden_after_s);
    let mut r = rules();
    for k in 0..40 {
        let t_s = k as f64 * 0.1;
        let t = seen(t_s);
        r.predictions = predict(std::slice::from_ref(&t), t_s, cfg);
        let pose = Isometry2::translation(jet_m_s * t_s - 30.0, 0.0);
        r.movers_at_body(&[t], &pose, t_s, false, cfg, hidden_after_s);
    }
    r.streaks.iter().any(|s| s.mover_s.is_some())
}

/// A car that pulled aside and stands (cells 0..24, 4.8 m), its front hidden a cell each 0.1 s
/// from 2 s as the jet goes by at 3 m/s (`tests/found/traffic_follow_me_car_head_on.toml`):
/// its box shrinks within the box it stood in, its rear end where it was, its centre slides
/// at 1 m/s, and that is no streak of a mover. The same shrinking seen from a jet standing (a
/// van driving on under a standing jet's wing) is one; so is a truck whose near end the moving
/// airframe cuts off as it drives on into its shadow (its far end moves with it).
#[test]
fn a_standing_car_whose_front_the_passing_jet_hides_makes_no_streak() {
    let front = |t_s: f64| {
        if t_s < 2.0 {
            0
        } else {
            ((t_s - 2.0) * 10.0) as i64
        }
    };
    let standing = |t_s: f64| {
        boxed(
            t_s,
            (front(t_s), 23),
            (60, 70),
            if t_s < 2.0 { 0.0 } else { 1.0 },
        )
    };
    assert!(
        !a_mover_after(3.0, standing),
        "hidden in place as the jet goes by"
    );
    assert!(
        a_mover_after(0.0, standing),
        "the jet standing: it may be driving on"
    );
    // A 12 m truck driving at 1 m/s towards a jet coming on at 1.5 m/s, its near end cut off
    // by the airframe's shadow moving on with the jet: its box shrinks within the old one
    // from both ends, and its centre seems to go away from the jet.
    let driving = |t_s: f64| {
        let (near, far) = ((t_s * 7.5) as i64, 60 - (t_s * 5.0) as i64);
        boxed(t_s, (near, far), (60, 70), 1.0)
    };
    assert!(
        a_mover_after(1.5, driving),
        "driving on into the moving shadow"
    );
}

/// A mover lately keeps its streak while less of it is seen where it is: the rule does not
/// demote a mover (a van that drove up and stands as the passing wing hides its front).
#[test]
fn a_mover_lately_keeps_its_streak_while_hidden_in_place() {
    let config = AutonomyConfig::default();
    let (cfg, hidden_after_s) = (&config.traffic, config.hidden_after_s);
    let mut r = rules();
    for k in 0..40 {
        let t_s = k as f64 * 0.1;
        // Driving up at 1 m/s (5 cells a second) for 2 s, then standing, its front hidden.
        let (x0, x1) = if t_s < 2.0 {
            ((t_s * 5.0) as i64, 23 + (t_s * 5.0) as i64)
        } else {
            (10 + ((t_s - 2.0) * 10.0) as i64, 33)
        };
        let t = boxed(t_s, (x0, x1), (60, 70), 1.0);
        r.predictions = predict(std::slice::from_ref(&t), t_s, cfg);
        let pose = Isometry2::translation(3.0 * t_s - 30.0, 0.0);
        r.movers_at_body(&[t], &pose, t_s, false, cfg, hidden_after_s);
    }
    let streak = r.streaks.iter().find(|s| s.id == 3).expect("a streak");
    // One streak from the start, a mover as of the last plan.
    assert_eq!(streak.since_s, 0.0, "{streak:?}");
    assert!(streak.mover_s.is_some_and(|m| m > 3.85), "{streak:?}");
}
