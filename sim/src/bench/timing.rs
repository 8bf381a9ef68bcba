//! The timing helpers every benchmark shares: a [`Figure`] (median, unit, baseline, ratio,
//! target), the median of samples, timed batches, and two things timed in alternation (this
//! machine's speed drifts by 10-40 %: only alternation compares like with like).

use std::time::Instant;

use serde::Serialize;

/// The median of `v` (sorted in place; NaN when empty).
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

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
    median(&mut times)
}

/// A figure of `seconds` in `unit` (`ms` or `ns`).
pub fn figure(
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

/// `f` compared with `baseline` (the ratio: > 1 when `f` is faster).
pub fn against(mut f: Figure, baseline: &Figure) -> Figure {
    f.baseline = Some(baseline.name.clone());
    f.ratio = Some(baseline.median / f.median);
    f
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
    (median(&mut ta), median(&mut tb))
}
