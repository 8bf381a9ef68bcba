//! Tests of `campaign compare`: figures over the variants both sides hold, the changed ones,
//! a kept record read as its directory, and what is refused.

use std::io::Write as _;

use super::*;

/// A run's record as a campaign writes it: `end`, a pilot call if any (needless or not), the
/// contacts at fault, its least clearance and its laps.
fn record(index: u64, end: &str, call: Option<(&str, bool)>, at_fault: usize) -> RunRecord {
    let mut r: RunRecord = serde_json::from_value(serde_json::json!({
        "index": index, "sample": index, "setting": 0, "seed": 3, "sampled": {},
        "parameters": {}, "u": [], "end": end,
        "expectations_met": at_fault == 0, "failed": at_fault > 0, "failures": [],
        "contacts": at_fault, "contacts_with": [], "contacts_at_fault": at_fault,
        "min_ttc_s": 2.0 + index as f64, "min_pet_s": null, "obstacles": [],
        "min_clearance_m": [0.5], "obstacle_clearance_m": 1.0 + index as f64,
        "static_clearance_m": 1.0, "stops": 1, "deviations": 0, "false_stops": 0,
        "needless_deviations": 0, "lap_times_s": if end == "completed" { vec![70.0 + index as f64] } else { vec![] },
        "sim_time_s": 73.1, "wall_time_s": 5.8, "score": 0.5, "failure_file": null,
    }))
    .expect("a record");
    r.pilot_call = call.map(|(c, _)| c.to_string());
    r.needless_pilot_call = call.is_some_and(|(_, n)| n);
    r
}

fn side(name: &str, digest: &str, records: Vec<RunRecord>) -> Side {
    Side {
        path: PathBuf::from(name),
        meta: serde_json::json!({"name": "traffic", "digest": digest, "sampler": "random", "seed": 7}),
        records,
        calls_recorded: true,
        meta_missing: None,
    }
}

const LOST: &str = "hidden_obstacle/mover_lost_at_body";

/// Before: 0 completes, 1 a needless call, 2 at fault, 3 completes, 4 only before. After: 1
/// completes, 2 a needless call, 5 only after. The figures count the four common variants
/// only; the changed ones are 1 and 2, in order, as they ended on each side.
#[test]
fn the_figures_are_over_the_common_variants_and_the_changed_ones_are_listed() {
    let before = side(
        "old",
        "d1",
        vec![
            record(0, "completed", None, 0),
            record(1, "waiting_for_hidden_obstacle", Some((LOST, true)), 0),
            record(2, "struck", Some(("struck/struck", false)), 1),
            record(3, "completed", None, 0),
            record(4, "completed", None, 0),
        ],
    );
    let after = side(
        "new",
        "d1",
        vec![
            record(0, "completed", None, 0),
            record(1, "completed", None, 0),
            record(2, "waiting_for_hidden_obstacle", Some((LOST, true)), 0),
            record(3, "completed", None, 0),
            record(5, "completed", None, 0),
        ],
    );
    let c = compare(&before, &after).expect("comparable");
    assert_eq!((c.common, c.only), (4, (1, 1)));
    assert!(!c.file_changed && !c.sets_differ && !c.falsify);
    let (o, n) = &c.figures;
    assert_eq!((o.at_fault, o.calls, o.completed), ((1, 1), (2, 1), 2));
    assert_eq!((n.at_fault, n.calls, n.completed), ((0, 0), (1, 1), 3));
    // Laps over the variants both completed (0 and 3: 70 and 73 s), not 1, which completes
    // after only.
    assert_eq!(o.lap_s, [Some(70.0), Some(73.0)]);
    assert_eq!(n.lap_s, o.lap_s);
    assert_eq!(o.clearance_m, [Some(1.0), Some(2.0)]);
    assert_eq!(c.causes[LOST], [(1, 1), (1, 1)]);
    assert_eq!(c.causes["struck/struck"], [(1, 0), (0, 0)]);
    let changed: Vec<String> = (c.changed.iter())
        .map(|(i, o, n)| format!("{i}: {o} -> {n}"))
        .collect();
    assert_eq!(
        changed,
        [
            format!("1: waiting_for_hidden_obstacle ({LOST}), needless -> completed"),
            format!(
                "2: struck (struck/struck), 1 at fault -> waiting_for_hidden_obstacle ({LOST}), needless"
            ),
        ]
    );
    assert!(c.worse().is_empty(), "{:?}", c.worse());
    let (mut before, mut after) = (before, after);
    std::mem::swap(&mut before, &mut after);
    let back = compare(&before, &after).unwrap();
    assert_eq!(back.worse(), ["runs at fault 0 -> 1", "pilot calls 1 -> 2"]);
    std::mem::swap(&mut before, &mut after);
    let text = render(&c, &before, &after);
    assert!(
        text.contains("| at fault (runs / contacts) | 1 / 1 | 0 / 0 |"),
        "{text}"
    );
    assert!(
        text.contains("| pilot calls | 2 (50.0 %) | 1 (25.0 %) |"),
        "{text}"
    );
    assert!(
        text.contains("Left out: 1 variants only before holds, 1 only after."),
        "{text}"
    );
}

