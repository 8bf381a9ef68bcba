//! `taxi-sim bench loop`: the closed loop's real-time factor, overlapped against sequential
//! sensing in alternation, and where a revolution's wall time goes.

use super::timing::{Figure, figure};

/// Where the median sequential run's wall time went, per revolution (0.1 s of simulated time),
/// by stage: what `bench loop --out DIR` draws ([`super::loop_chart::draw`]).
#[derive(Clone, Debug)]
pub struct StageSplit {
    /// The scenario's file stem.
    pub scenario: String,
    /// The overlapped loop's real-time factor (the median run's).
    pub real_time_factor: f64,
    /// Milliseconds per revolution of each stage of [`STAGES`], in its order.
    pub ms_per_revolution: [f64; STAGES.len()],
}

/// The stages of a run's `time_split_s`, as the figures and the picture name them.
pub const STAGES: [&str; 6] = [
    "lidar",
    "mapping",
    "distance_maps",
    "planning",
    "physics",
    "localization",
];

/// The closed-loop figures: `samples` runs of `scenario` with each schedule, in alternation,
/// for `laps` laps (0: the scenario's own; its offline map built first, in its default directory,
/// when missing or stale): the median real-time factor of the overlapped loop against the
/// sequential one's (each revolution mapped and planned the instant it is taken), and, from the
/// median sequential run, the wall time per 0.1 s of simulated time spent in each stage. The
/// figures' names say how many runs the medians are of. With them, the stage split drawn by
/// `--out`. (The traffic check's figures are [`traffic_figures`], apart: they do not depend on
/// the scenario.)
pub fn loop_figures(
    scenario: &std::path::Path,
    laps: u32,
    samples: usize,
    progress: &mut dyn FnMut(&str),
) -> crate::Result<(Vec<Figure>, StageSplit)> {
    let scenario = crate::scenario::Scenario::from_file(scenario)?;
    let config = crate::scenario::RunConfig::default();
    let map_dir = &crate::offline_map::default_map_dir(&scenario, &config);
    crate::offline_map::ensure(
        &scenario,
        &config,
        map_dir,
        &mut || progress("mapping drive"),
        &mut |_, _| {},
    )?;
    let setup = |schedule| crate::engine::RunSetup {
        laps: (laps > 0).then_some(laps),
        config: crate::scenario::RunConfig {
            schedule,
            ..config.clone()
        },
        ..crate::engine::RunSetup::new(map_dir.to_path_buf())
    };
    let samples = samples.max(1);
    let (mut sequential, mut overlapped) = (Vec::new(), Vec::new());
    for k in 0..samples {
        // The straightforward way first in each round: mapped and planned the instant taken.
        progress(&format!("closed loop {} of {samples}, sequential", k + 1));
        sequential.push(crate::engine::run(
            &scenario,
            &setup(crate::scenario::Schedule::Sequential),
        )?);
        progress(&format!("closed loop {} of {samples}, overlapped", k + 1));
        overlapped.push(crate::engine::run(
            &scenario,
            &setup(crate::scenario::Schedule::Overlapped),
        )?);
    }
    let median_run = |runs: &mut Vec<crate::engine::RunReport>| {
        runs.sort_by(|a, b| a.real_time_factor.total_cmp(&b.real_time_factor));
        runs.swap_remove(runs.len() / 2)
    };
    let (sequential, report) = (median_run(&mut sequential), median_run(&mut overlapped));
    let scans = sequential.sim_time_s / 0.1;
    let per_scan = |seconds: f64| seconds / scans.max(1.0);
    let runs = if samples == 1 {
        "one_run".to_string()
    } else {
        format!("median_of_{samples}")
    };
    let stem = scenario
        .path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = |what: &str| format!("loop/{stem}/{what}/{runs}");
    // Where the time goes, from the sequential run: there each stage has both cores to itself.
    let s = &sequential.time_split_s;
    // A factor, not a time: the ratio is this over the baseline (> 1: this is faster).
    let mut out = vec![
        Figure {
            name: name("real_time_factor"),
            median: report.real_time_factor,
            unit: "x",
            baseline: Some(name("real_time_factor_sequential")),
            ratio: Some(report.real_time_factor / sequential.real_time_factor.max(1e-9)),
            target: Some(">= 30x parking lot, >= 20x aerodrome"),
        },
        Figure {
            name: name("real_time_factor_sequential"),
            median: sequential.real_time_factor,
            unit: "x",
            baseline: None,
            ratio: None,
            target: None,
        },
    ];
    let seconds = [
        s.lidar,
        s.mapping,
        s.distance_maps,
        s.planning,
        s.physics,
        s.localization,
    ];
    for (stage, seconds) in STAGES.iter().zip(seconds) {
        out.push(figure(
            &name(&format!("{stage}_per_scan")),
            per_scan(seconds),
            "ms",
            None,
        ));
    }
    let split = StageSplit {
        scenario: stem.clone(),
        real_time_factor: report.real_time_factor,
        ms_per_revolution: seconds.map(|seconds| 1e3 * per_scan(seconds)),
    };
    Ok((out, split))
}

