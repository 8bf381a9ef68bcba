//! Campaigns through the library on the smoke campaign (`scenarios/campaigns/smoke.toml`, 12
//! runs of a car on a straight road): the results are the same whatever the number of jobs; a
//! campaign resumes where it stopped, over a half-written last line, without running a variant
//! twice; a stop leaves only whole runs; bad campaign files are refused with their place; an
//! invalid variant is recorded and the campaign goes on. What needs the `taxi-sim` binary
//! (reproducing failure files with `taxi-sim run`, merging shards) is tested in the `taxi-sim`
//! package (`sim/cli/tests/it/campaign.rs`).

use std::sync::atomic::{AtomicBool, Ordering};

use sim::campaign::{Campaign, RunOptions, Shard, read_results, run_campaign, variant};

use crate::smoke_campaign::{full, run, smoke, smoke_path};

#[test]
fn the_smoke_campaign_runs_every_variant_under_every_setting() {
    let (dir, records) = full();
    assert_eq!(records.len(), 12);
    assert!(records.iter().enumerate().all(|(i, r)| r.index == i as u64));
    for pair in records.chunks(2) {
        // A sample's two runs drew the same world and differ in the setting only.
        assert_eq!(pair[0].sampled, pair[1].sampled);
        assert_eq!((pair[0].setting, pair[1].setting), (0, 1));
        assert_ne!(pair[0].parameters, pair[1].parameters);
    }
    // The results file is the records, one per line, by index.
    assert_eq!(read_results(dir.path()).unwrap(), *records);
    let summary = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
    assert!(
        summary.contains("| autonomy.planner_safety_m = 0.4 | 6 |"),
        "{summary}"
    );
    assert!(
        summary.contains("| autonomy.planner_safety_m = 0.6 | 6 |"),
        "{summary}"
    );
    // Every run that ended in a pilot call says why (and what stood there); the summary counts
    // them by cause.
    for r in records.iter() {
        let called = matches!(
            r.end.as_str(),
            "waiting_for_hidden_obstacle" | "blocked" | "waiting_for_walk_around" | "struck"
        );
        assert_eq!(
            r.pilot_call.is_some(),
            called,
            "variant {}: {}",
            r.index,
            r.end
        );
        assert!(r.pilot_call_object.is_some() || !called || r.needless_pilot_call);
        // A needless call's variant is written to be run alone, and listed.
        assert_eq!(
            r.needless_file.is_some(),
            r.needless_pilot_call,
            "{}",
            r.index
        );
        if let Some(f) = &r.needless_file {
            assert!(dir.path().join(f).exists(), "{f}");
            assert!(summary.contains(&format!("`{f}`")), "{summary}");
        }
        // Every pilot call's variant, needed or not, is written to be run alone or replayed: a
        // scenario file, the very text a failure's or a needless call's file holds.
        assert_eq!(r.called_file.is_some(), called, "{}", r.index);
        if let Some(f) = &r.called_file {
            let path = dir.path().join(f);
            sim::scenario::Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
            let text = std::fs::read_to_string(&path).unwrap();
            for other in r.failure_file.iter().chain(&r.needless_file) {
                assert_eq!(
                    std::fs::read_to_string(dir.path().join(other)).unwrap(),
                    text
                );
            }
        }
    }
    let calls = records.iter().filter(|r| r.pilot_call.is_some()).count();
    assert!(calls > 0, "the smoke campaign's variant 10 calls a pilot");
    assert!(
        summary.contains(&format!("{calls} of 12 runs ended with a pilot call")),
        "{summary}"
    );
    // Every failing variant and only those has a failure file, listed in the error table, and
    // its bag (run again: `record_failures`) with the run's clouds and its events.
    let files = std::fs::read_dir(dir.path().join("failures"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "toml")
        })
        .count();
    assert_eq!(files, records.iter().filter(|r| r.failed).count());
    assert!(files > 0);
    for r in records.iter().filter(|r| r.failed) {
        let bag = dir.path().join(format!("failures/{0}/{0}.mcap", r.index));
        assert!(
            bag.with_file_name("metadata.yaml").exists(),
            "{}",
            bag.display()
        );
        let topics = ros2::BagReader::open(&bag).unwrap().topics().unwrap();
        let count = |name: &str| {
            topics
                .iter()
                .find(|t| t.name == name)
                .map_or(0, |t| t.count)
        };
        assert!(
            count("/velodyne_points") > 10 && count("/events") > 0,
            "{topics:?}"
        );
    }
    for r in records.iter().filter(|r| r.failed) {
        assert!(
            !r.failures.is_empty() && (r.contacts > 0 || !r.expectations_met),
            "{r:?}"
        );
        assert!(
            summary.contains(&format!("`failures/{}.toml`", r.index)),
            "{summary}"
        );
    }
    // The chart: a point per run, and the two of the legend.
    let svg = std::fs::read_to_string(dir.path().join("clearance.svg")).unwrap();
    assert_eq!(svg.matches("<circle").count(), records.len() + 2);
    assert!(summary.contains("(clearance.svg)"));
    // One map served all 12 runs: the static world never changed.
    assert_eq!(
        std::fs::read_dir(dir.path().join("maps")).unwrap().count(),
        1
    );
}

