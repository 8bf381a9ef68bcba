//! Unit tests of the regression runner's parts that need no run: discovery, the counts and
//! exit codes, JUnit read back, known-problem marks in scenario files.

use std::path::{Path, PathBuf};

use super::results::{Counts, junit, summary};
use super::{CaseResult, Status, Tier, discover};

const SCENARIO: &str = r#"
name = "a straight road"
[world]
min_m = [-10.0, -10.0]
max_m = [100.0, 10.0]
[vehicle]
description = "iara_car"
[route]
waypoints_m = [[0.0, 0.0], [50.0, 0.0]]
speed_m_s = 2.0
"#;

fn write(dir: &Path, rel: &str, text: &str) -> PathBuf {
    let p = dir.join(rel);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn discovery_recurses_in_path_order_skips_campaigns_and_filters() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "b.toml", SCENARIO);
    write(d.path(), "a/z.toml", SCENARIO);
    write(d.path(), "a/c.toml", "name = [broken");
    write(
        d.path(),
        "campaigns/fam.toml",
        "name = \"f\"\nbase = \"../b.toml\"\n",
    );
    write(d.path(), "notes.md", "not a scenario");
    let cases = discover(&[d.path().to_path_buf()], None).unwrap();
    let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["c", "z", "b"], "{cases:?}");
    assert_eq!(cases[0].suite, d.path().join("a").display().to_string());
    let filtered = discover(&[d.path().to_path_buf()], Some("*/a/*")).unwrap();
    assert_eq!(filtered.len(), 2);
    // A file named twice is one case; a missing path is refused by name.
    let twice = discover(&[d.path().join("b.toml"), d.path().join("b.toml")], None).unwrap();
    assert_eq!(twice.len(), 1);
    let e = discover(&[d.path().join("nope")], None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope") && e.contains("no such file"), "{e}");
    let e = discover(&[d.path().to_path_buf()], Some("[")).unwrap_err();
    assert!(e.to_string().contains("--filter"), "{e}");
}

fn result(name: &str, suite: &str, status: Status) -> CaseResult {
    CaseResult {
        index: 0,
        suite: suite.into(),
        name: name.into(),
        file: format!("{suite}/{name}.toml"),
        status,
        tier: Tier::Quick,
        messages: match status {
            Status::Passed => vec![],
            _ => vec![format!("{name}: what happened & <why>")],
        },
        known_problem: (status == Status::KnownProblem).then(|| "the van goes on".into()),
        seed: 3,
        laps: 1,
        laps_in_file: 2,
        end: Some("completed".into()),
        contacts: 0,
        contacts_at_fault: 0,
        contacts_struck: 0,
        obstacle_clearance_m: Some(1.25),
        sim_time_s: 40.0,
        wall_time_s: 2.0,
        real_time_factor: 20.0,
        rerun: format!("taxi-sim run {suite}/{name}.toml --seed 3 --laps 1"),
    }
}

#[test]
fn exit_code_is_two_for_a_bad_file_one_for_a_failure_zero_for_known_problems() {
    let mut rs = vec![
        result("a", "s", Status::Passed),
        result("b", "s", Status::KnownProblem),
        result("c", "s", Status::NotRun),
    ];
    assert_eq!(Counts::of(&rs).exit_code(), 0);
    rs.push(result("d", "s", Status::Failed));
    assert_eq!(Counts::of(&rs).exit_code(), 1);
    rs.push(result("e", "s", Status::Error));
    let c = Counts::of(&rs);
    assert_eq!(
        (
            c.passed,
            c.known_problems,
            c.not_run,
            c.failed,
            c.errors,
            c.exit_code()
        ),
        (1, 1, 1, 1, 1, 2)
    );
}

