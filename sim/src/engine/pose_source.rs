//! Pose sources: what stands between the world's true pose and the stack's pose estimate. The
//! truth; the truth with a seeded localizer-like error (Gauss-Markov drift plus white noise,
//! published at a localizer's rate); the particle filter over the offline map
//! (`autonomy::localizer`), started from a GNSS-like fix and fed the odometry and every
//! revolution.

use autonomy::localizer::{LocalizerConfig, Particle, ParticleFilter};
use autonomy::{LidarRevolution, Odometry, PoseEstimate};
use nalgebra::{Isometry2, Vector2};
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;

use crate::scenario::{NoisyTruthConfig, PoseSourceConfig};

/// Gives the stack its pose estimates. Called at every physics step with the true pose; returns
/// an estimate when one is published at that step.
pub trait PoseSource: Send {
    /// The estimate published at `t_s`, if any.
    fn publish(&mut self, t_s: f64, truth: &Isometry2<f64>) -> Option<PoseEstimate>;
    /// The vehicle was moved by the simulator to `truth` (a new lap of an open route): publish
    /// at the next step.
    fn reset(&mut self, _truth: &Isometry2<f64>) -> crate::error::Result<()> {
        Ok(())
    }
    /// The odometry of this physics step.
    fn on_odometry(&mut self, _odometry: &Odometry) {}
    /// A revolution as the stack receives it.
    fn on_revolution(&mut self, _revolution: &LidarRevolution) -> crate::error::Result<()> {
        Ok(())
    }
    /// The particles, when it has any (for the replay).
    fn particles(&self) -> Option<&[Particle]> {
        None
    }
}

/// What a particle filter is built from besides its configuration.
pub struct LocalizationContext<'a> {
    /// The offline map's block directory.
    pub blocks_dir: &'a std::path::Path,
    /// The offline map's configuration and levels.
    pub map: mapper::MapConfig,
    /// The levels.
    pub levels: mapper::Levels,
    /// The vehicle's wheelbase, metres.
    pub wheelbase_m: f64,
    /// The vehicle's self-hit filter model and margin.
    pub self_filter: mapper::CollisionModel,
    /// See `self_filter`.
    pub self_margin_m: f64,
    /// Where the vehicle starts.
    pub start: Isometry2<f64>,
}

/// The pose source a configuration asks for, seeded from the run's seed.
pub fn from_config(
    config: &PoseSourceConfig,
    seed: u64,
    context: LocalizationContext<'_>,
) -> crate::error::Result<Box<dyn PoseSource>> {
    Ok(match config {
        PoseSourceConfig::Truth => Box::new(Truth),
        PoseSourceConfig::NoisyTruth(c) => Box::new(NoisyTruth::new(c.clone(), seed)),
        PoseSourceConfig::ParticleFilter(c) => Box::new(Localizer::new(c.clone(), seed, context)?),
    })
}

/// The particle filter as a pose source: started from a fix (the truth plus the fix's seeded
/// error) at the start and after every move by the simulator; publishes its mean and covariance
/// at its rate.
pub struct Localizer {
    filter: ParticleFilter,
    rng: rand::rngs::Xoshiro256PlusPlus,
    self_filter: mapper::CollisionModel,
    self_margin_m: f64,
    last_t_s: Option<f64>,
}

impl Localizer {
    /// A filter over the offline map of `context`, initialised at a fix near its start.
    pub fn new(
        config: LocalizerConfig,
        seed: u64,
        context: LocalizationContext<'_>,
    ) -> crate::error::Result<Self> {
        let start = context.start.translation.vector;
        let map = mapper::MultiHeightMap::with_stores(
            context.map,
            context.levels,
            start.into(),
            Some(context.blocks_dir),
            None,
        )?;
        let filter = ParticleFilter::new(config, context.wheelbase_m, map, seed);
        let mut localizer = Localizer {
            filter,
            rng: rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x6E55_F1C5),
            self_filter: context.self_filter,
            self_margin_m: context.self_margin_m,
            last_t_s: None,
        };
        localizer.reset(&context.start)?;
        Ok(localizer)
    }

    /// The filter.
    pub fn filter(&self) -> &ParticleFilter {
        &self.filter
    }
}

