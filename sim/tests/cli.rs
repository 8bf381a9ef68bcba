//! The `taxi-sim` binary end to end: exit codes, messages on bad input, files written.

use std::process::Command;

fn taxi_sim(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn check_accepts_every_shipped_scenario() {
    for entry in std::fs::read_dir("../scenarios").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let (code, stdout, stderr) = taxi_sim(&["check", path.to_str().unwrap()]);
            assert_eq!(code, 0, "{}: {stderr}", path.display());
            assert!(
                stdout.contains("valid") && stdout.contains("route"),
                "{stdout}"
            );
        }
    }
}

#[test]
fn a_bad_scenario_exits_2_naming_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string("../scenarios/straight_cone_under_wing.toml")
        .unwrap()
        .replacen("speed_m_s = ", "speed_m_s = -", 1);
    std::fs::write(&bad, text).unwrap();
    let (code, _, stderr) = taxi_sim(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("bad.toml:") && stderr.contains("speed_m_s"),
        "{stderr}"
    );
    let (code, _, stderr) = taxi_sim(&["check", "no/such/file.toml"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("no/such/file.toml"), "{stderr}");
    let (code, _, stderr) = taxi_sim(&["model", "fit", "cessna"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("praetor600"), "{stderr}");
}

#[test]
fn scan_writes_a_ply_from_a_point_of_the_route() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("scan.ply");
    let (code, stdout, stderr) = taxi_sim(&[
        "scan",
        "../scenarios/cone_in_path_car.toml",
        "--at",
        "20",
        "--out",
        ply.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("rays returned"), "{stdout}");
    let points = sim::ply::decode(&std::fs::read(&ply).unwrap()).unwrap();
    assert!(points.len() > 30_000, "{} points", points.len());
    let (code, _, stderr) = taxi_sim(&[
        "scan",
        "../scenarios/cone_in_path_car.toml",
        "--at",
        "100000",
        "--out",
        ply.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("route is only"), "{stderr}");
}

/// `--laps 0` used to run one lap and exit 0 (`laps = 0` in a file exits 2): it is refused.
#[test]
fn run_with_laps_0_exits_2() {
    let (code, _, stderr) = taxi_sim(&[
        "run",
        "../scenarios/straight_cone_under_wing.toml",
        "--laps",
        "0",
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("--laps 0"), "{stderr}");
}

/// `taxi-sim config` prints the defaults as TOML, which `--config` reads back; a mistake in a
/// configuration file names the file, the line and the field, or the field and what is wrong.
#[test]
fn the_printed_default_configuration_reads_back_and_mistakes_are_located() {
    let (code, stdout, stderr) = taxi_sim(&["config"]);
    assert_eq!(code, 0, "{stderr}");
    let parsed = sim::config::RunConfig::from_toml(&stdout, "printed").unwrap();
    assert_eq!(parsed, sim::config::RunConfig::default());
    assert!(stdout.contains("[pose_source]") && stdout.contains("schedule = \"overlapped\""));

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.toml");
    let run_with = |text: &str| {
        std::fs::write(&file, text).unwrap();
        taxi_sim(&[
            "run",
            "../scenarios/straight_cone_under_wing.toml",
            "--config",
            file.to_str().unwrap(),
        ])
    };
    let (code, _, stderr) =
        run_with("scan_hz = 10.0\n\n[autonomy]\nhorizon_m = 30.0\nhorizn = 3\n");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("run.toml:5:") && stderr.contains("horizn"),
        "{stderr}"
    );
    let (code, _, stderr) = run_with("[pose_source]\nkind = \"noisy_truth\"\nrate_hz = -5.0\n");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("run.toml") && stderr.contains("pose_source.rate_hz = -5"),
        "{stderr}"
    );
}
