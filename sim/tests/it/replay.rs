//! The Rerun replay: a short run's recording is complete (every message decodes, the footer is
//! there), holds the entity paths docs/commands.md lists, and appears only when the run finished; bad
//! replay options name their flag. The command line's refusal of a bad replay option is tested in
//! the `taxi-sim` package (`sim/cli/tests/it/replay.rs`).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rerun::external::re_log_encoding::rrd::DecoderApp;
use rerun::log::{Chunk, LogMsg};
use sim::engine::{EndReason, RunHandles, RunReport, RunSetup, run_with};
use sim::replay::{Replay, ReplayOptions};
use sim::scenario::{RunConfig, Scenario};

fn scenario(name: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// The entity paths of the recording's data (blueprint excluded), and whether it has a footer.
fn entity_paths(rrd: &Path) -> (BTreeSet<String>, bool) {
    let file = std::fs::File::open(rrd).unwrap();
    let mut messages = DecoderApp::decode_lazy(std::io::BufReader::new(file));
    let mut paths = BTreeSet::new();
    for msg in messages.by_ref() {
        let msg = msg.unwrap_or_else(|e| panic!("{}: {e}", rrd.display()));
        if let LogMsg::ArrowMsg(store, arrow) = msg
            && store.kind() == rerun::StoreKind::Recording
        {
            let chunk = Chunk::from_arrow_msg(&arrow).unwrap();
            paths.insert(
                chunk
                    .entity_path()
                    .to_string()
                    .trim_start_matches('/')
                    .to_string(),
            );
        }
    }
    let footer = !messages.rrd_manifests().unwrap().is_empty();
    (paths, footer)
}

/// Scenario `name` on a fresh map, recorded into `TMP/replay/run.rrd` until `until_s` of
/// simulated time, then stopped as Ctrl-C would: the directory, the recording's path, the
/// report and the replay.
fn recorded(name: &str, until_s: f64) -> (tempfile::TempDir, PathBuf, RunReport, Replay) {
    let s = scenario(name);
    let dir = tempfile::tempdir().unwrap();
    let map_dir = dir.path().join("map");
    sim::offline_map::map_drive(&s, &RunConfig::default(), &map_dir, &mut |_, _| {}).unwrap();
    let rrd = dir.path().join("replay").join("run.rrd");
    let mut replay = Replay::new(
        &ReplayOptions {
            record: Some(rrd.clone()),
            ..ReplayOptions::default()
        },
        &s.name,
    )
    .unwrap();
    let stop = AtomicBool::new(false);
    let report = run_with(
        &s,
        &RunSetup::new(map_dir),
        RunHandles {
            stop: Some(&stop),
            progress: &mut |p| {
                if p.sim_time_s >= until_s {
                    stop.store(true, Ordering::Relaxed);
                }
            },
            observer: &mut replay,
        },
    )
    .unwrap();
    (dir, rrd, report, replay)
}

#[test]
fn a_short_run_is_recorded_completely_with_every_entity_path() {
    // 18 s of simulated time: past the cone (x = 60 m at 5 m/s), then Ctrl-C as a user would.
    let (dir, rrd, report, replay) = recorded("straight_cone_under_wing", 18.0);
    let out = dir.path().join("replay");
    assert!(
        report.end == EndReason::Interrupted && report.sim_time_s >= 18.0,
        "{report:?}"
    );
    let (written, bytes) = replay.summary().recorded.clone().expect("a recording");
    assert_eq!(written, rrd);
    assert_eq!(bytes, std::fs::metadata(&rrd).unwrap().len());
    // Atomic: the destination and nothing else (no temporary file left behind).
    let files: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(files, vec![std::ffi::OsString::from("run.rrd")]);
    assert!(bytes > 50_000, "{bytes} bytes");

    let (paths, footer) = entity_paths(&rrd);
    assert!(footer, "no footer: the recording was not closed");
    for expected in [
        "world",
        "world/ground",
        "world/objects/lamp_n_1",
        "world/route",
        "world/obstacles/cone_under_wing",
        "world/vehicle",
        "world/vehicle/circles/level_0",
        "world/vehicle/circles/level_1",
        "world/lidar",
        "world/maps/level_0/occupancy",
        "world/maps/level_1/occupancy",
        "maps/level_0/distance",
        "maps/level_1/distance",
        "world/planner/candidates",
        "world/planner/chosen",
        "plots/speed_m_s",
        "plots/steering_rad",
        "plots/clearance_m/level_0",
        "plots/clearance_m/level_1",
        "plots/real_time_factor",
        "plots/speed_scale",
        "events",
    ] {
        assert!(
            paths.contains(expected),
            "{expected} missing from {paths:?}"
        );
    }
    assert!(
        paths.iter().any(|p| p.starts_with("world/vehicle/parts/")),
        "no vehicle parts in {paths:?}"
    );
}

#[test]
fn a_replay_dropped_before_the_run_finished_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let rrd = dir.path().join("run.rrd");
    let replay = Replay::new(
        &ReplayOptions {
            record: Some(rrd.clone()),
            ..ReplayOptions::default()
        },
        "dropped",
    )
    .unwrap();
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "the temporary file"
    );
    drop(replay);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn bad_replay_options_name_their_flag() {
    let cases = [
        (
            ReplayOptions {
                point_stride: 0,
                ..ReplayOptions::default()
            },
            "--replay-point-stride",
        ),
        (
            ReplayOptions {
                scan_every: 0,
                ..ReplayOptions::default()
            },
            "--replay-scan-every",
        ),
        (
            ReplayOptions {
                maps_hz: f64::NAN,
                ..ReplayOptions::default()
            },
            "--replay-maps-hz",
        ),
        (
            ReplayOptions {
                map_half_m: -1.0,
                ..ReplayOptions::default()
            },
            "--replay-map-half-m",
        ),
        (
            ReplayOptions {
                steps_hz: 0.0,
                ..ReplayOptions::default()
            },
            "--replay-steps-hz",
        ),
        (
            ReplayOptions {
                connect: Some("not a url://".into()),
                ..ReplayOptions::default()
            },
            "--connect",
        ),
    ];
    for (options, flag) in cases {
        let e = options.validate().expect_err(flag);
        assert!(format!("{e:#}").contains(flag), "{flag}: {e:#}");
    }
    assert!(ReplayOptions::default().validate().is_ok());
}

/// The ground the start-up rule finds unseen at the stand (its area in the report) is drawn on
/// the ground in the recording (`world/start/unseen`; the autonomy tests check its cells).
#[test]
fn the_ground_unseen_at_the_start_is_drawn_in_the_replay() {
    // Past the walk-around at 8 s.
    let (_dir, rrd, report, replay) = recorded("jet_moves_off_after_the_walk_around", 9.0);
    let unseen = report.start_unseen_m2.expect("the start-up rule checked");
    assert!(unseen > 10.0, "{unseen} m2");
    drop(replay);
    let (paths, _) = entity_paths(&rrd);
    assert!(
        paths.contains(sim::replay::START_UNSEEN),
        "no {} in {paths:?}",
        sim::replay::START_UNSEEN
    );
}
