//! `taxi-sim regress` through the binary, on files that need no run: a file that is not a
//! scenario is a case with its located error (exit 2, the run going on, every output written);
//! a campaign file is skipped; shards' results merge back in the order one machine gives; bad
//! flags are refused by name.

use std::path::Path;

fn taxi_sim(dir: &Path, args: &[&str]) -> (i32, String, String) {
    crate::taxi_sim_in(dir, args)
}

#[test]
fn a_bad_file_is_an_error_case_the_run_goes_on_and_every_output_is_written() {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(d.path().join("cases/campaigns")).unwrap();
    std::fs::write(
        d.path().join("cases/a_broken.toml"),
        "name = \"x\"\nseed = -3\n",
    )
    .unwrap();
    std::fs::write(d.path().join("cases/b_broken.toml"), "not toml at all [").unwrap();
    std::fs::write(
        d.path().join("cases/campaigns/c.toml"),
        "name = \"c\"\nbase = \"../a_broken.toml\"\n",
    )
    .unwrap();
    let (code, out, err) = taxi_sim(
        d.path(),
        &[
            "regress",
            "cases",
            "--junit",
            "out/r.xml",
            "--json",
            "out/r.jsonl",
            "--summary",
            "out/r.md",
            "--jobs",
            "1",
        ],
    );
    assert_eq!(code, 2, "{out}\n{err}");
    assert!(err.contains("regress: 2 scenario files"), "{err}");
    assert!(
        out.contains("cases/a_broken.toml:2") && out.contains("`seed`"),
        "{out}"
    );
    assert!(
        out.contains("2 cases: 0 passed, 0 failed, 0 known problems, 0 not run, 2 errors"),
        "{out}"
    );
    let xml = std::fs::read_to_string(d.path().join("out/r.xml")).unwrap();
    assert_eq!(xml.matches("<error ").count(), 2, "{xml}");
    assert!(xml.contains("<testsuite name=\"cases\""), "{xml}");
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(d.path().join("out/r.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let names: Vec<&str> = lines.iter().map(|l| l["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["a_broken", "b_broken"]);
    assert!(lines.iter().all(|l| l["status"] == "error"));
    let md = std::fs::read_to_string(d.path().join("out/r.md")).unwrap();
    assert!(md.contains("| cases/b_broken | ERROR |"), "{md}");

    // The two cases as two shards, merged back: the same results in the same order.
    for i in 0..2 {
        let shard = format!("{i}/2");
        let json = format!("out/s{i}.jsonl");
        let (code, _, err) = taxi_sim(
            d.path(),
            &["regress", "cases", "--shard", &shard, "--json", &json],
        );
        assert_eq!(code, 2, "{err}");
    }
    let (code, out, _) = taxi_sim(
        d.path(),
        &[
            "regress",
            "--merge",
            "out/s1.jsonl",
            "out/s0.jsonl",
            "--json",
            "out/m.jsonl",
        ],
    );
    assert_eq!(code, 2, "{out}");
    let strip = |p: &str| -> Vec<serde_json::Value> {
        std::fs::read_to_string(d.path().join(p))
            .unwrap()
            .lines()
            .map(|l| {
                let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                v["wall_time_s"] = 0.into();
                v
            })
            .collect()
    };
    assert_eq!(strip("out/m.jsonl"), strip("out/r.jsonl"));
    // A shard merged twice is refused by name.
    let (code, _, err) = taxi_sim(
        d.path(),
        &["regress", "--merge", "out/s0.jsonl", "out/s0.jsonl"],
    );
    assert_eq!(code, 2);
    assert!(
        err.contains("more than one shard") && err.contains("a_broken"),
        "{err}"
    );
}

#[test]
fn bad_paths_globs_and_numbers_are_refused_by_name() {
    let d = tempfile::tempdir().unwrap();
    for (args, says) in [
        (
            &["regress", "nowhere"][..],
            "nowhere: no such file or folder",
        ),
        (&["regress", ".", "--filter", "["][..], "--filter"),
        (&["regress", ".", "--jobs", "0"][..], "--jobs 0"),
        (
            &["regress", ".", "--time-limit-s", "0"][..],
            "--time-limit-s 0",
        ),
        (&["regress", "."][..], "no scenario files under ."),
        (&["regress", ".", "--shard", "3/2"][..], "3/2"),
        // Golden numbers are the quick tier's whole run: not blessed from --full or a cut run.
        (&["regress", ".", "--bless", "--full"][..], "--full"),
        (
            &["regress", ".", "--bless", "--time-limit-s", "5"][..],
            "--time-limit-s",
        ),
    ] {
        let (code, _, err) = taxi_sim(d.path(), args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
}
