//! Static objects and rows of them (the `resolve` stage): shape fields fit the kind, ids are
//! unique, and a `[[rows]]` table expands into objects along its line or the route, checked like
//! objects.

use sim::scenario::Scenario;
use sim::world::{ObjectKind, SolidShape};

use super::{BASE, assert_error, error, read};

#[test]
fn shape_fields_must_fit_the_kind() {
    let text =
        format!("{BASE}[[objects]]\nid = \"h\"\nkind = \"building\"\nx_m = 30.0\ny_m = 5.0\n");
    assert_error(
        &text,
        "[[objects]]\nid = \"h\"",
        "objects[1].size_m",
        "a building needs size_m",
    );
    let text = format!(
        "{BASE}[[objects]]\nid = \"c\"\nkind = \"cone\"\nx_m = 30.0\ny_m = 5.0\nsize_m = [1, 1, 1]\n"
    );
    assert_error(&text, "[1, 1, 1]", "objects[1].size_m", "a cone is round");
    let text = format!(
        "{BASE}[[objects]]\nid = \"k\"\nkind = \"container\"\nx_m = 30.0\ny_m = 5.0\nradius_m = 0.5\n"
    );
    assert_error(
        &text,
        "radius_m = |0.5",
        "objects[1].radius_m",
        "a container is box-like",
    );
}

#[test]
fn duplicate_ids_are_errors_at_the_second() {
    let text = format!(
        "{BASE}[[obstacles]]\nid = \"lamp\"\nkind = \"cone\"\nx_m = 30.0\ny_m = 0.0\nexpect = \"stop\"\n"
    );
    let second = text.rfind("\"lamp\"").expect("second id");
    let message = error(&text);
    let line = text[..second].matches('\n').count() + 1;
    assert!(
        message.contains(&format!("bad.toml:{line}:6:")),
        "{message}"
    );
    assert!(message.contains("`obstacles[0].id`"), "{message}");
    assert!(
        message.contains("duplicate id `lamp` (already used by `objects[0].id`)"),
        "{message}"
    );
}

/// BASE with one `[[rows]]` table made of `fields`.
fn with_row(fields: &str) -> String {
    format!("{BASE}[[rows]]\nid = \"m\"\nkind = \"marker\"\n{fields}")
}

