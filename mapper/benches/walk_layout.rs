//! Would cells in tiles pay for the free-space walk? One revolution's walks over a window stored
//! row-major (as the map is) against the same walks over it in 4x4 and 8x8 tiles.
//!
//! The workload is the mapper's: a 1050-cell window of 0.2 m cells, an HDL-32E's 2187 columns
//! walked coarse to fine (`map/insert.rs`, `ColumnHierarchy`: a column at depth j starts where a
//! stride of 2^(j+1) would leave walkers a cell apart), each to a return 20-70 m out, with the
//! walk's update (`map/walk.rs`: a free cell lowered by one comparison and a clamp; unknown or
//! occupied cells the longer way). No walk stops at an occupied cell here, so every layout visits
//! the same cells; before timing, one revolution in each tiled layout is checked cell for cell,
//! bit for bit, against the row-major one. The row-major walk steps the cell's index as
//! `walk_free` does; a tiled walk steps x and y and computes the index.
//!
//! `cargo bench -p mapper --bench walk_layout` (run it twice, the second time with the layouts'
//! order reversed by a filter, and compare like with like: criterion times one after another).

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

const SIDE: i64 = 1050;
const COLUMNS: usize = 2187;
const RESOLUTION_M: f64 = 0.2;
const L_MAX: f32 = 4.0;
const DELTA: f32 = -0.4;
const FAST_BELOW: f32 = -f32::MIN_POSITIVE;
/// The coarsest depth of the column hierarchy for 2187 columns (`ColumnHierarchy::new`).
const MAX_DEPTH: u32 = 7;

/// One walk: from the sensor's cell to its return's, from step `first` on.
struct Line {
    from: (i64, i64),
    to: (i64, i64),
    first: i64,
}

/// A revolution's walks in the mapper's order: coarsest columns first, each finer one starting
/// where its band begins (`COVER` 0.5 of a cell between walkers at the band's outer end).
fn revolution(seed: u64) -> Vec<Line> {
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
    let sensor = (SIDE / 2, SIDE / 2);
    let r1_m = 0.5 * RESOLUTION_M * COLUMNS as f64 / std::f64::consts::TAU;
    let mut lines = Vec::with_capacity(COLUMNS);
    for depth in (0..=MAX_DEPTH).rev() {
        let step = 1usize << depth;
        let (first, stride) = if depth == MAX_DEPTH {
            (0, step)
        } else {
            (step, 2 * step)
        };
        for c in (first..COLUMNS).step_by(stride) {
            let azimuth = c as f64 * std::f64::consts::TAU / COLUMNS as f64;
            let range_cells = rng.random_range(20.0..70.0) / RESOLUTION_M;
            let to = (
                sensor.0 + (range_cells * azimuth.cos()).round() as i64,
                sensor.1 + (range_cells * azimuth.sin()).round() as i64,
            );
            let start_m = if depth == MAX_DEPTH {
                0.0
            } else {
                r1_m / f64::from(1u32 << (depth + 1))
            };
            let first = (start_m / RESOLUTION_M).ceil() as i64;
            lines.push(Line {
                from: sensor,
                to,
                first,
            });
        }
    }
    lines
}

/// The walk's update of one cell.
#[inline(always)]
fn update(v: &mut f32) {
    if *v <= FAST_BELOW {
        *v = (*v + DELTA).max(-L_MAX);
    } else {
        let cur = if v.is_nan() { 0.0 } else { *v };
        *v = (cur + DELTA).max(-L_MAX);
    }
}

/// One Bresenham step's error update (`d` = (|dx|, -|dy|)): whether x and y step, without
/// branches, as `walk_free` steps.
#[inline(always)]
fn advance(err: &mut i64, (dx, dy): (i64, i64)) -> (i64, i64) {
    let e2 = 2 * *err;
    let (mx, my) = (i64::from(e2 >= dy), i64::from(e2 <= dx));
    *err += mx * dy + my * dx;
    (mx, my)
}

/// The line's Bresenham state after `first` steps (stepped, as the walks are short to start).
fn start(line: &Line) -> (i64, i64, i64, (i64, i64), (i64, i64), i64) {
    let (a, b) = (line.from, line.to);
    let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
    let (sx, sy) = ((b.0 - a.0).signum(), (b.1 - a.1).signum());
    let (mut x, mut y, mut err) = (a.0, a.1, dx + dy);
    for _ in 0..line.first {
        let (mx, my) = advance(&mut err, (dx, dy));
        x += mx * sx;
        y += my * sy;
    }
    (x, y, err, (dx, dy), (sx, sy), dx.max(-dy) + 1 - line.first)
}

