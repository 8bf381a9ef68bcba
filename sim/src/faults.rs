//! Faults injected between the world and the stack under test: revolutions lost (singly or in
//! bursts), beams that drop out (at random, or dead for the whole run), extra range noise,
//! spurious returns (rain- or dust-like, near the sensor), and a pose estimate biased or drifting
//! beyond its source's own error. Every draw is seeded by the run's
//! seed and the revolution's index, so a run with faults is as reproducible as one without.

use mapper::{Return, Scan};
use nalgebra::{Point3, Vector3};
use rand::{RngExt as _, SeedableRng as _};
use serde::{Deserialize, Serialize};

/// The `[faults]` of a run configuration (or a scenario's `[config.faults]`). All off by default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FaultsConfig {
    /// Chance, per revolution, that a burst of lost revolutions starts there. Default 0.
    pub lost_revolution_probability: f64,
    /// Revolutions a burst loses (the first included). Default 1.
    pub lost_burst_revolutions: u32,
    /// Chance that a beam's return is lost, per return. Default 0.
    pub beam_dropout_probability: f64,
    /// Beams (0 = lowest) that never return. Default none.
    pub dead_beams: Vec<usize>,
    /// Standard deviation of Gaussian range noise added to every return, metres. Default 0.
    pub extra_range_noise_m: f64,
    /// Mean number of spurious returns a revolution (Poisson): points 1-15 m from the sensor in
    /// random columns and beams, where a raindrop or dust would answer. Default 0.
    pub spurious_returns_per_revolution: f64,
    /// A constant error of the pose estimate beyond the pose source's own, in the vehicle frame:
    /// `[along, across]` metres (positive: the estimate is ahead, left of the truth). Default 0.
    pub pose_bias_m: [f64; 2],
    /// A constant heading error of the estimate, radians. Default 0.
    pub pose_bias_rad: f64,
    /// An across-track error growing with time (a localizer drifting off), metres per second.
    /// Default 0.
    pub pose_drift_m_per_s: f64,
}

impl Default for FaultsConfig {
    fn default() -> Self {
        FaultsConfig {
            lost_revolution_probability: 0.0,
            lost_burst_revolutions: 1,
            beam_dropout_probability: 0.0,
            dead_beams: Vec::new(),
            extra_range_noise_m: 0.0,
            spurious_returns_per_revolution: 0.0,
            pose_bias_m: [0.0, 0.0],
            pose_bias_rad: 0.0,
            pose_drift_m_per_s: 0.0,
        }
    }
}

/// What the faults did in a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FaultCounts {
    /// Revolutions that never reached the stack.
    pub lost_revolutions: u64,
    /// Returns removed (dropout and dead beams).
    pub dropped_returns: u64,
    /// Spurious returns added.
    pub spurious_returns: u64,
    /// Times the stack's watchdog stopped the vehicle for want of a fresh revolution.
    pub watchdog_stops: u64,
}

impl FaultsConfig {
    /// Checks the values; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        for (field, p) in [
            (
                "faults.lost_revolution_probability",
                self.lost_revolution_probability,
            ),
            (
                "faults.beam_dropout_probability",
                self.beam_dropout_probability,
            ),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return Err(format!("{field} = {p}: must be a probability in [0, 1]"));
            }
        }
        if self.lost_burst_revolutions == 0 {
            return Err("faults.lost_burst_revolutions = 0: a burst loses at least one".into());
        }
        for (field, v) in [
            ("faults.extra_range_noise_m", self.extra_range_noise_m),
            (
                "faults.spurious_returns_per_revolution",
                self.spurious_returns_per_revolution,
            ),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{field} = {v}: must be a finite number >= 0"));
            }
        }
        Ok(())
    }

    /// Whether any fault is on.
    pub fn any(&self) -> bool {
        *self != FaultsConfig::default()
    }

    /// The pose estimate at `t_s` with the pose faults applied (`estimate` unchanged without).
    pub fn bias_pose(
        &self,
        t_s: f64,
        estimate: &nalgebra::Isometry2<f64>,
    ) -> nalgebra::Isometry2<f64> {
        let across = self.pose_bias_m[1] + self.pose_drift_m_per_s * t_s;
        if self.pose_bias_m[0] == 0.0 && across == 0.0 && self.pose_bias_rad == 0.0 {
            return *estimate;
        }
        estimate
            * nalgebra::Isometry2::new(
                nalgebra::Vector2::new(self.pose_bias_m[0], across),
                self.pose_bias_rad,
            )
    }
}

/// A generator for revolution `index` of a run seeded `seed` (`stream` separates the uses).
fn rng(seed: u64, index: u64, stream: u64) -> rand::rngs::StdRng {
    let mut z = seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ stream.rotate_left(48);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    rand::rngs::StdRng::seed_from_u64(z ^ (z >> 31))
}

/// Decides, revolution by revolution, which are lost.
#[derive(Debug, Default)]
pub struct LostRevolutions {
    lost_until: u64,
}

impl LostRevolutions {
    /// Whether revolution `index` is lost.
    pub fn is_lost(&mut self, faults: &FaultsConfig, seed: u64, index: u64) -> bool {
        if index < self.lost_until {
            return true;
        }
        if faults.lost_revolution_probability > 0.0
            && rng(seed, index, 1).random::<f64>() < faults.lost_revolution_probability
        {
            self.lost_until = index + u64::from(faults.lost_burst_revolutions);
            return true;
        }
        false
    }
}

