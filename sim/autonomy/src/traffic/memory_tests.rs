//! What the rules remember of movers (`memory.rs`) on made-up tracks: where each mover was
//! seen lately, and what that tells of a track dropped near it.

use mapper::TrackState;
use nalgebra::{Isometry2, Point2};

use super::rules_tests::{rules_with_mover, track};
use super::*;
use crate::planner::AutonomyConfig;

/// A follow-me car's front, tracked apart, coasts out of view towards the standing jet while
/// the car backs aside (variants 41, 107 and 134 of `traffic_jet.toml`): the car's constant
/// velocity, backing or standing, put it far from its front as last seen; where the car was
/// seen then says the front was part of it. A car first seen after, or seen then beyond its
/// extent of the front, does not.
#[test]
fn a_part_of_a_car_that_backed_aside_is_let_go_by_where_the_car_was_seen() {
    let config = AutonomyConfig::default();
    let (cfg, hidden_after_s) = (&config.traffic, config.hidden_after_s);
    let pose = Isometry2::identity();
    let front = track(21, 10.0, (4.0, -13.0), (0.0, 4.0), 0b01);
    let car = |t_s: f64, y: f64, vy: f64| TrackState {
        extent_m: 3.0,
        ..track(22, t_s, (4.0, y), (0.0, vy), 0b01)
    };
    let held = |car_then: Option<TrackState>| {
        let mut r = rules_with_mover(&front, cfg);
        let seen = |t: &[TrackState]| [std::slice::from_ref(&front), t].concat();
        let then: Vec<TrackState> = car_then.into_iter().collect();
        r.movers_at_body(&seen(&then), &pose, 10.0, true, cfg, hidden_after_s);
        let now: Vec<TrackState> = then.iter().map(|_| car(10.5, -16.0, -4.0)).collect();
        r.movers_at_body(&seen(&now), &pose, 10.5, true, cfg, hidden_after_s);
        assert_eq!(r.coasting.iter().map(|t| t.id).collect::<Vec<_>>(), [21]);
        // The front dropped; the car stands where it backed to, 9 m from the front as last seen.
        r.movers_at_body(
            &[car(12.5, -22.0, 0.0)],
            &pose,
            12.5,
            true,
            cfg,
            hidden_after_s,
        )
    };
    assert_eq!(held(Some(car(10.0, -14.0, -4.0))), None);
    for then in [None, Some(car(10.0, -17.5, -4.0))] {
        let h = held(then.clone());
        assert!(
            matches!(
                h,
                Some(BodyHold::Lost {
                    why: LostMover::Coasting,
                    ..
                })
            ),
            "{then:?}: {h:?}"
        );
    }
}

/// Where a mover was between two sightings: linear between them; nothing before the first
/// kept or after the last.
#[test]
fn a_movers_path_answers_between_its_sightings_only() {
    let p = rules::MoverPath {
        id: 1,
        seen: vec![(1.0, Point2::new(0.0, 0.0)), (2.0, Point2::new(4.0, 2.0))],
    };
    assert_eq!(p.at(1.0), Some(Point2::new(0.0, 0.0)));
    assert_eq!(p.at(1.25), Some(Point2::new(1.0, 0.5)));
    assert_eq!(p.at(2.0), Some(Point2::new(4.0, 2.0)));
    assert_eq!((p.at(0.9), p.at(2.1)), (None, None));
}
