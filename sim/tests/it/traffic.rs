//! Traffic on the ramp (issue 36, the world's side): the new kinds (`person`, `tug`,
//! `baggage_cart`, `fuel_truck`) and their default sizes, the movers' fields
//! (`acceleration_m_s2`, `stops`, `yields_to_vehicle_m`, `makes_room_m`, `train`) checked while read - each bad
//! value's error names its field -, and towed trains: cars expanded behind their lead, keeping
//! their spacing along a bend, waiting with it.

use std::path::Path;

use nalgebra::{Isometry2, Vector2};
use sim::engine::Traffic;
use sim::scenario::Scenario;
use sim::world::{ObjectKind, SolidShape};

/// A straight road for the fake-wing car; the obstacles follow.
const BASE: &str = r#"name = "traffic"
[world]
min_m = [-60.0, -60.0]
max_m = [120.0, 60.0]
[vehicle]
description = "iara_car_fake_wing"
[route]
waypoints_m = [[0.0, 0.0], [100.0, 0.0]]
speed_m_s = 3.0
"#;

fn read(text: &str) -> Result<Scenario, String> {
    Scenario::from_str(text, Path::new("traffic.toml")).map_err(|e| e.to_string())
}

/// A tug on a path with `extra` fields.
fn tug(extra: &str) -> String {
    format!(
        "{BASE}[[obstacles]]\nid = \"tug\"\nkind = \"tug\"\nexpect = \"yield\"\npath_m = [[40.0, -40.0], [40.0, 0.0], [80.0, 0.0]]\nspeed_m_s = 2.0\n{extra}"
    )
}

/// A static obstacle with `extra` fields.
fn parked(extra: &str) -> String {
    format!(
        "{BASE}[[obstacles]]\nid = \"tug\"\nkind = \"tug\"\nexpect = \"stop\"\nx_m = 40.0\ny_m = 0.0\n{extra}"
    )
}

/// Asserts the text is refused at the line holding `line_has`, naming `field` and saying `says`.
fn refused(text: &str, line_has: &str, field: &str, says: &str) {
    let message = match read(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    };
    let offset = text
        .find(line_has)
        .unwrap_or_else(|| panic!("`{line_has}` not in the text"));
    let line = text[..offset].matches('\n').count() + 1;
    assert!(
        message.starts_with(&format!("traffic.toml:{line}:")),
        "expected line {line}\n got: {message}"
    );
    assert!(
        message.contains(&format!("`{field}`")),
        "expected field `{field}`\n got: {message}"
    );
    assert!(message.contains(says), "expected `{says}`\n got: {message}");
}

#[test]
fn each_bad_mover_field_is_refused_naming_it() {
    refused(
        &tug("acceleration_m_s2 = -1.0\n"),
        "acceleration_m_s2",
        "obstacles[0].acceleration_m_s2",
        "must be finite and > 0",
    );
    refused(
        &tug("yields_to_vehicle_m = 0.0\n"),
        "yields_to_vehicle_m",
        "obstacles[0].yields_to_vehicle_m",
        "must be finite and > 0",
    );
    refused(
        &tug("makes_room_m = -2.0\nyields_to_vehicle_m = 40.0\n"),
        "makes_room_m",
        "obstacles[0].makes_room_m",
        "must be finite and > 0",
    );
    refused(
        &tug("makes_room_m = 6.0\n"),
        "makes_room_m",
        "obstacles[0].makes_room_m",
        "only for a driver that yields: give yields_to_vehicle_m too",
    );
    refused(
        &tug("yields_to_vehicle_m = 40.0\nmakes_room_m = 6.0\ntrain = { cars = 2 }\n"),
        "makes_room_m",
        "obstacles[0].makes_room_m",
        "not for a train",
    );
    refused(
        &tug("stops = [{ at_m = -1.0, wait_s = 4.0 }]\n"),
        "stops",
        "obstacles[0].stops.at_m",
        "must be finite and >= 0",
    );
    refused(
        &tug("stops = [{ at_m = 10.0, wait_s = 0.0 }]\n"),
        "stops",
        "obstacles[0].stops.wait_s",
        "must be finite and > 0",
    );
    refused(
        &tug("stops = [{ at_m = 10.0 }]\n"),
        "stops",
        "obstacles[0].stops",
        "missing field `wait_s`",
    );
    refused(
        &tug("train = { cars = 0 }\n"),
        "train",
        "obstacles[0].train.cars",
        "must be an integer >= 1",
    );
    refused(
        &tug("train = { cars = 2, gap_m = -0.5 }\n"),
        "train",
        "obstacles[0].train.gap_m",
        "must be finite and >= 0",
    );
    refused(
        &tug("train = { cars = 2, kind = \"trolley\" }\n"),
        "train",
        "obstacles[0].train.kind",
        "unknown variant `trolley`",
    );
    refused(
        &tug("train = { cars = 2, wagons = 1 }\n"),
        "train",
        "obstacles[0].train.wagons",
        "unknown field `wagons`",
    );
}

