//! Hostile input: a corpus of malformed files (`sim/tests/hostile/`: scenarios, pose files,
//! vehicle sidecars, URDFs, campaign files, run configurations) and corrupted map blocks and
//! manifests made from a real map, each given to the `taxi-sim` command that reads it. Every one
//! must exit with code 2 and an error that names the file and the line or field at fault and
//! says what is wrong - never a panic, never a run.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One malformed input: the file, the command (`{file}` stands for it, `{out}` for a fresh
/// output directory) and what the error must say besides the file's name.
struct Case {
    file: &'static str,
    args: &'static [&'static str],
    says: &'static [&'static str],
}

const CHECK: &[&str] = &["check", "{file}"];
const FIT: &[&str] = &["model", "fit", "{file}"];
const CAMPAIGN: &[&str] = &["campaign", "run", "{file}", "--out", "{out}", "--runs", "1"];
const CONFIG: &[&str] = &[
    "run",
    "../../../scenarios/cone_in_path_car.toml",
    "--config",
    "{file}",
    "--map-dir",
    "{out}",
];

const CASES: &[Case] = &[
    // Scenarios.
    Case {
        file: "scenario_empty.toml",
        args: CHECK,
        says: &[":1:1:", "missing field `name`"],
    },
    Case {
        file: "scenario_not_toml.toml",
        args: CHECK,
        says: &[":2:", "unclosed table"],
    },
    Case {
        file: "scenario_binary.toml",
        args: CHECK,
        says: &[":1:", "expected `=`"],
    },
    Case {
        file: "scenario_unknown_field.toml",
        args: CHECK,
        says: &[":9:1:", "unknown field `speeed`"],
    },
    Case {
        file: "scenario_walk_around_bad.toml",
        args: CHECK,
        says: &[
            ":18:15:",
            "`vehicle.walk_around`",
            "\"soon\"",
            "a time in seconds > 0",
        ],
    },
    Case {
        file: "scenario_seed_negative.toml",
        args: CHECK,
        says: &[":8:", "`seed`", "-4"],
    },
    Case {
        file: "scenario_nan_speed.toml",
        args: CHECK,
        says: &[":20:", "`route.speed_m_s`", "NaN"],
    },
    Case {
        file: "scenario_inf_world.toml",
        args: CHECK,
        says: &[":12:", "`world.max_m`", "finite"],
    },
    Case {
        file: "scenario_world_inverted.toml",
        args: CHECK,
        says: &[":12:", "must be above the lower corner"],
    },
    Case {
        file: "scenario_unknown_vehicle.toml",
        args: CHECK,
        says: &[":16:", "`vehicle.description`", "boeing_747"],
    },
    Case {
        file: "scenario_one_waypoint.toml",
        args: CHECK,
        says: &[":19:", "at least 2"],
    },
    Case {
        file: "scenario_route_outside_world.toml",
        args: CHECK,
        says: &[":19:", "outside the world"],
    },
    Case {
        file: "scenario_duplicate_id.toml",
        args: CHECK,
        says: &[":41:", "duplicate id `lamp_n_1`"],
    },
    Case {
        file: "scenario_unknown_kind.toml",
        args: CHECK,
        says: &[":90:", "`obstacles[0].kind`", "unicorn"],
    },
    Case {
        file: "scenario_bad_expectation.toml",
        args: CHECK,
        says: &[":93:", "`obstacles[0].expect`", "fly_over"],
    },
    Case {
        file: "scenario_obstacle_on_start.toml",
        args: CHECK,
        says: &[":89:", "overlaps the vehicle at its start pose"],
    },
    Case {
        file: "scenario_laps_zero.toml",
        args: CHECK,
        says: &[":9:", "`laps`", "got 0"],
    },
    Case {
        file: "scenario_config_bad_value.toml",
        args: CHECK,
        says: &[":95:", "scan_hz = 0"],
    },
    Case {
        file: "scenario_config_unknown_key.toml",
        args: CHECK,
        says: &[":95:", "unknown field `horizon`"],
    },
    Case {
        file: "scenario_pose_file_missing.toml",
        args: CHECK,
        says: &[":19:", "`route.pose_file`", "no_such_route.csv"],
    },
    // Pose files, through the scenarios that name them: the error names the pose file's line.
    Case {
        file: "scenario_pose_file_bad.toml",
        args: CHECK,
        says: &["route_bad_number.csv:3:6:", "`abc` is not a finite number"],
    },
    Case {
        file: "scenario_pose_file_nan.toml",
        args: CHECK,
        says: &["route_nan.csv:2:1:", "`NaN` is not a finite number"],
    },
    Case {
        file: "scenario_pose_file_short.toml",
        args: CHECK,
        says: &[":19:", "at least 2"],
    },
    // Vehicle sidecars.
    Case {
        file: "vehicle_unknown_field.toml",
        args: FIT,
        says: &[":11:1:", "unknown field `wing_span_m`"],
    },
    Case {
        file: "vehicle_heights_not_zero.toml",
        args: FIT,
        says: &["`heights_of_interest_m`", "h_0 must be 0"],
    },
    Case {
        file: "vehicle_heights_decreasing.toml",
        args: FIT,
        says: &["`heights_of_interest_m`", "h_2 = 0.5"],
    },
    Case {
        file: "vehicle_negative_wheelbase.toml",
        args: FIT,
        says: &["`motion.wheelbase_m`", "-2.625"],
    },
    Case {
        file: "vehicle_nan_speed.toml",
        args: FIT,
        says: &["`motion.max_speed_m_s`", "NaN"],
    },
    Case {
        file: "vehicle_bad_steering.toml",
        args: FIT,
        says: &[":13:", "unknown variant `tank`"],
    },
    Case {
        file: "vehicle_zero_circles.toml",
        args: FIT,
        says: &["`fit.max_circles`", "at least 1"],
    },
    Case {
        file: "vehicle_missing_urdf.toml",
        args: FIT,
        says: &["no_such.urdf", "No such file"],
    },
    // URDFs, through the sidecars that name them: the error names the URDF and the link.
    Case {
        file: "vehicle_urdf_not_xml.toml",
        args: FIT,
        says: &["robot_not_xml.urdf", "invalid URDF"],
    },
    Case {
        file: "vehicle_urdf_missing_link.toml",
        args: FIT,
        says: &["robot_missing_link.urdf", "joint `j`", "`wing`"],
    },
    Case {
        file: "vehicle_urdf_negative_box.toml",
        args: FIT,
        says: &["robot_negative_box.urdf", "link `base`", "box size y = -1"],
    },
    Case {
        file: "vehicle_urdf_nan_origin.toml",
        args: FIT,
        says: &[
            "robot_nan_origin.urdf",
            "link `base`",
            "origin xyz[1] = NaN",
        ],
    },
    Case {
        file: "vehicle_urdf_no_collision.toml",
        args: FIT,
        says: &["robot_no_collision.urdf", "no link has collision geometry"],
    },
    // Campaign files.
    Case {
        file: "campaign_unknown_key.toml",
        args: CAMPAIGN,
        says: &[":12:1:", "unknown field `samples`"],
    },
    Case {
        file: "campaign_runs_zero.toml",
        args: CAMPAIGN,
        says: &[":10:", "`runs`", "at least 1"],
    },
    Case {
        file: "campaign_missing_base.toml",
        args: CAMPAIGN,
        says: &[":8:", "`base`", "nowhere.toml"],
    },
    Case {
        file: "campaign_bad_distribution.toml",
        args: CAMPAIGN,
        says: &[":13:", "uniform = [100, 50]", "lo <= hi"],
    },
    Case {
        file: "campaign_bad_sampler.toml",
        args: CAMPAIGN,
        says: &[":11:", "unknown variant `sobol`"],
    },
    Case {
        file: "campaign_bad_parameter.toml",
        args: CAMPAIGN,
        says: &[":34:", "autonomy.planner_safety_m", ">= 0"],
    },
    Case {
        file: "campaign_parameter_not_list.toml",
        args: CAMPAIGN,
        says: &[":34:", "non-empty list"],
    },
    Case {
        file: "campaign_empty_circle_model.toml",
        args: CAMPAIGN,
        says: &[":34:", "collision_model", "no circles"],
    },
    Case {
        file: "campaign_obstacle_without_id.toml",
        args: CAMPAIGN,
        says: &[":13:", "needs an `id`"],
    },
    Case {
        file: "campaign_pool_too_big.toml",
        args: CAMPAIGN,
        says: &[":23:", "`pool`", "at most 100"],
    },
    // Run configurations.
    Case {
        file: "config_unknown_key.toml",
        args: CONFIG,
        says: &[":2:1:", "unknown field `planer_safety_m`"],
    },
    Case {
        file: "config_bad_heights.toml",
        args: CONFIG,
        says: &["mapping.heights_of_interest_m", "h_2 = 0.5"],
    },
    Case {
        file: "config_nan_noise.toml",
        args: CONFIG,
        says: &["pose_source.white_sigma_m = NaN"],
    },
    Case {
        file: "config_bad_schedule.toml",
        args: CONFIG,
        says: &[":1:", "unknown variant `whenever`"],
    },
    Case {
        file: "config_negative_latency.toml",
        args: CONFIG,
        says: &["faults.lidar_latency_s = -0.1", "finite number >= 0"],
    },
    Case {
        file: "config_stale_fraction.toml",
        args: CONFIG,
        says: &[
            "faults.stale_map.removed_fraction = 1.5",
            "fraction in [0, 1]",
        ],
    },
];

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/hostile")
}

