//! The vehicle's odometry as its sensors report it: the wheel speed and the steering angle with
//! seeded white noise and a constant bias (a speed scale error, a steering offset), published at
//! every physics step. The driver dead-reckons on it and the particle filter moves its particles
//! with it.

use autonomy::Odometry;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

/// The odometry's error model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OdometryConfig {
    /// Standard deviation of the white noise on the speed, m/s. Default 0.02.
    pub speed_sigma_m_s: f64,
    /// The reported speed is the true one times `1 + speed_scale_bias` (a wheel radius off).
    /// Default 0.01.
    pub speed_scale_bias: f64,
    /// Standard deviation of the white noise on the steering angle, radians. Default 0.002.
    pub steering_sigma_rad: f64,
    /// Constant offset of the reported steering angle, radians. Default 0.002.
    pub steering_bias_rad: f64,
}

impl Default for OdometryConfig {
    fn default() -> Self {
        OdometryConfig {
            speed_sigma_m_s: 0.02,
            speed_scale_bias: 0.01,
            steering_sigma_rad: 0.002,
            steering_bias_rad: 0.002,
        }
    }
}

impl OdometryConfig {
    /// No noise and no bias: the true speed and steering.
    pub fn exact() -> Self {
        OdometryConfig {
            speed_sigma_m_s: 0.0,
            speed_scale_bias: 0.0,
            steering_sigma_rad: 0.0,
            steering_bias_rad: 0.0,
        }
    }

    /// Checks every field, naming the first wrong one.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v, min) in [
            ("odometry.speed_sigma_m_s", self.speed_sigma_m_s, 0.0),
            ("odometry.steering_sigma_rad", self.steering_sigma_rad, 0.0),
            ("odometry.speed_scale_bias", self.speed_scale_bias, -0.5),
            ("odometry.steering_bias_rad", self.steering_bias_rad, -0.2),
        ] {
            if !(v.is_finite() && v >= min) {
                return Err(format!("{name} = {v}: must be finite and >= {min}"));
            }
        }
        if self.speed_scale_bias > 0.5 || self.steering_bias_rad > 0.2 {
            return Err(format!(
                "odometry: a speed scale bias of {} or a steering bias of {} rad is not an \
                 odometry error (at most 0.5 and 0.2)",
                self.speed_scale_bias, self.steering_bias_rad
            ));
        }
        Ok(())
    }
}

/// The odometry sensor: reports the true motion through the error model, seeded.
pub struct OdometrySensor {
    config: OdometryConfig,
    rng: rand::rngs::Xoshiro256PlusPlus,
}

impl OdometrySensor {
    /// A sensor with `config`, its noise seeded from `seed`.
    pub fn new(config: OdometryConfig, seed: u64) -> Self {
        OdometrySensor {
            config,
            rng: rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x0D0_3E7E5),
        }
    }

    /// What the sensors report at `t_s` of a true speed and steering angle.
    pub fn measure(&mut self, t_s: f64, speed_m_s: f64, steering_rad: f64) -> Odometry {
        let c = &self.config;
        let (n1, n2): (f64, f64) = (
            self.rng.sample(StandardNormal),
            self.rng.sample(StandardNormal),
        );
        let speed = if speed_m_s == 0.0 {
            // Standing wheels turn no encoder: a stopped vehicle reads 0.
            0.0
        } else {
            speed_m_s * (1.0 + c.speed_scale_bias) + c.speed_sigma_m_s * n1
        };
        Odometry {
            t_s,
            speed_m_s: speed,
            steering_rad: steering_rad + c.steering_bias_rad + c.steering_sigma_rad * n2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bias_and_noise_have_their_size() {
        let mut s = OdometrySensor::new(OdometryConfig::default(), 1);
        let n = 100_000;
        let r: Vec<Odometry> = (0..n).map(|k| s.measure(k as f64, 2.0, 0.1)).collect();
        let mean = |f: &dyn Fn(&Odometry) -> f64| r.iter().map(f).sum::<f64>() / n as f64;
        let ms = mean(&|o| o.speed_m_s);
        let sd = mean(&|o| (o.speed_m_s - ms).powi(2)).sqrt();
        assert!((ms - 2.02).abs() < 0.001, "mean speed {ms}");
        assert!((sd - 0.02).abs() < 0.001, "speed sd {sd}");
        let mst = mean(&|o| o.steering_rad);
        assert!((mst - 0.102).abs() < 0.0001, "mean steering {mst}");
    }

    #[test]
    fn exact_odometry_is_the_truth_and_a_stopped_vehicle_reads_zero() {
        let mut s = OdometrySensor::new(OdometryConfig::exact(), 1);
        let o = s.measure(1.0, 3.0, -0.2);
        assert_eq!((o.speed_m_s, o.steering_rad), (3.0, -0.2));
        let mut s = OdometrySensor::new(OdometryConfig::default(), 1);
        assert_eq!(s.measure(1.0, 0.0, 0.0).speed_m_s, 0.0);
    }

    #[test]
    fn a_scale_bias_beyond_half_is_refused_naming_the_field() {
        let c = OdometryConfig {
            speed_scale_bias: 0.9,
            ..Default::default()
        };
        let e = c.validate().unwrap_err();
        assert!(e.contains("speed scale bias of 0.9"), "{e}");
    }
}
