//! Routes and vehicles (the `resolve` stage): a route needs two distinct points, one source
//! and to stay in the world; sidecar and pose files are found relative to the scenario.

use sim::scenario::Scenario;

use super::{BASE, assert_error, fixtures, read};

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