#[test]
fn results_are_the_same_whatever_jobs() {
    let (_, records) = full();
    let dir = tempfile::tempdir().unwrap();
    let one = run(&smoke(), dir.path(), 1, Some(4));
    assert_eq!(one.len(), 4);
    for (a, b) in one.iter().zip(records) {
        assert_eq!(a.timeless(), b.timeless());
    }
}

/// `--variants`: variants named (`2,7`) run alone into another directory are the same runs
/// as in the full campaign, and nothing else runs.
#[test]
fn picked_variants_run_alone_as_they_ran_in_the_full_campaign() {
    let (_, records) = full();
    let picked = sim::campaign::select::parse_variants("2,7", 12).unwrap().0;
    let dir = tempfile::tempdir().unwrap();
    let campaign = smoke();
    let stop = AtomicBool::new(false);
    let options = RunOptions {
        shard: None,
        maps_dir: None,
        out: dir.path().to_path_buf(),
        jobs: 2,
        runs: None,
        variants: Some(&picked),
        stop: &stop,
        record_failures: false,
        progress: &|_| {},
        stack: None,
    };
    let outcome = run_campaign(&campaign, &options).unwrap();
    let got: Vec<u64> = outcome.records.iter().map(|r| r.index).collect();
    assert_eq!(got, picked);
    for r in &outcome.records {
        assert_eq!(r.timeless(), records[r.index as usize].timeless());
    }
    // Picked from that run, for this campaign as it is run now: the same; with a --set, the
    // same variants changed (a note); sampled another way, refused.
    use sim::campaign::select::check_same_campaign;
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("campaign.json")).unwrap())
            .unwrap();
    assert_eq!(check_same_campaign(&meta, &campaign).unwrap(), None);
    let mut set = smoke();
    set.set_field("route.speed_m_s", toml::Value::Float(2.0))
        .unwrap();
    let note = check_same_campaign(&meta, &set).unwrap().expect("a note");
    assert!(note.contains("other --set values"), "{note}");
    let mut random = smoke();
    random.set_sampler(sim::campaign::SamplerKind::Random); // the file's is halton
    let e = check_same_campaign(&meta, &random).unwrap_err().to_string();
    assert!(e.contains("another sampler"), "{e}");
}