impl PoseSource for Localizer {
    fn publish(&mut self, t_s: f64, _truth: &Isometry2<f64>) -> Option<PoseEstimate> {
        let period = 1.0 / self.filter.config().rate_hz;
        if self.last_t_s.is_some_and(|last| t_s - last < period - 5e-7) {
            return None;
        }
        self.last_t_s = Some(t_s);
        Some(self.filter.estimate().at(t_s))
    }

    fn reset(&mut self, truth: &Isometry2<f64>) -> crate::error::Result<()> {
        let c = self.filter.config();
        let (sm, sr) = (c.fix_sigma_m, c.fix_sigma_rad);
        let mut normal = || -> f64 { self.rng.sample(StandardNormal) };
        let fix = Isometry2::new(
            truth.translation.vector + Vector2::new(sm * normal(), sm * normal()),
            truth.rotation.angle() + sr * normal(),
        );
        self.filter.clear();
        self.filter.initialise(&fix)?;
        self.last_t_s = None;
        Ok(())
    }

    fn on_odometry(&mut self, odometry: &Odometry) {
        self.filter.on_odometry(odometry);
    }

    fn on_revolution(&mut self, revolution: &LidarRevolution) -> crate::error::Result<()> {
        self.filter
            .on_revolution(revolution, Some(&self.self_filter), self.self_margin_m)?;
        Ok(())
    }

    fn particles(&self) -> Option<&[Particle]> {
        Some(self.filter.particles())
    }
}

/// The true pose, at every step.
pub struct Truth;

impl PoseSource for Truth {
    fn publish(&mut self, t_s: f64, truth: &Isometry2<f64>) -> Option<PoseEstimate> {
        Some(PoseEstimate::exact(t_s, *truth))
    }
}

/// The true pose with an error `e = drift + white` in the vehicle frame (along track, across
/// track, heading), published every `1 / rate_hz`. The drift is a first-order Gauss-Markov
/// process, advanced exactly over the time since the last publication:
/// `drift <- a drift + sigma sqrt(1 - a^2) w`, `a = exp(-dt / tau)`, so its standard deviation
/// is `sigma` whatever the rate; the white part is drawn afresh at each publication.
pub struct NoisyTruth {
    config: NoisyTruthConfig,
    rng: rand::rngs::Xoshiro256PlusPlus,
    /// Drift: along, across (metres), heading (radians).
    drift: [f64; 3],
    last_t_s: Option<f64>,
}

impl NoisyTruth {
    /// A source with `config`, its draws seeded from `seed`; the drift starts from its
    /// stationary distribution.
    pub fn new(config: NoisyTruthConfig, seed: u64) -> Self {
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x005E_ED0F_u64);
        let mut normal = || -> f64 { rng.sample(StandardNormal) };
        let drift = [
            config.drift_sigma_m * normal(),
            config.drift_sigma_m * normal(),
            config.drift_sigma_rad * normal(),
        ];
        NoisyTruth {
            config,
            rng,
            drift,
            last_t_s: None,
        }
    }

    /// The drift now: along, across (metres), heading (radians).
    pub fn drift(&self) -> [f64; 3] {
        self.drift
    }
}

impl PoseSource for NoisyTruth {
    fn publish(&mut self, t_s: f64, truth: &Isometry2<f64>) -> Option<PoseEstimate> {
        let period = 1.0 / self.config.rate_hz;
        if let Some(last) = self.last_t_s {
            // Half a microsecond of slack: steps of 0.01 s do not add up exactly.
            if t_s - last < period - 5e-7 {
                return None;
            }
            let a = (-(t_s - last) / self.config.drift_time_constant_s).exp();
            let b = (1.0 - a * a).sqrt();
            let sigma = [
                self.config.drift_sigma_m,
                self.config.drift_sigma_m,
                self.config.drift_sigma_rad,
            ];
            for (d, s) in self.drift.iter_mut().zip(sigma) {
                let w: f64 = self.rng.sample(StandardNormal);
                *d = a * *d + s * b * w;
            }
        }
        self.last_t_s = Some(t_s);
        let mut white = [0.0; 3];
        for (k, w) in white.iter_mut().enumerate() {
            let sigma = if k < 2 {
                self.config.white_sigma_m
            } else {
                self.config.white_sigma_rad
            };
            let n: f64 = self.rng.sample(StandardNormal);
            *w = sigma * n;
        }
        let e = [
            self.drift[0] + white[0],
            self.drift[1] + white[1],
            self.drift[2] + white[2],
        ];
        let offset = truth.rotation * Vector2::new(e[0], e[1]);
        Some(PoseEstimate::exact(
            t_s,
            Isometry2::new(
                truth.translation.vector + offset,
                truth.rotation.angle() + e[2],
            ),
        ))
    }

