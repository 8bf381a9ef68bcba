//! Run-time obstacles and the run's expectations (the `resolve` and `overlap` stages): timing
//! and motion are checked; nothing may overlap the vehicle at its start pose (a short cone under
//! the wing does not); the danger distance is read and checked.

use sim::scenario::Expectation;

use super::{BASE, assert_error, error, read};

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
