//! The shipped scenarios (`scenarios/*.toml`, the `model` stage): every one reads and converts
//! into its scenes and says what it was written for; the thesis' experiments (the parking lot of
//! figure 10, the four-mile aerodrome circuit) are laid out as the thesis describes.

use std::path::PathBuf;

use sim::scenario::{Expectation, Scenario};
use sim::world::{ObjectKind, SolidShape};

use super::{repo, shipped};

#[test]
fn every_shipped_scenario_parses_and_converts() {
    let dir = repo().join("scenarios");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenarios/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 5, "{files:?}");
    for path in &files {
        let s = Scenario::from_file(path).unwrap_or_else(|e| panic!("{e}"));
        let offline = s.static_scene();
        let full = s.full_scene();
        assert_eq!(offline.solids.len(), s.objects.len(), "{}", path.display());
        assert!(offline.solids.iter().all(|o| !o.runtime));
        assert_eq!(full.solids.len(), s.objects.len() + s.obstacles.len());
        assert_eq!(
            full.solids.iter().filter(|o| o.runtime).count(),
            s.obstacles.len()
        );
        assert_eq!(full.patches.len(), s.patches.len());
        assert!(
            !s.patches.is_empty() && !s.objects.is_empty(),
            "{}",
            path.display()
        );
        assert!(!s.obstacles.is_empty(), "{}", path.display());
        assert!(s.route.length_m() > 0.0);
    }
}

#[test]
fn shipped_scenarios_say_what_the_next_issues_need() {
    let s = shipped("straight_cone_under_wing.toml");
    assert_eq!(s.vehicle.vehicle.spec.name, "iara_car_fake_wing");
    let cone = &s.obstacles[0];
    assert_eq!(cone.expect, Expectation::PassUnder);
    assert_eq!(cone.solid.shape.height_m(), 0.45);
    assert_eq!(s.seed, 7);

    let s = shipped("cone_in_path_car.toml");
    assert_eq!(s.vehicle.vehicle.spec.name, "iara_car");
    assert_eq!(s.obstacles[0].expect, Expectation::Deviate);

    let s = shipped("cone_in_path_jet.toml");
    assert_eq!(s.vehicle.vehicle.spec.name, "praetor600");
    assert_eq!(s.obstacles[0].expect, Expectation::Stop);
    assert_eq!(s.obstacles[0].solid.y_m, 0.0);

    let s = shipped("container_in_wing_path.toml");
    let c = &s.obstacles[0];
    assert_eq!(
        (c.solid.kind, c.expect),
        (ObjectKind::Container, Expectation::Deviate)
    );
    assert_eq!(c.solid.shape.height_m(), 1.1);

    let s = shipped("crossing_vehicle.toml");
    let v = &s.obstacles[0];
    assert_eq!(
        (v.solid.kind, v.expect),
        (ObjectKind::Vehicle, Expectation::Stop)
    );
    let motion = v.motion.as_ref().expect("moving");
    assert_eq!(motion.speed_m_s, 1.5);
    // Starts at the path's first point, heading along it; 30 m along it at t = 20 s.
    assert_eq!((v.solid.x_m, v.solid.y_m), (50.0, -20.0));
    let (x, y, yaw) = v.pose_at(20.0).expect("present");
    assert!((x - 50.0).abs() < 1e-12 && (y - 10.0).abs() < 1e-9);
    assert!((yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(v.pose_at(30.0).map(|p| (p.0, p.1)), Some((50.0, 20.0)));
    assert_eq!(v.pose_at(40.0), None);

    let s = shipped("closed_loop_pose_file.toml");
    assert!(s.route.closed);
    assert_eq!(s.laps, 2);
    assert!(s.route.waypoints_m.len() > 10);
    assert!(s.route.yaws_rad.iter().all(Option::is_some));
    assert_eq!(s.obstacles[0].pose_at(10.0), None);
    assert!(s.obstacles[0].pose_at(20.0).is_some());
}

/// `(s, d)` of a point on a scenario's route: arc length and lateral offset, left positive.
fn on_route(s: &Scenario, x: f64, y: f64) -> (f64, f64) {
    sim::autonomy::RoutePath::new(&s.route.waypoints_m, s.route.closed).project(
        &nalgebra::Point2::new(x, y),
        0.0,
        f64::INFINITY,
    )
}

/// Smallest horizontal distance from a static object's footprint to a scenario's route (a box's
/// edges sampled every 0.25 m).
fn clearance_to_route(s: &Scenario, o: &sim::world::Solid) -> f64 {
    let distance = |x: f64, y: f64| on_route(s, x, y).1.abs();
    match o.shape {
        SolidShape::Box { size_m } => {
            let (sin, cos) = o.yaw_rad.sin_cos();
            let corner = |u: f64, v: f64| {
                let (dx, dy) = (u * 0.5 * size_m[0], v * 0.5 * size_m[1]);
                (o.x_m + cos * dx - sin * dy, o.y_m + sin * dx + cos * dy)
            };
            let corners = [
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
            ];
            let mut best = f64::INFINITY;
            for k in 0..4 {
                let (a, b) = (corners[k], corners[(k + 1) % 4]);
                let n = (((b.0 - a.0).hypot(b.1 - a.1)) / 0.25).ceil().max(1.0) as usize;
                for i in 0..=n {
                    let t = i as f64 / n as f64;
                    best = best.min(distance(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
                }
            }
            best
        }
        shape => distance(o.x_m, o.y_m) - shape.footprint_radius_m(),
    }
}

/// The lateral extent `(min y, max y)` of a vehicle's parts, in its frame, that `keep` accepts.
fn lateral_extent(s: &Scenario, keep: impl Fn(&aircraft::Part) -> bool) -> (f64, f64) {
    use aircraft::footprint::Footprint;
    let mut range = (f64::INFINITY, f64::NEG_INFINITY);
    for part in s.vehicle.vehicle.parts.iter().filter(|p| keep(p)) {
        let (lo, hi) = match part.footprint() {
            Footprint::Polygon(p) => p
                .vertices()
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v.y), hi.max(v.y))
                }),
            Footprint::Disc(d) => (d.center.y - d.radius_m, d.center.y + d.radius_m),
        };
        range = (range.0.min(lo), range.1.max(hi));
    }
    range
}