/// `(id, x, y)` of the objects a scenario's rows made (every object after the BASE lamp).
fn row_objects(s: &Scenario) -> Vec<(String, f64, f64)> {
    s.objects[1..]
        .iter()
        .map(|o| (o.id.clone(), o.x_m, o.y_m))
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn a_row_expands_into_static_objects_along_its_line() {
    let s = read(&with_row(
        "along_m = [[10.0, 0.0], [60.0, 0.0]]\nspacing_m = 10.0\noffsets_m = [-6.0, 6.0]\n",
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    let made = row_objects(&s);
    // Stations at 0, 10, ..., 50 m (both ends included), two offsets each.
    assert_eq!(made.len(), 12, "{made:?}");
    assert_eq!(made[0], ("m_1".to_string(), 10.0, -6.0));
    assert_eq!(made[1], ("m_2".to_string(), 10.0, 6.0));
    assert_eq!(made[2], ("m_3".to_string(), 20.0, -6.0));
    assert_eq!(made[11], ("m_12".to_string(), 60.0, 6.0));
    for o in &s.objects[1..] {
        assert_eq!(o.kind, ObjectKind::Marker);
        assert!(!o.runtime);
        assert_eq!(
            o.shape,
            SolidShape::Cylinder {
                radius_m: 0.10,
                height_m: 0.35
            }
        );
        assert_eq!(o.remission, 0.7);
    }
    // Static: in the offline scene.
    assert_eq!(s.static_scene().solids.len(), 13);

    // start_m / end_m limit the stations (inclusive); one offset by default, on the line.
    let s = read(&with_row(
        "along_m = [[10.0, 0.0], [60.0, 0.0]]\nspacing_m = 10.0\nstart_m = 5.0\nend_m = 35.0\n",
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    let xs: Vec<f64> = row_objects(&s).iter().map(|o| o.1).collect();
    assert_eq!(xs, vec![15.0, 25.0, 35.0, 45.0]);
    assert!(row_objects(&s).iter().all(|o| o.2 == 0.0));
}

#[test]
fn a_row_follows_the_turns_of_its_line() {
    // East 20 m, then north 10 m: stations every 5 m; on the corner the object takes the
    // heading of the segment leaving it; boxes turn with the line (yaw_rad is relative to it).
    let s = read(
        &format!(
            "{BASE}[[rows]]\nid = \"k\"\nkind = \"container\"\nalong_m = [[10.0, -5.0], [30.0, -5.0], [30.0, 5.0]]\nspacing_m = 5.0\nyaw_rad = 0.1\n"
        ),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let made = &s.objects[1..];
    assert_eq!(made.len(), 7);
    let corner = &made[4];
    assert!(
        close(corner.x_m, 30.0) && close(corner.y_m, -5.0),
        "{corner:?}"
    );
    assert!(close(corner.yaw_rad, std::f64::consts::FRAC_PI_2 + 0.1));
    assert!(close(made[3].yaw_rad, 0.1));
    let last = &made[6];
    assert!(close(last.x_m, 30.0) && close(last.y_m, 5.0), "{last:?}");
    assert_eq!(
        last.shape,
        SolidShape::Box {
            size_m: [0.8, 0.6, 1.1]
        }
    );
}

#[test]
fn a_row_along_a_closed_route_does_not_repeat_its_first_station() {
    // A 60 x 10 m closed rectangle, counter-clockwise, 140 m: markers every 20 m, 3 m outside.
    let text = with_row("along = \"route\"\nspacing_m = 20.0\noffsets_m = [-3.0]\n").replace(
        "waypoints_m = [[0.0, 0.0], [50.0, 0.0]]",
        "waypoints_m = [[0.0, -5.0], [60.0, -5.0], [60.0, 5.0], [0.0, 5.0]]\nclosed = true",
    );
    let s = read(&text).unwrap_or_else(|e| panic!("{e}"));
    assert!(close(s.route.length_m(), 140.0));
    let made = row_objects(&s);
    // Stations 0, 20, ..., 120: none at 140 (it is the first again).
    assert_eq!(made.len(), 7, "{made:?}");
    let at = |k: usize| (made[k].1, made[k].2);
    assert_eq!(at(0), (0.0, -8.0));
    assert_eq!(at(3), (63.0, -5.0)); // s = 60: the corner, heading north, right is east
    assert_eq!(at(6), (10.0, 8.0)); // s = 120: heading west, right is north
    // Every object stands 3 m from the route.
    for (id, x, y) in &made {
        let d = [(-5.0f64, true), (5.0, true), (0.0, false), (60.0, false)]
            .iter()
            .map(|&(c, horizontal)| {
                if horizontal {
                    let dx = (0.0 - x).max(x - 60.0).max(0.0);
                    dx.hypot(y - c)
                } else {
                    let dy = (-5.0 - y).max(y - 5.0).max(0.0);
                    dy.hypot(x - c)
                }
            })
            .fold(f64::INFINITY, f64::min);
        assert!(close(d, 3.0), "{id} at ({x}, {y}): {d} m from the route");
    }
    // An explicit end_m at the full length keeps the last station.
    let s = read(&text.replace(
        "offsets_m = [-3.0]",
        "offsets_m = [-3.0]\nstart_m = 10.0\nend_m = 140.0",
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(row_objects(&s).len(), 7);
}

#[test]
fn a_row_turns_parked_cars_across_its_line() {
    let s = read(&format!(
        "{BASE}[[rows]]\nid = \"car\"\nkind = \"parked_car\"\nalong_m = [[30.0, 0.0], [30.0, 9.0]]\nspacing_m = 3.0\nyaw_rad = 1.5707963267948966\nremission = 0.45\n"
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    let made = &s.objects[1..];
    assert_eq!(made.len(), 4);
    for (k, c) in made.iter().enumerate() {
        assert_eq!(c.id, format!("car_{}", k + 1));
        assert!(close(c.x_m, 30.0) && close(c.y_m, 3.0 * k as f64));
        // The line heads north (pi/2); turned by pi/2 more, the car's length runs east-west.
        assert!(
            close(c.yaw_rad.abs(), std::f64::consts::PI),
            "{}",
            c.yaw_rad
        );
        assert_eq!(c.remission, 0.45);
    }
}

#[test]
fn row_mistakes_are_errors_at_the_field() {
    let line = "along_m = [[10.0, 0.0], [60.0, 0.0]]\n";
    let text = with_row(&format!("{line}along = \"route\"\nspacing_m = 10.0\n"));
    assert_error(&text, "along = |\"route\"", "rows[0].along", "not both");

    let text = with_row("spacing_m = 10.0\n");
    assert_error(&text, "[[rows]]", "rows[0]", "missing the row's line");

    let text = with_row("along = \"runway\"\nspacing_m = 10.0\n");
    assert_error(
        &text,
        "\"runway\"",
        "rows[0].along",
        "unknown variant `runway`",
    );

    let text = with_row("along_m = [[10.0, 0.0]]\nspacing_m = 10.0\n");
    assert_error(
        &text,
        "[[10.0, 0.0]]",
        "rows[0].along_m",
        "1 point(s): a row's line needs at least 2",
    );

    let text = with_row("along_m = [[10.0, 0.0], [10.0, 0.0]]\nspacing_m = 10.0\n");
    assert_error(
        &text,
        "[[10.0, 0.0], [10",
        "rows[0].along_m",
        "points 0 and 1 are the same",
    );

    let text = with_row(&format!("{line}spacing_m = 0.0\n"));
    assert_error(
        &text,
        "spacing_m = |0.0",
        "rows[0].spacing_m",
        "must be finite and > 0, got 0",
    );

    let text = with_row(line);
    assert_error(&text, "[[rows]]", "rows[0]", "missing field `spacing_m`");

    let text = with_row(&format!("{line}spacing_m = 10.0\nspacing = 5.0\n"));
    assert_error(
        &text,
        "spacing = ",
        "rows[0].spacing",
        "unknown field `spacing`",
    );

    let text = with_row(&format!("{line}spacing_m = 10.0\noffsets_m = []\n"));
    assert_error(&text, "offsets_m = |[]", "rows[0].offsets_m", "no offsets");

    let text = with_row(&format!(
        "{line}spacing_m = 10.0\noffsets_m = [-6.0, -6.0]\n"
    ));
    assert_error(
        &text,
        "offsets_m = |[-6.0",
        "rows[0].offsets_m",
        "offset -6 m is given twice",
    );

    let text = with_row(&format!("{line}spacing_m = 10.0\noffsets_m = [1.0, nan]\n"));
    assert_error(
        &text,
        "offsets_m = |[1.0",
        "rows[0].offsets_m",
        "must be a finite number",
    );

    let text = with_row(&format!(
        "{line}spacing_m = 10.0\nstart_m = 20.0\nend_m = 20.0\n"
    ));
    assert_error(
        &text,
        "end_m = |20.0",
        "rows[0].end_m",
        "20 m is not after start_m (20 m)",
    );

    let text = with_row(&format!("{line}spacing_m = 10.0\nend_m = 50.5\n"));
    assert_error(
        &text,
        "end_m = |50.5",
        "rows[0].end_m",
        "lies beyond the end of the line (50.000 m long)",
    );

    let text = with_row(&format!("{line}spacing_m = 10.0\nstart_m = 50.0\n"));
    assert_error(
        &text,
        "start_m = |50.0",
        "rows[0].start_m",
        "at or beyond the end of the line",
    );

    let text = with_row(&format!("{line}spacing_m = 10.0\nstart_m = -1.0\n"));
    assert_error(
        &text,
        "start_m = |-1.0",
        "rows[0].start_m",
        "must be finite and >= 0",
    );

    let text = with_row(&format!("{line}spacing_m = 0.001\n"));
    assert_error(
        &text,
        "spacing_m = |0.001",
        "rows[0].spacing_m",
        "makes 50001 objects, more than 10000",
    );

    let text = with_row(&format!(
        "{line}spacing_m = 10.0\nsize_m = [1.0, 1.0, 1.0]\n"
    ));
    assert_error(
        &text,
        "[1.0, 1.0, 1.0]",
        "rows[0].size_m",
        "a marker is round",
    );
}

#[test]
fn an_offset_too_large_for_a_turn_of_the_line_is_an_error() {
    // East then north: 3 m to the left (inside the turn), the stations just before the corner
    // would land on the northbound segment.
    let text = with_row(
        "along_m = [[10.0, -5.0], [30.0, -5.0], [30.0, 5.0]]\nspacing_m = 1.0\noffsets_m = [3.0]\n",
    );
    assert_error(
        &text,
        "offsets_m = |[3.0]",
        "rows[0].offsets_m",
        "turns too sharply there for this offset",
    );
    // The same offset outside the turn is fine.
    read(&text.replace("[3.0]", "[-3.0]")).unwrap_or_else(|e| panic!("{e}"));
    // And so is the inside offset when the row stops short of the corner.
    read(&text.replace("[3.0]", "[3.0]\nend_m = 16.0")).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn row_ids_and_objects_are_checked_like_objects() {
    // The row's own id is taken.
    let text = with_row("along_m = [[10.0, 0.0], [60.0, 0.0]]\nspacing_m = 10.0\n")
        .replace("id = \"m\"", "id = \"lamp\"");
    assert_error(
        &text,
        "id = |\"lamp\"\nkind = \"marker\"",
        "rows[0].id",
        "duplicate id `lamp` (already used by `objects[0].id`)",
    );
    // An id it makes is taken by an object ...
    let text = format!(
        "{BASE}[[objects]]\nid = \"m_2\"\nkind = \"cone\"\nx_m = 90.0\ny_m = 5.0\n[[rows]]\nid = \"m\"\nkind = \"marker\"\nalong_m = [[10.0, 0.0], [60.0, 0.0]]\nspacing_m = 10.0\n"
    );
    assert_error(
        &text,
        "id = |\"m\"",
        "rows[0].id",
        "its object 2 (arc length 10.00 m, offset 0 m) is `m_2`: duplicate id `m_2` (already used by `objects[1].id`)",
    );
    // ... or by an obstacle after it.
    let text = format!(
        "{}[[obstacles]]\nid = \"m_3\"\nkind = \"cone\"\nx_m = 90.0\ny_m = 0.0\nexpect = \"stop\"\n",
        with_row("along_m = [[10.0, 0.0], [60.0, 0.0]]\nspacing_m = 10.0\n")
    );
    assert_error(
        &text,
        "id = |\"m_3\"",
        "obstacles[0].id",
        "duplicate id `m_3` (already used by `rows[0]`, its object 3 (arc length 20.00 m, offset 0 m))",
    );
    // An object outside the world.
    let text = with_row("along_m = [[50.0, 0.0], [150.0, 0.0]]\nspacing_m = 20.0\n");
    assert_error(
        &text,
        "id = |\"m\"",
        "rows[0]",
        "`m_4` at (110.000, 0.000), lies outside the world",
    );
    // An object overlapping the vehicle at its start: a container under the fake wing.
    let text = format!(
        "{BASE}[[rows]]\nid = \"k\"\nkind = \"container\"\nalong_m = [[3.4, -1.4], [3.4, -9.4]]\nspacing_m = 4.0\n"
    );
    assert_error(
        &text,
        "id = |\"k\"",
        "rows[0]",
        "`k_1` (container, z 0.00..1.10 m) overlaps the vehicle at its start pose",
    );
}

/// A `parked_aircraft` places its vehicle's collision parts (at their heights, turned as they are)
/// as static objects; it needs a vehicle and takes no shape of its own; no other kind names one.
#[test]
fn a_parked_aircraft_places_its_vehicles_parts() {
    let jet = "[[objects]]\nid = \"jet\"\nkind = \"parked_aircraft\"\nx_m = 60.0\ny_m = 30.0\nyaw_rad = 1.25\n";
    let wide = BASE.replace("max_m = [100.0, 10.0]", "max_m = [100.0, 60.0]");
    let s = read(&format!("{wide}{jet}vehicle = \"praetor600\"\n")).expect("reads");
    let parts: Vec<_> = s
        .objects
        .iter()
        .filter(|o| o.kind == ObjectKind::ParkedAircraft)
        .collect();
    let vehicle = aircraft::Vehicle::shipped("praetor600").expect("shipped");
    assert_eq!(parts.len(), vehicle.parts.len());
    let fin = parts.iter().find(|o| o.id == "jet/fin#0").expect("the fin");
    assert!(matches!(fin.shape, SolidShape::Part { .. }));
    let (under, top) = fin.shape.z_range_m(fin.z_min_m);
    assert!(
        (under - 2.3).abs() < 0.01 && (top - 6.604).abs() < 0.01,
        "{under}..{top}"
    );
    // Every part is placed by the object's pose; the farthest reach from it (the nose or the tail
    // cone, about 12 m) bounds each part's footprint.
    assert!(
        parts
            .iter()
            .all(|o| (o.x_m, o.y_m, o.yaw_rad, o.z_min_m) == (60.0, 30.0, 1.25, 0.0))
    );
    let reach = parts
        .iter()
        .map(|o| o.shape.footprint_radius_m())
        .fold(0.0, f64::max);
    assert!((11.0..12.5).contains(&reach), "{reach}");
    assert_error(
        &format!("{wide}{jet}"),
        "[[objects]]\nid = \"jet\"",
        "objects[1].vehicle",
        "a parked_aircraft needs vehicle = \"a320\"",
    );
    assert_error(
        &format!("{wide}{jet}vehicle = \"a320\"\nsize_m = [1, 1, 1]\n"),
        "[[objects]]\nid = \"jet\"",
        "objects[1].size_m",
        "a parked_aircraft's shape is its vehicle's",
    );
    assert_error(
        &format!("{wide}{jet}vehicle = \"b747\"\n"),
        "\"b747\"",
        "objects[1].vehicle",
        "cannot load the vehicle",
    );
    let cone =
        "[[objects]]\nid = \"c\"\nkind = \"cone\"\nx_m = 30.0\ny_m = 5.0\nvehicle = \"a320\"\n";
    assert_error(
        &format!("{BASE}{cone}"),
        "\"a320\"",
        "objects[1].vehicle",
        "only a parked_aircraft names a vehicle, not a cone",
    );
    let moving = "[[obstacles]]\nid = \"p\"\nkind = \"parked_aircraft\"\nx_m = 30.0\ny_m = 5.0\nexpect = \"stop\"\n";
    assert_error(
        &format!("{BASE}{moving}"),
        "[[obstacles]]\nid = \"p\"",
        "obstacles[0].kind",
        "only in [[objects]]",
    );
}
