//! The small-obstacle sweep end to end on two heights at one speed: a 0.3 m box in the car's
//! left wheels' path is mapped some 40 m out and gone round; a 0.05 m one, under the obstacle
//! height (0.1 m), is never mapped and driven over. Each run is left as a scenario file. And the
//! jet, which maps a flat box too late at 8 m/s, stops for it with the avoider capped.

use sim::scenario::RunConfig;
use sim::studies::small_obstacles::{SweepSpec, run_sweep};

#[test]
fn a_tall_box_is_mapped_far_out_and_avoided_a_flat_one_is_never_mapped() {
    let dir = tempfile::tempdir().unwrap();
    let spec = SweepSpec {
        vehicle: "iara_car".into(),
        heights_m: vec![0.05, 0.3],
        speeds_m_s: vec![5.0],
        phases: 1,
        seed: 1,
        config: RunConfig::default(),
    };
    let done = std::sync::atomic::AtomicUsize::new(0);
    let mut rows = run_sweep(&spec, dir.path(), &|_| {
        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!(done.into_inner(), 2);
    rows.sort_by(|a, b| a.height_m.total_cmp(&b.height_m));
    let (flat, tall) = (&rows[0], &rows[1]);
    assert_eq!(flat.first_mapped_m, None, "{flat:?}");
    assert!(flat.contacts > 0 && !flat.avoided(), "{flat:?}");
    let range = tall.first_mapped_m.expect("mapped");
    assert!(range > 35.0, "{tall:?}");
    assert!(tall.avoided() && tall.outcome == "deviated", "{tall:?}");
    for h in [0.05, 0.3] {
        let file = dir.path().join(format!("scenarios/h{h}_v5_p0.toml"));
        sim::scenario::Scenario::from_file(&file).unwrap_or_else(|e| panic!("{e}"));
    }
}

/// The jet's nose sensor maps a 0.07 m box (under the obstacle height, over the 0.05 m safe
/// height from the ground below which nothing is an obstacle) only about 5.7 m ahead of itself
/// (5.65 m seen; 6.2 m with the 2 cm range noise of the sensor before its calibration, whose
/// errors lifted the box over the test sooner), 15.4 m ahead of the main gear: at 8 m/s its gear
/// hits the box; with the avoider capped to what stops within 15.3 m (`detection_range_m`,
/// about 5.4 m/s) it stops short.
#[test]
fn a_detection_range_slows_the_jet_enough_to_stop_for_a_flat_box() {
    let run = |detection_range_m| {
        let dir = tempfile::tempdir().unwrap();
        let mut config = RunConfig::default();
        config.autonomy.detection_range_m = detection_range_m;
        let spec = SweepSpec {
            vehicle: "praetor600".into(),
            heights_m: vec![0.07],
            speeds_m_s: vec![8.0],
            phases: 1,
            seed: 1,
            config,
        };
        run_sweep(&spec, dir.path(), &|_| {}).unwrap().remove(0)
    };
    let uncapped = run(None);
    assert!(uncapped.contacts > 0, "{uncapped:?}");
    let capped = run(Some(15.3));
    assert!(capped.first_mapped_m.is_some_and(|m| m < 7.0), "{capped:?}");
    assert_eq!(
        (capped.contacts, capped.outcome.as_str()),
        (0, "stopped"),
        "{capped:?}"
    );
}