#[test]
fn junit_has_a_suite_per_folder_and_reads_back_with_each_status() {
    let rs = vec![
        result("a", "scenarios", Status::Passed),
        result("b", "tests/found", Status::KnownProblem),
        result("c", "scenarios", Status::Failed),
        result("d", "tests/found", Status::Error),
    ];
    let xml = junit("taxi-sim regress", &rs).to_string().unwrap();
    let back = quick_junit::Report::deserialize_from_str(&xml).unwrap();
    assert_eq!(back.test_suites.len(), 2);
    assert_eq!((back.tests, back.failures, back.errors), (4, 1, 1));
    let scen = &back.test_suites[0];
    assert_eq!(scen.name.as_str(), "scenarios");
    assert_eq!(scen.test_cases.len(), 2);
    let kinds: Vec<String> = back
        .test_suites
        .iter()
        .flat_map(|s| &s.test_cases)
        .map(|c| match &c.status {
            quick_junit::TestCaseStatus::Success { .. } => format!("{} ok", c.name.as_str()),
            quick_junit::TestCaseStatus::Skipped { message, .. } => {
                format!(
                    "{} skipped {}",
                    c.name.as_str(),
                    message.as_ref().unwrap().as_str()
                )
            }
            quick_junit::TestCaseStatus::NonSuccess { kind, message, .. } => {
                format!(
                    "{} {kind:?} {}",
                    c.name.as_str(),
                    message.as_ref().unwrap().as_str()
                )
            }
        })
        .collect();
    assert_eq!(
        kinds,
        [
            "a ok",
            "c Failure c: what happened & <why>",
            "b skipped known problem: the van goes on",
            "d Error d: what happened & <why>",
        ]
    );
    let md = summary(&rs, 10.0);
    assert!(md.contains("4 cases: 1 passed, 1 failed, 1 known problems, 0 not run, 1 errors"));
    assert!(
        md.contains("rerun: `taxi-sim run scenarios/c.toml --seed 3 --laps 1`"),
        "{md}"
    );
}

fn scenario_with(extra: &str) -> Result<crate::scenario::Scenario, String> {
    let text = format!("{SCENARIO}{extra}");
    crate::scenario::Scenario::from_str(&text, Path::new("k.toml")).map_err(|e| e.to_string())
}

#[test]
fn a_known_problem_needs_its_outcome_today_and_a_text() {
    let s = scenario_with(
        "[expectations]\nknown_problem = \"the van goes on\"\n[expectations.today]\nend = \"blocked\"\ncontacts_with = [\"van_1\"]\n",
    )
    .unwrap();
    let k = s.known_problem.unwrap();
    assert_eq!(k.text, "the van goes on");
    assert_eq!(k.today.end, Some(crate::scenario::TodayEnd::Blocked));
    assert_eq!(
        k.today.contacts_with.as_deref(),
        Some(&["van_1".to_string()][..])
    );

    let e = scenario_with("[expectations]\nknown_problem = \"x\"\n").unwrap_err();
    assert!(
        e.contains("expectations.known_problem") && e.contains("[expectations.today]"),
        "{e}"
    );
    let e = scenario_with("[expectations.today]\ncontacts = 1\n").unwrap_err();
    assert!(
        e.contains("expectations.today") && e.contains("`known_problem`"),
        "{e}"
    );
    let e = scenario_with(
        "[expectations]\nknown_problem = \" \"\n[expectations.today]\ncontacts = 1\n",
    )
    .unwrap_err();
    assert!(e.contains("empty"), "{e}");
    let e = scenario_with(
        "[expectations]\nknown_problem = \"x\"\n[expectations.today]\nend = \"crashed\"\n",
    )
    .unwrap_err();
    assert!(e.contains("k.toml:") && e.contains("crashed"), "{e}");
}

#[test]
fn quick_laps_are_at_most_the_files_laps() {
    let s = scenario_with("[regress]\nquick_laps = 1\n").unwrap();
    assert_eq!((s.laps, super::laps_in(&s, Tier::Quick)), (1, 1));
    // A campaign's variant of a three-lap file with `laps = 1` runs its one lap.
    let text = SCENARIO.replacen("name = \"a straight road\"", "name = \"r\"\nlaps = 3", 1);
    let three = |extra: &str| {
        crate::scenario::Scenario::from_str(&format!("{text}{extra}"), Path::new("r.toml")).unwrap()
    };
    let s = three("[regress]\nquick_laps = 2\n");
    assert_eq!(
        (
            super::laps_in(&s, Tier::Quick),
            super::laps_in(&s, Tier::Full)
        ),
        (2, 3)
    );
    let mut s = three("[regress]\nquick_laps = 2\n");
    s.laps = 1;
    assert_eq!(super::laps_in(&s, Tier::Quick), 1);
    let e = scenario_with("[regress]\nquick_laps = 0\n").unwrap_err();
    assert!(e.contains("quick_laps"), "{e}");
    let s = scenario_with("[regress]\nfull_only = true\n").unwrap();
    assert!(s.full_only);
    assert_eq!(super::laps_in(&s, Tier::Full), 1);
}

