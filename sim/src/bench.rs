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

pub(crate) fn figure(
    name: &str,
    seconds: f64,
    unit: &'static str,
    target: Option<&'static str>,
) -> Figure {
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

pub(crate) fn against(mut f: Figure, baseline: &Figure) -> Figure {
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
    let [every_map, coarse_map] = &mut maps;
    let insert = |map: &mut mapper::MultiHeightMap| {
        black_box(
            map.insert_scan(&scan, Some(&car))
                .map(|s| s.hits.len())
                .unwrap_or(0),
        );
    };
    let (every, coarse) = alternating(samples, 1, || insert(every_map), || insert(coarse_map));
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

    progress("self_hits");
    out.extend(self_hit_figures(samples, &scan));

    out.extend(edt_figures(samples, progress));

    progress("check_pose");
    out.extend(check_figures(samples));
    out
}

/// The self-hit test of a revolution's 69,984 returns against the 62-circle jet: the binned
/// filter the mapper uses against every circle per return (inside the bounding circle), one
/// thread each, in alternation.
fn self_hit_figures(samples: usize, scan: &mapper::Scan) -> Vec<Figure> {
    let jet = workloads::jet_62_circles();
    let margin = MapConfig::default().self_hit_margin_m;
    let filter = mapper::SelfHitFilter::new(&jet, margin);
    let beams = scan.beams().max(1);
    let points: Vec<(nalgebra::Point2<f64>, f64)> = scan
        .returns()
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let (r, column) = (r.as_ref()?, scan.columns().get(i / beams)?);
            let p = r.point_in_world;
            let v = column.world_from_vehicle.inverse() * nalgebra::Point2::new(p.x, p.y);
            Some((v, p.z))
        })
        .collect();
    let (binned, every) = alternating(
        samples,
        1,
        || {
            black_box(
                points
                    .iter()
                    .filter(|(p, z)| filter.is_self_hit(p, *z))
                    .count(),
            );
        },
        || {
            black_box(
                points
                    .iter()
                    .filter(|(p, z)| jet.is_self_hit(p, *z, margin))
                    .count(),
            );
        },
    );
    let every = figure(
        "self_hits/hdl32e_69984_returns/62_circles/every_circle",
        every,
        "ms",
        None,
    );
    let binned = figure(
        "self_hits/hdl32e_69984_returns/62_circles",
        binned,
        "ms",
        None,
    );
    vec![against(binned, &every), every]
}

/// The 62-circle pose check near obstacles, and far from them the bounding-circle early out
/// against the full check of the same pose, and one distance-map lookup; pairs in alternation.
fn check_figures(samples: usize) -> Vec<Figure> {
    let maps = workloads::distance_maps_for_checks();
    let jet = workloads::jet_62_circles();
    let (far, near) = workloads::far_and_near_poses();
    let Ok(checker) = jet.checker(&maps) else {
        return Vec::new();
    };
    let batch = 20_000;
    let level0 = &maps.levels()[0];
    let centre = nalgebra::Point2::new(far.translation.x, far.translation.y);
    let (near_t, lookup_t) = alternating(
        samples,
        batch,
        || {
            black_box(checker.check_pose(black_box(&near), 0.2));
        },
        || {
            black_box(level0.distance_at(black_box(&centre)));
        },
    );
    let (far_t, far_full_t) = alternating(
        samples,
        batch,
        || {
            black_box(checker.check_pose(black_box(&far), 0.2));
        },
        || {
            black_box(checker.clearance(black_box(&far), 0.2));
        },
    );
    // The full check near obstacles, eight circles at a time (AVX2) against one at a time.
    let (full_t, portable_t) = alternating(
        samples,
        batch,
        || {
            black_box(checker.clearance(black_box(&near), 0.2));
        },
        || {
            black_box(checker.clearance_portable(black_box(&near), 0.2));
        },
    );
    let near_f = figure(
        "check_pose/62_circles/near_obstacles",
        near_t,
        "ns",
        Some("<= 200 ns"),
    );
    let far_full = figure(
        "check_pose/62_circles/far_from_obstacles/full_check",
        far_full_t,
        "ns",
        None,
    );
    let far_f = figure(
        "check_pose/62_circles/far_from_obstacles",
        far_t,
        "ns",
        Some("close to one lookup"),
    );
    let lookup = figure("distance_map/one_lookup", lookup_t, "ns", None);
    let lanes = if checker.vectorised() {
        "8_lanes_avx2"
    } else {
        "1_lane_no_avx2_here"
    };
    let full = figure(
        &format!("check_pose/62_circles/near_obstacles/full_check/{lanes}"),
        full_t,
        "ns",
        None,
    );
    let portable = figure(
        "check_pose/62_circles/near_obstacles/full_check/1_lane",
        portable_t,
        "ns",
        None,
    );
    // The early out against the full check of the same pose; one lookup against the early out
    // (1.0 would be exactly one lookup).
    let lookup = against(lookup, &far_f);
    vec![
        near_f,
        against(full, &portable),
        portable,
        against(far_f, &far_full),
        far_full,
        lookup,
    ]
}