/// Every turn of the route (the circle through three consecutive waypoints) is within the
/// vehicle's steering and centripetal limits at the route's speed.
fn assert_turns_are_drivable(s: &Scenario) {
    let m = &s.vehicle.vehicle.spec.motion;
    let v = s.route.speed_m_s;
    let needed = (v * v / m.max_centripetal_acceleration_m_s2)
        .max(m.wheelbase_m / m.max_steering_angle_rad.tan());
    let p = &s.route.waypoints_m;
    let n = p.len();
    for k in 0..n {
        let (a, b, c) = (p[k], p[(k + 1) % n], p[(k + 2) % n]);
        let cross = (b - a).perp(&(c - b));
        if cross.abs() < 1e-9 {
            continue;
        }
        let radius = (b - a).norm() * (c - b).norm() * (c - a).norm() / (2.0 * cross.abs());
        assert!(
            radius >= needed,
            "{}: the turn at point {} has radius {radius:.1} m, under the {needed:.1} m the vehicle needs",
            s.name,
            (k + 1) % n
        );
    }
}

#[test]
fn the_parking_lot_is_the_thesis_figure_10() {
    let s = shipped("parking_lot.toml");
    assert_eq!(s.vehicle.vehicle.spec.name, "iara_car_fake_wing");
    assert_eq!(s.laps, 7);
    assert!(s.route.closed);
    assert_eq!(s.danger_distance_m, Some(0.2));
    let length = s.route.length_m();
    assert!((250.0..=400.0).contains(&length), "{length}");
    assert_turns_are_drivable(&s);

    // The wing, the body (everything else) across the car; the wing's underside.
    let wing = lateral_extent(&s, |p| p.link == "fake_wing");
    let body = lateral_extent(&s, |p| p.link != "fake_wing");
    let underside = s
        .vehicle
        .vehicle
        .parts
        .iter()
        .find(|p| p.link == "fake_wing")
        .expect("wing")
        .underside_m();
    assert!(
        wing.0 < body.0 - 0.9,
        "the wing sticks out on the right: {wing:?} {body:?}"
    );

    // Six obstacles, two of each kind, 42 passes over seven laps.
    assert_eq!(s.obstacles.len() * s.laps as usize, 42);
    let mut windows = Vec::new();
    let (mut under, mut in_path, mut tall) = (0, 0, 0);
    for o in &s.obstacles {
        let (at_s, d) = on_route(&s, o.solid.x_m, o.solid.y_m);
        let half = match o.solid.shape {
            SolidShape::Box { size_m } => 0.5 * size_m[1], // the long side along the route
            shape => shape.footprint_radius_m(),
        };
        let (lo, hi) = (d - half, d + half);
        let height = o.solid.shape.height_m();
        match (o.expect, o.solid.kind) {
            (Expectation::PassUnder, ObjectKind::Cone) => {
                // Under the wing, clear of the body, lower than the wing.
                assert!(lo >= wing.0 && hi <= wing.1, "{}: {lo}..{hi}", o.solid.id);
                assert!(hi < body.0 - 0.2, "{}", o.solid.id);
                assert!(height < underside - 0.2, "{}", o.solid.id);
                under += 1;
            }
            (Expectation::Deviate, ObjectKind::Cone) => {
                assert!(d.abs() < 0.2, "{}: on the centreline", o.solid.id);
                in_path += 1;
            }
            (Expectation::Deviate, ObjectKind::Container) => {
                // In the wing's way only: clear of the body, as tall as the wing.
                assert!(lo >= wing.0 && hi <= wing.1, "{}: {lo}..{hi}", o.solid.id);
                assert!(hi < body.0 - 0.2, "{}", o.solid.id);
                assert!(height > underside, "{}", o.solid.id);
                assert!(
                    (o.solid.yaw_rad.sin()).abs() < 1e-3 || (o.solid.yaw_rad.cos()).abs() < 1e-3
                );
                tall += 1;
            }
            other => panic!("{}: unexpected {other:?}", o.solid.id),
        }
        assert_eq!((o.appears_s, o.disappears_s), (0.0, None));
        windows.push((at_s - 25.0, at_s + 10.0));
    }
    assert_eq!((under, in_path, tall), (2, 2, 2));
    // Pass windows neither overlap nor wrap past the start of a lap.
    windows.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(windows[0].0 > 0.0 && windows[5].1 < length, "{windows:?}");
    assert!(windows.windows(2).all(|w| w[0].1 < w[1].0), "{windows:?}");

    // Nothing static within 6 m of the route (3 m of planner offset + the wing's 1.9 m).
    for o in &s.objects {
        let clear = clearance_to_route(&s, o);
        assert!(clear > 6.0, "{} is {clear:.2} m from the route", o.id);
    }
    assert!(
        s.objects
            .iter()
            .filter(|o| o.kind == ObjectKind::ParkedCar)
            .count()
            > 100
    );
    assert!(!s.patches.is_empty());
}