/// Prediction and the space-time check of one revolution: 20 movers around the 62-circle jet's
/// 41.5 m path (its horizon at 10 m/s, 84 poses), none in conflict so every pose is checked for
/// every mover - the worst case - against the same check of every circle at every pose, one
/// thread each, in alternation.
pub fn traffic_figures(samples: usize) -> Vec<Figure> {
    use autonomy::traffic::{
        SpeedProfile, TimedPath, TrafficConfig, first_conflict, first_conflict_straightforward,
        predict,
    };
    use nalgebra::{Isometry2, Matrix4, Point2, Vector2, Vector4};
    let model = mapper::workloads::jet_62_circles();
    let poses: Vec<Isometry2<f64>> = (0..84)
        .map(|k| Isometry2::new(Vector2::new(k as f64 * 0.5, 0.0), 0.0))
        .collect();
    // Movers 15-40 m either side, driving along the road: always near, never in conflict.
    let tracks: Vec<mapper::TrackState> = (0..20)
        .map(|i| {
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            mapper::TrackState {
                id: i,
                t_s: 0.0,
                position: Point2::new(2.0 * i as f64, side * (15.0 + i as f64)),
                velocity: Vector2::new(if i % 3 == 0 { -3.0 } else { 2.0 }, 0.0),
                covariance: Matrix4::from_diagonal(&Vector4::new(0.02, 0.02, 0.05, 0.05)),
                extent_m: 4.9,
                levels: 0b11,
                open_top_m: None,
                confirmed: true,
                travel_m: 20.0,
                bbox: ((0, 0), (22, 8)),
                size_m: [4.6, 1.8],
                peak_speed_m_s: if i % 3 == 0 { 3.0 } else { 2.0 },
                born_s: -8.0,
                origin: Point2::new(2.0 * i as f64, side * (35.0 + i as f64)),
            }
        })
        .collect();
    let cfg = TrafficConfig::default();
    let path = TimedPath {
        poses: &poses,
        step_m: 0.5,
        profile: SpeedProfile {
            speed_m_s: 10.0,
            target_m_s: 10.0,
            acceleration_m_s2: 0.5,
        },
        now_s: 0.0,
        yielding: false,
    };
    let (mut found, mut plain_found) = (None, None);
    let (fast, plain) = super::timing::alternating(
        samples,
        20,
        || {
            let p = predict(&tracks, 0.0, &cfg);
            found = std::hint::black_box(first_conflict(&path, &model, &p, &cfg));
        },
        || {
            let p = predict(&tracks, 0.0, &cfg);
            plain_found =
                std::hint::black_box(first_conflict_straightforward(&path, &model, &p, &cfg));
        },
    );
    debug_assert_eq!(found, plain_found);
    let plain = figure(
        "traffic/predict_and_check/20_movers/jet_62_circles/every_circle",
        plain,
        "ms",
        None,
    );
    let fast = figure(
        "traffic/predict_and_check/20_movers/jet_62_circles",
        fast,
        "ms",
        Some("< 0.5 ms a revolution"),
    );
    vec![super::timing::against(fast, &plain), plain]
}