#[test]
fn stops_and_trains_are_checked_against_the_path() {
    refused(
        &tug("stops = [{ at_m = 30.0, wait_s = 4.0 }, { at_m = 20.0, wait_s = 1.0 }]\n"),
        "stops",
        "obstacles[0].stops[1].at_m",
        "is not after the previous stop (30 m)",
    );
    refused(
        &tug("stops = [{ at_m = 30.0, wait_s = 4.0 }, { at_m = 30.0, wait_s = 1.0 }]\n"),
        "stops",
        "obstacles[0].stops[1].at_m",
        "is not after",
    );
    refused(
        &tug("stops = [{ at_m = 81.0, wait_s = 4.0 }]\n"),
        "stops",
        "obstacles[0].stops[0].at_m",
        "beyond the path's end (80.000 m)",
    );
    refused(
        &tug("train = { cars = 51 }\n"),
        "train",
        "obstacles[0].train.cars",
        "at most 50",
    );
    refused(
        &tug("train = { cars = 2, kind = \"box\" }\n"),
        "train",
        "obstacles[0].train.kind",
        "a box has no default size",
    );
    // Cars start behind the path's start, on the line of its first segment: 45 m of train
    // reach out of the world.
    refused(
        &tug("train = { cars = 12 }\n"),
        "train",
        "obstacles[0].train",
        "lies outside the world",
    );
    let text = format!(
        "{}[[objects]]\nid = \"tug_car2\"\nkind = \"cone\"\nx_m = 90.0\ny_m = 20.0\n",
        tug("train = { cars = 3 }\n")
    );
    refused(
        &text,
        "train",
        "obstacles[0].train",
        "its car 2 is `tug_car2`: duplicate id `tug_car2`",
    );
    for (key, value) in [
        ("stops", "[{ at_m = 1.0, wait_s = 1.0 }]"),
        ("train", "{ cars = 3 }"),
        ("acceleration_m_s2", "1.0"),
        ("yields_to_vehicle_m", "5.0"),
        ("makes_room_m", "6.0"),
    ] {
        refused(
            &parked(&format!("{key} = {value}\n")),
            &format!("{key} ="),
            &format!("obstacles[0].{key}"),
            "only for a moving obstacle: give path_m and speed_m_s too",
        );
    }
}