/// `scan` with the return faults of revolution `index` applied; adds what it did to `counts`.
pub fn degrade(
    scan: &Scan,
    faults: &FaultsConfig,
    seed: u64,
    index: u64,
    counts: &mut FaultCounts,
) -> Result<Scan, mapper::MapError> {
    let beams = scan.beams();
    let mut returns: Vec<Option<Return>> = scan.returns().to_vec();
    let mut r = rng(seed, index, 2);
    let normal = rand_distr::Normal::new(0.0, faults.extra_range_noise_m).ok();
    for (k, slot) in returns.iter_mut().enumerate() {
        let Some(ret) = slot else { continue };
        let beam = k % beams;
        let drop = faults.dead_beams.contains(&beam)
            || (faults.beam_dropout_probability > 0.0
                && r.random::<f64>() < faults.beam_dropout_probability);
        if drop {
            *slot = None;
            counts.dropped_returns += 1;
            continue;
        }
        if let Some(normal) = normal.filter(|_| faults.extra_range_noise_m > 0.0) {
            let column = &scan.columns()[k / beams];
            let origin = Point3::from(column.world_from_sensor.translation.vector);
            let ray = ret.point_in_world - origin;
            let range = ray.norm();
            if range > 1e-6 {
                let new = (range + r.sample(normal)).max(0.0);
                ret.point_in_world = origin + ray * (new / range);
                ret.range_m = new as f32;
            }
        }
    }
    if faults.spurious_returns_per_revolution > 0.0 && scan.column_count() > 0 {
        let n = match rand_distr::Poisson::new(faults.spurious_returns_per_revolution) {
            Ok(p) => r.sample(p) as u64,
            Err(_) => 0,
        };
        for _ in 0..n {
            let column = r.random_range(0..scan.column_count());
            let beam = r.random_range(0..beams);
            let range = r.random_range(1.0..15.0);
            let sensor = scan.columns()[column].world_from_sensor;
            // Along the beam's direction if it had a return, else level and ahead of the column.
            let dir = returns[column * beams + beam]
                .map(|ret| {
                    (ret.point_in_world - Point3::from(sensor.translation.vector)).normalize()
                })
                .unwrap_or_else(|| sensor.rotation * Vector3::x());
            returns[column * beams + beam] = Some(Return {
                point_in_world: Point3::from(sensor.translation.vector) + dir * range,
                range_m: range as f32,
                intensity: r.random_range(0.0..0.2),
            });
            counts.spurious_returns += 1;
        }
    }
    Scan::new(beams, scan.columns().to_vec(), returns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_bias_is_in_the_vehicle_frame_and_a_drift_grows_with_time() {
        use nalgebra::{Isometry2, Vector2};
        let truth = Isometry2::new(Vector2::new(10.0, 5.0), std::f64::consts::FRAC_PI_2);
        assert_eq!(FaultsConfig::default().bias_pose(3.0, &truth), truth);
        let f = FaultsConfig {
            pose_bias_m: [0.5, 0.2],
            pose_drift_m_per_s: 0.01,
            ..FaultsConfig::default()
        };
        // Heading north: ahead is +y, left is -x; at 10 s the drift adds 0.1 m to the left.
        let e = f.bias_pose(10.0, &truth);
        assert!((e.translation.x - (10.0 - 0.3)).abs() < 1e-12, "{e}");
        assert!((e.translation.y - 5.5).abs() < 1e-12, "{e}");
        assert!((e.rotation.angle() - truth.rotation.angle()).abs() < 1e-12);
        let turned = FaultsConfig {
            pose_bias_rad: 0.05,
            ..FaultsConfig::default()
        }
        .bias_pose(0.0, &truth);
        assert!((turned.rotation.angle() - truth.rotation.angle() - 0.05).abs() < 1e-12);
    }

    #[test]
    fn bursts_lose_consecutive_revolutions_at_the_rate_asked_and_the_same_ones_each_run() {
        let faults = FaultsConfig {
            lost_revolution_probability: 0.05,
            lost_burst_revolutions: 4,
            ..FaultsConfig::default()
        };
        let lost = |seed| {
            let mut l = LostRevolutions::default();
            (0..4000)
                .map(|i| l.is_lost(&faults, seed, i))
                .collect::<Vec<bool>>()
        };
        let a = lost(7);
        assert_eq!(a, lost(7));
        assert_ne!(a, lost(8));
        // Runs of lost revolutions are at least a burst long.
        let mut run = 0;
        for (i, &x) in a.iter().enumerate() {
            if x {
                run += 1;
            } else {
                assert!(run == 0 || run >= 4, "a run of {run} ending at {i}");
                run = 0;
            }
        }
        // A burst starts with p = 0.05 at a revolution not already lost: a fraction
        // 4p / (1 + 3p) = 17.4 % of revolutions are lost.
        let fraction = a.iter().filter(|&&x| x).count() as f64 / a.len() as f64;
        assert!((fraction - 0.174).abs() < 0.03, "{fraction}");
        assert!(FaultsConfig::default().validate().is_ok());
        let bad = FaultsConfig {
            beam_dropout_probability: 1.5,
            ..FaultsConfig::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("faults.beam_dropout_probability")
        );
    }
}
