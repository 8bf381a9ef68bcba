//! Campaigns with the `taxi-sim` binary on the smoke campaign (`scenarios/campaigns/smoke.toml`,
//! 12 runs of a car on a straight road): every failure file (and any variant written out) is
//! reproduced by `taxi-sim run`; shards run apart and merged with `taxi-sim campaign merge` equal
//! the single-machine run, and a lost shard is named and run again with `--only-missing`. The
//! campaign's library behaviour is tested in `sim/tests/it/campaign.rs`.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use sim::campaign::{Campaign, RunOptions, RunRecord, Shard, read_results, run_campaign, variant};

use crate::smoke_campaign::{full, smoke, smoke_path};

/// `taxi-sim run FILE --report`: the report's JSON.
fn taxi_sim_run(file: &Path, work: &Path) -> serde_json::Value {
    let report = work.join("report.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .arg("run")
        .arg(file)
        .arg("--map-dir")
        .arg(work.join("map"))
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    assert!(
        matches!(out.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap()
}

/// The report agrees with the record: end, contacts, clearances, verdict.
fn assert_reproduces(report: &serde_json::Value, r: &RunRecord) {
    assert_eq!(report["end"].as_str(), Some(r.end.as_str()), "{}", r.index);
    assert_eq!(report["contacts"].as_array().unwrap().len(), r.contacts);
    assert_eq!(
        report["expectations_met"].as_bool(),
        Some(r.expectations_met)
    );
    let clearance: Vec<Option<f64>> = report["min_clearance_m"]
        .as_array()
        .unwrap()
        .iter()
        .map(serde_json::Value::as_f64)
        .collect();
    assert_eq!(clearance, r.min_clearance_m, "{}", r.index);
    assert_eq!(report["sim_time_s"].as_f64(), Some(r.sim_time_s));
}

#[test]
fn failure_files_and_written_variants_reproduce_with_taxi_sim_run() {
    let (dir, records) = full();
    let campaign = smoke();
    let work = tempfile::tempdir().unwrap();
    // Every failure file as it is (its setting is in its `[config]`).
    for r in records.iter().filter(|r| r.failed) {
        let file = dir.path().join(r.failure_file.as_deref().unwrap());
        let report = taxi_sim_run(&file, work.path());
        assert_reproduces(&report, r);
    }
    // And a passing variant under the other setting, written out by hand.
    let r = &records[1];
    let v = variant(&campaign, 1, records);
    let file = work.path().join("variant-1.toml");
    std::fs::write(&file, &v.text).unwrap();
    assert_reproduces(&taxi_sim_run(&file, work.path()), r);
}

fn run_shard(campaign: &Campaign, out: &Path, maps: &Path, shard: Shard) -> Vec<RunRecord> {
    let stop = AtomicBool::new(false);
    run_campaign(
        campaign,
        &RunOptions {
            shard: Some(shard),
            maps_dir: Some(maps.to_path_buf()),
            out: out.to_path_buf(),
            jobs: 1,
            runs: None,
            variants: None,
            stop: &stop,
            record_failures: false,
            progress: &|_| {},
            stack: None,
        },
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .records
}

#[test]
fn shards_merged_equal_the_single_machine_run_and_a_lost_shard_is_named_and_rerun() {
    let (full_dir, records) = full();
    let root = tempfile::tempdir().unwrap();
    let maps = root.path().join("maps");
    let campaign = smoke();
    let dirs: Vec<PathBuf> = (0..4)
        .map(|i| root.path().join(format!("shard-{i}")))
        .collect();
    // Shards 0, 1 and 3 run; shard 2 is lost (a node went down).
    for i in [0u64, 1, 3] {
        let got = run_shard(
            &campaign,
            &dirs[i as usize],
            &maps,
            Shard { index: i, count: 4 },
        );
        assert!(got.iter().all(|r| r.index % 4 == i), "{i}");
        assert_eq!(got.len(), 3);
    }
    // One map for all three shards, in the shared cache, and no scratch left behind.
    let cached: Vec<_> = std::fs::read_dir(&maps).unwrap().collect();
    assert_eq!(cached.len(), 1, "{cached:?}");
    // A shard's directory refuses another shard of the campaign.
    let stop = AtomicBool::new(false);
    let e = run_campaign(
        &campaign,
        &RunOptions {
            shard: Some(Shard { index: 2, count: 4 }),
            maps_dir: Some(maps.clone()),
            out: dirs[0].clone(),
            jobs: 1,
            runs: None,
            variants: None,
            stop: &stop,
            record_failures: false,
            progress: &|_| {},
            stack: None,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("shard 0/4") && e.contains("shard 2/4"), "{e}");

    let merged = root.path().join("merged");
    let exe = env!("CARGO_BIN_EXE_taxi-sim");
    let out = std::process::Command::new(exe)
        .args(["campaign", "merge", "--out"])
        .arg(&merged)
        .args(&dirs[..2])
        .arg(&dirs[3])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains("missing 3 variants: 2, 6, 10"), "{said}");
    assert!(said.contains("--only-missing"), "{said}");
    // The missing ones, run into the merged directory.
    let status = std::process::Command::new(exe)
        .args(["campaign", "run"])
        .arg(smoke_path())
        .arg("--out")
        .arg(&merged)
        .args(["--only-missing", "--jobs", "2", "--maps-dir"])
        .arg(&maps)
        .status()
        .unwrap();
    assert!(status.code().is_some_and(|c| c <= 1), "{status}");
    let all = read_results(&merged).unwrap();
    assert_eq!(all.len(), records.len());
    for (a, b) in all.iter().zip(records) {
        assert_eq!(a.timeless(), b.timeless(), "variant {}", b.index);
    }
    // The same failure files as the single-machine run.
    for r in records.iter().filter(|r| r.failed) {
        let f = r.failure_file.as_ref().unwrap();
        assert_eq!(
            std::fs::read_to_string(merged.join(f)).unwrap(),
            std::fs::read_to_string(full_dir.path().join(f)).unwrap()
        );
    }
    // --only-missing refuses a directory with nothing to complete.
    let empty = root.path().join("empty");
    let out = std::process::Command::new(exe)
        .args(["campaign", "run"])
        .arg(smoke_path())
        .arg("--out")
        .arg(&empty)
        .arg("--only-missing")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("holds no results"));
}

/// `taxi-sim campaign compare`: the smoke campaign's run against a copy in which one variant
/// ends in a needless pilot call - exit 1 one way (worse, and why), 0 the other - and a side
/// that is no run, exit 2 naming it; `campaign run --variants` beyond the campaign, exit 2.
#[test]
fn compare_exits_by_whether_the_second_run_is_worse() {
    let (dir, records) = full();
    let work = tempfile::tempdir().unwrap();
    let worse = work.path().join("worse");
    std::fs::create_dir_all(&worse).unwrap();
    std::fs::copy(
        dir.path().join("campaign.json"),
        worse.join("campaign.json"),
    )
    .unwrap();
    let i = records.iter().position(|r| r.pilot_call.is_none()).unwrap();
    let mut changed = records.to_vec();
    changed[i].end = "waiting_for_hidden_obstacle".into();
    changed[i].pilot_call = Some("hidden_obstacle/lost_obstacle".into());
    changed[i].needless_pilot_call = true;
    let text: String = (changed.iter())
        .map(|r| serde_json::to_string(r).unwrap() + "\n")
        .collect();
    std::fs::write(worse.join("results.jsonl"), text).unwrap();
    let compare = |a: &Path, b: &Path| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
            .args(["campaign", "compare"])
            .args([a, b])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string()
            + &String::from_utf8_lossy(&out.stderr);
        (out.status.code(), text)
    };
    let (code, text) = compare(dir.path(), &worse);
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains("**After is worse**"), "{text}");
    assert!(text.contains(&format!("| {i} | ")), "{text}");
    let (code, text) = compare(&worse, dir.path());
    assert_eq!(code, Some(0), "{text}");
    let (code, text) = compare(dir.path(), &work.path().join("nothing"));
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("nothing"), "{text}");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .args(["campaign", "run"])
        .arg(smoke_path())
        .arg("--out")
        .arg(work.path().join("out"))
        .args(["--variants", "3,40"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("variant 40 is beyond the 12 variants"),
        "{err}"
    );
}