    fn reset(&mut self, _truth: &Isometry2<f64>) -> crate::error::Result<()> {
        self.last_t_s = None;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(c: NoisyTruthConfig) -> NoisyTruth {
        NoisyTruth::new(c, 7)
    }

    #[test]
    fn noisy_truth_publishes_at_its_rate_not_the_physics_rate() {
        let mut s = source(NoisyTruthConfig {
            rate_hz: 20.0,
            ..Default::default()
        });
        let published = (0..100)
            .filter(|k| {
                s.publish(*k as f64 * 0.01, &Isometry2::identity())
                    .is_some()
            })
            .count();
        assert_eq!(published, 20, "1 s of 100 Hz steps at 20 Hz");
    }

    /// The drift's spread is its sigma and its correlation time is its tau, whatever the rate it
    /// is sampled at (the old white noise per 100 Hz step changed meaning with the rate).
    #[test]
    fn gauss_markov_drift_has_its_sigma_and_correlation_time_at_any_rate() {
        for rate in [10.0, 50.0] {
            let mut s = source(NoisyTruthConfig {
                rate_hz: rate,
                drift_sigma_m: 0.3,
                drift_time_constant_s: 2.0,
                ..Default::default()
            });
            let dt = 1.0 / rate;
            let xs: Vec<f64> = (0..200_000)
                .filter_map(|k| {
                    let t = k as f64 * dt;
                    s.publish(t, &Isometry2::identity())
                        .map(|e| e.world_from_vehicle.translation.x)
                })
                .collect();
            let n = xs.len() as f64;
            let var = xs.iter().map(|x| x * x).sum::<f64>() / n;
            assert!(
                (var.sqrt() - 0.3).abs() < 0.015,
                "rate {rate}: sd {}",
                var.sqrt()
            );
            // Autocorrelation at lag tau is exp(-1).
            let lag = (2.0 * rate) as usize;
            let c = xs.iter().zip(&xs[lag..]).map(|(a, b)| a * b).sum::<f64>()
                / (xs.len() - lag) as f64
                / var;
            assert!(
                (c - (-1.0f64).exp()).abs() < 0.05,
                "rate {rate}: rho(tau) {c}"
            );
        }
    }

    #[test]
    fn the_error_is_in_the_vehicle_frame() {
        let mut s = source(NoisyTruthConfig {
            rate_hz: 10.0,
            drift_sigma_m: 1.0,
            ..Default::default()
        });
        let [along, across, _] = s.drift();
        let truth = Isometry2::new(Vector2::new(5.0, 2.0), std::f64::consts::FRAC_PI_2);
        let e = s.publish(0.0, &truth).expect("first step publishes");
        let d = e.world_from_vehicle.translation.vector - truth.translation.vector;
        // Heading north: along track is +y, across (left) is -x.
        assert!((d.y - along).abs() < 1e-12 && (d.x + across).abs() < 1e-12);
    }

    #[test]
    fn the_same_seed_gives_the_same_estimates() {
        let c = NoisyTruthConfig {
            drift_sigma_m: 0.2,
            white_sigma_m: 0.05,
            white_sigma_rad: 0.01,
            ..Default::default()
        };
        let run = |seed| {
            let mut s = NoisyTruth::new(c.clone(), seed);
            (0..500)
                .filter_map(|k| s.publish(k as f64 * 0.01, &Isometry2::identity()))
                .map(|e| e.world_from_vehicle)
                .collect::<Vec<_>>()
        };
        assert_eq!(run(3), run(3));
        assert_ne!(run(3), run(4));
    }
}
