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
    assert_eq!(motion.speed_m_s, 2.0);
    // Starts at the path's first point, heading along it; crosses y = 0 at t = 10 s.
    assert_eq!((v.solid.x_m, v.solid.y_m), (50.0, -20.0));
    let (x, y, yaw) = v.pose_at(10.0).expect("present");
    assert!((x - 50.0).abs() < 1e-12 && y.abs() < 1e-12);
    assert!((yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(v.pose_at(25.0).map(|p| (p.0, p.1)), Some((50.0, 20.0)));
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
