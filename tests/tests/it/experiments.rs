//! The thesis' two experiments against their golden numbers (issue #6), shortened so the test
//! command stays in its budget: the parking lot's first two of seven laps (12 obstacle passes),
//! the aerodrome's first of three (the wings over the cones and edge markers). Each asserts what
//! its laps must show and compares a summary of the metrics with `tests/golden/<name>.json`, so
//! a change in behaviour shows in the diff. Their files' expectations in full - every lap, the
//! aerodrome's stop for the follow-me car on lap 2 - are `taxi-sim regress`'s (the quick tier in
//! CI runs the aerodrome's two laps and the parking lot's first; `--full` all of them). After a change that is meant, bless the new summaries with
//! `TAXI_SIM_BLESS=1 cargo test --release -p tests --test it experiments` and commit them.

use std::path::PathBuf;

use serde_json::{Value, json};
use sim::engine::{PassOutcome, RunReport, RunSetup, run};
use sim::scenario::{Expectation, RunConfig, Scenario};

fn scenario(name: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn run_scenario(s: &Scenario, laps: Option<u32>) -> RunReport {
    let setup = RunSetup {
        laps,
        ..RunSetup::new(crate::common::map_for(s, &RunConfig::default()))
    };
    run(s, &setup).unwrap_or_else(|e| panic!("{}: {e:#}", s.name))
}

/// Rounds to a multiple of `step` (a summary must not change with the last bits of a float).
fn round(x: f64, step: f64) -> Value {
    if x.is_finite() {
        json!(((x / step).round() * step * 1000.0).round() / 1000.0)
    } else {
        Value::Null
    }
}

/// What the golden file holds: everything in the report that says what the vehicle did, rounded
/// (times to 0.1 s, distances to 0.05 m); wall time and real-time factor left out.
fn summary(r: &RunReport) -> Value {
    json!({
        "scenario": r.scenario,
        "seed": r.seed,
        "expectations_met": r.expectations_met,
        "laps_completed": r.laps_completed,
        "lap_times_s": r.lap_times_s.iter().map(|t| round(*t, 0.1)).collect::<Vec<_>>(),
        "contacts": r.contacts.iter().map(|c| format!("{} by {} at {:.1} s", c.object, c.part, c.time_s)).collect::<Vec<_>>(),
        "stops": r.stops.iter().map(|s| json!({
            "start_s": round(s.start_s, 0.1),
            "end_s": s.end_s.map(|e| round(e, 0.1)),
            "route_s_m": round(s.route_s_m, 0.5),
        })).collect::<Vec<_>>(),
        "min_clearance_m": r.min_clearance_m.iter().map(|d| round(*d, 0.05)).collect::<Vec<_>>(),
        "obstacles": r.obstacles.iter().map(|o| json!({
            "id": o.id,
            "expected": o.expected,
            "passes": o.passes.iter().map(|p| format!(
                "lap {} {} offset {} clearance {} {}",
                p.lap,
                p.outcome.as_str(),
                round(p.max_offset_m, 0.05),
                p.min_clearance_m.iter().map(|d| round(*d, 0.05).to_string()).collect::<Vec<_>>().join("/"),
                if p.met { "met" } else { "NOT MET" },
            )).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "sim_time_s": round(r.sim_time_s, 0.1),
    })
}

/// Compares with the golden file, or writes it with `TAXI_SIM_BLESS=1`.
fn check_golden(name: &str, got: &Value) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("golden")
        .join(format!("{name}.json"));
    let text = serde_json::to_string_pretty(got).unwrap() + "\n";
    if std::env::var_os("TAXI_SIM_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        mapper::write_atomically(&path, text.as_bytes()).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; bless it with TAXI_SIM_BLESS=1 (see this file's header)",
            path.display()
        )
    });
    if want != text {
        let diff: Vec<String> = want
            .lines()
            .zip(text.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .take(20)
            .map(|(i, (a, b))| format!("line {}:\n  golden: {a}\n  now:    {b}", i + 1))
            .collect();
        panic!(
            "{} differs from this run (bless with TAXI_SIM_BLESS=1 if the change is meant):\n{}\n\nthis run:\n{text}",
            path.display(),
            diff.join("\n")
        );
    }
}

#[test]
fn parking_lot_two_laps_12_passes_no_contact() {
    let s = scenario("parking_lot");
    let r = run_scenario(&s, Some(2));
    assert!(r.expectations_met, "{r:#?}");
    assert_eq!(r.laps_completed, 2);
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    let passes: usize = r.obstacles.iter().map(|o| o.passes.len()).sum();
    assert_eq!(passes, 12, "six obstacles, two laps");
    let danger = s
        .danger_distance_m
        .expect("the scenario states its danger distance");
    for o in &r.obstacles {
        for p in &o.passes {
            let what = format!("{} lap {}: {p:?}", o.id, p.lap);
            assert!(p.met, "{what}");
            assert!(p.min_clearance_m.iter().all(|d| *d >= danger), "{what}");
            match o.expected.as_str() {
                // The wing passes over the short cones beside the path: no deviation.
                "pass_under" => {
                    assert!(
                        p.outcome == PassOutcome::Passed && p.max_offset_m < 0.5,
                        "{what}"
                    );
                    assert!(
                        p.min_clearance_m[1] > 0.1,
                        "the wing clears the cone: {what}"
                    );
                }
                "deviate" => assert_eq!(p.outcome, PassOutcome::Deviated, "{what}"),
                other => panic!("unexpected expectation {other}"),
            }
        }
    }
    // The car never stops here. With the prediction of movers (issue 36) it held once, about
    // 3 s on lap 3, for a static object whose visible part seemed to move; not since the
    // particles spread twice the fix's sigma and mapping waits for a trusted estimate.
    assert!(r.stops.is_empty(), "the car stops {:?}", r.stops);
    check_golden("parking_lot_2_laps", &summary(&r));
}

/// The aerodrome's first lap: the wings pass over the cones and the edge markers without a stop
/// or a deviation (the jet only ever plans offset 0), nothing within the danger distance. The
/// follow-me car, on the centreline on lap 2 only, is not met here (its stop is `taxi-sim
/// regress`'s to check, on two laps). Long (the 6.4 km circuit's mapping drive and a lap: about
/// 2.5 minutes here), so out of the test command's budget: CI runs it (`cargo test --release
/// --workspace -- --ignored experiments`).
#[test]
#[ignore = "long: CI runs it with --ignored experiments"]
fn aerodrome_first_lap_wings_over_cones_without_a_stop() {
    let s = scenario("aerodrome");
    let r = run_scenario(&s, Some(1));
    assert_eq!(r.laps_completed, 1);
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert!(r.stops.is_empty(), "{:?}", r.stops);
    let danger = s
        .danger_distance_m
        .expect("the scenario states its danger distance");
    for o in &r.obstacles {
        if o.id == "follow_me_car" {
            assert!(o.passes.is_empty(), "on lap 2 only: {:?}", o.passes);
            continue;
        }
        assert_eq!(o.passes.len(), 1, "{o:?}");
        for p in &o.passes {
            let what = format!("{} lap {}: {p:?}", o.id, p.lap);
            assert!(p.met, "{what}");
            assert!(p.min_clearance_m.iter().all(|d| *d >= danger), "{what}");
            assert_eq!(o.expected, Expectation::PassUnder, "{what}");
            assert!(
                p.outcome == PassOutcome::Passed && p.max_offset_m < 0.5,
                "{what}"
            );
        }
    }
    check_golden("aerodrome_1_lap", &summary(&r));
}
