//! `taxi-sim bench`: the README's headline figures, each against its straightforward baseline.
//!
//! Criterion (`cargo bench -p mapper`) gives the same figures with statistics; this module lets
//! a user measure their own machine with the release binary alone. Each figure is the median of
//! `samples` timed batches after one warm-up batch.

use std::hint::black_box;
use std::time::Instant;

use mapper::edt::{EdtScratch, chamfer_3x3, exact_edt};
use mapper::{FreeSpaceWalks, MapConfig, workloads};
use serde::Serialize;

/// One measured figure.
#[derive(Clone, Debug, Serialize)]
pub struct Figure {
    /// What was measured.
    pub name: String,
    /// Median time of one operation.
    pub median: f64,
    /// Unit of `median` (`ms`, `ns`).
    pub unit: &'static str,
    /// The figure this one is compared with, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<String>,
    /// `baseline median / this median` (> 1: this is faster).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ratio: Option<f64>,
    /// The design target, as text.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target: Option<&'static str>,
}

/// Median seconds per call of `f`, over `samples` batches of `batch` calls.
pub fn median_seconds(samples: usize, batch: usize, mut f: impl FnMut()) -> f64 {
    for _ in 0..batch {
        f();
    }
    let mut times: Vec<f64> = (0..samples.max(1))
        .map(|_| {
            let t = Instant::now();
            for _ in 0..batch {
                f();
            }
            t.elapsed().as_secs_f64() / batch as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn figure(name: &str, seconds: f64, unit: &'static str, target: Option<&'static str>) -> Figure {
    let scale = if unit == "ms" { 1e3 } else { 1e9 };
    Figure {
        name: name.into(),
        median: seconds * scale,
        unit,
        baseline: None,
        ratio: None,
        target,
    }
}

fn against(mut f: Figure, baseline: &Figure) -> Figure {
    f.baseline = Some(baseline.name.clone());
    f.ratio = Some(baseline.median / f.median);
    f
}

/// The mapper's figures: scan insertion, exact EDT vs chamfer, pose checks. `progress` is told
/// the name of each figure before it is measured.
pub fn mapper_figures(samples: usize, progress: &mut dyn FnMut(&str)) -> Vec<Figure> {
    let mut out = Vec::new();

    progress("insert_scan");
    let scan = workloads::parking_lot_scan();
    let car = workloads::fake_wing_car();
    // The free-space walk of every column (CARMEN's) against the coarse-to-fine one, timed in
    // alternation so that the machine's drift falls on both.
    let mut maps = [FreeSpaceWalks::EveryColumn, FreeSpaceWalks::CoarseToFine].map(|walks| {
        workloads::two_level_map_with(MapConfig {
            free_space_walks: walks,
            ..MapConfig::default()
        })
        .unwrap_or_else(|e| unreachable!("fixed config: {e}"))
    });
    let mut times = [Vec::new(), Vec::new()];
    for round in 0..=samples.max(1) {
        for (map, times) in maps.iter_mut().zip(&mut times) {
            let t = Instant::now();
            black_box(
                map.insert_scan(&scan, Some(&car))
                    .map(|s| s.hits.len())
                    .unwrap_or(0),
            );
            if round > 0 {
                times.push(t.elapsed().as_secs_f64()); // round 0 warms up
            }
        }
    }
    let [every, coarse] = times.map(|mut t| {
        t.sort_by(f64::total_cmp);
        t[t.len() / 2]
    });
    let every = figure(
        "insert_scan/hdl32e_69984_returns/2_levels/every_column_walks",
        every,
        "ms",
        None,
    );
    let coarse = figure(
        "insert_scan/hdl32e_69984_returns/2_levels",
        coarse,
        "ms",
        Some("<= 5 ms"),
    );
    out.push(against(coarse, &every));
    out.push(every);

    let mut output = vec![0.0f32; 1050 * 1050];
    let mut scratch = EdtScratch::default();
    for (label, fraction) in [("sparse_0.1pct", 0.001), ("dense_2pct", 0.02)] {
        progress(&format!("edt {label}"));
        let mask = workloads::obstacle_mask(fraction, 1);
        let chamfer = median_seconds(samples, 1, || {
            chamfer_3x3(1050, 1050, 0.2, 30.0, |i| mask[i], black_box(&mut output))
        });
        let chamfer = figure(
            &format!("edt_1050x1050/chamfer_3x3/{label}"),
            chamfer,
            "ms",
            None,
        );
        let exact = median_seconds(samples, 1, || {
            exact_edt(
                1050,
                1050,
                0.2,
                30.0,
                |i| mask[i],
                &mut scratch,
                black_box(&mut output),
            )
        });
        out.push(against(
            figure(
                &format!("edt_1050x1050/exact/{label}"),
                exact,
                "ms",
                Some("<= 10 ms"),
            ),
            &chamfer,
        ));
        out.push(chamfer);
    }

    progress("check_pose");
    let maps = workloads::distance_maps_for_checks();
    let jet = workloads::jet_62_circles();
    let (far, near) = workloads::far_and_near_poses();
    if let Ok(checker) = jet.checker(&maps) {
        let batch = 20_000;
        let near_t = median_seconds(samples, batch, || {
            black_box(checker.check_pose(black_box(&near), 0.2));
        });
        let near_f = figure(
            "check_pose/62_circles/near_obstacles",
            near_t,
            "ns",
            Some("<= 200 ns"),
        );
        let far_t = median_seconds(samples, batch, || {
            black_box(checker.check_pose(black_box(&far), 0.2));
        });
        let level0 = &maps.levels()[0];
        let centre = nalgebra::Point2::new(far.translation.x, far.translation.y);
        let lookup_t = median_seconds(samples, batch, || {
            black_box(level0.distance_at(black_box(&centre)));
        });
        let lookup = figure("distance_map/one_lookup", lookup_t, "ns", None);
        // Far from obstacles: compared with the full check (how much the early out saves) ...
        out.push(against(
            figure(
                "check_pose/62_circles/far_from_obstacles",
                far_t,
                "ns",
                Some("close to one lookup"),
            ),
            &near_f,
        ));
        out.push(near_f);
        // ... and one lookup compared with it (1.0 would be exactly one lookup).
        out.push(against(lookup, &out[out.len() - 2]));
    }
    out
}

/// A parking lot of about 300 objects for the LiDAR figures: the mapper's benchmark lot (parked
/// cars, lamp posts, cones, containers) plus 80 cones scattered between the rows.
pub fn lidar_scene() -> crate::scene::Scene {
    use crate::scene::{ObjectKind, Scene, Solid, SolidShape};
    use mapper::synthetic::Solid as Synthetic;
    let mut solids = Vec::new();
    for (i, s) in workloads::parking_lot_scene().solids.iter().enumerate() {
        let (shape, x, y, kind) = match *s {
            Synthetic::Box { min, max } => {
                let size = max - min;
                let kind = if size.z > 1.3 {
                    ObjectKind::ParkedCar
                } else {
                    ObjectKind::Container
                };
                (
                    SolidShape::Box {
                        size_m: [size.x, size.y, size.z],
                    },
                    0.5 * (min.x + max.x),
                    0.5 * (min.y + max.y),
                    kind,
                )
            }
            Synthetic::Cylinder {
                center,
                radius_m,
                z_max,
                ..
            } => {
                let kind = if z_max > 1.0 {
                    ObjectKind::LampPost
                } else {
                    ObjectKind::Cone
                };
                let shape = if kind == ObjectKind::Cone {
                    SolidShape::Cone {
                        radius_m,
                        height_m: z_max,
                    }
                } else {
                    SolidShape::Cylinder {
                        radius_m,
                        height_m: z_max,
                    }
                };
                (shape, center.x, center.y, kind)
            }
        };
        solids.push(Solid {
            id: format!("lot_{i}"),
            kind,
            shape,
            x_m: x,
            y_m: y,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.6,
            runtime: false,
        });
    }
    let mut rng = workloads::XorShift::new(99);
    for i in 0..80 {
        let (x, y) = (rng.range(-60.0, 60.0), rng.range(-60.0, 60.0));
        if x.abs() < 5.0 && (y + 3.0).abs() < 5.0 {
            continue;
        }
        let shape = SolidShape::Cone {
            radius_m: 0.18,
            height_m: 0.45,
        };
        solids.push(Solid {
            id: format!("cone_{i}"),
            kind: ObjectKind::Cone,
            shape,
            x_m: x,
            y_m: y,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.8,
            runtime: false,
        });
    }
    Scene {
        min_m: [-100.0, -100.0],
        max_m: [100.0, 100.0],
        ground_remission: 0.2,
        solids,
        patches: Vec::new(),
    }
}

/// The LiDAR figures: one HDL-32E revolution with the fast path and with Rapier's generic
/// per-ray query, same scene, same run.
pub fn lidar_figures(samples: usize, progress: &mut dyn FnMut(&str)) -> crate::Result<Vec<Figure>> {
    use crate::lidar::{Lidar, LidarConfig, SweepPoses};
    progress("building the world");
    let scene = lidar_scene();
    let vehicle = aircraft::Vehicle::shipped("iara_car_fake_wing")?;
    let pose = nalgebra::Isometry2::new(nalgebra::Vector2::new(0.0, -3.0), 0.1);
    let world = crate::world::World::new(&scene, true, &vehicle, &pose);
    let lidar = Lidar::new(LidarConfig::default(), vehicle.vehicle_from_lidar())
        .map_err(crate::Error::Invalid)?;
    let sweep = SweepPoses::still(pose);
    progress("generic cast");
    let generic = median_seconds(samples.min(7), 1, || {
        black_box(lidar.scan_generic(&world, &sweep, 0, 1));
    });
    let generic = figure(
        &format!(
            "lidar/generic_query/{}_rays/{}_objects",
            lidar.rays(),
            scene.solids.len()
        ),
        generic,
        "ms",
        None,
    );
    progress("fast cast");
    let fast = median_seconds(samples, 1, || {
        black_box(lidar.scan(&world, &sweep, 0, 1));
    });
    let fast = figure(
        &format!(
            "lidar/fast/{}_rays/{}_objects",
            lidar.rays(),
            scene.solids.len()
        ),
        fast,
        "ms",
        Some("<= 10 ms, >= 3x generic"),
    );
    Ok(vec![against(fast, &generic), generic])
}

/// The closed-loop figures: runs of `scenario` for `laps` laps (0: the scenario's own; its
/// offline map built first, in its default directory, when missing or stale), reporting the
/// real-time factor against the sequential loop's (each revolution mapped and planned the instant
/// it is taken), and, from the sequential run, the wall time per 0.1 s of simulated time spent
/// in each stage. One run each, not a median.
pub fn loop_figures(
    scenario: &std::path::Path,
    laps: u32,
    progress: &mut dyn FnMut(&str),
) -> crate::Result<Vec<Figure>> {
    let scenario = crate::scenario::Scenario::from_file(scenario)?;
    let config = crate::config::RunConfig::default();
    let map_dir = &crate::mapping::default_map_dir(&scenario, &config);
    if crate::mapping::fresh_manifest(&scenario, &config, map_dir)?.is_none() {
        progress("mapping drive");
        crate::mapping::map_drive(&scenario, &config, map_dir, &mut |_, _| {})?;
    }
    // The straightforward way first: each revolution mapped and planned the instant it is taken.
    progress("closed loop, sequential");
    let setup = |schedule| crate::run::RunSetup {
        laps: (laps > 0).then_some(laps),
        config: crate::config::RunConfig {
            schedule,
            ..config.clone()
        },
        ..crate::run::RunSetup::new(map_dir.to_path_buf())
    };
    let sequential = crate::run::run(&scenario, &setup(crate::config::Schedule::Sequential))?;
    progress("closed loop");
    let report = crate::run::run(&scenario, &setup(crate::config::Schedule::Overlapped))?;
    let scans = sequential.sim_time_s / 0.1;
    let per_scan = |seconds: f64| seconds / scans.max(1.0);
    let name = |what: &str| {
        format!(
            "loop/{}/{what}",
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
            target: Some(">= 20x (parking lot)"),
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
    ] {
        out.push(figure(&name(what), per_scan(seconds), "ms", None));
    }
    Ok(out)
}
