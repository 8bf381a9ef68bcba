//! The traffic functions' unit tests: made-up tracks against a straight path.

use super::conflict::touches;
use super::predict::{Footprint, swept};
use super::*;
use mapper::{Circle, CollisionModel};
use nalgebra::{Matrix4, Vector2};

/// A 10 m vehicle on level 0 (gear, fuselage) with a 1 m circle on level 1 far out left
/// (a wing tip); the rules' tests use it too.
pub(super) fn model() -> CollisionModel {
    let mut circles: Vec<Circle> = (0..6)
        .map(|i| Circle {
            x_m: i as f64 * 2.0,
            y_m: 0.0,
            radius_m: 1.0,
            level: 0,
        })
        .collect();
    circles.push(Circle {
        x_m: 4.0,
        y_m: 8.0,
        radius_m: 1.0,
        level: 1,
    });
    CollisionModel::new(circles, vec![0.0, 1.1]).unwrap()
}

fn straight(n: usize) -> Vec<Isometry2<f64>> {
    (0..n)
        .map(|k| Isometry2::new(Vector2::new(k as f64 * 0.5, 0.0), 0.0))
        .collect()
}

fn mover(x: f64, y: f64, vx: f64, vy: f64, levels: u32) -> TrackState {
    TrackState {
        id: 7,
        t_s: 0.0,
        position: Point2::new(x, y),
        velocity: Vector2::new(vx, vy),
        covariance: Matrix4::from_diagonal(&nalgebra::Vector4::new(0.01, 0.01, 0.01, 0.01)),
        extent_m: 2.0,
        levels,
        open_top_m: None,
        confirmed: true,
        travel_m: 10.0,
        // Its hits: the 1 m cell it stands in.
        bbox: (
            (x.floor() as i64, y.floor() as i64),
            (x.floor() as i64, y.floor() as i64),
        ),
        size_m: [1.0, 1.0],
        peak_speed_m_s: vx.hypot(vy),
        born_s: -10.0,
        origin: Point2::new(x - 10.0 * vx, y - 10.0 * vy),
    }
}

/// `poses` driven at 2 m/s from now.
fn at_2_m_s(poses: &[Isometry2<f64>]) -> TimedPath<'_> {
    TimedPath {
        poses,
        step_m: 0.5,
        profile: at_speed(2.0),
        now_s: 0.0,
        yielding: false,
    }
}

fn at_speed(v: f64) -> SpeedProfile {
    SpeedProfile {
        speed_m_s: v,
        target_m_s: v,
        acceleration_m_s2: 0.5,
    }
}

fn check(m: &TrackState, profile: &SpeedProfile, yielding: bool) -> Option<Conflict> {
    let cfg = TrafficConfig::default();
    let p = predict(std::slice::from_ref(m), 0.0, &cfg);
    let poses = straight(121);
    let path = TimedPath {
        poses: &poses,
        step_m: 0.5,
        profile: *profile,
        now_s: 0.0,
        yielding,
    };
    first_conflict(&path, &model(), &p, &cfg)
}

