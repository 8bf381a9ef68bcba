//! `taxi-sim regress` end to end on one short scenario written five ways: a case that passes, a
//! known problem that still fails as stated (expected failure), one that was fixed and one that
//! changed (both failures, as pytest's strict xfail), a file that is not a scenario (an error,
//! the run going on), and a campaign file beside them (skipped). The four runs share one map.
//! A copy of the low bar that allows no stop fails on `max_stops` with the count.
//! Then golden numbers: written by `--bless`, the same run matches them, a changed line fails;
//! and a known problem skipped on request is reported not run, never driven.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use sim::regress::results::{Counts, junit};
use sim::regress::{CaseResult, Options, Status, Tier, discover, run_cases};

/// The straight road with the cone under the wing, cut to 80 m (the cone stands at 60 m): the
/// cases below need a pass, not the whole road.
fn short_road() -> String {
    let text = shipped("straight_cone_under_wing");
    let whole = "waypoints_m = [[0.0, 0.0], [200.0, 0.0]]";
    assert!(text.contains(whole));
    text.replace(whole, "waypoints_m = [[0.0, 0.0], [80.0, 0.0]]")
}

fn shipped(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../scenarios/{name}.toml"));
    std::fs::read_to_string(p).unwrap()
}

/// The straight road with the cone expected to be gone round: the car passes under it, so the
/// run fails that expectation (the cone `passed`, expected `deviate`).
fn expecting_deviation(text: &str) -> String {
    assert!(text.contains("expect = \"pass_under\""));
    text.replace("expect = \"pass_under\"", "expect = \"deviate\"")
}

fn mark(text: &str, today: &str) -> String {
    // `[expectations]` goes before the first table: after `laps = 1`.
    text.replacen(
        "laps = 1\n",
        &format!("laps = 1\n\n[expectations]\nknown_problem = \"the car passes under the cone it should go round\"\n\n[expectations.today]\n{today}\n"),
        1,
    )
}

fn run_dir(dir: &Path, tier: Tier) -> Vec<CaseResult> {
    run_dir_with(dir, tier, Mode::Check)
}

/// How `run_dir_with` runs the cases.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    Check,
    Bless,
    SkipKnownProblems,
}

fn run_dir_with(dir: &Path, tier: Tier, mode: Mode) -> Vec<CaseResult> {
    let cases = discover(&[dir.to_path_buf()], None).unwrap();
    let maps = tempfile::tempdir().unwrap();
    let stop = AtomicBool::new(false);
    run_cases(
        &cases,
        &Options {
            jobs: 2,
            tier,
            maps_dir: maps.path().to_path_buf(),
            shard: None,
            time_limit_s: None,
            bless: mode == Mode::Bless,
            skip_known_problems: mode == Mode::SkipKnownProblems,
            stop: &stop,
            progress: &|_| {},
            started: &|_| {},
        },
    )
    .unwrap()
}

#[test]
fn regress_reports_passes_known_problems_fixed_and_changed_ones_and_bad_files() {
    let base = short_road();
    let d = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| std::fs::write(d.path().join(name), text).unwrap();
    write("a_pass.toml", &base);
    write(
        "b_known.toml",
        &mark(
            &expecting_deviation(&base),
            "end = \"completed\"\ncontacts = 0",
        ),
    );
    write("c_fixed.toml", &mark(&base, "end = \"completed\""));
    write(
        "d_changed.toml",
        &mark(&expecting_deviation(&base), "end = \"blocked\""),
    );
    write("e_broken.toml", "name = \"broken\"\nlaps = \"many\"\n");
    // The low bar: one stop for it, where the copy allows none.
    let low_bar = shipped("low_bar_car");
    let golden = low_bar.find("[regress]").unwrap();
    write(
        "f_stops.toml",
        &low_bar[..golden].replace("max_stops = 1\n", "max_stops = 0\n"),
    );
    std::fs::create_dir(d.path().join("campaigns")).unwrap();
    std::fs::write(
        d.path().join("campaigns/family.toml"),
        "name = \"f\"\nbase = \"../a_pass.toml\"\nruns = 2\n",
    )
    .unwrap();

    let rs = run_dir(d.path(), Tier::Quick);
    let got: Vec<(&str, Status)> = rs.iter().map(|r| (r.name.as_str(), r.status)).collect();
    assert_eq!(
        got,
        [
            ("a_pass", Status::Passed),
            ("b_known", Status::KnownProblem),
            ("c_fixed", Status::Failed),
            ("d_changed", Status::Failed),
            ("e_broken", Status::Error),
            ("f_stops", Status::Failed),
        ],
        "{rs:#?}"
    );
    let by = |n: &str| rs.iter().find(|r| r.name == n).unwrap();
    // The known problem's verdict says how it fails today, with the numbers.
    let known = by("b_known");
    assert_eq!(
        known.messages,
        ["cone_under_wing lap 1: passed, expected deviate (clearance 0.25 m)"],
        "{known:?}"
    );
    assert!(by("c_fixed").messages[0].starts_with("known problem fixed"));
    assert_eq!(
        by("d_changed").messages[0],
        "known problem changed: ended completed, today's end is blocked"
    );
    let broken = &by("e_broken").messages[0];
    assert!(
        broken.contains("e_broken.toml:2") && broken.contains("laps"),
        "{broken}"
    );
    assert_eq!(by("f_stops").messages, ["1 stops, at most 0 expected"]);
    let pass = by("a_pass");
    assert_eq!(pass.end.as_deref(), Some("completed"));
    assert!(
        pass.sim_time_s > 16.0 && pass.real_time_factor > 1.0,
        "{pass:?}"
    );
    assert_eq!(
        pass.rerun,
        format!("taxi-sim run {}/a_pass.toml --seed 7", d.path().display())
    );
    // The same run twice gives the same verdicts and numbers (wall time aside).
    assert_eq!(
        (known.sim_time_s, known.obstacle_clearance_m),
        (pass.sim_time_s, pass.obstacle_clearance_m)
    );
    let c = Counts::of(&rs);
    assert_eq!(
        (
            c.passed,
            c.known_problems,
            c.failed,
            c.errors,
            c.exit_code()
        ),
        (1, 1, 3, 1, 2)
    );
    // JUnit: one suite (the folder), the known problem skipped with its text.
    let xml = junit("r", &rs).to_string().unwrap();
    assert!(
        xml.contains(
            "<skipped message=\"known problem: the car passes under the cone it should go round\""
        ),
        "{xml}"
    );
}

