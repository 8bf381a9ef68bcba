//! `taxi-sim bench mapper`: scan insertion (hierarchical against every column), the self-hit
//! filter, pose checks (early out, AVX2 against portable) and the exact EDT against the 3x3
//! chamfer, one thread against one thread, each pair in alternation.

use std::hint::black_box;

use mapper::edt::{EdtScratch, chamfer_3x3, exact_edt};
use mapper::{FreeSpaceWalks, MapConfig, workloads};

use super::timing::{Figure, against, alternating, figure};

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