#[test]
fn the_new_kinds_have_their_default_shapes_and_remissions() {
    let mut text = BASE.to_string();
    for (k, kind) in ["person", "tug", "baggage_cart", "fuel_truck"]
        .iter()
        .enumerate()
    {
        text += &format!(
            "[[obstacles]]\nid = \"{kind}\"\nkind = \"{kind}\"\nexpect = \"no_contact\"\nx_m = {}.0\ny_m = 20.0\n",
            20 * k
        );
    }
    let s = read(&text).unwrap_or_else(|e| panic!("{e}"));
    let got: Vec<(ObjectKind, SolidShape, f32)> = s
        .obstacles
        .iter()
        .map(|o| (o.solid.kind, o.solid.shape, o.solid.remission))
        .collect();
    assert_eq!(
        got,
        vec![
            (
                ObjectKind::Person,
                SolidShape::Cylinder {
                    radius_m: 0.25,
                    height_m: 1.75
                },
                0.3
            ),
            (
                ObjectKind::Tug,
                SolidShape::Box {
                    size_m: [3.0, 1.8, 1.5]
                },
                0.3
            ),
            (
                ObjectKind::BaggageCart,
                SolidShape::Box {
                    size_m: [2.6, 1.4, 1.0]
                },
                0.4
            ),
            (
                ObjectKind::FuelTruck,
                SolidShape::Box {
                    size_m: [9.0, 2.5, 3.2]
                },
                0.3
            ),
        ]
    );
    // Under a Praetor's wing (1.1 m up).
    assert!(
        ObjectKind::BaggageCart
            .default_shape()
            .map(|s| s.height_m())
            < Some(1.1)
    );
    assert_eq!(ObjectKind::BaggageCart.name(), "baggage_cart");
    // A person is round: size_m is refused.
    let text = format!(
        "{BASE}[[obstacles]]\nid = \"p\"\nkind = \"person\"\nexpect = \"stop\"\nx_m = 40.0\ny_m = 0.0\nsize_m = [1.0, 1.0, 1.0]\n"
    );
    refused(&text, "size_m", "obstacles[0].size_m", "a person is round");
}

/// Centre-to-centre spacing along the path of a tug (3.0 m) and baggage carts (2.6 m), 1 m
/// apart.
const FIRST_CAR_M: f64 = 1.5 + 1.0 + 1.3;
const NEXT_CAR_M: f64 = 1.3 + 1.0 + 1.3;

