//! Diffusion and resampling: each update's noise and the particles' own odometry errors, the
//! low-variance sampler, and the weighted estimate of the particles.

use nalgebra::{Isometry2, Matrix3, Vector2};
use rand::RngExt;
use rand_distr::StandardNormal;

use super::{Estimate, Particle, ParticleFilter};
use crate::route::wrap_angle;

impl ParticleFilter {
    /// The per-update diffusion, and each particle's odometry errors until the next update.
    pub(super) fn diffuse(&mut self) {
        let c = &self.config;
        let d = self.travelled_m;
        let sp = c.diffusion_m + c.diffusion_per_m * d;
        let sh = c.diffusion_rad + 0.01 * d;
        let (ss, sst) = (c.speed_scale_sigma, c.steering_sigma_rad);
        let rng = &mut self.rng;
        for p in &mut self.particles {
            p.x += sp * normal(rng);
            p.y += sp * normal(rng);
            p.theta = wrap_angle(p.theta + sh * normal(rng));
            p.speed_scale = ss * normal(rng);
            p.steering_rad = sst * normal(rng);
        }
    }

    /// Low-variance (systematic) resampling: one uniform draw, particles taken at equal steps
    /// of the cumulative weight; the weights start equal again.
    pub(super) fn resample(&mut self) {
        let n = self.particles.len();
        let w: Vec<f64> = self.log_w.iter().map(|l| l.exp()).collect();
        let step = w.iter().sum::<f64>() / n as f64;
        let mut u = self.rng.random::<f64>() * step;
        let (mut i, mut cumulative) = (0, w[0]);
        let mut next = Vec::with_capacity(n);
        for _ in 0..n {
            while u > cumulative && i + 1 < n {
                i += 1;
                cumulative += w[i];
            }
            next.push(self.particles[i]);
            u += step;
        }
        self.particles = next;
        self.log_w.iter_mut().for_each(|l| *l = 0.0);
    }
}

/// A standard normal draw.
pub(super) fn normal(rng: &mut rand::rngs::Xoshiro256PlusPlus) -> f64 {
    rng.sample(StandardNormal)
}

/// Log-weights shifted so the largest is 0.
pub(super) fn normalise(log_w: &mut [f64]) {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max.is_finite() {
        log_w.iter_mut().for_each(|l| *l -= max);
    }
}

/// Effective sample size of log-weights: `(sum w)^2 / sum w^2`.
pub fn effective_size(log_w: &[f64]) -> f64 {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (s, s2) = log_w.iter().fold((0.0, 0.0), |(s, s2), l| {
        let w = (l - max).exp();
        (s + w, s2 + w * w)
    });
    if s2 > 0.0 { s * s / s2 } else { 0.0 }
}

/// The weighted mean and covariance of particles with log-weights `log_w`.
pub fn estimate_of(particles: &[Particle], log_w: &[f64]) -> Estimate {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = log_w.iter().map(|l| (l - max).exp()).collect();
    let total: f64 = w.iter().sum();
    if particles.is_empty() || total.is_nan() || total <= 0.0 {
        return Estimate {
            world_from_vehicle: Isometry2::identity(),
            covariance: Matrix3::from_diagonal_element(f64::INFINITY),
        };
    }
    let (mut mx, mut my, mut sc, mut ss) = (0.0, 0.0, 0.0, 0.0);
    for (p, w) in particles.iter().zip(&w) {
        mx += w * p.x;
        my += w * p.y;
        sc += w * p.theta.cos();
        ss += w * p.theta.sin();
    }
    let (mx, my, mt) = (mx / total, my / total, ss.atan2(sc));
    let mut cov = Matrix3::zeros();
    for (p, w) in particles.iter().zip(&w) {
        let e = nalgebra::Vector3::new(p.x - mx, p.y - my, wrap_angle(p.theta - mt));
        cov += (w / total) * e * e.transpose();
    }
    Estimate {
        world_from_vehicle: Isometry2::new(Vector2::new(mx, my), mt),
        covariance: cov,
    }
}
