//! `taxi-sim bench loop`: the closed loop's real-time factor, overlapped against sequential
//! sensing in alternation, and where a revolution's wall time goes.

use super::timing::{Figure, figure};

/// The closed-loop figures: `samples` runs of `scenario` with each schedule, in alternation,
/// for `laps` laps (0: the scenario's own; its offline map built first, in its default directory,
/// when missing or stale): the median real-time factor of the overlapped loop against the
/// sequential one's (each revolution mapped and planned the instant it is taken), and, from the
/// median sequential run, the wall time per 0.1 s of simulated time spent in each stage. The
/// figures' names say how many runs the medians are of.
pub fn loop_figures(
    scenario: &std::path::Path,
    laps: u32,
    samples: usize,
    progress: &mut dyn FnMut(&str),
) -> crate::Result<Vec<Figure>> {
    let scenario = crate::scenario::Scenario::from_file(scenario)?;
    let config = crate::scenario::RunConfig::default();
    let map_dir = &crate::offline_map::default_map_dir(&scenario, &config);
    if crate::offline_map::fresh_manifest(&scenario, &config, map_dir)?.is_none() {
        progress("mapping drive");
        crate::offline_map::map_drive(&scenario, &config, map_dir, &mut |_, _| {})?;
    }
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
    let name = |what: &str| {
        format!(
            "loop/{}/{what}/{runs}",
            scenario
                .path
                .file_stem()
                .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
        )
    };
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
    for (what, seconds) in [
        ("lidar_per_scan", s.lidar),
        ("mapping_per_scan", s.mapping),
        ("distance_maps_per_scan", s.distance_maps),
        ("planning_per_scan", s.planning),
        ("physics_per_scan", s.physics),
        ("localization_per_scan", s.localization),
    ] {
        out.push(figure(&name(what), per_scan(seconds), "ms", None));
    }
    Ok(out)
}
