//! `run --stack ros2` refuses what it cannot use by name: a domain id beyond DDS's range, a
//! timeout that is not a positive number, and - after waiting its discovery timeout on a domain
//! nobody else uses - the absence of a stack, naming both topics it found no peer on; a stack it
//! started that exits before it is found, with its status and the last lines it wrote.

use super::taxi_sim_in;

/// A car, 20 m east: a map drive of a second or two.
const SHORT: &str = r#"
name = "short"
seed = 1

[world]
min_m = [-10.0, -10.0]
max_m = [30.0, 10.0]

[vehicle]
description = "iara_car"

[route]
waypoints_m = [[0.0, 0.0], [20.0, 0.0]]
speed_m_s = 3.0
"#;

#[test]
fn bad_stack_options_are_refused_by_name() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("short.toml"), SHORT).unwrap();
    for (args, says) in [
        (&["--ros-domain-id", "233"][..], "ROS domain id 233"),
        (&["--stack-timeout-s", "0"][..], "--stack-timeout-s 0"),
        (
            &["--discovery-timeout-s", "nan"][..],
            "--discovery-timeout-s NaN",
        ),
        (&["--stack-command", " "][..], "--stack-command is empty"),
        (&["--stack-log", "s.log"][..], "--stack-command <CMD>"),
    ] {
        let mut all = vec!["run", "short.toml", "--stack", "ros2"];
        all.extend_from_slice(args);
        let (code, _, err) = taxi_sim_in(d.path(), &all);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

#[test]
fn with_no_stack_on_the_domain_the_run_does_not_start() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("short.toml"), SHORT).unwrap();
    let (code, out, err) = taxi_sim_in(
        d.path(),
        &[
            "run",
            "short.toml",
            "--stack",
            "ros2",
            "--ros-domain-id",
            "197",
            "--discovery-timeout-s",
            "1",
            "--report",
            "r.json",
        ],
    );
    assert_eq!(code, 2, "{out}\n{err}");
    assert!(
        err.contains("no stack found on ROS domain 197 within 1 s")
            && err.contains("no subscriber of /velodyne_points")
            && err.contains("no publisher of /cmd_vel"),
        "{err}"
    );
    assert!(!d.path().join("r.json").exists());
}

#[test]
fn a_started_stack_that_exits_ends_the_run_with_its_status_and_last_lines() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("short.toml"), SHORT).unwrap();
    let (code, out, err) = taxi_sim_in(
        d.path(),
        &[
            "run",
            "short.toml",
            "--stack",
            "ros2",
            "--ros-domain-id",
            "198",
            "--stack-command",
            "echo stack on domain $ROS_DOMAIN_ID; echo 'ImportError: no module rclpy' >&2; exit 4",
            "--stack-log",
            "stack.log",
            "--report",
            "r.json",
        ],
    );
    assert_eq!(code, 2, "{out}\n{err}");
    assert!(
        err.contains("started the stack (pid ")
            && err.contains("exited with status 4 before it was discovered")
            && err.contains("stack on domain 198")
            && err.contains("ImportError: no module rclpy"),
        "{err}"
    );
    assert!(!d.path().join("r.json").exists());
}