/// The vehicle about to stop 20 m ahead (standing 3 m before that: its circles over 17-27
/// m) for something further on, with a slow mover crossing there from the right: it stops
/// short of the mover's predicted path when it can, its circles then clear of every
/// position the mover is predicted to reach; too late to stop short, or the mover far off,
/// the line stays.
#[test]
fn a_stop_is_moved_short_of_another_movers_path() {
    let cfg = TrafficConfig::default();
    let poses = straight(121);
    let path = at_2_m_s(&poses);
    let clear = |m: &TrackState, stopping_m: f64| {
        let p = predict(std::slice::from_ref(m), 0.0, &cfg);
        stand_clear(&path, &model(), &p, &[], 20.0, 3.0, stopping_m, &cfg)
    };
    let truck = mover(22.0, -9.0, 0.0, 1.1, 0b11);
    let at = clear(&truck, 2.0).expect("moved short of the truck's path");
    assert!(at > 2.0 && at < 17.0, "{at}");
    // Standing there (3 m before the line), no circle meets the truck's 8-s sweep; half a
    // metre further on, one does (the line is the zone's start, not earlier).
    let (a, b, r) = swept(&truck, 0.0, cfg.horizon_s, &cfg);
    let touches_at = |x: f64| {
        let pose = Isometry2::new(Vector2::new(x, 0.0), 0.0);
        touches(&model(), &pose, truck.levels, &a, &b, r + cfg.margin_m)
    };
    assert!(!touches_at(at - 3.0));
    assert!(touches_at(at));
    // Too late to stop short of it: the line stays (driving on is the avoider's call; standing
    // sooner in its path would be no better).
    assert_eq!(clear(&truck, at + 0.5), None);
    // A mover predicted to stay 30 m off: standing at the line is clear.
    assert_eq!(clear(&mover(22.0, -40.0, 0.0, 1.1, 0b11), 2.0), None);
}

/// A known mover standing - a person waiting by the taxiway - may walk on without warning:
/// the path passing within `standing_reach_m` (3 m) beyond its footprint (2 m from its
/// centre here) and the margin (0.5 m) of a circle on a level it occupies slows the vehicle,
/// and a stop is moved short of that reach while the vehicle can still stop short of it.
#[test]
fn a_mover_standing_is_kept_at_its_reach() {
    let cfg = TrafficConfig::default();
    let poses = straight(121);
    let passes = |t: TrackState| passes_standing(&model(), &poses, &[t], &cfg);
    // The body's circles (radius 1) along y = 0: 6.5 m from the centre reaches them.
    assert!(passes(mover(30.0, -6.0, 0.0, 0.0, 0b01)));
    assert!(!passes(mover(30.0, -7.0, 0.0, 0.0, 0b01)));
    // 7.5 m left, under the wing tip's circle (y = 8, level 1): a cart on the ground level
    // is clear of the body, a person (both levels) is not.
    assert!(!passes(mover(30.0, 7.5, 0.0, 0.0, 0b01)));
    assert!(passes(mover(30.0, 7.5, 0.0, 0.0, 0b11)));
    // Walking, it is predicted instead.
    assert!(surely_moving(&mover(30.0, -6.0, 0.0, 1.4, 0b11), &cfg));
    assert!(!surely_moving(&mover(30.0, -6.0, 0.0, 0.1, 0b11), &cfg));

    // About to stop 40 m ahead (standing 3 m back, its circles over 37-47 m) beside a
    // person 5 m right at 44 m: the front circle (x + 10) first comes within 6.5 m of them
    // at 44 - (6.5^2 - 5^2)^0.5 = 39.85 m, so the vehicle stops with its origin at 30 m.
    let path = at_2_m_s(&poses);
    let person = [mover(44.0, -5.0, 0.0, 0.0, 0b11)];
    let clear =
        |stopping_m: f64| stand_clear(&path, &model(), &[], &person, 40.0, 3.0, stopping_m, &cfg);
    assert_eq!(clear(5.0), Some(30.0));
    // Too late to stop short of the reach: as short as it can, not deeper; unless it stops
    // nearer anyway.
    assert_eq!(clear(31.0), Some(31.0));
    // Which of the two it is: the stopping distance is taken because it is too late.
    let why = |stopping_m: f64| {
        let stop = StandStop {
            stop_at_m: 40.0,
            stand_back_m: 3.0,
            stopping_m,
        };
        stand_clear_why(&path, &model(), &[], &person, stop, &cfg)
    };
    assert_eq!(
        (why(5.0), why(31.0)),
        (Some((30.0, false)), Some((31.0, true)))
    );
    // Within a pose step (0.5 m) of the stop: left where it is.
    assert_eq!(clear(39.6), None);
    assert_eq!(clear(40.0), None);
    // A static object's parts that slid as it came into view, not beyond twice its extent
    // and 3 m (7 m): too late, the stop stays (a ground power unit under the wing).
    let travelled = |travel_m: f64| {
        let t = [TrackState {
            travel_m,
            ..person[0].clone()
        }];
        stand_clear(&path, &model(), &[], &t, 40.0, 3.0, 31.0, &cfg)
    };
    assert_eq!(travelled(7.0), None);
    assert_eq!(travelled(7.1), Some(31.0));
    // Standing at 31 m would put it in a crossing truck's sweep (at x = 30 m, across the
    // path): the stop stays rather.
    let truck = predict(&[mover(30.0, -20.0, 0.0, 3.0, 0b11)], 0.0, &cfg);
    let at_40 = stand_clear(&path, &model(), &truck, &[], 40.0, 3.0, 5.0, &cfg);
    assert_eq!(at_40, None, "standing at 37 m is clear of its sweep");
    assert_eq!(
        stand_clear(&path, &model(), &truck, &person, 40.0, 3.0, 31.0, &cfg),
        None
    );
    // (A mover predicted through the stop, too late: the stop stays,
    // `a_stop_is_moved_short_of_another_movers_path`.)
}

