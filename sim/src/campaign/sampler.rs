//! Samplers: which point of the unit cube each sample is drawn at. `grid` (every combination of
//! levels), `random` (independent uniform draws), `halton` (a low-discrepancy sequence with a
//! seeded shift) and `falsify`, a cross-entropy search: samples come in generations, the first
//! uniform, each next one drawn from per-dimension bin weights (ten bins of [0, 1) for a
//! continuous variation, a bin per category for a discrete one) fitted to the lowest-scoring
//! runs so far - toward the smallest clearance, contacts and unmet expectations. Every point is
//! a pure function of (campaign seed, sample index, and for `falsify` the scores of the earlier
//! generations).

use rand::rngs::StdRng;
use rand::{RngExt as _, SeedableRng as _};
use serde::{Deserialize, Serialize};

use super::dist::Dimension;

/// How samples are chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SamplerKind {
    /// Every combination of levels (`grid_steps` for a continuous variation, every category for
    /// a discrete one), in order.
    Grid,
    /// Independent uniform draws.
    #[default]
    Random,
    /// The Halton sequence (bases 2, 3, 5, ...), shifted by the seed.
    Halton,
    /// Cross-entropy search toward failures.
    Falsify,
}

impl SamplerKind {
    /// The name used in files.
    pub fn as_str(self) -> &'static str {
        match self {
            SamplerKind::Grid => "grid",
            SamplerKind::Random => "random",
            SamplerKind::Halton => "halton",
            SamplerKind::Falsify => "falsify",
        }
    }
}

/// The random stream of one sample: the campaign seed and the index mixed (SplitMix64), so
/// neighbouring indices are unrelated.
pub fn rng_of(seed: u64, sample: u64) -> StdRng {
    let mut z = seed ^ sample.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    StdRng::seed_from_u64(z ^ (z >> 31))
}

/// Levels of a dimension on the grid.
fn levels(d: &Dimension, steps: u32) -> u64 {
    d.categories.map_or(steps as u64, |c| c as u64)
}

/// Points on the grid: the product of every dimension's levels (saturating).
pub fn grid_size(dims: &[Dimension], steps: u32) -> u64 {
    dims.iter()
        .fold(1u64, |n, d| n.saturating_mul(levels(d, steps)))
}

/// Grid point `sample` (mixed radix, the first dimension fastest), at the centre of its cell.
pub fn grid_point(dims: &[Dimension], steps: u32, sample: u64) -> Vec<f64> {
    let mut rest = sample;
    dims.iter()
        .map(|d| {
            let n = levels(d, steps);
            let k = rest % n;
            rest /= n;
            (k as f64 + 0.5) / n as f64
        })
        .collect()
}

/// Uniform point of sample `sample`.
pub fn random_point(dims: usize, seed: u64, sample: u64) -> Vec<f64> {
    let mut rng = rng_of(seed, sample);
    (0..dims).map(|_| rng.random::<f64>()).collect()
}

/// The first `n` primes.
fn primes(n: usize) -> Vec<u64> {
    let mut p: Vec<u64> = Vec::with_capacity(n);
    let mut k = 2;
    while p.len() < n {
        if p.iter().take_while(|&&q| q * q <= k).all(|&q| k % q != 0) {
            p.push(k);
        }
        k += 1;
    }
    p
}

/// The radical inverse of `i` in base `b`.
fn radical_inverse(mut i: u64, b: u64) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// Halton point of sample `sample` (the sequence from its second point), each coordinate
/// shifted modulo 1 by a draw of the seed (a Cranley-Patterson rotation).
pub fn halton_point(dims: usize, seed: u64, sample: u64) -> Vec<f64> {
    let shift = random_point(dims, seed, u64::MAX);
    primes(dims)
        .iter()
        .zip(shift)
        .map(|(&b, s)| (radical_inverse(sample + 1, b) + s).fract())
        .collect()
}

/// The search distribution of one dimension: weights of equal bins of [0, 1) (a discrete
/// variation's categories when it has at most [`MAX_BINS`], else [`BINS`] bins), drawn
/// uniformly within the bin. Bins, not a normal: what fails is often in two places at once
/// (debris under the left or the right wheels, not between them), which one bell cannot hold.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposal(pub Vec<f64>);

/// Bins of a continuous variation.
pub const BINS: usize = 10;
/// Most categories given a bin each.
pub const MAX_BINS: usize = 20;
/// Smallest weight of a bin, before normalising: no part of a variation is ever ruled out.
const MIN_WEIGHT: f64 = 0.02;

fn bins_of(d: &Dimension) -> usize {
    match d.categories {
        Some(c) if c <= MAX_BINS => c,
        _ => BINS,
    }
}