/// Runs `taxi-sim args` in `dir`; returns the exit code and stderr.
fn taxi_sim(dir: &Path, args: &[String]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn refused(what: &str, code: Option<i32>, stderr: &str, says: &[&str]) -> Vec<String> {
    let mut wrong = Vec::new();
    if code != Some(2) {
        wrong.push(format!("{what}: exit code {code:?}, not 2"));
    }
    if !stderr.starts_with("error: ") || stderr.contains("panicked") {
        wrong.push(format!("{what}: not a clean error"));
    }
    for s in says {
        if !stderr.contains(s) {
            wrong.push(format!("{what}: the error does not say {s:?}"));
        }
    }
    if !wrong.is_empty() {
        wrong.push(format!("  stderr: {stderr}"));
    }
    wrong
}

#[test]
fn every_malformed_file_is_refused_with_code_2_naming_its_place() {
    let dir = corpus();
    let mut wrong = Vec::new();
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".toml"))
        .collect();
    files.sort();
    let listed: Vec<String> = CASES.iter().map(|c| c.file.to_string()).collect();
    // Every top-level file of the corpus is a case (the pose files and URDFs are named by them).
    for f in &files {
        if !listed.contains(f) {
            wrong.push(format!("{f} is in the corpus but not a case"));
        }
    }
    for case in CASES {
        let out = tempfile::tempdir().unwrap();
        let args: Vec<String> = case
            .args
            .iter()
            .map(|a| {
                a.replace("{file}", case.file)
                    .replace("{out}", &out.path().join("out").display().to_string())
            })
            .collect();
        let (code, stderr) = taxi_sim(&dir, &args);
        let mut says = vec![case.file];
        says.extend_from_slice(case.says);
        // A file of another kind is named by the one that points at it; the error names both.
        if case
            .says
            .iter()
            .any(|s| s.contains(".csv:") || s.contains(".urdf"))
        {
            says.remove(0);
        }
        wrong.extend(refused(case.file, code, &stderr, &says));
        // Nothing was run: no run output appeared.
        assert!(
            !out.path().join("out").join("results.jsonl").exists()
                && !out.path().join("out").join("manifest.json").exists(),
            "{}: something ran",
            case.file
        );
    }
    assert!(CASES.len() >= 40, "{} cases", CASES.len());
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// A way to corrupt a copy of a map: what it is, what it does given the map's first block (the
/// manifest is beside the blocks' folder), and what the error must say besides the file's name.
type Corruption = (&'static str, fn(&Path), &'static [&'static str]);

fn corruptions() -> [Corruption; 8] {
    [
        (
            "truncated block",
            |p| {
                let b = std::fs::read(p).unwrap();
                std::fs::write(p, &b[..b.len() - 100]).unwrap();
            },
            &["truncated or padded:", "its header says"],
        ),
        (
            "bad magic",
            |p| {
                let mut b = std::fs::read(p).unwrap();
                b[..8].copy_from_slice(b"XXXXXXXX");
                std::fs::write(p, b).unwrap();
            },
            &["not a taxi-sim map block"],
        ),
        (
            "flipped byte",
            |p| {
                let mut b = std::fs::read(p).unwrap();
                let middle = b.len() / 2;
                b[middle] ^= 0x40;
                std::fs::write(p, b).unwrap();
            },
            &["checksum mismatch"],
        ),
        (
            "other version",
            |p| {
                let mut b = std::fs::read(p).unwrap();
                b[8..12].copy_from_slice(&0u32.to_le_bytes());
                std::fs::write(p, b).unwrap();
            },
            &["format version 0"],
        ),
        (
            "block of the uncompressed format 1",
            |p| {
                let mut b = std::fs::read(p).unwrap();
                b[8..12].copy_from_slice(&1u32.to_le_bytes());
                std::fs::write(p, b).unwrap();
            },
            &["format version 1", "rebuild the map with `taxi-sim map`"],
        ),
        (
            "block of format 2 (float remission sums)",
            |p| {
                let mut b = std::fs::read(p).unwrap();
                b[8..12].copy_from_slice(&2u32.to_le_bytes());
                std::fs::write(p, b).unwrap();
            },
            &["format version 2", "rebuild the map with `taxi-sim map`"],
        ),
        (
            "garbage manifest",
            |p| {
                let m = p.parent().unwrap().parent().unwrap().join("manifest.json");
                std::fs::write(m, "{\"fingerprint\": 12,,").unwrap();
            },
            &["manifest.json:1:", "not a map manifest", "taxi-sim map"],
        ),
        (
            "manifest of another shape",
            |p| {
                let m = p.parent().unwrap().parent().unwrap().join("manifest.json");
                std::fs::write(m, "[1, 2, 3]").unwrap();
            },
            &["manifest.json:1:", "not a map manifest"],
        ),
    ]
}

/// Copies the map in `good` (its files and its blocks) to `copy`.
fn copy_map(good: &Path, copy: &Path) {
    std::fs::create_dir_all(copy.join("blocks")).unwrap();
    for entry in std::fs::read_dir(good).unwrap() {
        let p = entry.unwrap().path();
        if p.is_file() {
            std::fs::copy(&p, copy.join(p.file_name().unwrap())).unwrap();
        }
    }
    for entry in std::fs::read_dir(good.join("blocks")).unwrap() {
        let p = entry.unwrap().path();
        std::fs::copy(&p, copy.join("blocks").join(p.file_name().unwrap())).unwrap();
    }
}

/// What a corrupted copy of a real map does to `taxi-sim run`.
#[test]
fn corrupted_map_blocks_and_manifests_are_refused_naming_the_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scenario = root.join("scenarios/straight_cone_under_wing.toml");
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good");
    let (code, stderr) = taxi_sim(
        &root,
        &[
            "map".into(),
            scenario.display().to_string(),
            "--out".into(),
            good.display().to_string(),
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    let first_block = |dir: &Path| {
        let mut blocks: Vec<PathBuf> = std::fs::read_dir(dir.join("blocks"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        blocks.sort();
        blocks[0].clone()
    };
    let mut wrong = Vec::new();
    for (k, (what, corrupt, says)) in corruptions().iter().enumerate() {
        let copy = tmp.path().join(format!("bad{k}"));
        copy_map(&good, &copy);
        let block = first_block(&copy);
        corrupt(&block);
        let (code, stderr) = taxi_sim(
            &root,
            &[
                "run".into(),
                scenario.display().to_string(),
                "--map-dir".into(),
                copy.display().to_string(),
            ],
        );
        let name = if what.contains("manifest") {
            "manifest.json".to_string()
        } else {
            block.file_name().unwrap().to_string_lossy().into_owned()
        };
        let mut all = vec![name.as_str()];
        all.extend_from_slice(says);
        wrong.extend(refused(what, code, &stderr, &all));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Every command that writes a file creates the folders it names that do not exist yet, the
/// same way (they all write through `mapper::write_atomically`), and writes nothing else there.
#[test]
fn output_folders_that_do_not_exist_are_created_by_every_command() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let tmp = tempfile::tempdir().unwrap();
    let t = |rest: &str| tmp.path().join(rest).display().to_string();
    let scenario = root
        .join("scenarios/straight_cone_under_wing.toml")
        .display()
        .to_string();
    let runs: Vec<(Vec<String>, Vec<String>)> = vec![
        (
            vec![
                "model".into(),
                "fit".into(),
                "iara_car".into(),
                "--svg".into(),
                t("a/b/car.svg"),
                "--carmen".into(),
                t("c/car.txt"),
            ],
            vec![t("a/b/car.svg"), t("c/car.txt")],
        ),
        (
            vec![
                "scan".into(),
                scenario.clone(),
                "--out".into(),
                t("d/e/scan.ply"),
            ],
            vec![t("d/e/scan.ply")],
        ),
        (
            vec![
                "run".into(),
                scenario,
                "--map-dir".into(),
                t("f/map"),
                "--report".into(),
                t("g/h/run.json"),
            ],
            vec![t("f/map/manifest.json"), t("g/h/run.json")],
        ),
    ];
    for (args, files) in runs {
        let (code, stderr) = taxi_sim(&root, &args);
        assert!(code == Some(0), "{args:?}: {code:?} {stderr}");
        for f in files {
            assert!(Path::new(&f).is_file(), "{args:?} did not write {f}");
        }
    }
    let mut top: Vec<String> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    top.sort();
    assert_eq!(top, ["a", "c", "d", "f", "g"]);
}