/// A record kept gzipped beside its `campaign.json` reads as the directory it came from, and
/// compared with it nothing changed.
#[test]
fn a_kept_record_reads_as_its_campaign_directory() {
    let root = tempfile::tempdir().expect("a temporary directory");
    let dir = root.path().join("run");
    std::fs::create_dir_all(&dir).unwrap();
    let records = [
        record(0, "completed", None, 0),
        record(1, "blocked", Some(("blocked/mover", false)), 0),
    ];
    let lines: String = (records.iter())
        .map(|r| serde_json::to_string(r).unwrap() + "\n")
        .collect();
    let meta = r#"{"name": "traffic", "digest": "d1", "sampler": "random", "seed": 7}"#;
    std::fs::write(dir.join("results.jsonl"), &lines).unwrap();
    std::fs::write(dir.join("campaign.json"), meta).unwrap();
    let kept = root.path().join("traffic_abc.jsonl.gz");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(lines.as_bytes()).unwrap();
    std::fs::write(&kept, gz.finish().unwrap()).unwrap();
    std::fs::write(root.path().join("traffic_abc.campaign.json"), meta).unwrap();
    let (a, b) = (Side::read(&dir).unwrap(), Side::read(&kept).unwrap());
    assert_eq!(a.records, b.records);
    assert_eq!(b.meta["digest"], "d1");
    let c = compare(&a, &b).unwrap();
    assert_eq!((c.common, c.changed.len()), (2, 0));
}

/// Runs of two campaigns, sides with no variant in common, a bad line and a file that is no
/// record are refused, naming what is wrong.
#[test]
fn what_cannot_be_compared_is_refused_by_name() {
    let a = side("old", "d1", vec![record(0, "completed", None, 0)]);
    let mut b = side("new", "d2", vec![record(0, "completed", None, 0)]);
    b.meta["name"] = "airports".into();
    let e = compare(&a, &b).unwrap_err().to_string();
    assert!(e.contains("\"airports\", not of \"traffic\""), "{e}");
    let b = side("new", "d2", vec![record(1, "completed", None, 0)]);
    let e = compare(&a, &b).unwrap_err().to_string();
    assert!(e.contains("no variant in common with old"), "{e}");
    let b = side("new", "d2", vec![record(0, "completed", None, 0)]);
    assert!(compare(&a, &b).unwrap().file_changed);
    // The same file run with a --set: not a changed file.
    let b = side(
        "new",
        "d1-set0abc1234",
        vec![record(0, "completed", None, 0)],
    );
    let c = compare(&a, &b).unwrap();
    assert!(!c.file_changed && c.sets_differ);
    let mut b = side("new", "d1-halton", vec![record(0, "completed", None, 0)]);
    b.meta["sampler"] = "halton".into();
    let e = compare(&a, &b).unwrap_err().to_string();
    assert!(
        e.contains("a run of sampler \"halton\", not of \"random\""),
        "{e}"
    );
    let root = tempfile::tempdir().unwrap();
    let bad = root.path().join("x.jsonl");
    let good = serde_json::to_string(&record(0, "completed", None, 0)).unwrap();
    std::fs::write(&bad, format!("{good}\n{{\"index\": 1}}\n{good}\n")).unwrap();
    let e = Side::read(&bad).unwrap_err().to_string();
    assert!(e.contains("x.jsonl: line 2: not a run record"), "{e}");
    let other = root.path().join("notes.txt");
    std::fs::write(&other, "hello").unwrap();
    let e = Side::read(&other).unwrap_err().to_string();
    assert!(
        e.contains("notes.txt: not a campaign directory, nor a record"),
        "{e}"
    );
}