#[test]
fn a_campaign_resumes_over_a_cut_line_without_running_a_variant_twice() {
    let (_, records) = full();
    let dir = tempfile::tempdir().unwrap();
    let campaign = smoke();
    let first = run(&campaign, dir.path(), 2, Some(3));
    assert_eq!(first.len(), 3);
    // A process killed in the middle of a line.
    let results = dir.path().join("results.jsonl");
    let mut text = std::fs::read_to_string(&results).unwrap();
    text.push_str("{\"index\":3,\"sample\":1,\"se");
    std::fs::write(&results, text).unwrap();
    let stop = AtomicBool::new(false);
    let outcome = run_campaign(
        &campaign,
        &RunOptions {
            shard: None,
            maps_dir: None,
            out: dir.path().to_path_buf(),
            jobs: 2,
            runs: Some(5),
            variants: None,
            stop: &stop,
            record_failures: false,
            progress: &|_| {},
            stack: None,
        },
    )
    .unwrap();
    assert_eq!(outcome.ran, 2, "variants 3 and 4 only");
    assert_eq!(outcome.records.len(), 5);
    for (a, b) in outcome.records.iter().zip(records) {
        assert_eq!(a.timeless(), b.timeless());
    }
    // Another campaign's results are never mixed in.
    let other = dir.path().join("other.toml");
    let text = std::fs::read_to_string(smoke_path())
        .unwrap()
        .replace("seed = 1", "seed = 2");
    std::fs::write(
        &other,
        text.replace(
            "\"../cone_in_path_car.toml\"",
            &format!(
                "{:?}",
                smoke_path()
                    .parent()
                    .unwrap()
                    .join("../cone_in_path_car.toml")
            ),
        ),
    )
    .unwrap();
    let e = run_campaign(
        &Campaign::from_file(&other).unwrap(),
        &RunOptions {
            shard: None,
            maps_dir: None,
            out: dir.path().to_path_buf(),
            jobs: 1,
            runs: Some(1),
            variants: None,
            stop: &stop,
            record_failures: false,
            progress: &|_| {},
            stack: None,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("campaign.json") && e.contains("another campaign"),
        "{e}"
    );
}

#[test]
fn a_stop_keeps_only_whole_runs_and_the_rest_runs_later() {
    let (_, records) = full();
    let dir = tempfile::tempdir().unwrap();
    let campaign = smoke();
    let stop = AtomicBool::new(false);
    let outcome = run_campaign(
        &campaign,
        &RunOptions {
            shard: None,
            maps_dir: None,
            out: dir.path().to_path_buf(),
            jobs: 1,
            runs: Some(4),
            variants: None,
            stop: &stop,
            record_failures: false,
            progress: &|_| stop.store(true, Ordering::Relaxed),
            stack: None,
        },
    )
    .unwrap();
    assert!(outcome.interrupted);
    assert_eq!(
        outcome.records.len(),
        1,
        "the run in flight when stopped finished: {:?}",
        outcome.records
    );
    assert_eq!(read_results(dir.path()).unwrap().len(), 1);
    let rest = run(&campaign, dir.path(), 2, Some(4));
    assert_eq!(rest.len(), 4);
    for (a, b) in rest.iter().zip(records) {
        assert_eq!(a.timeless(), b.timeless());
    }
}

#[test]
fn bad_campaign_files_are_refused_with_their_place() {
    let dir = tempfile::tempdir().unwrap();
    let base = smoke_path()
        .parent()
        .unwrap()
        .join("../cone_in_path_car.toml");
    let head = format!("name = \"x\"\nbase = {base:?}\nruns = 4\n");
    let cases = [
        ("runz = 3\n", "2:1", "unknown field `runz`"),
        (
            "[[obstacles]]\nid = \"c\"\nalong_m = { uniform = [5.0, 1.0] }\n",
            "5:1",
            "uniform = [5, 1]",
        ),
        ("[[obstacles]]\nkind = \"cone\"\n", "5:1", "needs an `id`"),
        (
            "[parameters]\n\"autonomy.planner_safty_m\" = [0.4]\n",
            "5:1",
            "planner_safty_m",
        ),
        ("sampler = \"sobol\"\n", "5:11", "unknown variant `sobol`"),
    ];
    for (i, (tail, place, words)) in cases.iter().enumerate() {
        let text = if tail.starts_with("runz") {
            format!("name = \"x\"\n{tail}base = {base:?}\nruns = 4\n")
        } else {
            format!("{head}\n{tail}")
        };
        let file = dir.path().join(format!("c{i}.toml"));
        std::fs::write(&file, text).unwrap();
        let e = Campaign::from_file(&file).unwrap_err().to_string();
        assert!(
            e.contains(&format!("c{i}.toml:{place}")) && e.contains(words),
            "case {i}: {e}"
        );
    }
}

#[test]
fn a_scenario_config_table_is_checked_and_used() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(
        smoke_path()
            .parent()
            .unwrap()
            .join("../cone_in_path_car.toml"),
    )
    .unwrap();
    let file = dir.path().join("s.toml");
    std::fs::write(
        &file,
        format!("{base}\n[config.autonomy]\nplanner_safty_m = 0.4\n"),
    )
    .unwrap();
    let e = sim::scenario::Scenario::from_file(&file)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`config`") && e.contains("planner_safty_m"),
        "{e}"
    );
    std::fs::write(
        &file,
        format!("{base}\n[config.autonomy]\nplanner_safety_m = 0.4\n"),
    )
    .unwrap();
    let s = sim::scenario::Scenario::from_file(&file).unwrap();
    let c = sim::scenario::RunConfig::for_scenario(&s, None).unwrap();
    assert_eq!(c.autonomy.planner_safety_m, 0.4);
    assert_eq!(
        c.autonomy.avoider_safety_m,
        sim::scenario::RunConfig::default()
            .autonomy
            .avoider_safety_m
    );
}

