//! The free-space walk: one Bresenham line of cells from the sensor toward a column's farthest
//! return, each cell lowered by `l_free` ([`walk_free`]).
//!
//! The hot loop of the mapping, so its per-cell work is trimmed, under one rule: the trimmed
//! walk visits the same cells, adds the same increments in the same order, notes the same
//! touched cells, asks the same stop questions and ends where the plain per-step loop does
//! (`walk_free_plain`, compiled for tests only), so the maps are equal bit for bit. `tests::the_trimmed_walk_equals_the_plain_one` checks it on 20,000 random
//! walks (from inside and outside a small window, leaving it on every side, stopped by occupied
//! cells, from a start range on); `tests::bresenham_jumps_land_on_the_stepped_line` checks the
//! O(1) jump into a line it relies on. The trims:
//! - where the line leaves the window is found before the walk, by a binary search on the O(1)
//!   jump [`bresenham_at`] (a line from a cell inside leaves a rectangle once and for all), so
//!   the loop tests no edge;
//! - the increment, a function of the range, is recomputed every 8 cells in an outer loop;
//! - the line steps the cell's index (not x and y), without branches;
//! - a known free cell at or below the touched threshold takes one comparison (NaN fails it and
//!   takes the full path).

use super::distance::TouchedCells;

/// A free-space walk along the Bresenham line of cells `from` (the sensor's) to `to`, `length_m`
/// long, updating its cells from `start_m` on and leaving the last `stop_short` untouched.
pub(super) struct Walk {
    pub(super) from: (i64, i64),
    pub(super) to: (i64, i64),
    pub(super) length_m: f64,
    pub(super) start_m: f64,
    pub(super) stop_short: usize,
}

/// A [`Walk`] in Bresenham steps: `d` = (|dx|, -|dy|), `s` the signs, the steps it may take
/// (`stop_short` off its cells), metres per step, and the first step it updates (`start_m`).
struct WalkSteps {
    d: (i64, i64),
    s: (i64, i64),
    steps: i64,
    per_step: f64,
    first: i64,
}

impl Walk {
    fn steps(&self) -> WalkSteps {
        let (a, b) = (self.from, self.to);
        let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
        let cells = dx.max(-dy) + 1;
        let steps = (cells - self.stop_short as i64).max(0);
        let per_step = self.length_m / (cells - 1).max(1) as f64;
        let first = if self.start_m > 0.0 {
            ((self.start_m / per_step).ceil() as i64).min(steps)
        } else {
            0
        };
        WalkSteps {
            d: (dx, dy),
            s: ((b.0 - a.0).signum(), (b.1 - a.1).signum()),
            steps,
            per_step,
            first,
        }
    }
}

/// One step of the all-octant Bresenham loop (`d` = (|dx|, -|dy|), `s` the signs). Without
/// branches: on a slanted line which axis steps is as good as random, and the mispredicted
/// branches cost more than the free-space walk's memory accesses. [`walk_free`] takes the same
/// step on the cell's index instead of (x, y); this is the reference its tests step by.
#[cfg(test)]
fn bresenham_step(x: &mut i64, y: &mut i64, err: &mut i64, d: (i64, i64), s: (i64, i64)) {
    let e2 = 2 * *err;
    let (mx, my) = (i64::from(e2 >= d.1), i64::from(e2 <= d.0));
    *err += mx * d.1 + my * d.0;
    *x += mx * s.0;
    *y += my * s.1;
}

/// The Bresenham state (x, y, error) of the line `a` to `b` after `k` steps, in O(1): the step
/// along the major axis is taken every iteration, the other one `floor((2 minor k + major) / (2
/// major))` times in the first k (the integer form of rounding `k minor / major`).
fn bresenham_at(a: (i64, i64), b: (i64, i64), k: i64) -> (i64, i64, i64) {
    let (ax, ay) = ((b.0 - a.0).abs(), (b.1 - a.1).abs());
    let (sx, sy) = ((b.0 - a.0).signum(), (b.1 - a.1).signum());
    let (nx, ny) = if ax >= ay {
        (k, (2 * ay * k + ax) / (2 * ax).max(1))
    } else {
        ((2 * ax * k + ay) / (2 * ay), k)
    };
    // The loop's error term is ax (y steps + 1) - ay (x steps + 1).
    (a.0 + sx * nx, a.1 + sy * ny, ax * (ny + 1) - ay * (nx + 1))
}

