//! One object tracked twice (`memory.rs`): a dropped track let go by the other track of the same
//! object, seen since it dropped; a part lost standing let go once the whole drove over it.

use mapper::TrackState;
use nalgebra::Isometry2;

use super::rules_tests::{self, rules, rules_with_mover, track};
use crate::planner::AutonomyConfig;

/// A follow-me car making room, tracked twice: one track (2 m, at (4, -13)) coasts out of view
/// towards the standing jet and drops; the other, seen where it was when it was last seen, was
/// seen since - but not now, as the car stood aside (variant 287 of `traffic_jet.toml`) - or is
/// a tenth smaller (variant 399: 5.0 m against 5.2 m). Both let it go. One seen last before it
/// was, or a quarter smaller, does not.
#[test]
fn a_track_dropped_is_let_go_by_the_same_objects_other_track_seen_since() {
    let config = AutonomyConfig::default();
    let (cfg, hidden_after_s) = (&config.traffic, config.hidden_after_s);
    let pose = Isometry2::identity();
    // Whether the jet, standing, is held at 12.5 s for the dropped track, `other` seen then.
    let held = |other: TrackState| {
        let van = track(21, 10.0, (4.0, -13.0), (0.0, 4.0), 0b01);
        let mut r = rules_with_mover(&van, cfg);
        assert_eq!(
            r.movers_at_body(&[van], &pose, 10.5, true, cfg, hidden_after_s),
            None
        );
        let h = r.movers_at_body(&[other], &pose, 12.5, true, cfg, hidden_after_s);
        h.is_some()
    };
    // The other, last seen at `t_s`, 1.5 m beyond the dropped one at 10 s going 5 m/s crosswise.
    let other = |t_s: f64, extent_m: f64| TrackState {
        extent_m,
        ..track(22, t_s, (5.5 + 5.0 * (t_s - 10.0), -13.0), (5.0, 0.0), 0b01)
    };
    assert!(!held(other(11.0, 2.0)), "seen since, not now");
    assert!(!held(other(12.5, 1.9)), "a tenth smaller");
    assert!(held(other(9.5, 2.0)), "seen last before");
    assert!(held(other(12.5, 1.5)), "a quarter smaller");
}

/// A follow-me car backing aside at 2 m/s, its corner tracked apart as a person (1.4 m) who
/// stood and was lost at 10 s 4 m ahead of the car's centre, beyond what `carried_part` takes
/// for a part of it (variant 399 of `traffic_jet.toml`): the car drives over that spot at 12 s,
/// and the person is forgotten from then. Kept: one the car passes 1.5 m beside; one beside a
/// car standing; one the car drove over before they were last seen.
#[test]
fn a_part_lost_standing_is_let_go_once_the_whole_drives_over_it() {
    let config = AutonomyConfig::default();
    let (cfg, hidden_after_s) = (&config.traffic, config.hidden_after_s);
    let pose = Isometry2::identity();
    let corner = TrackState {
        extent_m: 1.4,
        ..track(31, 10.0, (12.5, -10.5), (0.0, 0.0), 0b01)
    };
    // The car (5 m), at (`x_at_10`, -10.5 + `aside`) at 10 s going `v` m/s along x.
    let car = |t_s: f64, x_at_10: f64, aside: f64, v: f64| TrackState {
        extent_m: 5.0,
        born_s: 0.0,
        ..track(
            32,
            t_s,
            (x_at_10 + v * (t_s - 10.0), -10.5 + aside),
            (v, 0.0),
            0b01,
        )
    };
    // Whether the corner is kept as lost standing at each plan from 10 s to 20 s.
    let kept = |x_at_10: f64, aside: f64, v: f64| {
        let mut r = rules();
        r.streaks.push(rules_tests::mover_streak(31, 9.0));
        (0..=20)
            .map(|k| {
                let now = 10.0 + 0.5 * f64::from(k);
                let tracks = [corner.clone(), car(now, x_at_10, aside, v)];
                r.movers_at_body(&tracks, &pose, now, now > 10.0, cfg, hidden_after_s);
                r.lost_standing.iter().any(|l| l.id == 31)
            })
            .collect::<Vec<_>>()
    };
    // Driven over at 12 s: kept until then (from the first plan it was out of view), not after.
    let over = kept(8.5, 0.0, 2.0);
    assert!(over[1..4].iter().all(|k| *k), "{over:?}");
    assert!(over[5..].iter().all(|k| !k), "{over:?}");
    // Passed 1.5 m beside, or beside a car standing, or driven over before: kept throughout.
    for (x_at_10, aside, v) in [(8.5, 1.5, 2.0), (11.0, 0.0, 0.0), (16.0, 0.0, 2.0)] {
        let k = kept(x_at_10, aside, v);
        assert!(k[1..].iter().all(|k| *k), "{x_at_10} {aside} {v}: {k:?}");
    }
}