/// What a comparison cannot trust is left out and said: variants not valid on a side (valid
/// before, invalid after is worse), a side that recorded no pilot calls (an older build: its
/// calls would read as none), a falsifier's variants (compared by figures only), a record
/// with no `campaign.json` beside it, and a last line cut short by a killed process.
#[test]
fn what_cannot_be_trusted_is_left_out_and_said() {
    let mut invalid = record(1, "invalid", None, 0);
    invalid.failed = false;
    let a = side(
        "old",
        "d1",
        vec![
            record(0, "completed", None, 0),
            record(1, "struck", Some(("struck/struck", false)), 1),
        ],
    );
    let b = side("new", "d1", vec![record(0, "completed", None, 0), invalid]);
    let c = compare(&a, &b).unwrap();
    assert_eq!((c.common, c.invalid), (1, (0, 0, 1)));
    assert_eq!(c.worse(), ["variants no longer valid 0 -> 1"]);
    let mut old = side("old", "d1", vec![record(0, "completed", None, 0)]);
    old.calls_recorded = false;
    let new = side(
        "new",
        "d1",
        vec![record(0, "blocked", Some(("blocked/mover", false)), 0)],
    );
    let c = compare(&old, &new).unwrap();
    assert!(!c.calls_known && c.worse().is_empty() && c.causes.is_empty());
    assert_eq!(c.changed[0].2.call, None);
    let text = render(&c, &old, &new);
    assert!(text.contains("`old` records no pilot calls"), "{text}");
    assert!(
        text.contains("| pilot calls | not recorded | not recorded |"),
        "{text}"
    );
    let (mut f1, mut f2) = (new.clone(), new.clone());
    f1.meta["sampler"] = "falsify".into();
    f2.meta["sampler"] = "falsify".into();
    f2.records[0] = record(0, "completed", None, 0);
    let c = compare(&f1, &f2).unwrap();
    assert!(c.falsify && c.changed.is_empty());
    assert!(render(&c, &f1, &f2).contains("not variant for variant"));

    let root = tempfile::tempdir().unwrap();
    let kept = root.path().join("lone.jsonl");
    let line = serde_json::to_string(&record(0, "completed", None, 0)).unwrap();
    std::fs::write(&kept, format!("{line}\n{{\"index\": 1, \"sam")).unwrap();
    let lone = Side::read(&kept).unwrap();
    assert_eq!(lone.records.len(), 1, "the cut line dropped");
    assert!(lone.calls_recorded);
    assert_eq!(
        lone.meta_missing,
        Some(root.path().join("lone.campaign.json"))
    );
    let text = render(&compare(&lone, &lone).unwrap(), &lone, &lone);
    assert!(
        text.contains("lone.campaign.json`: its campaign, sampler and digest are not known"),
        "{text}"
    );
}