/// The revolution over a row-major window, the cell's index stepped as `walk_free` steps it.
fn walk_row_major(data: &mut [f32], lines: &[Line]) {
    for line in lines {
        let (x, y, mut err, (dx, dy), (sx, sy), steps) = start(line);
        let mut i = y * SIDE + x;
        for _ in 0..steps {
            update(&mut data[i as usize]);
            let (mx, my) = advance(&mut err, (dx, dy));
            i += mx * sx + my * sy * SIDE;
        }
    }
}

/// Cell (x, y)'s index in a window of `T` x `T` tiles (`T` a power of two), tiles row-major.
#[inline(always)]
fn tiled<const T: i64>(x: i64, y: i64) -> usize {
    // Unsigned, so the divisions by a power of two are shifts (cells are never negative here).
    let (x, y, t) = (x as usize, y as usize, T as usize);
    let tiles_x = (SIDE as usize).div_ceil(t);
    ((y / t) * tiles_x + x / t) * t * t + (y % t) * t + x % t
}

/// The revolution over a tiled window: x and y stepped, the index computed.
fn walk_tiled<const T: i64>(data: &mut [f32], lines: &[Line]) {
    for line in lines {
        let (mut x, mut y, mut err, (dx, dy), (sx, sy), steps) = start(line);
        for _ in 0..steps {
            update(&mut data[tiled::<T>(x, y)]);
            let (mx, my) = advance(&mut err, (dx, dy));
            x += mx * sx;
            y += my * sy;
        }
    }
}

/// A window as a revolution finds it: mostly free, a twentieth occupied, a tenth unknown.
fn window(seed: u64) -> Vec<f32> {
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..SIDE * SIDE)
        .map(|_| match rng.random_range(0..20) {
            0 | 1 => f32::NAN,
            2 => 1.5,
            _ => -3.0,
        })
        .collect()
}

/// `row_major` copied into `T` x `T` tiles (the padding cells NaN, never walked).
fn to_tiles<const T: i64>(row_major: &[f32]) -> Vec<f32> {
    let padded = (SIDE + T - 1) / T * T;
    let mut out = vec![f32::NAN; (padded * padded) as usize];
    for y in 0..SIDE {
        for x in 0..SIDE {
            out[tiled::<T>(x, y)] = row_major[(y * SIDE + x) as usize];
        }
    }
    out
}

/// One revolution in `T` x `T` tiles leaves the same cells, bit for bit, as the row-major one.
fn check_same<const T: i64>(cells: &[f32], lines: &[Line]) {
    let mut plain = cells.to_vec();
    walk_row_major(&mut plain, lines);
    let mut tiles = to_tiles::<T>(cells);
    walk_tiled::<T>(&mut tiles, lines);
    let expected = to_tiles::<T>(&plain);
    let same = expected
        .iter()
        .zip(&tiles)
        .all(|(a, b)| a.to_bits() == b.to_bits());
    assert!(same, "{T}x{T} tiles changed a cell");
}

fn walk_layout(c: &mut Criterion) {
    let lines = revolution(3);
    let cells = window(5);
    check_same::<4>(&cells, &lines);
    check_same::<8>(&cells, &lines);
    let walked: i64 = lines.iter().map(|l| start(l).5).sum();
    println!(
        "one revolution: {} walks, {walked} cell updates",
        lines.len()
    );
    let mut group = c.benchmark_group("walk_layout/one_revolution");
    let mut row_major = cells.clone();
    group.bench_function("row_major", |b| {
        b.iter(|| walk_row_major(black_box(&mut row_major), &lines))
    });
    let mut tiles4 = to_tiles::<4>(&cells);
    group.bench_function("tiles_4x4", |b| {
        b.iter(|| walk_tiled::<4>(black_box(&mut tiles4), &lines))
    });
    let mut tiles8 = to_tiles::<8>(&cells);
    group.bench_function("tiles_8x8", |b| {
        b.iter(|| walk_tiled::<8>(black_box(&mut tiles8), &lines))
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(std::time::Duration::from_secs(1)).measurement_time(std::time::Duration::from_secs(3));
    targets = walk_layout
}
criterion_main!(benches);
