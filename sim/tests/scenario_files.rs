//! Scenario files: every shipped scenario reads and converts; every kind of mistake is an error
//! naming the file, the line, the column and the field; the start-overlap rule.

use std::path::{Path, PathBuf};

use sim::scenario::{Expectation, Scenario, ScenarioError};
use sim::scene::{ObjectKind, SolidShape};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// A valid scenario the error cases edit.
const BASE: &str = r#"name = "base"
[world]
min_m = [-10.0, -10.0]
max_m = [100.0, 10.0]
[vehicle]
description = "iara_car_fake_wing"
[route]
waypoints_m = [[0.0, 0.0], [50.0, 0.0]]
speed_m_s = 3.0
[[objects]]
id = "lamp"
kind = "lamp_post"
x_m = 20.0
y_m = 5.0
"#;

/// The path errors are labelled with (in the fixtures directory, so relative files resolve there).
fn bad_path() -> PathBuf {
    fixtures().join("bad.toml")
}

fn read(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::from_str(text, &bad_path())
}

/// The error message of a text that must be rejected.
fn error(text: &str) -> String {
    match read(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// `file:line:column` of the first occurrence of `needle` in `text`; with a `|` in the needle,
/// of the character after it (`"laps = |0"`: the value).
fn at(text: &str, needle: &str) -> String {
    let (before, after) = needle.split_once('|').unwrap_or(("", needle));
    let offset = text
        .find(&format!("{before}{after}"))
        .unwrap_or_else(|| panic!("`{needle}` not in the text"))
        + before.len();
    let line = text[..offset].matches('\n').count() + 1;
    let column = offset - text[..offset].rfind('\n').map_or(0, |i| i + 1) + 1;
    format!("{}:{line}:{column}:", bad_path().display())
}

/// Asserts the message starts with the location of `needle`, names `field` and says `says`.
fn assert_error(text: &str, needle: &str, field: &str, says: &str) {
    let message = error(text);
    let location = at(text, needle);
    assert!(
        message.starts_with(&location),
        "expected location {location}\n got: {message}"
    );
    assert!(
        message.contains(&format!("`{field}`")),
        "expected field `{field}`\n got: {message}"
    );
    assert!(message.contains(says), "expected `{says}`\n got: {message}");
}

#[test]
fn base_text_is_valid() {
    let s = read(BASE).expect("base scenario");
    assert_eq!(s.name, "base");
    assert_eq!((s.seed, s.laps), (1, 1));
    assert_eq!(s.world.ground_remission, 0.2);
    assert_eq!(s.objects.len(), 1);
    let lamp = &s.objects[0];
    assert_eq!(lamp.kind, ObjectKind::LampPost);
    assert_eq!(
        lamp.shape,
        SolidShape::Cylinder {
            radius_m: 0.12,
            height_m: 6.0
        }
    );
    // Default start: on the first point, heading to the second.
    assert_eq!(s.vehicle.world_from_start.translation.vector.x, 0.0);
    assert_eq!(s.vehicle.world_from_start.rotation.angle(), 0.0);
    assert!((s.route.length_m() - 50.0).abs() < 1e-12);
}

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
        let offline = s.scene(false);
        let full = s.scene(true);
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

fn shipped(name: &str) -> Scenario {
    Scenario::from_file(&repo().join("scenarios").join(name)).unwrap_or_else(|e| panic!("{e}"))
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

#[test]
fn sidecar_and_pose_file_paths_are_relative_to_the_scenario() {
    let s = Scenario::from_file(&fixtures().join("relative_sidecar.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.vehicle.vehicle.spec.name, "iara_car");

    let text = BASE.replace(
        "waypoints_m = [[0.0, 0.0], [50.0, 0.0]]",
        "pose_file = \"good_route.csv\"",
    );
    let s = read(&text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.route.waypoints_m.len(), 3);
    assert_eq!(s.route.yaws_rad, vec![Some(0.0), None, Some(0.5)]);
}

#[test]
fn unknown_key_is_an_error_at_the_key() {
    let text = format!("{BASE}colour = \"red\"\n");
    assert_error(
        &text,
        "colour",
        "objects[0].colour",
        "unknown field `colour`",
    );
    let text = BASE.replace("[world]\n", "[world]\nmin = [0, 0]\n");
    assert_error(&text, "min = ", "world.min", "unknown field `min`");
    let text = BASE.replace("name = \"base\"\n", "name = \"base\"\nlap = 2\n");
    assert_error(&text, "lap =", "lap", "unknown field `lap`");
}

#[test]
fn wrong_type_is_an_error_at_the_value() {
    let text = BASE.replace("speed_m_s = 3.0", "speed_m_s = \"fast\"");
    assert_error(
        &text,
        "\"fast\"",
        "route.speed_m_s",
        "invalid type: string \"fast\"",
    );
    let text = BASE.replace("kind = \"lamp_post\"", "kind = \"lamppost\"");
    assert_error(
        &text,
        "\"lamppost\"",
        "objects[0].kind",
        "unknown variant `lamppost`",
    );
    let text = format!("{BASE}[vehicle]\n");
    let message = error(&text);
    assert!(message.contains("bad.toml:"), "{message}");
}

#[test]
fn inline_table_fields_are_named() {
    let text = BASE.replace(
        "description = \"iara_car_fake_wing\"",
        "description = \"iara_car_fake_wing\"\nstart = { x_m = 0.0, y_m = \"zero\" }",
    );
    assert_error(&text, "\"zero\"", "vehicle.start.y_m", "invalid type");
}

#[test]
fn missing_required_field_names_the_table() {
    let text = BASE.replace("x_m = 20.0\n", "");
    assert_error(&text, "[[objects]]", "objects[0]", "missing field `x_m`");
    let text = BASE.replace("speed_m_s = 3.0\n", "");
    assert_error(&text, "[route]", "route", "missing field `speed_m_s`");
}

#[test]
fn missing_files_are_errors() {
    // The scenario itself.
    let missing = fixtures().join("no_such_scenario.toml");
    let message = Scenario::from_file(&missing)
        .expect_err("missing file")
        .to_string();
    assert!(message.contains("no_such_scenario.toml"), "{message}");
    assert!(message.contains("cannot read"), "{message}");

    // A vehicle sidecar, relative to the scenario.
    let text = BASE.replace("\"iara_car_fake_wing\"", "\"no_such_sidecar.toml\"");
    assert_error(
        &text,
        "\"no_such_sidecar.toml\"",
        "vehicle.description",
        "no_such_sidecar.toml",
    );
    // An unknown shipped name lists the shipped ones.
    let text = BASE.replace("\"iara_car_fake_wing\"", "\"cessna\"");
    assert_error(&text, "\"cessna\"", "vehicle.description", "praetor600");

    // A pose file.
    let text = BASE.replace(
        "waypoints_m = [[0.0, 0.0], [50.0, 0.0]]",
        "pose_file = \"no_such_route.csv\"",
    );
    assert_error(
        &text,
        "\"no_such_route.csv\"",
        "route.pose_file",
        "cannot read the pose file",
    );
}

#[test]
fn bad_pose_file_line_is_located_in_the_pose_file() {
    let text = BASE.replace(
        "waypoints_m = [[0.0, 0.0], [50.0, 0.0]]",
        "pose_file = \"bad_route.csv\"",
    );
    let message = error(&text);
    let expected = format!("{}:4:6:", fixtures().join("bad_route.csv").display());
    assert!(message.starts_with(&expected), "{message}");
    assert!(
        message.contains("`abc` is not a finite number"),
        "{message}"
    );
    assert!(message.contains("`route.pose_file`"), "{message}");
}

#[test]
fn bad_numbers_are_errors_at_the_value() {
    let with = |extra: &str| format!("{BASE}{extra}");
    let text = with(
        "[[objects]]\nid = \"box\"\nkind = \"box\"\nx_m = 30.0\ny_m = 5.0\nsize_m = [1.0, -2.0, 1.0]\n",
    );
    assert_error(
        &text,
        "[1.0, -2.0, 1.0]",
        "objects[1].size_m",
        "must be finite and > 0, got -2",
    );

    let text =
        with("[[objects]]\nid = \"c\"\nkind = \"cone\"\nx_m = 30.0\ny_m = 5.0\nradius_m = 0.0\n");
    assert_error(
        &text,
        "radius_m = |0.0",
        "objects[1].radius_m",
        "must be finite and > 0, got 0",
    );

    let text =
        with("[[objects]]\nid = \"c\"\nkind = \"cone\"\nx_m = 30.0\ny_m = 5.0\nheight_m = nan\n");
    assert_error(&text, "height_m = |nan", "objects[1].height_m", "got NaN");

    let text =
        with("[[objects]]\nid = \"c\"\nkind = \"cone\"\nx_m = 30.0\ny_m = 5.0\nremission = 1.5\n");
    assert_error(
        &text,
        "remission = |1.5",
        "objects[1].remission",
        "remission must be in [0, 1], got 1.5",
    );

    let text = BASE.replace("[world]\n", "[world]\nground_remission = -0.1\n");
    assert_error(
        &text,
        "= |-0.1",
        "world.ground_remission",
        "remission must be in [0, 1]",
    );

    let text = BASE.replace("x_m = 20.0", "x_m = inf");
    assert_error(
        &text,
        "x_m = |inf",
        "objects[0].x_m",
        "must be a finite number",
    );

    let text = BASE.replace("name = \"base\"\n", "name = \"base\"\nlaps = 0\n");
    assert_error(
        &text,
        "laps = |0",
        "laps",
        "laps must be an integer >= 1, got 0",
    );

    let text = BASE.replace("speed_m_s = 3.0", "speed_m_s = -1");
    assert_error(
        &text,
        "speed_m_s = |-1",
        "route.speed_m_s",
        "must be finite and > 0",
    );

    let text =
        with("[[patches]]\nid = \"p\"\nx_m = 1.0\ny_m = 1.0\nlength_m = 2.0\nwidth_m = -0.1\n");
    assert_error(
        &text,
        "width_m = |-0.1",
        "patches[0].width_m",
        "must be finite and > 0",
    );
}

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
fn route_needs_two_distinct_points_and_one_source() {
    let text = BASE.replace("[[0.0, 0.0], [50.0, 0.0]]", "[[0.0, 0.0]]");
    assert_error(
        &text,
        "[[0.0, 0.0]]",
        "route.waypoints_m",
        "1 point(s): a route needs at least 2",
    );

    let text = BASE.replace(
        "[[0.0, 0.0], [50.0, 0.0]]",
        "[[0.0, 0.0], [0.0, 0.0], [5.0, 0.0]]",
    );
    assert_error(
        &text,
        "[[0.0, 0.0], [0.0",
        "route.waypoints_m",
        "points 0 and 1 are the same",
    );

    let text = BASE.replace("speed_m_s = 3.0", "speed_m_s = 3.0\nclosed = true");
    assert_error(
        &text,
        "[[0.0, 0.0], [50",
        "route.waypoints_m",
        "closed, a route needs at least 3",
    );

    let text = BASE.replace("waypoints_m = [[0.0, 0.0], [50.0, 0.0]]\n", "");
    assert_error(&text, "[route]", "route", "give waypoints_m");

    let text = BASE.replace(
        "speed_m_s = 3.0",
        "speed_m_s = 3.0\npose_file = \"good_route.csv\"",
    );
    assert_error(&text, "\"good_route.csv\"", "route.pose_file", "not both");

    let text = BASE.replace("[50.0, 0.0]]", "[500.0, 0.0]]");
    assert_error(
        &text,
        "[[0.0, 0.0], [500",
        "route.waypoints_m",
        "outside the world",
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

#[test]
fn obstacle_timing_and_motion_are_checked() {
    let obstacle = |extra: &str| {
        format!("{BASE}[[obstacles]]\nid = \"o\"\nkind = \"vehicle\"\nexpect = \"stop\"\n{extra}")
    };
    let text = obstacle("x_m = 30.0\ny_m = 0.0\nappears_s = 5.0\ndisappears_s = 2.0\n");
    assert_error(
        &text,
        "disappears_s = |2.0",
        "obstacles[0].disappears_s",
        "is not after appears_s",
    );
    let text = obstacle("path_m = [[30.0, -5.0], [30.0, 5.0]]\n");
    assert_error(&text, "[[30.0", "obstacles[0].speed_m_s", "needs speed_m_s");
    let text = obstacle("x_m = 30.0\ny_m = 0.0\nspeed_m_s = 1.0\n");
    assert_error(
        &text,
        "speed_m_s = |1.0",
        "obstacles[0].speed_m_s",
        "give path_m too",
    );
    let text = obstacle("path_m = [[30.0, -5.0], [30.0, -5.0]]\nspeed_m_s = 1.0\n");
    assert_error(&text, "[[30.0", "obstacles[0].path_m", "are the same");
    let text = obstacle("path_m = [[30.0, -5.0], [30.0, 50.0]]\nspeed_m_s = 1.0\n");
    assert_error(
        &text,
        "[[30.0",
        "obstacles[0].path_m",
        "(30, 50) lies outside the world",
    );
    let text = obstacle("y_m = 0.0\n");
    assert_error(
        &text,
        "[[obstacles]]",
        "obstacles[0].x_m",
        "missing field `x_m`",
    );
    let text = obstacle("x_m = 30.0\ny_m = 0.0\nexpect_s = 1.0\n");
    assert_error(
        &text,
        "expect_s",
        "obstacles[0].expect_s",
        "unknown field `expect_s`",
    );
    let text = obstacle("x_m = 30.0\ny_m = 0.0\n").replace("\"stop\"", "\"swerve\"");
    assert_error(
        &text,
        "\"swerve\"",
        "obstacles[0].expect",
        "unknown variant `swerve`",
    );
}

/// The fake wing spans x 3.3 .. 3.5 m, y -0.85 .. -1.90 m of the vehicle frame, 0.70 .. 0.72 m up.
fn under_the_wing(kind: &str, extra: &str, section: &str) -> String {
    format!(
        "{BASE}[[{section}]]\nid = \"thing\"\nkind = \"{kind}\"\nx_m = 3.4\ny_m = -1.4\n{extra}"
    )
}

#[test]
fn container_overlapping_the_wing_at_the_start_is_an_error() {
    for section in ["objects", "obstacles"] {
        let extra = if section == "obstacles" {
            "expect = \"deviate\"\n"
        } else {
            ""
        };
        let text = under_the_wing("container", extra, section);
        let field = format!("{section}[{}]", if section == "objects" { 1 } else { 0 });
        assert_error(
            &text,
            "\"thing\"",
            &field,
            "`thing` (container, z 0.00..1.10 m) overlaps the vehicle at its start pose",
        );
        assert!(
            error(&text).contains("link `fake_wing` collision 0"),
            "{}",
            error(&text)
        );
    }
}

#[test]
fn short_cone_under_the_wing_at_the_start_is_not_an_overlap() {
    let text = under_the_wing(
        "cone",
        "height_m = 0.45\nexpect = \"pass_under\"\n",
        "obstacles",
    );
    let s = read(&text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.obstacles[0].expect, Expectation::PassUnder);
    // The same cone 0.8 m tall reaches the wing.
    let text = under_the_wing(
        "cone",
        "height_m = 0.8\nexpect = \"pass_under\"\n",
        "obstacles",
    );
    assert_error(&text, "\"thing\"", "obstacles[0]", "link `fake_wing`");
    // A cone in the body's path at the start overlaps the body.
    let text = format!(
        "{BASE}[[obstacles]]\nid = \"c\"\nkind = \"cone\"\nx_m = 1.0\ny_m = 0.0\nexpect = \"stop\"\n"
    );
    assert_error(&text, "\"c\"", "obstacles[0]", "overlaps the vehicle");
    // An obstacle appearing later is not checked against the start pose.
    let text = format!(
        "{BASE}[[obstacles]]\nid = \"c\"\nkind = \"cone\"\nx_m = 1.0\ny_m = 0.0\nexpect = \"stop\"\nappears_s = 30.0\n"
    );
    read(&text).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn start_pose_moves_the_overlap_check() {
    // Started 10 m further east, the container at (3.4, -1.4) is behind the car: valid.
    let text = under_the_wing("container", "", "objects").replace(
        "description = \"iara_car_fake_wing\"",
        "description = \"iara_car_fake_wing\"\nstart = { x_m = 10.0, y_m = 0.0 }",
    );
    read(&text).unwrap_or_else(|e| panic!("{e}"));
    // Turned round (yaw pi) at (6.8, 0): the wing is now at x 3.3 .. 3.5, y +0.85 .. +1.9.
    let text = format!(
        "{BASE}[[objects]]\nid = \"k\"\nkind = \"container\"\nx_m = 3.4\ny_m = 1.4\n"
    )
    .replace(
        "description = \"iara_car_fake_wing\"",
        "description = \"iara_car_fake_wing\"\nstart = { x_m = 6.8, y_m = 0.0, yaw_rad = 3.141592653589793 }",
    );
    assert_error(&text, "\"k\"", "objects[1]", "link `fake_wing`");
}

#[test]
fn errors_quote_the_offending_line() {
    let text = BASE.replace("speed_m_s = 3.0", "speed_m_s = \"fast\"");
    let message = error(&text);
    assert!(
        message.contains("\n 9 | speed_m_s = \"fast\"\n"),
        "{message}"
    );
    assert!(message.ends_with("   |             ^^^^^^"), "{message:?}");
}

// ---------------------------------------------------------------------------------------------
// Rows of objects
// ---------------------------------------------------------------------------------------------

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
    assert_eq!(s.scene(false).solids.len(), 13);

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

// ---------------------------------------------------------------------------------------------
// Run expectations
// ---------------------------------------------------------------------------------------------

#[test]
fn the_danger_distance_is_read_and_checked() {
    assert_eq!(read(BASE).expect("base").danger_distance_m, None);
    let text = format!("{BASE}[expectations]\ndanger_distance_m = 0.2\n");
    assert_eq!(read(&text).expect("valid").danger_distance_m, Some(0.2));
    let text = format!("{BASE}[expectations]\ndanger_distance_m = 0.0\n");
    assert_error(
        &text,
        "danger_distance_m = |0.0",
        "expectations.danger_distance_m",
        "must be finite and > 0, got 0",
    );
    let text = format!("{BASE}[expectations]\nsafety_distance_m = 0.6\n");
    assert_error(
        &text,
        "safety_distance_m",
        "expectations.safety_distance_m",
        "unknown field `safety_distance_m`",
    );
}

// ---------------------------------------------------------------------------------------------
// The thesis' experiments (issue 6)
// ---------------------------------------------------------------------------------------------

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
fn clearance_to_route(s: &Scenario, o: &sim::scene::Solid) -> f64 {
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

    // Cones under the wings, outside the gears; one car to stop for, on lap 2 only.
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
    // The jet at the route speed after accelerating from rest: it passes on lap 1 before the
    // car appears, and on lap 2 arrives with at least 5 minutes to spare before it leaves ...
    let (v, a) = (s.route.speed_m_s, motion.max_acceleration_m_s2);
    let at = |s_m: f64| v / (2.0 * a) + s_m / v;
    let disappears = car.disappears_s.expect("leaves");
    assert!(at(at_s + 40.0) < car.appears_s, "lap 1 passes first");
    assert!(
        at(length + at_s - 100.0) > car.appears_s + 300.0,
        "lap 2 finds it there"
    );
    // ... and it is gone 20-60 s after the jet, braking, has stopped about 17 m short.
    let stop_t = at(length + at_s - 17.0) + v / (2.0 * motion.max_deceleration_m_s2);
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
