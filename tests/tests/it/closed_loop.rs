//! The closed loop on the small scenarios of `scenarios/` under run configurations their files do
//! not carry (sequential sensing, no tracker, noisy poses, thread counts, faults, latency, a stale
//! map), and a run repeated with the same seed. Each file's own expectations are `taxi-sim
//! regress`'s to check (CI runs every shipped scenario).

use std::path::PathBuf;

use sim::engine::{EndReason, RunReport, RunSetup, run};
use sim::scenario::{NoisyTruthConfig, PoseSourceConfig, RunConfig, Scenario, Schedule};

fn scenario(name: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs the closed loop over the scenario's offline map (`common::map_for`: one mapping drive
/// per static world for the whole test binary), with the run's configuration changed by
/// `adjust`.
fn run_scenario_with(name: &str, adjust: impl FnOnce(RunConfig) -> RunConfig) -> RunReport {
    let s = scenario(name);
    let config = adjust(RunConfig::default());
    let setup = RunSetup {
        config: config.clone(),
        ..RunSetup::new(crate::common::map_for(&s, &config))
    };
    run(&s, &setup).unwrap_or_else(|e| panic!("{name}: {e:#}"))
}

fn outcomes(r: &RunReport) -> Vec<(String, String)> {
    r.obstacles
        .iter()
        .flat_map(|o| {
            o.passes
                .iter()
                .map(move |p| (o.id.clone(), p.outcome.as_str().to_string()))
        })
        .collect()
}

/// The same without the overlap of sensing and mapping: each revolution is mapped and planned
/// the instant it is taken.
#[test]
fn the_car_deviates_around_a_cone_in_its_path_with_sequential_sensing() {
    let r = run_scenario_with("cone_in_path_car", |c| RunConfig {
        schedule: Schedule::Sequential,
        ..c
    });
    assert!(r.expectations_met, "{r:#?}");
    assert!(outcomes(&r).iter().all(|(_, o)| o == "deviated"), "{r:#?}");
    // The report records the configuration it ran with, and it reads back as one.
    let json = serde_json::to_value(&r).unwrap();
    let config: RunConfig = serde_json::from_value(json["config"].clone()).unwrap();
    assert_eq!(config.schedule, Schedule::Sequential);
    assert_eq!(config, r.config);
}

/// Without the tracker, the trail stays and the jet waits for what it cannot see: it calls for
/// a pilot, and says where (ahead of the wing, on the car's path at x = 50 m). What
/// `scenarios/crossing_vehicle.toml` (the jet stops for the car, then goes on) needs the
/// tracker for.
#[test]
fn without_the_tracker_the_jet_waits_for_the_crossing_cars_hidden_trail() {
    let r = run_scenario_with("crossing_vehicle", |mut c| {
        c.mapping.forgetting.tracking.enabled = false;
        c
    });
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    let last = r.stops.last().expect("it stops");
    assert_eq!(last.end_s, None, "never resumes: {:?}", r.stops);
    assert!(!r.expectations_met && r.laps_completed == 0);
    assert_eq!(r.end, EndReason::WaitingForHiddenObstacle);
    let w = r.waiting_for.as_ref().expect("says what it waits for");
    // On the car's path, under the wing's span (10.75 m).
    assert!((w.x_m - 50.0).abs() < 2.0 && w.y_m.abs() < 11.0, "{w:?}");
    assert!(w.last_seen_s.is_some_and(|t| t < w.since_s), "{w:?}");
}

/// A noisy pose source (drift and jitter at 20 Hz, dead reckoning between) is part of the run's
/// pure function: the same seed gives the same report, another seed another one; and 5 cm of
/// drift does not stop the car from going round the cone.
#[test]
fn a_run_with_a_noisy_pose_source_is_reproducible_from_its_seed() {
    let noisy = |mut c: RunConfig| {
        c.pose_source = PoseSourceConfig::NoisyTruth(NoisyTruthConfig {
            drift_sigma_m: 0.05,
            drift_sigma_rad: 0.002,
            white_sigma_m: 0.02,
            ..NoisyTruthConfig::default()
        });
        c
    };
    let a = run_scenario_with("cone_in_path_car", noisy);
    let s = scenario("cone_in_path_car");
    let map = crate::common::map_for(&s, &noisy(RunConfig::default()));
    let setup = |seed| RunSetup {
        seed,
        config: noisy(RunConfig::default()),
        ..RunSetup::new(map.clone())
    };
    let b = run(&s, &setup(None)).unwrap();
    let c = run(&s, &setup(Some(s.seed + 1))).unwrap();
    let strip = |r: &RunReport| {
        let mut v = serde_json::to_value(r).unwrap();
        for k in ["wall_time_s", "real_time_factor", "time_split_s", "seed"] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    assert_eq!(strip(&a), strip(&b));
    assert_ne!(strip(&a), strip(&c), "another seed, other pose errors");
    assert!(a.expectations_met && c.expectations_met, "{a:#?}");
}

/// A run is the same whatever the number of threads - one, two (this machine's cores) or four
/// and eight - and so the same for the same seed (its report, wall times aside), and finishes
/// with any: with three or more, the overlapped schedule once
/// deadlocked (a worker inside the mapping task stole the plan, which waited for that mapping).
/// Each run has two minutes (it takes seconds) before the test fails instead of hanging.
#[test]
fn a_run_is_the_same_whatever_the_thread_count() {
    let map = crate::common::map_for(&scenario("cone_in_path_car"), &RunConfig::default());
    let strip = |r: &RunReport| {
        let mut v = serde_json::to_value(r).unwrap();
        for k in ["wall_time_s", "real_time_factor", "time_split_s"] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    let mut reports = Vec::new();
    for threads in [1, 2, 4, 8] {
        let (tx, rx) = std::sync::mpsc::channel();
        let (s, map_dir) = (scenario("cone_in_path_car"), map.clone());
        std::thread::spawn(move || {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let report = pool.install(|| run(&s, &RunSetup::new(map_dir)));
            let _ = tx.send(report.map_err(|e| e.to_string()));
        });
        let report = rx
            .recv_timeout(std::time::Duration::from_secs(120))
            .unwrap_or_else(|_| panic!("{threads} threads: no report in 2 minutes (deadlock?)"))
            .unwrap();
        assert!(report.expectations_met, "{threads} threads: {report:#?}");
        reports.push(strip(&report));
    }
    assert!(reports.iter().all(|r| *r == reports[0]));
}

/// The mapping drive writes the same map files, byte for byte, whatever the number of threads:
/// every block (log-odds, remission, checksum), the exports and the manifest.
#[test]
fn the_offline_map_is_the_same_whatever_the_thread_count() {
    let s = scenario("straight_cone_under_wing");
    let mut maps = Vec::new();
    for threads in [1, 2, 4] {
        let dir = tempfile::tempdir().unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            sim::offline_map::map_drive(&s, &RunConfig::default(), dir.path(), &mut |_, _| {})
        })
        .unwrap();
        let mut files: Vec<(String, Vec<u8>)> = Vec::new();
        for sub in ["", "blocks"] {
            for entry in std::fs::read_dir(dir.path().join(sub)).unwrap() {
                let p = entry.unwrap().path();
                if p.is_file() {
                    let name = format!("{sub}/{}", p.file_name().unwrap().to_string_lossy());
                    files.push((name, std::fs::read(&p).unwrap()));
                }
            }
        }
        files.sort();
        assert!(files.iter().filter(|(n, _)| n.ends_with(".tsmb")).count() >= 4);
        maps.push((threads, files));
    }
    for (threads, files) in &maps[1..] {
        let names: Vec<&String> = files.iter().map(|(n, _)| n).collect();
        let first: Vec<&String> = maps[0].1.iter().map(|(n, _)| n).collect();
        assert_eq!(names, first, "{threads} threads");
        for ((n, a), (_, b)) in files.iter().zip(&maps[0].1) {
            assert!(a == b, "{n} differs with {threads} threads");
        }
    }
}

/// Bursts of lost LiDAR revolutions (5 in a row, 0.5 s, longer than the 0.3 s watchdog): the
/// watchdog holds the car each time, it drives on when revolutions return, passes over the cone
/// under its wing as expected and touches nothing; the same faults give the same run. With the
/// watchdog off (a limit longer than the run) it never holds.
#[test]
fn the_watchdog_holds_the_car_through_lost_revolutions_and_it_drives_on() {
    let s = scenario("straight_cone_under_wing");
    let map = crate::common::map_for(&s, &RunConfig::default());
    let mut config = RunConfig::default();
    config.faults.lost_revolution_probability = 0.02;
    config.faults.lost_burst_revolutions = 5;
    let go = |config: &RunConfig| {
        let setup = RunSetup {
            config: config.clone(),
            ..RunSetup::new(map.clone())
        };
        run(&s, &setup).unwrap()
    };
    let a = go(&config);
    assert!(a.faults.lost_revolutions >= 10, "{:?}", a.faults);
    assert!(a.faults.watchdog_stops >= 1, "{:?}", a.faults);
    assert!(a.contacts.is_empty() && a.expectations_met, "{a:#?}");
    assert_eq!(a.end, EndReason::Completed);
    let b = go(&config);
    assert_eq!((a.faults, a.lap_times_s.clone()), (b.faults, b.lap_times_s));
    config.autonomy.watchdog_s = 1000.0;
    let blind = go(&config);
    assert_eq!(blind.faults.watchdog_stops, 0);
    assert_eq!(blind.faults.lost_revolutions, a.faults.lost_revolutions);
}

/// Degraded returns - 30 % dropout, the three lowest beams dead, 2 cm more range noise, two
/// spurious returns a revolution - with the prediction of movers off: the faults are applied
/// (more than a million returns dropped, more than a hundred spurious ones) and the car passes
/// over the cone touching nothing, on seed 3. Two known problems of the same road are data in
/// `tests/found/` (run by `taxi-sim regress`): on seed 1 it stops for a phantom at its start
/// and calls a pilot (`degraded_lidar_phantom_at_the_start_holds_the_car.toml`), and with the
/// prediction of movers on (the default) it stops for phantom movers again and again
/// (`degraded_lidar_phantom_movers_stop_the_car_again_and_again.toml`).
#[test]
fn the_car_copes_with_dropout_dead_beams_noise_and_spurious_returns() {
    let s = scenario("straight_cone_under_wing");
    let map = crate::common::map_for(&s, &RunConfig::default());
    let mut config = RunConfig::default();
    config.faults.beam_dropout_probability = 0.3;
    config.faults.dead_beams = vec![0, 1, 2];
    config.faults.extra_range_noise_m = 0.02;
    config.faults.spurious_returns_per_revolution = 2.0;
    config.autonomy.traffic.enabled = false;
    let setup = RunSetup {
        config,
        seed: Some(3),
        ..RunSetup::new(map)
    };
    let r = run(&s, &setup).unwrap();
    assert!(
        r.faults.dropped_returns > 1_000_000 && r.faults.spurious_returns > 100,
        "{:?}",
        r.faults
    );
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert_eq!(r.end, sim::engine::EndReason::Completed, "{:?}", r.stops);
    assert!(r.expectations_met, "{r:#?}");
}

/// LiDAR latency: every revolution 0.2 s late (taken in the world as it was, mapped at the pose
/// it was taken from). The car still passes over the cone under its wing and the jet still stops
/// for the cone on its centreline and goes on once it is towed away; the watchdog, which ages a
/// revolution from when it was taken, never holds (0.2 s + 0.1 s between revolutions is within
/// its 0.3 s).
#[test]
fn the_stack_meets_its_expectations_with_revolutions_two_tenths_late() {
    for name in ["straight_cone_under_wing", "cone_in_path_jet"] {
        let r = run_scenario_with(name, |mut c| {
            c.faults.lidar_latency_s = 0.2;
            c
        });
        assert!(
            r.contacts.is_empty() && r.expectations_met,
            "{name}: {r:#?}"
        );
        // Every revolution (one at t = 0, then one every 0.1 s) but those still in transit at the
        // end.
        let taken = (r.sim_time_s * 10.0 + 1e-6).floor() as u64 + 1;
        assert!(
            (taken - 3..=taken).contains(&r.faults.delayed_revolutions),
            "{name}: {} delayed of {taken}",
            r.faults.delayed_revolutions
        );
        assert_eq!(r.faults.watchdog_stops, 0, "{name}");
    }
}

/// Latency beyond the watchdog: 0.25 s plus up to 0.1 s of jitter makes most revolutions older
/// than 0.3 s when they arrive. The watchdog holds the car again and again, it never gets far,
/// and it touches nothing: it stops rather than drives on stale scans.
#[test]
fn revolutions_older_than_the_watchdog_allows_hold_the_car() {
    let s = scenario("straight_cone_under_wing");
    let mut config = RunConfig::default();
    config.faults.lidar_latency_s = 0.25;
    config.faults.lidar_jitter_s = 0.1;
    // A minute is enough to see it hold again and again (the scenario's own limit is 232 s).
    let setup = RunSetup {
        config: config.clone(),
        time_limit_s: Some(60.0),
        ..RunSetup::new(crate::common::map_for(&s, &config))
    };
    let r = run(&s, &setup).unwrap();
    assert!(r.faults.watchdog_stops >= 100, "{:?}", r.faults);
    assert!(r.contacts.is_empty(), "{r:#?}");
    assert_eq!(r.end, EndReason::TimedOut);
}

/// A stale offline map: at the mapping drive half the parked cars of the parking lot were not
/// there yet, the rest stood 2 m from where they stand now, and eight cars stood within 4 m of
/// the route that have gone since. The map differs (fewer occupied cells), and the car still
/// drives its lap meeting every expectation and touching nothing: what it sees overrules the
/// map.
#[test]
fn the_car_drives_the_parking_lot_on_a_stale_map() {
    let s = scenario("parking_lot");
    let mut config = RunConfig::default();
    config.faults.stale_map = sim::world::StaleMap {
        moved_m: 2.0,
        removed_fraction: 0.5,
        added_objects: 8,
    };
    // The good map is the one every parking-lot test shares (its manifest says what it holds).
    let good = crate::common::map_for(&s, &RunConfig::default());
    let g: sim::offline_map::MapManifest =
        serde_json::from_str(&std::fs::read_to_string(good.join("manifest.json")).unwrap())
            .unwrap();
    let stale = tempfile::tempdir().unwrap();
    let m = sim::offline_map::map_drive(&s, &config, stale.path(), &mut |_, _| {}).unwrap();
    assert_ne!(g.fingerprint, m.fingerprint);
    assert!(
        m.occupied_cells[0] < g.occupied_cells[0],
        "{:?} vs {:?}",
        m.occupied_cells,
        g.occupied_cells
    );
    // With the prediction of movers on (the default) the car stops for objects the map
    // misplaces, which seem to move: a known problem, as data in
    // tests/found/parking_lot_on_a_stale_map_movers_predicted.toml.
    config.autonomy.traffic.enabled = false;
    let setup = RunSetup {
        config,
        laps: Some(1),
        ..RunSetup::new(stale.path().to_path_buf())
    };
    let r = run(&s, &setup).unwrap();
    assert!(r.contacts.is_empty() && r.expectations_met, "{r:#?}");
}
