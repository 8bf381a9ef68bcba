//! Criterion benchmarks of the mapper's headline figures (README): scan insertion, EDT, pose check.

use criterion::{Criterion, criterion_group, criterion_main};
use mapper::edt::{EdtScratch, chamfer_3x3, exact_edt};
use mapper::workloads;
use std::hint::black_box;

fn insert(c: &mut Criterion) {
    let scan = workloads::parking_lot_scan();
    let car = workloads::fake_wing_car();
    let mut map = workloads::two_level_map();
    c.bench_function("insert_scan/hdl32e_69984_returns/2_levels", |b| {
        b.iter(|| black_box(map.insert_scan(&scan, Some(&car)).map(|s| s.hits.len())))
    });
}

/// The exact EDT on one thread and on every core, and the (single-threaded) chamfer: compare
/// `exact/1_thread` with the chamfer, `exact/all_threads` with `exact/1_thread`.
fn edt(c: &mut Criterion) {
    let mut group = c.benchmark_group("edt_1050x1050");
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
    let all = rayon::ThreadPoolBuilder::new()
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
    for (name, fraction) in [("sparse_0.1pct", 0.001), ("dense_2pct", 0.02)] {
        let mask = workloads::obstacle_mask(fraction, 1);
        let mut out = vec![0.0f32; 1050 * 1050];
        let mut scratch = EdtScratch::default();
        for (threads, pool) in [("1_thread", &one), ("all_threads", &all)] {
            group.bench_function(format!("exact/{threads}/{name}"), |b| {
                b.iter(|| {
                    pool.install(|| {
                        exact_edt(
                            1050,
                            1050,
                            0.2,
                            30.0,
                            |i| mask[i],
                            &mut scratch,
                            black_box(&mut out),
                        )
                    })
                })
            });
        }
        group.bench_function(format!("chamfer_3x3/1_thread/{name}"), |b| {
            b.iter(|| chamfer_3x3(1050, 1050, 0.2, 30.0, |i| mask[i], black_box(&mut out)))
        });
    }
    group.finish();
}

fn check_pose(c: &mut Criterion) {
    let maps = workloads::distance_maps_for_checks();
    let jet = workloads::jet_62_circles();
    let checker = jet.checker(&maps).unwrap_or_else(|e| panic!("{e}"));
    let (far, near) = workloads::far_and_near_poses();
    c.bench_function("check_pose/62_circles/near_obstacles", |b| {
        b.iter(|| black_box(checker.check_pose(black_box(&near), 0.2)))
    });
    c.bench_function("check_pose/62_circles/far_from_obstacles", |b| {
        b.iter(|| black_box(checker.check_pose(black_box(&far), 0.2)))
    });
    // The same far pose without the early out.
    c.bench_function("check_pose/62_circles/far_from_obstacles/full_check", |b| {
        b.iter(|| black_box(checker.clearance(black_box(&far), 0.2)))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(std::time::Duration::from_secs(1)).measurement_time(std::time::Duration::from_secs(3));
    targets = insert, edt, check_pose
}
criterion_main!(benches);