#[test]
fn the_profile_accelerates_then_holds() {
    let p = SpeedProfile {
        speed_m_s: 0.0,
        target_m_s: 2.0,
        acceleration_m_s2: 0.5,
    };
    // 4 s to reach 2 m/s over 4 m, then 2 m/s.
    assert!((p.time_to(4.0) - 4.0).abs() < 1e-9);
    assert!((p.time_to(1.0) - 2.0).abs() < 1e-9);
    assert!((p.time_to(10.0) - 7.0).abs() < 1e-9);
    assert_eq!(at_speed(0.0).time_to(1.0), f64::INFINITY);
}

/// A van crossing from the right at 3 m/s, timed to be on the path 30 m ahead when the
/// vehicle (5 m/s) gets there in 6 s: a conflict, and the zone starts before it.
#[test]
fn a_mover_timed_to_meet_the_vehicle_is_a_conflict() {
    let van = mover(30.0, -18.0, 0.0, 3.0, 1);
    let c = check(&van, &at_speed(5.0), false).expect("a conflict");
    assert_eq!(c.track_id, 7);
    // The nose (x = 10 m ahead of the origin plus 1 m) meets the van's disc (2 m + 0.5 m
    // margin + 2 sigma) when the van, at 3 m/s, is there: a few metres before 30 - 11.
    assert!(c.at_m > 10.0 && c.at_m < 19.5, "{c:?}");
    assert!(c.zone_m <= c.at_m, "{c:?}");
}

/// The same van, 10 s early (gone by the time the vehicle arrives) or 10 s late (the vehicle
/// long past), is no conflict; one far off the path's stretch is none either.
#[test]
fn a_mover_passing_before_or_after_the_vehicle_does_not_stop_it() {
    assert_eq!(
        check(&mover(30.0, 12.0, 0.0, 3.0, 1), &at_speed(5.0), false),
        None
    );
    assert_eq!(
        check(&mover(30.0, -48.0, 0.0, 3.0, 1), &at_speed(5.0), false),
        None
    );
    assert_eq!(
        check(&mover(30.0, -30.0, 3.0, 0.0, 1), &at_speed(5.0), false),
        None
    );
}

/// A baggage cart (level 0 only) crossing under the wing tip's path clears the wing; a
/// fuel truck (levels 0 and 1) on the same path does not.
#[test]
fn a_mover_under_a_wing_level_passes_under_it() {
    // The wing tip sweeps y = 8 +- 1; the fuselage y = 0 +- 1. A mover moving along x at
    // y = 8, level 0 only: only the wing tip's level could touch it.
    let cart = mover(40.0, 8.0, -2.0, 0.0, 0b01);
    assert_eq!(check(&cart, &at_speed(5.0), false), None);
    let truck = mover(40.0, 8.0, -2.0, 0.0, 0b11);
    assert!(check(&truck, &at_speed(5.0), false).is_some());
}