#[test]
fn a_golden_file_is_a_json_path_beside_the_scenario() {
    let text = format!("{SCENARIO}[regress]\ngolden = \"golden/k.json\"\n");
    let s = crate::scenario::Scenario::from_str(&text, Path::new("cases/k.toml")).unwrap();
    assert_eq!(s.golden.as_deref(), Some(Path::new("cases/golden/k.json")));
    let e = scenario_with("[regress]\ngolden = \"golden/k.txt\"\n").unwrap_err();
    assert!(
        e.contains("k.toml:") && e.contains("regress.golden") && e.contains(".json"),
        "{e}"
    );
}

#[test]
fn golden_numbers_differ_line_by_line_and_a_missing_file_says_how_to_write_it() {
    use super::golden::{check, differences};
    let p = Path::new("g.json");
    assert!(differences(p, "{\n  \"a\": 1\n}\n", "{\n  \"a\": 1\n}\n").is_empty());
    // CRLF and a missing last newline are no difference.
    assert!(differences(p, "{\r\n  \"a\": 1\r\n}\r\n", "{\n  \"a\": 1\n}").is_empty());
    // A line changed, then a line inserted: the lines after an insertion are not all "changed".
    let want = "{\n  \"a\": 1,\n  \"b\": 2,\n  \"c\": 3\n}\n";
    let now = "{\n  \"a\": 9,\n  \"b\": 2,\n  \"x\": 0,\n  \"c\": 3\n}\n";
    let d = differences(p, want, now);
    assert_eq!(
        d[1..],
        [
            "golden line 2: \"a\": 1,",
            "now line 2: \"a\": 9,",
            "now line 4: \"x\": 0,",
        ],
        "{d:?}"
    );
    assert!(
        d[0].starts_with("golden numbers differ from g.json"),
        "{d:?}"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("new/g.json");
    let v = serde_json::json!({"laps_completed": 1});
    let missing = check(&path, &v, false).unwrap();
    assert!(
        missing.len() == 1 && missing[0].contains("--bless"),
        "{missing:?}"
    );
    assert!(check(&path, &v, true).unwrap().is_empty());
    assert!(check(&path, &v, false).unwrap().is_empty());
    let other = serde_json::json!({"laps_completed": 2});
    assert_eq!(check(&path, &other, false).unwrap().len(), 3);
}

#[test]
fn localization_bounds_name_the_error_and_a_run_without_an_estimate_has_none() {
    use crate::engine::{ErrorStats, LocalizationErrors, LocalizationReport, localization_misses};
    let s = scenario_with(
        "[expectations]\nmax_cross_track_rmse_m = 0.1\nmax_heading_rmse_rad = 0.01\nmax_stops = 2\n",
    )
    .unwrap();
    assert_eq!(s.max_stops, Some(2));
    let report = |cross: f64, heading: f64| LocalizationReport {
        run: LocalizationErrors {
            cross_m: ErrorStats {
                rmse: cross,
                ..ErrorStats::default()
            },
            heading_rad: ErrorStats {
                rmse: heading,
                ..ErrorStats::default()
            },
            ..LocalizationErrors::default()
        },
        laps: Vec::new(),
    };
    assert!(localization_misses(&s, Some(&report(0.1, 0.01))).is_empty());
    assert!(localization_misses(&s, None).is_empty());
    assert_eq!(
        localization_misses(&s, Some(&report(0.1234, 0.02))),
        [
            "cross-track RMSE 0.123 m, at most 0.1 m expected",
            "heading RMSE 0.0200 rad, at most 0.01 rad expected"
        ]
    );
    assert_eq!(
        localization_misses(&s, Some(&report(f64::NAN, 0.0))).len(),
        1
    );
    // Unchecked without the bounds; a bound must be positive.
    let plain = scenario_with("").unwrap();
    assert!(localization_misses(&plain, Some(&report(5.0, 1.0))).is_empty());
    let e = scenario_with("[expectations]\nmax_cross_track_rmse_m = 0.0\n").unwrap_err();
    assert!(e.contains("max_cross_track_rmse_m"), "{e}");
}