#[test]
fn every_shipped_campaign_reads_and_its_first_variants_are_valid_scenarios() {
    let dir = smoke_path().parent().unwrap().to_path_buf();
    let mut names = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        // A campaign on real data the repository does not ship: the test below, with --ignored.
        if path.file_stem().is_some_and(|s| s == "airport_ksyr") {
            continue;
        }
        let campaign = Campaign::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
        for i in 0..8 {
            let v = variant(&campaign, i, &[]);
            sim::scenario::Scenario::from_str(&v.text, &campaign.variant_path(i))
                .unwrap_or_else(|e| panic!("{} variant {i}: {e}\n{}", path.display(), v.text));
        }
        names.push(path.file_stem().unwrap().to_string_lossy().into_owned());
    }
    names.sort();
    assert_eq!(
        names,
        [
            "faults",
            "faults_aerodrome",
            "jet_wing_and_engine_paths",
            "left_at_start",
            "left_at_start_no_walk_around",
            "left_at_start_two_lidars",
            "left_at_start_two_lidars_no_walk_around",
            "low_debris_car",
            "parking_lot_random",
            "sensor_bias",
            "smoke",
            "traffic_airliner",
            "traffic_jet",
            "traffic_jet_speed_profiles",
            "tune_a320",
            "tune_car",
            "tune_praetor",
            "tune_smoke",
            "your_stack"
        ]
    );
}

/// A draw the scenario rules refuse (here a cone on the start pose) is recorded as `invalid`,
/// left out of the statistics, and the campaign goes on; the grid visits both choices.
#[test]
fn an_invalid_variant_is_recorded_and_the_campaign_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let base = smoke_path()
        .parent()
        .unwrap()
        .join("../cone_in_path_car.toml");
    let file = dir.path().join("c.toml");
    std::fs::write(
        &file,
        format!(
            "name = \"x\"\nbase = {base:?}\nruns = 10\nsampler = \"grid\"\n\n[[obstacles]]\nid = \"cone_on_centreline\"\nalong_m = {{ choice = [0.0, 60.0] }}\n"
        ),
    )
    .unwrap();
    let records = run(
        &Campaign::from_file(&file).unwrap(),
        &dir.path().join("out"),
        2,
        None,
    );
    assert_eq!(records.len(), 2, "the grid has two points");
    assert_eq!(records[0].end, "invalid");
    assert!(
        !records[0].failed && records[0].failures[0].contains("overlap"),
        "{:?}",
        records[0]
    );
    assert_eq!(records[1].end, "completed");
    let summary = std::fs::read_to_string(dir.path().join("out/summary.md")).unwrap();
    assert!(
        summary.contains("1 variants were not valid scenarios"),
        "{summary}"
    );
    assert!(summary.contains("| base | 1 |"), "{summary}");
}