/// A standing vehicle yields to a mover about to cross in front of it, and drives on once
/// it has passed: the margin after grows while yielding.
#[test]
fn a_yielding_vehicle_waits_for_the_mover_to_pass() {
    let still = SpeedProfile {
        speed_m_s: 0.0,
        target_m_s: 5.0,
        acceleration_m_s2: 0.5,
    };
    // 20 m ahead, crossing from the right, 3 s away from the path.
    assert!(check(&mover(20.0, -9.0, 0.0, 3.0, 1), &still, true).is_some());
    // Past the path by 12 m: clear.
    assert_eq!(check(&mover(20.0, 12.0, 0.0, 3.0, 1), &still, true), None);
}

/// A mover beside the fuselage, seen there or predicted there while out of view, is at the
/// body; one 3 m off it, or on a level the near circles do not occupy, is not.
#[test]
fn a_mover_at_the_body_is_found_seen_or_predicted() {
    let cfg = TrafficConfig::default();
    let pose = Isometry2::identity();
    // The fuselage's circles: y = 0 +- 1 on level 0, x 0..10.
    let beside = mover(4.0, 1.8, 0.0, 0.0, 0b01);
    assert!(at_body(&model(), &pose, &beside, 0.0, &cfg));
    let off = mover(4.0, 5.0, 0.0, 0.0, 0b01);
    assert!(!at_body(&model(), &pose, &off, 0.0, &cfg));
    // Only the wing tip's level (1) there: the fuselage's level-0 circles do not count.
    let high = mover(4.0, 1.8, 0.0, 0.0, 0b10);
    assert!(!at_body(&model(), &pose, &high, 0.0, &cfg));
    // Last seen 5 m off walking towards it at 1.4 m/s: 3 s later its motion puts it there,
    // 10 s later through and 8 m beyond (the plans between found it at the body).
    let walking = mover(4.0, -6.0, 0.0, 1.4, 0b01);
    assert!(!at_body(&model(), &pose, &walking, 0.0, &cfg));
    assert!(at_body(&model(), &pose, &walking, 3.0, &cfg));
    assert!(!at_body(&model(), &pose, &walking, 10.0, &cfg));
    // A 9 m truck seen as its last metre 5 m off: its hidden front may touch the body.
    let hidden_front = TrackState {
        extent_m: 9.0,
        travel_m: 40.0,
        ..mover(4.0, 5.0, 0.0, 0.0, 0b01)
    };
    assert!(at_body(&model(), &pose, &hidden_front, 0.0, &cfg));
    // Never moved beyond its extent (plus what it may hide): perhaps a static object.
    assert!(moved_beyond_its_extent(&beside, &cfg));
    let sliding = TrackState {
        travel_m: 2.5,
        ..beside.clone()
    };
    assert!(!moved_beyond_its_extent(&sliding, &cfg));
}

