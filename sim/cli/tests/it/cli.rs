//! The `taxi-sim` binary end to end: exit codes, messages on bad input, files written.

use std::process::Command;

fn taxi_sim(args: &[&str]) -> (i32, String, String) {
    crate::taxi_sim_in(std::path::Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

#[test]
fn check_accepts_every_shipped_scenario() {
    for entry in std::fs::read_dir("../../scenarios").unwrap() {
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
    let text = std::fs::read_to_string("../../scenarios/straight_cone_under_wing.toml")
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
        "../../scenarios/cone_in_path_car.toml",
        "--at",
        "20",
        "--out",
        ply.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("rays returned"), "{stdout}");
    let points = sim::world::ply::decode(&std::fs::read(&ply).unwrap()).unwrap();
    assert!(points.len() > 30_000, "{} points", points.len());
    let (code, _, stderr) = taxi_sim(&[
        "scan",
        "../../scenarios/cone_in_path_car.toml",
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
        "../../scenarios/straight_cone_under_wing.toml",
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
    let parsed = sim::scenario::RunConfig::from_toml(&stdout, "printed").unwrap();
    assert_eq!(parsed, sim::scenario::RunConfig::default());
    assert!(stdout.contains("[pose_source]") && stdout.contains("schedule = \"overlapped\""));

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.toml");
    let run_with = |text: &str| {
        std::fs::write(&file, text).unwrap();
        taxi_sim(&[
            "run",
            "../../scenarios/straight_cone_under_wing.toml",
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

/// `taxi-sim campaign run`, interrupted by Ctrl-C (SIGINT) once a run is recorded: it exits
/// with whole runs only in `results.jsonl`, says how to resume, and `campaign show` prints the
/// summary of what is there.
#[test]
fn a_campaign_stopped_by_ctrl_c_keeps_whole_runs_and_shows_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("smoke");
    let child = Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .args([
            "campaign",
            "run",
            "../../scenarios/campaigns/smoke.toml",
            "--jobs",
            "1",
            "--out",
        ])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let results = out.join("results.jsonl");
    let t = std::time::Instant::now();
    while std::fs::read_to_string(&results).map_or(true, |s| s.is_empty()) {
        assert!(t.elapsed().as_secs() < 300, "no run recorded in 300 s");
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let done = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&done.stdout);
    assert_eq!(done.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("interrupted: run the same command again to resume"),
        "{stdout}"
    );
    let text = std::fs::read_to_string(&results).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        !lines.is_empty() && lines.len() < 20 && text.ends_with('\n'),
        "{text}"
    );
    for line in &lines {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        assert!(
            v["end"].as_str().is_some_and(|e| e != "interrupted"),
            "{line}"
        );
    }
    let (code, shown, stderr) = taxi_sim(&["campaign", "show", out.to_str().unwrap()]);
    assert!(matches!(code, 0 | 1), "{stderr}");
    assert!(
        shown.contains(&format!("{} runs recorded", lines.len()))
            && shown.contains("## Per parameter setting"),
        "{shown}"
    );
    let (code, _, stderr) = taxi_sim(&["campaign", "show", dir.path().to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(stderr.contains("not a campaign directory"), "{stderr}");
}

/// `run --maps-dir`: the map of the scenario's static world comes from a cache shared with
/// `regress` and campaigns - built there on the first run, the same entry reused by the next
/// (not rebuilt: its manifest is not rewritten) with the same result; `--map-dir` with it is
/// refused.
#[test]
fn run_with_a_map_cache_builds_the_map_once_and_reuses_it() {
    let d = tempfile::tempdir().unwrap();
    let cache = d.path().join("maps");
    let scenario = std::fs::canonicalize("../../scenarios/bridge_car.toml").unwrap();
    let run = |report: &str| {
        let (code, out, err) = taxi_sim(&[
            "run",
            scenario.to_str().unwrap(),
            "--maps-dir",
            cache.to_str().unwrap(),
            "--report",
            d.path().join(report).to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{out}\n{err}");
        assert!(!err.contains("missing or stale"), "{err}");
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.path().join(report)).unwrap()).unwrap();
        for k in ["wall_time_s", "real_time_factor", "time_split_s"] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    let entries = || -> Vec<std::path::PathBuf> {
        std::fs::read_dir(&cache)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect()
    };
    let first = run("a.json");
    let built = entries();
    assert_eq!(built.len(), 1, "{built:?}");
    let manifest = built[0].join("manifest.json");
    let written = std::fs::metadata(&manifest).unwrap().modified().unwrap();
    let second = run("b.json");
    assert_eq!(entries(), built);
    assert_eq!(
        std::fs::metadata(&manifest).unwrap().modified().unwrap(),
        written
    );
    assert_eq!(first, second);
    let (code, _, err) = taxi_sim(&[
        "run",
        scenario.to_str().unwrap(),
        "--maps-dir",
        cache.to_str().unwrap(),
        "--map-dir",
        "elsewhere",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--map-dir") && err.contains("--maps-dir"),
        "{err}"
    );
}

#[test]
fn model_coverage_reports_each_level_and_draws_them() {
    let dir = tempfile::tempdir().unwrap();
    let pictures = dir.path().join("pictures");
    let (code, stdout, stderr) = taxi_sim(&[
        "model",
        "coverage",
        "praetor600",
        "--margin-m",
        "6",
        "--json",
        "--picture",
        pictures.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let c: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let levels = c["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 2, "{stdout}");
    // Level 0's object is the 0.1 m the map holds; level 1's the 1.1 m height of interest.
    assert_eq!(levels[0]["object_height_m"], 0.1);
    assert_eq!(levels[1]["object_height_m"], 1.1);
    assert!(
        levels
            .iter()
            .all(|l| l["blind_area_m2"].as_f64().unwrap() > 0.0)
    );
    for ext in ["svg", "png"] {
        assert!(
            pictures
                .join(format!("coverage-praetor600.{ext}"))
                .is_file()
        );
    }
    let (code, _, stderr) = taxi_sim(&["model", "coverage", "praetor600", "--cell-m", "0"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("cell"), "{stderr}");
}

/// Every line of `stdout` one JSON object (what `--json` promises), parsed.
fn json_lines(stdout: &str) -> Vec<serde_json::Value> {
    assert!(!stdout.trim().is_empty(), "nothing printed");
    stdout
        .lines()
        .map(|line| {
            let v: serde_json::Value = serde_json::from_str(line)
                .unwrap_or_else(|e| panic!("not a JSON line ({e}): {line}"));
            assert!(v.is_object(), "not an object: {line}");
            v
        })
        .collect()
}

/// `--json` means JSON: `bench representations --json` prints one scene's results a line (what
/// `representations.json` lists), and no Markdown; `--redraw DIR --json` the same again.
#[test]
fn bench_representations_json_is_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rep");
    let (code, stdout, stderr) = taxi_sim(&[
        "bench",
        "representations",
        "--scenario",
        "../../scenarios/straight_cone_under_wing.toml",
        "--scenario",
        "../../scenarios/cone_in_path_car.toml",
        "--poses",
        "50",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let printed = json_lines(&stdout);
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("representations.json")).unwrap())
            .unwrap();
    assert_eq!(Some(&printed), written.as_array());
    assert_eq!(printed.len(), 2);
    assert!(printed[0]["rows"].as_array().is_some_and(|r| r.len() >= 3));
    assert!(out.join("representations.md").exists());
    let (code, again, stderr) = taxi_sim(&[
        "bench",
        "representations",
        "--redraw",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(Some(&json_lines(&again)), written.as_array());
}

/// Every command with a `--json` switch prints JSON lines on stdout and nothing else: the
/// commands are found in `taxi-sim --help` (so a new `--json` without a case here fails), each
/// run small.
#[test]
fn every_json_switch_prints_json_lines() {
    let (code, top, _) = taxi_sim(&["--help"]);
    assert_eq!(code, 0);
    // Every subcommand path (`bench`, `model coverage`, ...) whose help lists a `--json`
    // switch (not `--json <FILE>`, which writes a file).
    let mut with_switch = Vec::new();
    let mut pending: Vec<Vec<String>> = commands_in(&top).into_iter().map(|c| vec![c]).collect();
    while let Some(path) = pending.pop() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let (_, help, _) = taxi_sim(&args);
        pending.extend(commands_in(&help).into_iter().map(|c| {
            let mut p = path.clone();
            p.push(c);
            p
        }));
        let switch = |l: &str| {
            let mut words = l.split_whitespace();
            words.next() == Some("--json") && !words.next().is_some_and(|w| w.starts_with('<'))
        };
        if help.lines().any(switch) {
            with_switch.push(path.join(" "));
        }
    }
    with_switch.sort();
    let cases: &[(&str, &[&str])] = &[
        ("bench", &["bench", "mapper", "--samples", "1", "--json"]),
        (
            "model coverage",
            &[
                "model",
                "coverage",
                "praetor600",
                "--margin-m",
                "4",
                "--json",
            ],
        ),
    ];
    let covered: Vec<String> = cases.iter().map(|(c, _)| (*c).to_string()).collect();
    assert_eq!(with_switch, covered, "a --json switch with no case here");
    for (name, args) in cases {
        let (code, stdout, stderr) = taxi_sim(args);
        assert_eq!(code, 0, "{name}: {stderr}");
        assert!(!json_lines(&stdout).is_empty(), "{name}");
    }
}

/// The subcommands a `--help` lists under `Commands:` (`help` aside).
fn commands_in(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}