/// Medians of `a` and `b` over `samples` rounds of `batch` calls each, timed in alternation (one
/// warm-up round first), so the machine's drift falls on both.
pub fn alternating(
    samples: usize,
    batch: usize,
    mut a: impl FnMut(),
    mut b: impl FnMut(),
) -> (f64, f64) {
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for round in 0..=samples.max(1) {
        for (f, times) in [(&mut a as &mut dyn FnMut(), &mut ta), (&mut b, &mut tb)] {
            let t = Instant::now();
            for _ in 0..batch {
                f();
            }
            if round > 0 {
                times.push(t.elapsed().as_secs_f64() / batch as f64);
            }
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (median(ta), median(tb))
}

/// The exact EDT against the 3x3 chamfer, one thread each (like with like), and the exact EDT's
/// parallel speed-up on every core against its own single-thread time, each pair in alternation.
fn edt_figures(samples: usize, progress: &mut dyn FnMut(&str)) -> Vec<Figure> {
    let mut out = Vec::new();
    let (Ok(one), Ok(all)) = (
        rayon::ThreadPoolBuilder::new().num_threads(1).build(),
        rayon::ThreadPoolBuilder::new().build(),
    ) else {
        return out;
    };
    let mut output = vec![0.0f32; 1050 * 1050];
    let mut scratch = EdtScratch::default();
    for (label, fraction) in [("sparse_0.1pct", 0.001), ("dense_2pct", 0.02)] {
        progress(&format!("edt {label}"));
        let mask = workloads::obstacle_mask(fraction, 1);
        let exact = |pool: &rayon::ThreadPool, output: &mut [f32], scratch: &mut EdtScratch| {
            pool.install(|| {
                exact_edt(
                    1050,
                    1050,
                    0.2,
                    30.0,
                    |i| mask[i],
                    scratch,
                    black_box(output),
                )
            })
        };
        let mut chamfer_out = vec![0.0f32; 1050 * 1050];
        let (exact_1, chamfer) = alternating(
            samples,
            1,
            || exact(&one, &mut output, &mut scratch),
            || {
                one.install(|| {
                    chamfer_3x3(
                        1050,
                        1050,
                        0.2,
                        30.0,
                        |i| mask[i],
                        black_box(&mut chamfer_out),
                    )
                })
            },
        );
        let mut scratch_all = EdtScratch::default();
        let mut output_all = vec![0.0f32; 1050 * 1050];
        let (exact_1b, exact_n) = alternating(
            samples,
            1,
            || exact(&one, &mut output, &mut scratch),
            || exact(&all, &mut output_all, &mut scratch_all),
        );
        let name = |what: &str| format!("edt_1050x1050/{what}/{label}");
        let chamfer = figure(&name("chamfer_3x3/1_thread"), chamfer, "ms", None);
        let single = figure(&name("exact/1_thread"), exact_1, "ms", None);
        let single_b = figure(&name("exact/1_thread_again"), exact_1b, "ms", None);
        let threads = all.current_num_threads();
        out.push(against(
            figure(
                &name(&format!("exact/{threads}_threads")),
                exact_n,
                "ms",
                Some("<= 10 ms"),
            ),
            &single_b,
        ));
        out.push(single_b);
        out.push(against(single, &chamfer));
        out.push(chamfer);
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
        pavement_texture: 0.0,
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
    let config = crate::config::RunConfig::default();
    let map_dir = &crate::mapping::default_map_dir(&scenario, &config);
    if crate::mapping::fresh_manifest(&scenario, &config, map_dir)?.is_none() {
        progress("mapping drive");
        crate::mapping::map_drive(&scenario, &config, map_dir, &mut |_, _| {})?;
    }
    let setup = |schedule| crate::run::RunSetup {
        laps: (laps > 0).then_some(laps),
        config: crate::config::RunConfig {
            schedule,
            ..config.clone()
        },
        ..crate::run::RunSetup::new(map_dir.to_path_buf())
    };
    let samples = samples.max(1);
    let (mut sequential, mut overlapped) = (Vec::new(), Vec::new());
    for k in 0..samples {
        // The straightforward way first in each round: mapped and planned the instant taken.
        progress(&format!("closed loop {} of {samples}, sequential", k + 1));
        sequential.push(crate::run::run(
            &scenario,
            &setup(crate::config::Schedule::Sequential),
        )?);
        progress(&format!("closed loop {} of {samples}, overlapped", k + 1));
        overlapped.push(crate::run::run(
            &scenario,
            &setup(crate::config::Schedule::Overlapped),
        )?);
    }
    let median_run = |runs: &mut Vec<crate::report::RunReport>| {
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
