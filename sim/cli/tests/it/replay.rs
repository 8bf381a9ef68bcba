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
