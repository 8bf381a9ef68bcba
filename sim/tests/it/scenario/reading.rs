//! Reading a scenario file (the `spec` and `numbers` stages): the base text is valid; unknown
//! keys, wrong types, missing fields and files, and numbers out of their range are errors at the
//! key or the value, naming the dotted field and quoting the line.

use sim::scenario::Scenario;
use sim::world::{ObjectKind, SolidShape};

use super::{BASE, assert_error, error, fixtures, read};

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
fn errors_quote_the_offending_line() {
    let text = BASE.replace("speed_m_s = 3.0", "speed_m_s = \"fast\"");
    let message = error(&text);
    assert!(
        message.contains("\n 9 | speed_m_s = \"fast\"\n"),
        "{message}"
    );
    assert!(message.ends_with("   |             ^^^^^^"), "{message:?}");
}
