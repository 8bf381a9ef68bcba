//! The measurement update's weighing: each particle's log-likelihood of a revolution over the
//! localization map (the tables, point-major over blocks of particles; in parallel; and the
//! straightforward way, for comparison).

use mapper::RemissionCell;
use nalgebra::{Isometry2, Point2, Vector2};
use rayon::prelude::*;

use super::{LocalizationMap, LocalizerConfig, MeasurementModel, Observation, Particle};

/// Each particle's log-likelihood of `obs` over `lmap`. Point-major over blocks of particles:
/// the particles of a block stand within a few cells of each other, so one return placed from
/// each of them reads the same few cache lines of the tables (particle-major, each particle
/// would sweep the whole window on its own). One thread: in the closed loop the other cores
/// are mapping, so the blocks run one after the other; [`weigh_parallel`] is the parallel form
/// `taxi-sim bench localization` measures against it. Equal to [`weigh_straightforward`] to
/// rounding (`the_tables_weigh_like_the_straightforward_way`).
pub fn weigh(
    particles: &[Particle],
    obs: &Observation,
    lmap: &LocalizationMap,
    config: &LocalizerConfig,
) -> Vec<f64> {
    let mut out = vec![0.0; particles.len()];
    for (out, block) in out
        .chunks_mut(PARTICLE_BLOCK)
        .zip(particles.chunks(PARTICLE_BLOCK))
    {
        weigh_block(block, obs, lmap, config, out);
    }
    out
}

/// [`weigh`] with the blocks in parallel (measured against it by `taxi-sim bench
/// localization`).
pub fn weigh_parallel(
    particles: &[Particle],
    obs: &Observation,
    lmap: &LocalizationMap,
    config: &LocalizerConfig,
) -> Vec<f64> {
    let mut out = vec![0.0; particles.len()];
    out.par_chunks_mut(PARTICLE_BLOCK)
        .zip(particles.par_chunks(PARTICLE_BLOCK))
        .for_each(|(out, block)| weigh_block(block, obs, lmap, config, out));
    out
}

/// Particles weighed together, point by point.
const PARTICLE_BLOCK: usize = 32;

/// [`weigh`] of one block of particles into `out`.
fn weigh_block(
    block: &[Particle],
    obs: &Observation,
    lmap: &LocalizationMap,
    config: &LocalizerConfig,
    out: &mut [f64],
) {
    let g = &lmap.geometry;
    let (w, h) = (g.width(), g.height());
    let (wf, hf) = (w as f64, h as f64);
    let origin = g.origin_m();
    let inv = 1.0 / g.resolution_m();
    let floor = config.floor();
    let unknown = (-0.5 * config.remission_unknown_sigmas * config.remission_unknown_sigmas) as f32;
    let poses: Vec<(f64, f64, f64, f64)> = block
        .iter()
        .map(|p| {
            let (s, c) = p.theta.sin_cos();
            (c, s, p.x, p.y)
        })
        .collect();
    // The cell `GridGeometry::cell_coords` gives, without its NaN and sign handling: a
    // coordinate in [0, w) truncates to its floor, and NaN fails the comparisons.
    let index = |&(c, s, x, y): &(f64, f64, f64, f64), px: f64, py: f64| -> Option<usize> {
        let fx = ((c * px - s * py + x) - origin.x) * inv;
        let fy = ((s * px + c * py + y) - origin.y) * inv;
        (fx >= 0.0 && fy >= 0.0 && fx < wf && fy < hf).then(|| fy as usize * w + fx as usize)
    };
    let mut sums = vec![0.0f32; block.len()];
    if config.measurement != MeasurementModel::LikelihoodField {
        for &[px, py, intensity] in &obs.ground {
            for (sum, pose) in sums.iter_mut().zip(&poses) {
                *sum += match index(pose, px, py) {
                    Some(i) => {
                        let [mean, weight] = lmap.remission[i];
                        if mean.is_nan() {
                            unknown
                        } else {
                            let d = intensity as f32 - mean;
                            (weight * d * d).max(floor)
                        }
                    }
                    None => unknown,
                };
            }
        }
    }
    if config.measurement != MeasurementModel::Remission {
        for &[px, py] in &obs.obstacles {
            for (sum, pose) in sums.iter_mut().zip(&poses) {
                *sum += index(pose, px, py).map_or(floor, |i| lmap.field[i]);
            }
        }
    }
    for (o, s) in out.iter_mut().zip(sums) {
        *o = f64::from(s) * config.likelihood_weight;
    }
}

/// The straightforward measurement update, for comparison: one particle at a time, each return
/// through the particle's `Isometry2`, the map's `Option` lookups, the cell's mean and variance
/// computed from its sums and the likelihood field's Gaussian evaluated at each lookup.
pub fn weigh_straightforward(
    particles: &[Particle],
    obs: &Observation,
    remission: &mapper::Grid<RemissionCell>,
    field: Option<&mapper::DistanceMap>,
    config: &LocalizerConfig,
) -> Vec<f64> {
    let floor = f64::from(config.floor());
    let unknown = -0.5 * config.remission_unknown_sigmas * config.remission_unknown_sigmas;
    let floor2 = config.remission_sigma_floor * config.remission_sigma_floor;

    particles
        .iter()
        .map(|p| {
            let pose = Isometry2::new(Vector2::new(p.x, p.y), p.theta);
            let mut sum = 0.0;
            if config.measurement != MeasurementModel::LikelihoodField {
                for &[px, py, intensity] in &obs.ground {
                    let at = pose * Point2::new(px, py);
                    sum += match remission
                        .at(&at)
                        .and_then(|c| Some((c.mean()?, c.variance()?)))
                    {
                        Some((mean, var)) => {
                            let d = intensity - f64::from(mean);
                            (-0.5 * d * d / (f64::from(var) + floor2)).max(floor)
                        }
                        None => unknown,
                    };
                }
            }
            if config.measurement != MeasurementModel::Remission {
                for &[px, py] in &obs.obstacles {
                    let at = pose * Point2::new(px, py);
                    sum += match (field, remission.geometry().contains(&at)) {
                        (Some(f), true) => {
                            let d = f64::from(f.distance_at(&at)) / config.field_sigma_m;
                            (-0.5 * d * d).max(floor)
                        }
                        _ => floor,
                    };
                }
            }
            sum * config.likelihood_weight
        })
        .collect()
}
