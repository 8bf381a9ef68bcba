//! Samplers: which point of the unit cube each sample is drawn at. `grid` (every combination of
//! levels), `random` (independent uniform draws), `halton` (a low-discrepancy sequence with a
//! seeded shift) and `falsify`, a cross-entropy search: samples come in generations, the first
//! uniform, each next one drawn from per-dimension distributions (a truncated normal on [0, 1]
//! for a continuous variation, category weights for a discrete one) fitted to the lowest-scoring
//! runs so far - toward the smallest clearance, contacts and unmet expectations. Every point is
//! a pure function of (campaign seed, sample index, and for `falsify` the scores of the earlier
//! generations).

use rand::rngs::StdRng;
use rand::{RngExt as _, SeedableRng as _};
use serde::{Deserialize, Serialize};

use super::dist::{Continuous, Dimension};

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

/// The search distribution of one dimension.
#[derive(Clone, Debug, PartialEq)]
pub enum Proposal {
    /// A normal truncated to [0, 1]; `None`: uniform (the first generation).
    Continuous(Option<(f64, f64)>),
    /// Category weights (summing to 1).
    Discrete(Vec<f64>),
}

/// Smallest standard deviation of a continuous proposal, on [0, 1].
const MIN_SD: f64 = 0.03;
/// Smallest weight of a category: no category is ever ruled out.
const MIN_WEIGHT: f64 = 0.02;

/// The first generation's proposals: uniform.
pub fn initial(dims: &[Dimension]) -> Vec<Proposal> {
    dims.iter()
        .map(|d| match d.categories {
            Some(c) => Proposal::Discrete(vec![1.0 / c as f64; c]),
            None => Proposal::Continuous(None),
        })
        .collect()
}

/// The next proposals: each dimension fitted to the elite points, blended with the previous by
/// `smoothing` (the new fit's weight).
pub fn refit(previous: &[Proposal], elites: &[&[f64]], smoothing: f64) -> Vec<Proposal> {
    if elites.is_empty() {
        return previous.to_vec();
    }
    let n = elites.len() as f64;
    previous
        .iter()
        .enumerate()
        .map(|(d, p)| match p {
            Proposal::Continuous(old) => {
                let mean = elites.iter().map(|u| u[d]).sum::<f64>() / n;
                let var = elites.iter().map(|u| (u[d] - mean).powi(2)).sum::<f64>() / n;
                let (m0, s0) = old.unwrap_or((0.5, 1.0 / 12f64.sqrt()));
                let m = smoothing * mean + (1.0 - smoothing) * m0;
                let s = smoothing * var.sqrt() + (1.0 - smoothing) * s0;
                Proposal::Continuous(Some((m, s.max(MIN_SD))))
            }
            Proposal::Discrete(w) => {
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
                Proposal::Discrete(blended.iter().map(|w| w / total).collect())
            }
        })
        .collect()
}

/// A point drawn from `proposals` for sample `sample`.
pub fn propose(proposals: &[Proposal], seed: u64, sample: u64) -> Vec<f64> {
    let mut rng = rng_of(seed, sample);
    proposals
        .iter()
        .map(|p| {
            let (a, b): (f64, f64) = (rng.random(), rng.random());
            match p {
                Proposal::Continuous(None) => a,
                Proposal::Continuous(Some((mean, sd))) => {
                    let dist = Continuous::Normal {
                        mean: mean.clamp(0.0, 1.0),
                        sd: *sd,
                        min: 0.0,
                        max: 1.0,
                    };
                    dist.at(a).min(1.0 - 1e-12)
                }
                Proposal::Discrete(w) => {
                    let mut acc = 0.0;
                    let k = w
                        .iter()
                        .position(|w| {
                            acc += w;
                            a < acc
                        })
                        .unwrap_or(w.len() - 1);
                    (k as f64 + b) / w.len() as f64
                }
            }
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
    fn refit_moves_toward_the_elites() {
        let d = dims(&[None, Some(4)]);
        let p0 = initial(&d);
        let elites: Vec<Vec<f64>> = (0..10).map(|i| vec![0.9 + 0.005 * i as f64, 0.1]).collect();
        let refs: Vec<&[f64]> = elites.iter().map(Vec::as_slice).collect();
        let p1 = refit(&p0, &refs, 0.7);
        let Proposal::Continuous(Some((m, s))) = p1[0] else {
            panic!()
        };
        assert!(
            (m - (0.7 * 0.9225 + 0.3 * 0.5)).abs() < 1e-9 && s >= MIN_SD,
            "{m} {s}"
        );
        let Proposal::Discrete(w) = &p1[1] else {
            panic!()
        };
        assert!(
            w[0] > 0.7 && w[1..].iter().all(|&x| x >= MIN_WEIGHT / 1.1),
            "{w:?}"
        );
        // Draws follow: most land near the elites.
        let near = (0..200)
            .filter(|&i| {
                let u = propose(&p1, 3, i);
                u[1] < 0.25 && u[0] > 0.5
            })
            .count();
        assert!(near > 120, "{near} of 200");
    }
}
