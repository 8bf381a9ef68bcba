//! `taxi-sim bench figures` without its real runs (minutes long, CI's job): its flags, the
//! inputs it refuses before starting any, and a failing run.

use std::path::Path;
use std::process::Command;

use crate::taxi_sim_in as taxi_sim;

#[test]
fn bench_help_lists_figures_and_its_flags() {
    let (code, stdout, stderr) = taxi_sim(Path::new("."), &["bench", "figures", "--help"]);
    assert_eq!(code, 0, "{stderr}");
    for word in ["figures", "--json-out", "--keep", "--out"] {
        assert!(stdout.contains(word), "{word} missing from:\n{stdout}");
    }
}

#[test]
fn figures_refuse_a_used_map_directory_and_a_wrong_directory_before_running() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let work = tempfile::tempdir().unwrap();
    let map = work.path().join("aerodrome-map");
    std::fs::create_dir(&map).unwrap();
    std::fs::write(map.join("manifest.json"), "{}").unwrap();
    let (code, _, stderr) = taxi_sim(
        &root,
        &["bench", "figures", "--out", work.path().to_str().unwrap()],
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("aerodrome-map is not empty") && stderr.contains("--out"),
        "{stderr}"
    );
    // From elsewhere than the repository's root the scenarios are not found.
    let (code, _, stderr) = taxi_sim(work.path(), &["bench", "figures"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("scenarios/aerodrome.toml not found") && stderr.contains("root"),
        "{stderr}"
    );
}

#[test]
fn a_failing_run_is_an_error_naming_its_command_line_status_and_output() {
    let work = tempfile::tempdir().unwrap();
    std::fs::create_dir(work.path().join("scenarios")).unwrap();
    for name in ["aerodrome.toml", "parking_lot.toml"] {
        std::fs::write(work.path().join("scenarios").join(name), "name = 3\n").unwrap();
    }
    let tmp = work.path().join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .args(["bench", "figures"])
        .current_dir(work.path())
        .env("TMPDIR", &tmp) // the working directory, kept on failure, stays in `work`
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("run scenarios/aerodrome.toml --laps 1 --map-dir")
            && stderr.contains("exit status: 2")
            && stderr.contains("aerodrome-first-run.stderr.txt")
            && stderr.contains("`name`")
            && stderr.contains("is kept"),
        "{stderr}"
    );
}