/// Bresenham walk along `walk` adding `l_free(distance from the sensor)` to each cell from
/// `walk.start_m` on, stopping at the window's edge or at the first known cell with p >= 0.5 for
/// which `stops(index, distance)` holds (other occupied cells are lowered and passed). Notes in
/// `touched.1` every cell it lowers from above `touched.0` or from unknown. Returns the cells
/// updated and the distance reached.
///
/// The hot loop of the mapping, trimmed as the module's documentation says: the same cells,
/// increments and order as `walk_free_plain`, so the maps are the same bit for bit.
pub(super) fn walk_free(
    data: &mut [f32],
    (w, h): (i64, i64),
    walk: &Walk,
    l_free: impl Fn(f64) -> f32,
    l_max: f32,
    mut stops: impl FnMut(usize, f64) -> bool,
    touched: (f32, &mut TouchedCells),
) -> (usize, f64) {
    let (watch, touched) = touched;
    let (a, b) = (walk.from, walk.to);
    let WalkSteps {
        d: (dx, dy),
        s: (sx, sy),
        steps,
        per_step,
        first,
    } = walk.steps();
    if first >= steps {
        return (0, per_step * steps as f64);
    }
    let inside = |(x, y, _): (i64, i64, i64)| x >= 0 && y >= 0 && x < w && y < h;
    let start = bresenham_at(a, b, first);
    if !inside(start) {
        return (0, per_step * first as f64);
    }
    // The first step outside the window (or `steps`): inside is a prefix of the walk from here.
    let end = if inside(bresenham_at(a, b, steps - 1)) {
        steps
    } else {
        let (mut lo, mut hi) = (first, steps - 1); // lo inside, hi outside
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if inside(bresenham_at(a, b, mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    };
    // The common cell is known free and not above `watch`: one comparison (NaN fails it) and
    // the update; anything else takes the full path. The cell's index is stepped along with the
    // line's error term, x and y are not needed.
    let fast_below = watch.min(-f32::MIN_POSITIVE);
    let (x, y, mut err) = start;
    let mut i = y * w + x;
    let (di_x, di_y) = (sx, sy * w);
    let mut step = first;
    while step < end {
        // The increment changes only a few times along a walk: recomputed every 8 cells.
        let delta = l_free(per_step * step as f64);
        let chunk_end = (step + 8).min(end);
        while step < chunk_end {
            let v = &mut data[i as usize];
            if *v <= fast_below {
                *v = (*v + delta).max(-l_max);
            } else {
                // p >= 0.5 (NaN, unknown, compares false)
                if *v >= 0.0 && stops(i as usize, per_step * step as f64) {
                    return ((step - first) as usize, per_step * step as f64);
                }
                if v.is_nan() || *v > watch {
                    touched.note(i as u32); // may have been an obstacle (NaN: unknown, the prior's)
                }
                let cur = if v.is_nan() { 0.0 } else { *v };
                *v = (cur + delta).max(-l_max);
            }
            let e2 = 2 * err;
            let (mx, my) = (i64::from(e2 >= dy), i64::from(e2 <= dx));
            err += mx * dy + my * dx;
            i += mx * di_x + my * di_y;
            step += 1;
        }
    }
    ((end - first) as usize, per_step * end as f64)
}

/// [`walk_free`] the plain way: one step at a time, the window's edge tested at every step.
#[cfg(test)]
fn walk_free_plain(
    data: &mut [f32],
    (w, h): (i64, i64),
    walk: &Walk,
    l_free: impl Fn(f64) -> f32,
    l_max: f32,
    mut stops: impl FnMut(usize, f64) -> bool,
    touched: (f32, &mut TouchedCells),
) -> (usize, f64) {
    let (watch, touched) = touched;
    let (a, b) = (walk.from, walk.to);
    let WalkSteps {
        d: (dx, dy),
        s: (sx, sy),
        steps,
        per_step,
        first,
    } = walk.steps();
    let (mut x, mut y, mut err) = bresenham_at(a, b, first);
    let mut updated = 0;
    let mut delta = 0.0;
    for step in first..steps {
        let r = per_step * step as f64;
        if x < 0 || y < 0 || x >= w || y >= h {
            return (updated, r);
        }
        if (step - first) & 7 == 0 {
            delta = l_free(r);
        }
        let i = (y * w + x) as usize;
        let v = &mut data[i];
        if *v >= 0.0 && stops(i, r) {
            return (updated, r);
        }
        if v.is_nan() || *v > watch {
            touched.note(i as u32);
        }
        let cur = if v.is_nan() { 0.0 } else { *v };
        *v = (cur + delta).max(-l_max);
        updated += 1;
        bresenham_step(&mut x, &mut y, &mut err, (dx, dy), (sx, sy));
    }
    (updated, per_step * steps as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trimmed free-space walk updates the same cells by the same amounts, notes the same
    /// touched cells and stops where the plain per-step loop does: walks from inside and outside
    /// a small window, leaving it on every side, stopped by occupied cells, from a start range on.
    #[test]
    fn the_trimmed_walk_equals_the_plain_one() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(11);
        let (w, h) = (23i64, 17i64);
        let (mut exits, mut stopped, mut complete) = (0, 0, 0);
        for _ in 0..20_000 {
            let cells: Vec<f32> = (0..w * h)
                .map(|_| match rng.random_range(0..10) {
                    0 => f32::NAN,
                    1 => rng.random_range(0.0..4.0),
                    _ => rng.random_range(-4.0..0.0),
                })
                .collect();
            let from = (rng.random_range(-3..w + 3), rng.random_range(-3..h + 3));
            let to = if rng.random_bool(0.5) {
                (rng.random_range(0..w), rng.random_range(0..h))
            } else {
                (rng.random_range(-30..w + 30), rng.random_range(-30..h + 30))
            };
            let length_m = 0.2 * ((to.0 - from.0) as f64).hypot((to.1 - from.1) as f64);
            let walk = Walk {
                from,
                to,
                length_m,
                start_m: [0.0, 0.0, rng.random_range(0.0..length_m.max(0.1))]
                    [rng.random_range(0..3)],
                stop_short: rng.random_range(0..3),
            };
            let stop_every = rng.random_range(1..4usize);
            let l_free = |r: f64| -0.4 * (1.0 + (r * 1.7).floor() as f32);
            let run = |trimmed: bool| {
                let mut data = cells.clone();
                let mut touched = TouchedCells::default();
                let mut asked = Vec::new();
                let stops = |i: usize, r: f64| {
                    asked.push((i, r.to_bits()));
                    i.is_multiple_of(stop_every)
                };
                let out = if trimmed {
                    walk_free(
                        &mut data,
                        (w, h),
                        &walk,
                        l_free,
                        4.0,
                        stops,
                        (1.0, &mut touched),
                    )
                } else {
                    walk_free_plain(
                        &mut data,
                        (w, h),
                        &walk,
                        l_free,
                        4.0,
                        stops,
                        (1.0, &mut touched),
                    )
                };
                (
                    out.0,
                    out.1.to_bits(),
                    data.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    touched.cells,
                    asked,
                )
            };
            let (plain, trimmed) = (run(false), run(true));
            assert_eq!(
                trimmed, plain,
                "{:?} to {:?}, start {} m, {} short",
                walk.from, walk.to, walk.start_m, walk.stop_short
            );
            // Where it ended: stopped by a cell, at the window's edge, or at its last cell.
            let cells = (to.0 - from.0).abs().max((to.1 - from.1).abs()) + 1;
            let steps = (cells - walk.stop_short as i64).max(0);
            let per_step = walk.length_m / (cells - 1).max(1) as f64;
            if per_step == 0.0 {
                continue; // a line of one cell: every step is at 0 m
            }
            let reached = (f64::from_bits(plain.1) / per_step).round() as i64;
            let at = bresenham_at(from, to, reached);
            if plain
                .4
                .last()
                .is_some_and(|&(i, r)| r == plain.1 && i.is_multiple_of(stop_every))
            {
                stopped += 1;
            } else if reached < steps && (at.0 < 0 || at.1 < 0 || at.0 >= w || at.1 >= h) {
                exits += 1;
            } else {
                assert_eq!(
                    reached, steps,
                    "{:?} to {:?} ended early",
                    walk.from, walk.to
                );
                complete += 1;
            }
        }
        assert!(
            exits > 2_000 && stopped > 2_000 && complete > 2_000,
            "{exits} left the window, {stopped} stopped, {complete} ran to their end"
        );
    }

    /// The O(1) jump into a Bresenham line lands where stepping from its start does.
    #[test]
    fn bresenham_jumps_land_on_the_stepped_line() {
        let mut lines = 0;
        for (bx, by) in (-13..=13).flat_map(|x| (-13..=13).map(move |y| (x, y))) {
            let (a, b): ((i64, i64), (i64, i64)) = ((3, -2), (3 + bx, -2 + by));
            let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
            let (sx, sy) = ((b.0 - a.0).signum(), (b.1 - a.1).signum());
            let (mut x, mut y, mut err) = (a.0, a.1, dx + dy);
            for k in 0..=dx.max(-dy) {
                assert_eq!(
                    bresenham_at(a, b, k),
                    (x, y, err),
                    "{a:?} to {b:?}, step {k}"
                );
                bresenham_step(&mut x, &mut y, &mut err, (dx, dy), (sx, sy));
            }
            lines += 1;
        }
        assert_eq!(lines, 27 * 27);
    }
}
