//! The LiDAR's parameters (`[lidar]` of a run configuration): an HDL-32E by default, each
//! field checked by [`LidarConfig::validate`].

use serde::{Deserialize, Serialize};

/// LiDAR parameters (defaults: Velodyne HDL-32E, range noise and general drop-off calibrated
/// on a real one; no per-laser bias; intensity-based drop-off off, CARLA's defaults being 0.45 / 0.8 /
/// 0.4).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LidarConfig {
    /// Number of beams (lasers). Default 32.
    pub channels: usize,
    /// Elevation of the lowest beam, degrees. Default -30.67.
    pub lower_fov_deg: f64,
    /// Elevation of the highest beam, degrees. Default 10.67.
    pub upper_fov_deg: f64,
    /// Columns (firings) per revolution. Default 2187.
    pub columns: usize,
    /// Revolutions per second, Hz. Default 10.
    pub rotation_frequency_hz: f64,
    /// Maximum range, metres. Default 100.
    pub range_m: f64,
    /// Standard deviation of the Gaussian range noise, fresh at every return, metres. Default
    /// 0.004: a real HDL-32E's precision, measured on VeloView's recording (4.2 mm between one
    /// laser's consecutive firings on the ground; `taxi-sim compare-lidar`).
    pub noise_stddev_m: f64,
    /// Standard deviation of each laser's constant range bias, metres: drawn once per sensor
    /// unit (`range_bias_unit`), the same every revolution. Default 0: a recording's consecutive
    /// firings cannot see a bias, and the datasheet's +-2 cm accuracy does not say how much of it
    /// is one (`docs/velodyne.md`: at 0.02 six closed-loop tests move).
    pub range_bias_stddev_m: f64,
    /// Which sensor unit: seeds the lasers' range biases (a unit's biases are the same in the
    /// mapping drive and every run, whatever the run's seed). Default 1.
    pub range_bias_unit: u64,
    /// Intensity attenuation with distance, 1/m (`intensity = remission exp(-a d)`). Default 0.004.
    pub atmosphere_attenuation_rate: f64,
    /// Probability of dropping any return. Default 0.013: a real HDL-32E's low beams miss 1.3 %
    /// of their ground returns outside its mount's shadow (VeloView's recording, `taxi-sim
    /// compare-lidar`; 0-4 % by sector).
    pub dropoff_general_rate: f64,
    /// Returns at or above this intensity are never dropped by intensity. Default 0.8.
    pub dropoff_intensity_limit: f64,
    /// Probability of dropping a zero-intensity return (linear up to the limit). Default 0.
    pub dropoff_zero_intensity: f64,
    /// Fire each column from the pose at its firing time. Default false.
    pub motion_during_sweep: bool,
}

impl Default for LidarConfig {
    fn default() -> Self {
        LidarConfig {
            channels: 32,
            lower_fov_deg: -30.67,
            upper_fov_deg: 10.67,
            columns: 2187,
            rotation_frequency_hz: 10.0,
            range_m: 100.0,
            noise_stddev_m: 0.004,
            range_bias_stddev_m: 0.0,
            range_bias_unit: 1,
            atmosphere_attenuation_rate: 0.004,
            dropoff_general_rate: 0.013,
            dropoff_intensity_limit: 0.8,
            dropoff_zero_intensity: 0.0,
            motion_during_sweep: false,
        }
    }
}

impl LidarConfig {
    /// A Velodyne VLP-16 at 10 Hz: 16 beams from -15 to +15 degrees every 2 (its user manual),
    /// 0.2 degrees between firings (1,800 a revolution), 100 m; the rest as the HDL-32E's.
    pub fn vlp16() -> Self {
        LidarConfig {
            channels: 16,
            lower_fov_deg: -15.0,
            upper_fov_deg: 15.0,
            columns: 1800,
            ..LidarConfig::default()
        }
    }

    /// A sensor model by name: `hdl-32e` (the default) or `vlp-16`.
    pub fn model(name: &str) -> Option<Self> {
        match name.to_ascii_lowercase().as_str() {
            "hdl-32e" | "hdl32e" | "hdl32" => Some(LidarConfig::default()),
            "vlp-16" | "vlp16" => Some(LidarConfig::vlp16()),
            _ => None,
        }
    }

    /// This configuration (the run's: its rate, range, noise, drop-outs) with model `name`'s beam
    /// table and firings instead of its own; `None` for a model not known.
    pub fn with_model(&self, name: &str) -> Option<Self> {
        let m = LidarConfig::model(name)?;
        Some(LidarConfig {
            channels: m.channels,
            lower_fov_deg: m.lower_fov_deg,
            upper_fov_deg: m.upper_fov_deg,
            columns: m.columns,
            ..self.clone()
        })
    }

    /// Checks every field, naming the first wrong one.
    pub fn validate(&self) -> Result<(), String> {
        let bad = |f: &str, why: &str| Err(format!("lidar.{f}: {why}"));
        if self.channels == 0 || self.columns == 0 {
            return bad("channels/columns", "must be > 0");
        }
        if !(self.lower_fov_deg.is_finite()
            && self.upper_fov_deg.is_finite()
            && self.lower_fov_deg < self.upper_fov_deg)
        {
            return bad("lower_fov_deg", "must be finite and below upper_fov_deg");
        }
        for (f, v) in [
            ("rotation_frequency_hz", self.rotation_frequency_hz),
            ("range_m", self.range_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(f, "must be > 0");
            }
        }
        for (f, v) in [
            ("noise_stddev_m", self.noise_stddev_m),
            ("range_bias_stddev_m", self.range_bias_stddev_m),
            (
                "atmosphere_attenuation_rate",
                self.atmosphere_attenuation_rate,
            ),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(f, "must be >= 0");
            }
        }
        for (f, v) in [
            ("dropoff_general_rate", self.dropoff_general_rate),
            ("dropoff_intensity_limit", self.dropoff_intensity_limit),
            ("dropoff_zero_intensity", self.dropoff_zero_intensity),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return bad(f, "must be in [0, 1]");
            }
        }
        Ok(())
    }
}