#[test]
fn a_train_expands_into_cars_behind_its_lead() {
    let s = read(&tug(
        "appears_s = 2.0\ndisappears_s = 90.0\ntrain = { cars = 3 }\n",
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    let ids: Vec<&str> = s.obstacles.iter().map(|o| o.solid.id.as_str()).collect();
    assert_eq!(ids, ["tug", "tug_car1", "tug_car2", "tug_car3"]);
    for (k, car) in s.obstacles.iter().enumerate().skip(1) {
        assert_eq!(car.solid.kind, ObjectKind::BaggageCart);
        assert_eq!((car.appears_s, car.disappears_s), (2.0, Some(90.0)));
        assert_eq!(car.expect, s.obstacles[0].expect);
        let link = car
            .motion
            .as_ref()
            .and_then(|m| m.train)
            .expect("a car is linked");
        assert_eq!(link.lead, 0);
        let behind = FIRST_CAR_M + (k - 1) as f64 * NEXT_CAR_M;
        assert!((link.behind_m - behind).abs() < 1e-12);
        // It enters as a unit: the cars start behind the path's start, on the line of its
        // first segment (northwards from (40, -40)).
        assert!((car.solid.x_m - 40.0).abs() < 1e-9);
        assert!((car.solid.y_m - (-40.0 - behind)).abs() < 1e-9);
    }
}

/// Arc lengths along the tug's path of each vehicle of the train, from their positions (before
/// the start: negative, along the first segment).
fn arc_of(x: f64, y: f64) -> f64 {
    if (x - 40.0).abs() < 1e-9 && y <= 0.0 {
        y + 40.0
    } else {
        40.0 + (x - 40.0)
    }
}

#[test]
fn the_cars_keep_their_spacing_along_a_bend_and_stop_with_their_lead() {
    let s = read(&tug(
        "acceleration_m_s2 = 1.0\nstops = [{ at_m = 42.0, wait_s = 5.0 }]\ntrain = { cars = 3 }\n",
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    let mut traffic = Traffic::new(&s.obstacles, &s.vehicle.vehicle);
    let away = Isometry2::new(Vector2::new(0.0, 0.0), 0.0);
    let mut chord_min = f64::INFINITY;
    let mut stood = 0;
    for step in 0..=8000 {
        let t = f64::from(step) * 0.01;
        traffic.step(t, &away);
        let states: Vec<_> = (0..4).map(|k| traffic.state(k).expect("present")).collect();
        for k in 1..4 {
            let want = if k == 1 { FIRST_CAR_M } else { NEXT_CAR_M };
            let (a, b) = (&states[k - 1], &states[k]);
            assert!(
                (a.arc_m.min(80.0) - b.arc_m - want).abs() < 1e-9 || a.arc_m > 80.0,
                "t {t}: car {k} at arc {} behind {}",
                b.arc_m,
                a.arc_m
            );
            // The positions are on the path where the arc lengths say (the bend at 40 m).
            assert!((arc_of(b.x_m, b.y_m) - b.arc_m).abs() < 1e-9);
            // Along the bend the centres come closer than along a straight, never much.
            let chord = (a.x_m - b.x_m).hypot(a.y_m - b.y_m);
            assert!(chord <= want + 1e-9 && chord > 0.7 * want, "chord {chord}");
            chord_min = chord_min.min(chord / want);
            assert_eq!(b.speed_m_s, a.speed_m_s);
        }
        if states[0].arc_m == 42.0 && states[0].speed_m_s == 0.0 {
            stood += 1;
        }
    }
    assert!(chord_min < 0.99, "the train went round the bend");
    // The stop at 42 m is waited for 5 s (and the step the lead arrives).
    assert!((499..=502).contains(&stood), "stood {stood} steps");
    // At the end the lead stands at the path's end, its cars behind it.
    let end: Vec<f64> = (0..4)
        .map(|k| traffic.state(k).expect("present").arc_m)
        .collect();
    assert_eq!(end[0], 80.0);
    assert!((end[3] - (80.0 - FIRST_CAR_M - 2.0 * NEXT_CAR_M)).abs() < 1e-9);
}

#[test]
fn a_yielding_tug_holds_its_train_while_the_vehicle_stands_across_its_path() {
    let s = read(&tug("yields_to_vehicle_m = 4.0\ntrain = { cars = 3 }\n"))
        .unwrap_or_else(|e| panic!("{e}"));
    let mut traffic = Traffic::new(&s.obstacles, &s.vehicle.vehicle);
    // The car stands across the tug's first leg, at (38, -10), heading +x.
    let across = Isometry2::new(Vector2::new(38.0, -10.0), 0.0);
    for step in 0..=3000 {
        traffic.step(f64::from(step) * 0.01, &across);
    }
    let lead = traffic.state(0).expect("present");
    assert_eq!(lead.speed_m_s, 0.0);
    assert!(traffic.yielding(0) && traffic.yielding(3));
    // Short of the car (whose parts reach y = -11.9 at the wing).
    assert!(lead.y_m + 1.5 < -11.9 - 4.0 + 0.2, "lead at {}", lead.y_m);
    for k in 1..4 {
        let (a, b) = (
            traffic.state(k - 1).expect("present"),
            traffic.state(k).expect("present"),
        );
        assert_eq!(b.speed_m_s, 0.0);
        assert!(b.y_m < a.y_m);
    }
}

#[test]
fn the_readme_example_reads() {
    let text = format!(
        "{BASE}{}",
        r#"
[[obstacles]]            # a van that gives way to the aircraft
id = "van"
kind = "vehicle"
expect = "yield"
path_m = [[60.0, -40.0], [60.0, 40.0]]
speed_m_s = 4.0
yields_to_vehicle_m = 6.0

[[obstacles]]            # a person crossing, stopping to look half-way
id = "walker"
kind = "person"
expect = "yield"
appears_s = 5.0
path_m = [[30.0, -15.0], [30.0, 15.0]]
speed_m_s = 1.4
acceleration_m_s2 = 0.5
stops = [{ at_m = 10.0, wait_s = 3.0 }]

[[obstacles]]            # a tug towing three baggage carts across the route
id = "tug"
kind = "tug"
expect = "yield"
path_m = [[80.0, -40.0], [80.0, 40.0]]
speed_m_s = 3.0
acceleration_m_s2 = 1.0
yields_to_vehicle_m = 5.0
train = { cars = 3, kind = "baggage_cart", gap_m = 1.0 }
"#
    );
    let s = read(&text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.obstacles.len(), 6);
}
