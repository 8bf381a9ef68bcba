//! `taxi-sim bench loop --vehicle B`: what another sensor layout costs the closed loop - the
//! scenario with its own vehicle against the same scenario with vehicle `B` (e.g. the same
//! airframe with a second LiDAR), runs in alternation, each over its own offline map.

use super::timing::Figure;

/// `samples` runs of `scenario` with its own vehicle and with `vehicle` (a shipped name or a
/// sidecar path), in alternation, `laps` laps each (0: the scenario's own): the median real-time
/// factors, their ratio, and per 0.1 s of simulated time the LiDAR's and the mapping's wall
/// time of each (from the median runs).
pub fn vehicle_figures(
    scenario: &std::path::Path,
    vehicle: &str,
    laps: u32,
    samples: usize,
    progress: &mut dyn FnMut(&str),
) -> crate::Result<Vec<Figure>> {
    let own = crate::scenario::Scenario::from_file(scenario)?;
    let mut other = own.clone();
    other.vehicle.vehicle = aircraft::Vehicle::load(vehicle)
        .map_err(|e| crate::Error::Invalid(format!("--vehicle {vehicle}: {e}")))?;
    let config = crate::scenario::RunConfig::default();
    let mut setups = Vec::new();
    for (k, s) in [&own, &other].into_iter().enumerate() {
        let mut map_dir = crate::offline_map::default_map_dir(s, &config);
        if k == 1 {
            // Its own directory: a map's manifest names the vehicle it was built for.
            let name = map_dir
                .file_name()
                .map(|n| n.to_string_lossy().into_owned());
            map_dir.set_file_name(format!(
                "{}-{}",
                name.unwrap_or_default(),
                s.vehicle.vehicle.spec.name
            ));
        }
        crate::offline_map::ensure(
            s,
            &config,
            &map_dir,
            &mut || progress("mapping drive"),
            &mut |_, _| {},
        )?;
        setups.push(crate::engine::RunSetup {
            laps: (laps > 0).then_some(laps),
            ..crate::engine::RunSetup::new(map_dir)
        });
    }
    let samples = samples.max(1);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for k in 0..samples {
        progress(&format!(
            "closed loop {} of {samples}, its own vehicle",
            k + 1
        ));
        a.push(crate::engine::run(&own, &setups[0])?);
        progress(&format!("closed loop {} of {samples}, {vehicle}", k + 1));
        b.push(crate::engine::run(&other, &setups[1])?);
    }
    let median_run = |runs: &mut Vec<crate::engine::RunReport>| {
        runs.sort_by(|x, y| x.real_time_factor.total_cmp(&y.real_time_factor));
        runs.swap_remove(runs.len() / 2)
    };
    let (a, b) = (median_run(&mut a), median_run(&mut b));
    let runs = if samples == 1 {
        "one_run".to_string()
    } else {
        format!("median_of_{samples}")
    };
    let stem = own
        .path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = |who: &str, what: &str| format!("loop/{stem}/{who}/{what}/{runs}");
    let own_name = own.vehicle.vehicle.spec.name.clone();
    let other_name = other.vehicle.vehicle.spec.name.clone();
    let mut out = vec![
        Figure {
            name: name(&other_name, "real_time_factor"),
            median: b.real_time_factor,
            unit: "x",
            baseline: Some(name(&own_name, "real_time_factor")),
            ratio: Some(b.real_time_factor / a.real_time_factor.max(1e-9)),
            target: None,
        },
        Figure {
            name: name(&own_name, "real_time_factor"),
            median: a.real_time_factor,
            unit: "x",
            baseline: None,
            ratio: None,
            target: None,
        },
    ];
    for (who, r) in [(&own_name, &a), (&other_name, &b)] {
        let scans = (r.sim_time_s / 0.1).max(1.0);
        for (what, seconds) in [
            ("lidar_per_scan", r.time_split_s.lidar),
            ("mapping_per_scan", r.time_split_s.mapping),
        ] {
            out.push(super::timing::figure(
                &name(who, what),
                seconds / scans,
                "ms",
                None,
            ));
        }
    }
    Ok(out)
}
