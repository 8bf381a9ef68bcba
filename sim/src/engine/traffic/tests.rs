//! Tests of run-time traffic: yielding, making room, clearing the way, halting.

use std::path::Path;

use super::*;
use crate::scenario::Scenario;

/// The fake-wing car at the origin heading +x; a van crossing x = 20 northwards, yielding
/// within 5 m.
fn scenario(extra: &str) -> Scenario {
    let text = format!(
        r#"name = "yield"
[world]
min_m = [-50.0, -50.0]
max_m = [100.0, 50.0]
[vehicle]
description = "iara_car_fake_wing"
[route]
waypoints_m = [[0.0, 0.0], [90.0, 0.0]]
speed_m_s = 3.0
[[obstacles]]
id = "van"
kind = "vehicle"
expect = "yield"
path_m = [[20.0, -30.0], [20.0, 30.0]]
speed_m_s = 3.0
{extra}
"#
    );
    Scenario::from_str(&text, Path::new("yield.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn run(traffic: &mut Traffic, from_s: f64, to_s: f64, pose: &Isometry2<f64>) -> f64 {
    let dt = 0.01;
    let mut t = from_s;
    while t < to_s - 1e-9 {
        t += dt;
        traffic.step(t, pose);
    }
    t
}

#[test]
fn a_yielding_driver_stops_short_of_a_standing_vehicle_and_goes_once_it_is_clear() {
    let s = scenario("yields_to_vehicle_m = 5.0");
    let mut traffic = Traffic::new(&s.obstacles, &s.vehicle.vehicle);
    // The car stands across the van's path, its rear axle on it.
    let across = Isometry2::new(nalgebra::Vector2::new(20.0, 0.0), 0.0);
    traffic.step(0.0, &across);
    let t = run(&mut traffic, 0.0, 30.0, &across);
    let van = traffic.state(0).expect("present");
    assert_eq!(van.speed_m_s, 0.0, "stands");
    assert!(traffic.yielding(0));
    let front = van.y_m + 2.25;
    // Across the van's line (x = 20) the car's body reaches y = -0.88 (its wing, 3.3 m
    // ahead, is farther): the van's stretch (front + its length, 4.5 m, standing) stays
    // 5 m off it, give or take a step.
    assert!(
        (-0.88 - 5.0 - 4.5 - 0.1..-0.88 - 5.0 - 4.5 + 0.3).contains(&front),
        "front at {front}"
    );
    let stood = van.y_m;
    // Still there 20 s later; then the car drives off and the van goes on to its end.
    let t = run(&mut traffic, t, t + 20.0, &across);
    assert_eq!(traffic.state(0).map(|v| v.y_m), Some(stood));
    let gone = Isometry2::new(nalgebra::Vector2::new(80.0, 0.0), 0.0);
    let t = run(&mut traffic, t, t + 5.0, &gone);
    let van = traffic.state(0).expect("present");
    assert!(!traffic.yielding(0));
    assert!(van.y_m > stood + 5.0, "moved on to {}", van.y_m);
    run(&mut traffic, t, t + 30.0, &gone);
    assert_eq!(traffic.state(0).map(|v| (v.x_m, v.y_m)), Some((20.0, 30.0)));
}

#[test]
fn a_yielding_driver_ignores_a_vehicle_far_off_and_a_plain_mover_never_yields() {
    let s = scenario("yields_to_vehicle_m = 5.0");
    let mut traffic = Traffic::new(&s.obstacles, &s.vehicle.vehicle);
    let far = Isometry2::new(nalgebra::Vector2::new(0.0, 0.0), 0.0);
    traffic.step(0.0, &far);
    run(&mut traffic, 0.0, 30.0, &far);
    // From rest at 2 m/s^2 to 3 m/s and braking to its end: 60 m in 21.5 s.
    assert_eq!(traffic.state(0).map(|v| (v.x_m, v.y_m)), Some((20.0, 30.0)));
    let plain = scenario("");
    let mut traffic = Traffic::new(&plain.obstacles, &plain.vehicle.vehicle);
    let across = Isometry2::new(nalgebra::Vector2::new(20.0, 0.0), 0.0);
    for k in 0..=1000 {
        let t = f64::from(k) * 0.01;
        traffic.step(t, &across);
        assert_eq!(
            traffic.state(0).map(|v| (v.x_m, v.y_m, v.yaw_rad)),
            plain.obstacles[0].pose_at(t)
        );
    }
}

/// A driver that makes room, head-on to the standing vehicle: it stands 3 s, backs and
/// pulls aside until its near side is `makes_room_m` beyond the vehicle's widest part,
/// nose along its path, then yields on beside its path as before, and once the vehicle is
/// gone drives on to its end.
/// Crossing the vehicle's path where it stands clear of the vehicle's way already, it only waits.
#[test]
fn a_driver_head_on_makes_room_and_drives_on_beside_its_path() {
    let head_on = scenario("yields_to_vehicle_m = 30.0\nmakes_room_m = 3.0\n").obstacles[0].clone();
    let mut van = head_on.clone();
    let m = van.motion.as_mut().expect("moves");
    m.path_m = vec![Point2::new(80.0, 0.5), Point2::new(-40.0, 0.5)];
    let s = scenario("yields_to_vehicle_m = 30.0\nmakes_room_m = 3.0\n");
    let mut traffic = Traffic::new(std::slice::from_ref(&van), &s.vehicle.vehicle);
    let here = Isometry2::identity();
    traffic.step(0.0, &here);
    let mut t = 0.0;
    // Until it first stands for the vehicle, then 2.9 s on: it has not moved.
    while !(traffic.yielding(0) && traffic.state(0).is_some_and(|v| v.speed_m_s == 0.0)) {
        t = run(&mut traffic, t, t + 0.01, &here);
    }
    let first = traffic.state(0).expect("present");
    t = run(&mut traffic, t, t + 2.9, &here);
    assert_eq!(traffic.state(0), Some(first));
    let mut farthest = first.x_m;
    for _ in 0..6000 {
        t = run(&mut traffic, t, t + 0.01, &here);
        farthest = farthest.max(traffic.state(0).expect("present").x_m);
    }
    let stood = traffic.state(0).expect("present");
    assert_eq!(stood.speed_m_s, 0.0);
    assert!(traffic.yielding(0));
    // Its near side (half its 1.9 m width in) stands 3 m beyond the widest part, on the
    // side it was (+y), its nose along its path (-x).
    let near_side = stood.y_m - 0.5 * van.solid.shape.width_m();
    assert!(
        (near_side - traffic.half_span_m - 3.0).abs() < 1e-9,
        "near side at {near_side}, span {}",
        traffic.half_span_m
    );
    assert!((stood.heading_rad.abs() - std::f64::consts::PI).abs() < 1e-9);
    // Backed three times the shift (at least 8 m) from where it stopped first, then came
    // on beside its path as far as the yield rule lets it: 30 m from the vehicle again.
    let shift = stood.y_m - first.y_m;
    let back = farthest - first.x_m;
    assert!(
        (stood.x_m - first.x_m).abs() < 1.0,
        "stands at {}",
        stood.x_m
    );
    assert!(
        (back - (3.0 * shift).clamp(8.0, 30.0)).abs() < 1e-9,
        "backed {back} for {shift}"
    );
    // The vehicle gone, it drives on to its path's end, shifted aside.
    let gone = Isometry2::new(nalgebra::Vector2::new(200.0, 0.0), 0.0);
    run(&mut traffic, t, t + 60.0, &gone);
    let end = traffic.state(0).expect("present");
    assert_eq!((end.x_m, end.y_m), (-40.0, stood.y_m));
    // Crossing the vehicle's path, the same driver only waits (the yield test's van).
    let mut traffic = Traffic::new(&s.obstacles, &s.vehicle.vehicle);
    let across = Isometry2::new(nalgebra::Vector2::new(20.0, 0.0), 0.0);
    traffic.step(0.0, &across);
    run(&mut traffic, 0.0, 30.0, &across);
    let van = traffic.state(0).expect("present");
    assert_eq!((van.x_m, van.speed_m_s), (20.0, 0.0));
}

/// A crossing driver that makes room, standing in the vehicle's way ahead of it, clears the
/// way after 3 s: along its path (on from its path's start; back when that is shorter) to
/// where all of its body is `makes_room_m` beyond the vehicle's widest part, at up to 2 m/s,
/// then yields there as before; once the vehicle is gone it drives on to its end. A driver
/// already that far aside only waits; one without `makes_room_m` stands in the way.
#[test]
fn a_crossing_driver_caught_in_the_vehicles_way_clears_it() {
    let here = Isometry2::identity();
    let clear_m = 3.0;
    // The van on `path`, the vehicle standing at the origin: the traffic after `secs`, the van,
    // its fastest speed and the time.
    let stand = |extra: &str, path: &[[f64; 2]], secs: f64| {
        let s = scenario(extra);
        let mut van = s.obstacles[0].clone();
        let m = van.motion.as_mut().expect("moves");
        m.path_m = path.iter().map(|p| Point2::new(p[0], p[1])).collect();
        let mut traffic = Traffic::new(std::slice::from_ref(&van), &s.vehicle.vehicle);
        traffic.step(0.0, &here);
        let mut t = 0.0;
        let mut fastest: f64 = 0.0;
        while t < secs {
            t = run(&mut traffic, t, t + 0.01, &here);
            fastest = fastest.max(traffic.state(0).expect("present").speed_m_s.abs());
        }
        (traffic, van, fastest, t)
    };
    let makes_room = "yields_to_vehicle_m = 30.0\nmakes_room_m = 3.0\n";
    // From its path's start, in the way (y = -1): on, northwards.
    let (traffic, van, fastest, _) = stand(makes_room, &[[20.0, -1.0], [20.0, 40.0]], 20.0);
    let v = traffic.state(0).expect("present");
    let length_m = van.solid.shape.length_m();
    let near_side = v.y_m - 0.5 * length_m;
    let wanted = traffic.half_span_m + clear_m;
    assert_eq!(v.speed_m_s, 0.0);
    assert!(traffic.yielding(0));
    assert!(
        (wanted..wanted + 0.25 + 1e-9).contains(&near_side),
        "near side at {near_side}, wanted {wanted}"
    );
    assert!(fastest <= MAKE_ROOM_SPEED_M_S + 1e-12, "{fastest}");
    // Stood its first 3 s at its start.
    let (early, ..) = stand(makes_room, &[[20.0, -1.0], [20.0, 40.0]], 2.9);
    assert_eq!(early.state(0).map(|v| v.y_m), Some(-1.0));
    // Come in from the north, the vehicle out of the way (x = 200) until the van is 4 m north
    // of its line, then standing at the origin: the van brakes to stand just north of the
    // line, and backs the short way (north).
    let s = scenario(makes_room);
    let mut van = s.obstacles[0].clone();
    van.motion.as_mut().expect("moves").path_m =
        vec![Point2::new(20.0, 30.0), Point2::new(20.0, -40.0)];
    let mut traffic = Traffic::new(std::slice::from_ref(&van), &s.vehicle.vehicle);
    let gone = Isometry2::new(nalgebra::Vector2::new(200.0, 0.0), 0.0);
    traffic.step(0.0, &gone);
    let mut t = 0.0;
    while traffic.state(0).expect("present").y_m > 4.0 {
        t = run(&mut traffic, t, t + 0.01, &gone);
    }
    let t = run(&mut traffic, t, t + 2.0, &here);
    let stopped = traffic.state(0).expect("present");
    assert!(stopped.speed_m_s == 0.0 && stopped.y_m > 0.0, "{stopped:?}");
    let t = run(&mut traffic, t, t + 40.0, &here);
    let v = traffic.state(0).expect("present");
    let back_side = v.y_m - 0.5 * length_m;
    assert!(v.speed_m_s == 0.0, "stands");
    assert!(
        (wanted..wanted + 0.25 + 1e-9).contains(&back_side),
        "backed to {back_side}, wanted {wanted}"
    );
    // The vehicle gone, it drives on to its path's end.
    run(&mut traffic, t, t + 60.0, &gone);
    assert_eq!(
        traffic.state(0).map(|v| (v.x_m, v.y_m)),
        Some((20.0, -40.0))
    );
    // The same, the vehicle standing at the origin once the van is 1 m south of its line: it
    // stands south of the line and goes on, the short way (south).
    let mut traffic = Traffic::new(std::slice::from_ref(&van), &s.vehicle.vehicle);
    traffic.step(0.0, &gone);
    let mut t = 0.0;
    while traffic.state(0).expect("present").y_m > -1.0 {
        t = run(&mut traffic, t, t + 0.01, &gone);
    }
    let t = run(&mut traffic, t, t + 40.0, &here);
    let v = traffic.state(0).expect("present");
    let on_side = -v.y_m - 0.5 * length_m;
    assert!(
        v.speed_m_s == 0.0 && (wanted..wanted + 0.25 + 1e-9).contains(&on_side),
        "went on to {on_side}, wanted {wanted}"
    );
    assert!(t > 0.0);
    // The vehicle standing across its way on (its origin 6 m north of the van, on the van's
    // line): it does not drive into it, and cannot back (its path's start): it stands.
    let across_way = Isometry2::new(nalgebra::Vector2::new(20.0, 5.0), 0.0);
    let s2 = scenario(makes_room);
    let mut start = s2.obstacles[0].clone();
    start.motion.as_mut().expect("moves").path_m =
        vec![Point2::new(20.0, -1.0), Point2::new(20.0, 40.0)];
    let mut traffic = Traffic::new(std::slice::from_ref(&start), &s2.vehicle.vehicle);
    traffic.step(0.0, &across_way);
    run(&mut traffic, 0.0, 20.0, &across_way);
    assert_eq!(traffic.state(0).map(|v| v.y_m), Some(-1.0));
    // A stop it went on past (at y = 2) is passed: it stays where it cleared the way.
    let with_stop = format!("{makes_room}stops = [{{ at_m = 3.0, wait_s = 1.0 }}]\n");
    let (traffic, ..) = stand(&with_stop, &[[20.0, -1.0], [20.0, 40.0]], 20.0);
    let v = traffic.state(0).expect("present");
    assert!(v.y_m - 0.5 * length_m >= wanted, "at {}", v.y_m);
    // Already that far aside: it only waits where it stands.
    let aside = wanted + 0.5 * length_m + 0.1;
    let (traffic, ..) = stand(makes_room, &[[20.0, aside], [20.0, 40.0]], 20.0);
    assert_eq!(traffic.state(0).map(|v| v.y_m), Some(aside));
    // Without `makes_room_m`, it stands in the way.
    let (traffic, ..) = stand(
        "yields_to_vehicle_m = 30.0",
        &[[20.0, -1.0], [20.0, 40.0]],
        20.0,
    );
    assert_eq!(traffic.state(0).map(|v| v.y_m), Some(-1.0));
}

/// Having backed out of the vehicle's way, a driver stands while some of its body is ahead of
/// the vehicle's origin, however far the vehicle; not once it is behind, nor after going on.
#[test]
fn a_driver_that_backed_out_of_the_way_waits_for_the_vehicle_to_pass() {
    let s = scenario("yields_to_vehicle_m = 5.0\nmakes_room_m = 6.0\n");
    let o = &s.obstacles[0];
    let m = o.motion.as_ref().expect("moves");
    let size_m = [o.solid.shape.length_m(), o.solid.shape.width_m()];
    // The van at arc 10 (x = 20, y = -20), having backed 5 m.
    let backed = Room {
        from_arc_m: 15.0,
        back_m: 5.0,
        shift: Vector2::zeros(),
        done: true,
    };
    let r = Reactive {
        arc_m: 10.0,
        started: true,
        room: Some(backed),
        ..Reactive::default()
    };
    let view = |x: f64| VehicleView {
        world_from_vehicle: Isometry2::new(nalgebra::Vector2::new(x, 0.0), 0.0),
        half_span_m: 2.0,
    };
    assert!(backed_out_ahead(&r, m, size_m, &view(-500.0)));
    // Its near edge (half its width) 0.95 m past x = 20: passed once the origin is beyond.
    assert!(backed_out_ahead(&r, m, size_m, &view(20.9)));
    assert!(!backed_out_ahead(&r, m, size_m, &view(21.0)));
    let on = Reactive {
        room: Some(Room {
            back_m: -5.0,
            ..backed
        }),
        ..r
    };
    assert!(!backed_out_ahead(&on, m, size_m, &view(-500.0)));
    let head_on = Reactive {
        room: Some(Room {
            shift: Vector2::new(0.0, 3.0),
            ..backed
        }),
        ..r
    };
    assert!(!backed_out_ahead(&head_on, m, size_m, &view(-500.0)));
    assert!(!backed_out_ahead(
        &Reactive { room: None, ..r },
        m,
        size_m,
        &view(-500.0)
    ));
}

/// A plain mover and a yielding driver, halted (they touched the vehicle), stand where
/// they were for good, speed 0; a static obstacle or an absent one is left alone.
#[test]
fn a_halted_mover_stands_for_good() {
    for extra in ["", "yields_to_vehicle_m = 5.0"] {
        let s = scenario(extra);
        let mut traffic = Traffic::new(&s.obstacles, &s.vehicle.vehicle);
        let far = Isometry2::new(nalgebra::Vector2::new(-200.0, 0.0), 0.0);
        traffic.halt(0); // not there yet: nothing to halt
        let t = run(&mut traffic, -0.01, 5.0, &far);
        let before = traffic.state(0).expect("present");
        assert!(before.speed_m_s > 0.0, "{extra}: moving");
        traffic.halt(0);
        run(&mut traffic, t, t + 20.0, &far);
        let after = traffic.state(0).expect("present");
        assert_eq!(
            (after.x_m, after.y_m, after.speed_m_s),
            (before.x_m, before.y_m, 0.0),
            "{extra}"
        );
    }
}

#[test]
fn distances_between_segments_and_footprints() {
    let p = |x, y| Point2::new(x, y);
    assert_eq!(
        segments_distance(&p(0.0, -1.0), &p(0.0, 1.0), &p(-1.0, 0.0), &p(1.0, 0.0)),
        0.0
    );
    let d = segments_distance(&p(0.0, 0.0), &p(1.0, 0.0), &p(2.0, 1.0), &p(2.0, 3.0));
    assert!((d - 2f64.sqrt()).abs() < 1e-12);
    let square = aircraft::footprint::ConvexPolygon::hull(&[
        p(0.0, 0.0),
        p(1.0, 0.0),
        p(1.0, 1.0),
        p(0.0, 1.0),
    ])
    .map(Footprint::Polygon)
    .expect("a square");
    // A segment passing through without an end inside.
    assert_eq!(
        footprint_segment_distance(&square, &p(-1.0, 0.5), &p(2.0, 0.5)),
        0.0
    );
    let d = footprint_segment_distance(&square, &p(3.0, -1.0), &p(3.0, 2.0));
    assert!((d - 2.0).abs() < 1e-12);
}