/// A mover lost 24 m off walking toward the fuselage, read at 2 m/s with a peak of 4 m/s:
/// from 6 s to 8 s after it was last seen it may be at the body at its peak (24-32 m on), not
/// at its read speed alone (12-16 m on: its box still 4 m short of touching); one read
/// moving away, or along the fuselage's axis, may not.
#[test]
fn a_lost_mover_may_reach_the_body_at_its_peak_speed() {
    let cfg = TrafficConfig::default();
    let pose = Isometry2::identity();
    let window = (6.0, 8.0);
    let toward = TrackState {
        peak_speed_m_s: 4.0,
        ..mover(4.0, -24.0, 0.0, 2.0, 0b01)
    };
    assert!(may_reach_body(&model(), &pose, &toward, window, &cfg));
    let read_speed = TrackState {
        peak_speed_m_s: 2.0,
        ..toward.clone()
    };
    assert!(!may_reach_body(&model(), &pose, &read_speed, window, &cfg));
    // At its read speed it is there 10 s after it was last seen.
    assert!(may_reach_body(
        &model(),
        &pose,
        &read_speed,
        (9.0, 11.0),
        &cfg
    ));
    let away = TrackState {
        velocity: Vector2::new(0.0, -2.0),
        ..toward.clone()
    };
    assert!(!may_reach_body(&model(), &pose, &away, window, &cfg));
    let alongside = TrackState {
        velocity: Vector2::new(2.0, 0.0),
        ..toward.clone()
    };
    assert!(!may_reach_body(&model(), &pose, &alongside, window, &cfg));
}

/// A slow mover is left to the map.
#[test]
fn a_standing_mover_is_not_predicted() {
    let cfg = TrafficConfig::default();
    assert!(predict(&[mover(5.0, 0.0, 0.1, 0.0, 1)], 0.0, &cfg).is_empty());
    assert_eq!(predict(&[mover(5.0, 0.0, 1.0, 0.0, 1)], 0.0, &cfg).len(), 1);
}

/// A mover known to move stays predicted down to half the speed floor (a truck whose front
/// the airframe hides seems to slow to half its speed); an unknown one that slow does not.
#[test]
fn a_known_mover_that_seems_to_slow_stays_predicted() {
    let cfg = TrafficConfig::default();
    let slow = mover(5.0, 0.0, 0.0, -0.6, 1);
    assert!(predict_keeping(std::slice::from_ref(&slow), 0.0, &cfg, &[8]).is_empty());
    let p = predict_keeping(std::slice::from_ref(&slow), 0.0, &cfg, &[7]);
    assert_eq!(p.len(), 1);
    assert!(
        (p[0].discs[4].center.y - -1.2).abs() < 1e-9,
        "{:?}",
        p[0].discs[4]
    );
    // Stopped (under half the floor): the map's again.
    let stopped = mover(5.0, 0.0, 0.0, -0.3, 1);
    assert!(predict_keeping(std::slice::from_ref(&stopped), 0.0, &cfg, &[7]).is_empty());
}

/// A van last seen at 1.5 m/s, having been seen at 4.5 m/s: its predicted footprint reaches
/// from where its speed now puts it to where the peak would; with no peak above its speed,
/// the footprint is where its speed puts it.
#[test]
fn a_movers_footprint_stretches_to_where_its_peak_speed_would_take_it() {
    let cfg = TrafficConfig::default();
    let van = TrackState {
        peak_speed_m_s: 4.5,
        ..mover(0.0, 20.0, 0.0, -1.5, 1)
    };
    let p = &predict(std::slice::from_ref(&van), 0.0, &cfg)[0];
    let d = p.discs.iter().find(|d| d.dt_s == 4.0).unwrap();
    let f = Footprint::of(&van, &cfg);
    // 4 s on: 6 m (its speed) to 18 m (its peak) towards -y.
    assert!((d.center.y - 8.0).abs() < 1e-9, "{d:?}");
    assert!(
        (d.half_length_m - (f.half_length_m + 6.0)).abs() < 1e-9,
        "{d:?}"
    );
    let (_, b, _) = swept(&van, 0.0, 4.0, &cfg);
    assert!((b.y - (2.0 - f.half_length_m)).abs() < 1e-9, "{b:?}");
    let steady = mover(0.0, 20.0, 0.0, -1.5, 1);
    let p = &predict(std::slice::from_ref(&steady), 0.0, &cfg)[0];
    let d = p.discs.iter().find(|d| d.dt_s == 4.0).unwrap();
    assert!((d.center.y - 14.0).abs() < 1e-9 && (d.half_length_m - f.half_length_m).abs() < 1e-9);
}