/// The first generation's proposals: uniform.
pub fn initial(dims: &[Dimension]) -> Vec<Proposal> {
    dims.iter()
        .map(|d| Proposal(vec![1.0 / bins_of(d) as f64; bins_of(d)]))
        .collect()
}

/// The next proposals: each dimension's bin weights fitted to the elite points, blended with
/// the previous by `smoothing` (the new fit's weight), floored, normalised.
pub fn refit(previous: &[Proposal], elites: &[&[f64]], smoothing: f64) -> Vec<Proposal> {
    if elites.is_empty() {
        return previous.to_vec();
    }
    let n = elites.len() as f64;
    previous
        .iter()
        .enumerate()
        .map(|(d, Proposal(w))| {
            let k = w.len();
            let mut counts = vec![0.0; k];
            for u in elites {
                counts[((u[d] * k as f64).floor() as usize).min(k - 1)] += 1.0;
            }
            let blended: Vec<f64> = w
                .iter()
                .zip(&counts)
                .map(|(w, c)| (smoothing * c / n + (1.0 - smoothing) * w).max(MIN_WEIGHT))
                .collect();
            let total: f64 = blended.iter().sum();
            Proposal(blended.iter().map(|w| w / total).collect())
        })
        .collect()
}

/// A point drawn from `proposals` for sample `sample`.
pub fn propose(proposals: &[Proposal], seed: u64, sample: u64) -> Vec<f64> {
    let mut rng = rng_of(seed, sample);
    proposals
        .iter()
        .map(|Proposal(w)| {
            let (a, b): (f64, f64) = (rng.random(), rng.random());
            let mut acc = 0.0;
            let k = w
                .iter()
                .position(|w| {
                    acc += w;
                    a < acc
                })
                .unwrap_or(w.len() - 1);
            ((k as f64 + b) / w.len() as f64).min(1.0 - 1e-12)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dims(cats: &[Option<usize>]) -> Vec<Dimension> {
        cats.iter()
            .map(|&categories| Dimension {
                label: String::new(),
                categories,
            })
            .collect()
    }

    #[test]
    fn grid_visits_every_cell_once() {
        let d = dims(&[None, Some(2)]);
        assert_eq!(grid_size(&d, 3), 6);
        let mut seen: Vec<Vec<f64>> = (0..6).map(|i| grid_point(&d, 3, i)).collect();
        seen.sort_by(|a, b| a.partial_cmp(b).unwrap());
        seen.dedup();
        assert_eq!(seen.len(), 6);
        assert_eq!(grid_point(&d, 3, 4), vec![1.5 / 3.0, 0.75]);
    }

    #[test]
    fn halton_is_more_even_than_random() {
        // The largest empty gap of 64 points on [0, 1) in the first coordinate.
        let gap = |pts: Vec<f64>| {
            let mut p = pts;
            p.sort_by(f64::total_cmp);
            let inner = p.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
            inner.max(p[0] + 1.0 - p[p.len() - 1])
        };
        let h = gap((0..64).map(|i| halton_point(2, 7, i)[0]).collect());
        let r = gap((0..64).map(|i| random_point(2, 7, i)[0]).collect());
        assert!(h <= 1.0 / 32.0 + 1e-12, "halton gap {h}");
        assert!(r > h, "random gap {r} vs halton {h}");
    }

    #[test]
    fn refit_moves_toward_the_elites_in_two_places_at_once() {
        let d = dims(&[None, Some(4)]);
        let p0 = initial(&d);
        assert_eq!(p0[0].0.len(), BINS);
        // Elites in two places of the first dimension (bins 1 and 8), one category of the second.
        let elites: Vec<Vec<f64>> = (0..10)
            .map(|i| vec![if i % 2 == 0 { 0.15 } else { 0.85 }, 0.1])
            .collect();
        let refs: Vec<&[f64]> = elites.iter().map(Vec::as_slice).collect();
        let p1 = refit(&p0, &refs, 0.7);
        let w = &p1[0].0;
        let expected = (0.7 * 0.5 + 0.3 * 0.1) / (2.0 * 0.38 + 8.0 * 0.03);
        assert!(
            (w[1] - expected).abs() < 1e-9 && (w[8] - expected).abs() < 1e-9,
            "{w:?}"
        );
        assert!(w[4] < 0.05, "{w:?}");
        let c = &p1[1].0;
        assert!(c[0] > 0.7 && c[1..].iter().all(|&x| x > 0.0), "{c:?}");
        // Draws follow: most land in one of the two places, few between.
        let u: Vec<f64> = (0..400).map(|i| propose(&p1, 3, i)[0]).collect();
        let near = u
            .iter()
            .filter(|&&x| (0.1..0.2).contains(&x) || (0.8..0.9).contains(&x))
            .count();
        let between = u.iter().filter(|&&x| (0.4..0.6).contains(&x)).count();
        assert!(near > 280 && between < 40, "{near} near, {between} between");
    }
}