#[test]
fn the_falsifier_cannot_be_sharded() {
    let mut campaign = smoke();
    campaign.set_sampler(sim::campaign::SamplerKind::Falsify);
    let dir = tempfile::tempdir().unwrap();
    let stop = AtomicBool::new(false);
    let e = run_campaign(
        &campaign,
        &RunOptions {
            shard: Some(Shard { index: 0, count: 2 }),
            maps_dir: None,
            out: dir.path().to_path_buf(),
            jobs: 1,
            runs: Some(2),
            variants: None,
            stop: &stop,
            record_failures: false,
            progress: &|_| {},
            stack: None,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("cannot be split"), "{e}");
}

/// The KSYR campaign (issue 37) reads its base from `../shared/data`, which a fresh clone need
/// not have: run with `--ignored` (CI does). Its first variants are valid scenarios, each on its
/// own drawn route with its obstacles placed along that route.
#[test]
#[ignore = "reads ../shared/data"]
fn shared_data_the_ksyr_campaign_reads_and_places_obstacles_on_each_variants_route() {
    let path = smoke_path().parent().unwrap().join("airport_ksyr.toml");
    let campaign = Campaign::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut routes = std::collections::BTreeSet::new();
    for i in 0..12 {
        let v = variant(&campaign, i, &[]);
        let s = sim::scenario::Scenario::from_str(&v.text, &campaign.variant_path(i))
            .unwrap_or_else(|e| panic!("variant {i}: {e}\n{}", v.text));
        routes.insert(format!("{:.0}", s.route.length_m()));
        let route = autonomy::RoutePath::new(&s.route.waypoints_m, false);
        for o in s.obstacles.iter().filter(|o| o.motion.is_none()) {
            // Cones and debris stand within 10 m of the variant's own route.
            let p = nalgebra::Point2::new(o.solid.x_m, o.solid.y_m);
            let (_, d) = route.project(&p, 0.0, f64::INFINITY);
            assert!(
                d.abs() < 10.0,
                "variant {i}: {} {d} m off its route",
                o.solid.id
            );
        }
    }
    assert!(routes.len() >= 5, "{routes:?}");
}

/// `campaign run --set`: a field set in every variant over what the file draws, the other draws
/// unchanged, the digest changed (their results never mix); a value no scenario takes is refused
/// naming the field.
#[test]
fn a_field_set_over_the_file_changes_every_variant_and_only_that() {
    let plain = Campaign::from_file(&smoke_path()).unwrap();
    let mut set = Campaign::from_file(&smoke_path()).unwrap();
    set.set_field("route.speed_m_s", toml::Value::Float(2.5))
        .unwrap();
    assert_ne!(plain.digest, set.digest);
    for i in 0..6 {
        let (a, b) = (variant(&plain, i, &[]), variant(&set, i, &[]));
        let read = |v: &sim::campaign::Variant| {
            sim::scenario::Scenario::from_str(&v.text, &plain.variant_path(i)).unwrap()
        };
        let (sa, sb) = (read(&a), read(&b));
        assert_eq!(sb.route.speed_m_s, 2.5);
        assert_ne!(sa.route.speed_m_s, 2.5);
        assert_eq!(a.u, b.u);
        assert_eq!(
            sa.obstacles, sb.obstacles,
            "variant {i}: the draws are the file's"
        );
    }
    let mut bad = Campaign::from_file(&smoke_path()).unwrap();
    let e = bad
        .set_field("route.speed_m_s", toml::Value::String("fast".into()))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--set route.speed_m_s") && e.contains("speed_m_s"),
        "{e}"
    );
}

/// `campaign run --set config.*`: the variants run with the configuration their files hold, so a
/// variant's file run alone (`failures/`, `needless/`) is the campaign's run - the set field
/// over the base's `[config]`, the file's settings over both.
#[test]
fn a_configuration_field_set_over_the_file_is_the_one_each_variant_runs_with() {
    let plain = Campaign::from_file(&smoke_path()).unwrap();
    let mut set = Campaign::from_file(&smoke_path()).unwrap();
    set.set_field(
        "config.mapping.map.intensity_falloff_per_m",
        toml::Value::Float(0.004),
    )
    .unwrap();
    // What a variant runs with (`execute.rs`) and `taxi-sim run` of its file reads: its own
    // file's `[config]`.
    let run_config = |c: &Campaign, v: &sim::campaign::Variant| {
        let file = sim::scenario::Scenario::from_str(&v.text, &c.variant_path(v.index)).unwrap();
        sim::scenario::RunConfig::for_scenario(&file, None).unwrap()
    };
    for i in 0..4 {
        let (a, b) = (variant(&plain, i, &[]), variant(&set, i, &[]));
        let (ca, cb) = (run_config(&plain, &a), run_config(&set, &b));
        assert_eq!(cb.mapping.map.intensity_falloff_per_m, 0.004);
        assert_eq!(ca.mapping.map.intensity_falloff_per_m, 0.0);
        // Without a set field, the file's configuration is the setting's over the base's.
        assert_eq!(ca, plain.config(a.setting).unwrap(), "variant {i}");
        assert_eq!(
            ca,
            sim::scenario::RunConfig {
                mapping: sim::scenario::MappingConfig {
                    map: mapper::MapConfig {
                        intensity_falloff_per_m: 0.0,
                        ..cb.mapping.map
                    },
                    ..cb.mapping.clone()
                },
                ..cb.clone()
            },
            "only the set field differs"
        );
    }
}