/// `[regress] golden`, with `[regress]` before the first table.
fn with_golden(text: &str, golden: &str) -> String {
    text.replacen(
        "laps = 1\n",
        &format!("laps = 1\n\n[regress]\ngolden = \"{golden}\"\n"),
        1,
    )
}

#[test]
fn golden_numbers_are_blessed_then_matched_and_a_changed_line_fails_the_case() {
    let base = short_road();
    let d = tempfile::tempdir().unwrap();
    let blessing = d.path().join("bless");
    std::fs::create_dir(&blessing).unwrap();
    std::fs::write(blessing.join("g.toml"), with_golden(&base, "golden/g.json")).unwrap();
    let rs = run_dir_with(&blessing, Tier::Quick, Mode::Bless);
    assert_eq!(rs[0].status, Status::Passed, "{rs:#?}");
    let blessed = std::fs::read_to_string(blessing.join("golden/g.json")).unwrap();
    assert!(
        blessed.contains("\"laps_completed\": 1") && blessed.contains("cone_under_wing"),
        "{blessed}"
    );
    // The same run against the blessed numbers, and against them with one lap time changed.
    let checking = d.path().join("check");
    std::fs::create_dir(&checking).unwrap();
    std::fs::write(checking.join("same.json"), &blessed).unwrap();
    let lap = blessed
        .lines()
        .skip_while(|l| !l.contains("lap_times_s"))
        .nth(1)
        .unwrap()
        .trim()
        .to_string();
    let changed = blessed.replacen(&format!("    {lap}\n"), "    999.9\n", 1);
    assert_ne!(changed, blessed);
    std::fs::write(checking.join("changed.json"), changed).unwrap();
    for (name, golden) in [("a_same", "same.json"), ("b_changed", "changed.json")] {
        std::fs::write(
            checking.join(format!("{name}.toml")),
            with_golden(&base, golden),
        )
        .unwrap();
    }
    let rs = run_dir(&checking, Tier::Quick);
    assert_eq!(
        (rs[0].status, rs[1].status),
        (Status::Passed, Status::Failed),
        "{rs:#?}"
    );
    let m = &rs[1].messages;
    assert!(
        m[0].starts_with("golden numbers differ from") && m[0].contains("changed.json"),
        "{m:?}"
    );
    let lap_line = blessed.lines().position(|l| l.trim() == lap).unwrap() + 1;
    assert_eq!(
        m[1..],
        [
            format!("golden line {lap_line}: 999.9"),
            format!("now line {lap_line}: {lap}")
        ],
        "{m:?}"
    );
}

#[test]
fn known_problems_skipped_on_request_are_reported_not_run_and_not_driven() {
    let base = short_road();
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("known.toml"),
        mark(&expecting_deviation(&base), "end = \"completed\""),
    )
    .unwrap();
    let rs = run_dir_with(d.path(), Tier::Quick, Mode::SkipKnownProblems);
    assert_eq!(rs.len(), 1);
    let r = &rs[0];
    assert_eq!(r.status, Status::NotRun, "{r:#?}");
    assert!(r.messages[0].contains("--skip-known-problems"), "{r:?}");
    assert_eq!(
        (r.end.as_deref(), r.sim_time_s),
        (None, 0.0),
        "driven: {r:?}"
    );
    assert!(
        r.known_problem
            .as_deref()
            .unwrap()
            .contains("the car passes under")
    );
    let xml = junit("r", &rs).to_string().unwrap();
    assert!(xml.contains("<skipped") && xml.contains("not run"), "{xml}");
}
