//! The replay options on the command line: a bad one is refused with exit code 2, naming its
//! flag, before anything runs or is written.

use std::path::Path;

#[test]
fn the_command_line_rejects_a_bad_replay_option_with_exit_code_2() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .args([
            "run",
            "../../scenarios/straight_cone_under_wing.toml",
            "--record",
            "unused.rrd",
            "--replay-point-stride",
            "0",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--replay-point-stride"), "{stderr}");
    assert!(
        !Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("unused.rrd")
            .exists()
    );
}

/// `--record` takes a Rerun recording (.rrd) and a ROS 2 bag (.mcap), one of each at most;
/// anything else is refused with exit code 2 before the mapping drive, naming the flag.
#[test]
fn record_takes_an_rrd_and_an_mcap_and_refuses_anything_else() {
    for (files, says) in [
        (
            &["run.bag"][..],
            "--record run.bag: a Rerun recording (.rrd) or a ROS 2 bag (.mcap)",
        ),
        (&["a.mcap", "b.mcap"], "--record: one .mcap file at most"),
    ] {
        let mut args = vec!["run", "../../scenarios/straight_cone_under_wing.toml"];
        for f in files {
            args.extend(["--record", f]);
        }
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
            .args(&args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(says), "{stderr}");
        assert!(!stderr.contains("mapping drive"), "{stderr}");
    }
}