#[test]
fn the_aerodrome_is_the_thesis_four_mile_circuit() {
    let s = shipped("aerodrome.toml");
    let motion = &s.vehicle.vehicle.spec.motion;
    assert_eq!(s.vehicle.vehicle.spec.name, "praetor600");
    assert_eq!(s.laps, 3);
    assert!(s.route.closed);
    assert_eq!(s.danger_distance_m, Some(0.5));
    let length = s.route.length_m();
    assert!((6300.0..=6500.0).contains(&length), "four miles: {length}");
    assert!(s.route.speed_m_s <= motion.max_speed_m_s);
    assert_turns_are_drivable(&s);

    // The gears (level 0, below the wing) and the wing tips across the jet.
    let gear = lateral_extent(&s, |p| p.link.starts_with("main_gear"));
    let span = lateral_extent(&s, |_| true);
    assert!(gear.1 < 2.5 && span.1 > 10.0, "{gear:?} {span:?}");

    // Edge markers in rows: hundreds, none in the gears' path; the taxiway ones under the wings.
    let markers: Vec<_> = s
        .objects
        .iter()
        .filter(|o| o.kind == ObjectKind::Marker)
        .collect();
    assert!((200..=400).contains(&markers.len()), "{}", markers.len());
    let mut under_wings = 0;
    for m in &markers {
        let (_, d) = on_route(&s, m.x_m, m.y_m);
        let clear = d.abs() - m.shape.footprint_radius_m();
        assert!(
            clear > gear.1 + 4.0,
            "{} is {clear:.2} m from the route",
            m.id
        );
        assert!(m.shape.height_m() < 1.1);
        if d.abs() < span.1 - 1.0 {
            under_wings += 1;
        }
    }
    assert!(under_wings > 120, "{under_wings}");
    // Everything else static is beyond the wing tips.
    for o in s.objects.iter().filter(|o| o.kind != ObjectKind::Marker) {
        let clear = clearance_to_route(&s, o);
        assert!(
            clear > span.1 + 4.0,
            "{} is {clear:.2} m from the route",
            o.id
        );
    }

    // Cones under the wings, outside the gears; one car to stop for, on lap 1 only.
    let cones: Vec<_> = s
        .obstacles
        .iter()
        .filter(|o| o.expect == Expectation::PassUnder)
        .collect();
    assert_eq!(cones.len(), 4);
    for c in &cones {
        let (_, d) = on_route(&s, c.solid.x_m, c.solid.y_m);
        assert!(
            (gear.1 + 3.0..span.1 - 3.0).contains(&d.abs()),
            "{}: {d}",
            c.solid.id
        );
        assert_eq!(c.solid.kind, ObjectKind::Cone);
    }
    let stops: Vec<_> = s
        .obstacles
        .iter()
        .filter(|o| o.expect == Expectation::Stop)
        .collect();
    assert_eq!(stops.len(), 1);
    let car = stops[0];
    let (at_s, d) = on_route(&s, car.solid.x_m, car.solid.y_m);
    assert!(d.abs() < 0.1, "on the centreline: {d}");
    // The jet at the route speed after accelerating from rest: the car appears while the jet is
    // still more than 500 m (five LiDAR ranges) short of it, at least a minute before it comes
    // within 100 m ...
    let (v, a) = (s.route.speed_m_s, motion.max_acceleration_m_s2);
    let at = |s_m: f64| v / (2.0 * a) + s_m / v;
    let disappears = car.disappears_s.expect("leaves");
    assert!(
        at(at_s - 500.0) > car.appears_s,
        "out of sight when it appears"
    );
    assert!(
        at(at_s - 100.0) > car.appears_s + 60.0,
        "lap 1 finds it there"
    );
    // ... and it is gone 20-60 s after the jet, braking, has stopped about 17 m short, long
    // before lap 2 comes back.
    let stop_t = at(at_s - 17.0) + v / (2.0 * motion.max_deceleration_m_s2);
    assert!(
        disappears + 300.0 < at(length + at_s - 100.0),
        "gone before lap 2"
    );
    assert!(
        (stop_t + 20.0..stop_t + 60.0).contains(&disappears),
        "stops at {stop_t:.0} s, the car leaves at {disappears} s"
    );
    // Pass windows neither overlap nor wrap past the start of a lap.
    let mut windows: Vec<(f64, f64)> = s
        .obstacles
        .iter()
        .map(|o| {
            let (at_s, _) = on_route(&s, o.solid.x_m, o.solid.y_m);
            (at_s - 25.0, at_s + 10.0)
        })
        .collect();
    windows.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(windows[0].0 > 0.0 && windows[windows.len() - 1].1 < length);
    assert!(windows.windows(2).all(|w| w[0].1 < w[1].0), "{windows:?}");
}
