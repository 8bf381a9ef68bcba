//! The sidecar TOML beside each URDF: what URDF does not say about a vehicle (motion limits,
//! LiDAR mount, heights of interest, overhead clearance, fit options). Unknown fields are errors.
//!
//! ```toml
//! name = "iara_car"                 # vehicle name
//! urdf = "iara_car.urdf"            # URDF path, relative to this file
//! heights_of_interest_m = [0.0]     # h_0 = 0 < h_1 < ..., metres above the ground
//! overhead_clearance_m = 0.4        # optional, >= 0, default 0.4: the map's ceiling is the
//!                                   # vehicle's top (highest collision part) plus this, m
//!
//! [motion]
//! steering = "front_wheels"         # "front_wheels" or "nose_wheel"
//! wheelbase_m = 2.625               # rear axle (main gear) to front axle (nose gear), m
//! max_steering_angle_rad = 0.5537   # |steering angle| limit, rad
//! max_steering_rate_rad_s = 0.4     # |steering rate| limit, rad/s
//! max_speed_m_s = 8.33              # forward speed limit, m/s
//! max_reverse_speed_m_s = 1.5       # reverse speed limit (magnitude), m/s; 0 = none
//! max_acceleration_m_s2 = 1.0       # forward acceleration limit, m/s^2
//! max_deceleration_m_s2 = 3.0       # braking limit (magnitude), m/s^2
//! max_centripetal_acceleration_m_s2 = 2.0   # lateral acceleration limit, m/s^2
//!
//! [lidar]
//! xyz_m = [0.57, 0.0, 2.15]         # sensor origin in the vehicle frame, m
//! rpy_rad = [0.0, 0.0, 0.0]         # roll, pitch, yaw (fixed X, Y, Z axes), rad; default 0
//!
//! [[extra_lidars]]                  # optional, any number: more LiDARs on the vehicle
//! name = "nose_low"                 # its frame and topic name: a-z, 0-9, _; unique
//! model = "vlp-16"                  # its beam table: "hdl-32e" or "vlp-16"
//! xyz_m = [11.85, 0.0, 0.5]         # as [lidar]
//! rpy_rad = [0.0, 0.0, 0.0]
//!
//! [fit]                             # optional; see `FitOptions`
//! max_overshoot_m = 0.15
//! ```

use std::path::PathBuf;

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use serde::Deserialize;

use crate::error::{Error, Result};
use crate::fit::{FitOptions, check_heights};

/// Which wheels steer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Steering {
    /// Ackermann steering on the front axle (the car).
    FrontWheels,
    /// A steerable nose wheel ahead of fixed main gears (the aircraft).
    NoseWheel,
}

/// Motion limits of the vehicle's bicycle model. Every value must be finite and > 0, except the
/// reverse speed, which may be 0 (a vehicle that cannot back up under its own power).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionLimits {
    /// Which wheels steer.
    pub steering: Steering,
    /// Distance from the rear axle (main-gear centre, the vehicle origin) to the steered axle, metres.
    pub wheelbase_m: f64,
    /// Largest steering angle magnitude, radians.
    pub max_steering_angle_rad: f64,
    /// Largest steering rate magnitude, radians per second.
    pub max_steering_rate_rad_s: f64,
    /// Largest forward speed, metres per second.
    pub max_speed_m_s: f64,
    /// Largest reverse speed magnitude, metres per second (0: cannot reverse).
    pub max_reverse_speed_m_s: f64,
    /// Largest forward acceleration, metres per second squared.
    pub max_acceleration_m_s2: f64,
    /// Largest braking deceleration magnitude, metres per second squared.
    pub max_deceleration_m_s2: f64,
    /// Largest lateral (centripetal) acceleration, metres per second squared.
    pub max_centripetal_acceleration_m_s2: f64,
}

/// Where the LiDAR sits on the vehicle.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarMount {
    /// Sensor origin in the vehicle frame (x forward, y left, z up from the ground), metres.
    pub xyz_m: [f64; 3],
    /// Sensor orientation: roll, pitch, yaw about the fixed X, Y, Z axes, radians. Default 0.
    #[serde(default)]
    pub rpy_rad: [f64; 3],
}

/// A LiDAR besides the main one (`[lidar]`, the one the run configuration's `lidar` describes):
/// its name, its model's beam table and its mount. It turns at the main one's rate, in step.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtraLidar {
    /// Its frame and topic name (`a-z`, `0-9`, `_`; not `velodyne`, the main one's frame).
    pub name: String,
    /// Its model, by name (`hdl-32e`, `vlp-16`): the simulator knows the beam tables.
    pub model: String,
    /// Sensor origin in the vehicle frame, metres.
    pub xyz_m: [f64; 3],
    /// Sensor orientation (as [`LidarMount::rpy_rad`]), radians. Default 0.
    #[serde(default)]
    pub rpy_rad: [f64; 3],
}

impl ExtraLidar {
    /// The sensor's pose in the vehicle frame.
    pub fn vehicle_from_lidar(&self) -> Isometry3<f64> {
        LidarMount {
            xyz_m: self.xyz_m,
            rpy_rad: self.rpy_rad,
        }
        .vehicle_from_lidar()
    }
}

/// Checks the extra LiDARs: finite mounts, names fit for a ROS frame, each once.
fn check_extra_lidars(lidars: &[ExtraLidar]) -> std::result::Result<(), (String, String)> {
    for (k, l) in lidars.iter().enumerate() {
        let at = |f: &str| format!("extra_lidars[{k}].{f}");
        let good = |c: char| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_';
        if l.name.is_empty() || !l.name.chars().all(good) || l.name == "velodyne" {
            return Err((
                at("name"),
                format!(
                    "{:?}: a frame name of a-z, 0-9 and _ (not \"velodyne\", the main LiDAR's)",
                    l.name
                ),
            ));
        }
        if lidars[..k].iter().any(|o| o.name == l.name) {
            return Err((at("name"), format!("{:?} names two LiDARs", l.name)));
        }
        if l.model.trim().is_empty() {
            return Err((
                at("model"),
                "empty: say which model (hdl-32e, vlp-16)".into(),
            ));
        }
        if l.xyz_m.iter().chain(&l.rpy_rad).any(|v| !v.is_finite()) {
            return Err((at("xyz_m"), "every value must be finite".into()));
        }
    }
    Ok(())
}

impl LidarMount {
    /// The sensor's pose in the vehicle frame.
    pub fn vehicle_from_lidar(&self) -> Isometry3<f64> {
        let [x, y, z] = self.xyz_m;
        let [roll, pitch, yaw] = self.rpy_rad;
        Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_euler_angles(roll, pitch, yaw),
        )
    }
}

/// The default overhead clearance, metres: 0.4 m.
///
/// What it must cover is the error in the height of a return near the top of the vehicle,
/// when a structure ahead must be judged: the map takes the vehicle as level on flat ground, so
/// a pitch of 1 degree (braking, a ramp, a bump; unmodelled) moves a point 10 m ahead by
/// 0.17 m; the suspension's or gear struts' travel over a bump, about 0.1 m; the LiDAR's range
/// error, 0.02 m; and roof-top items the URDF leaves out (antennas, beacons). That sums to about
/// 0.3 m; 0.4 m leaves a margin over it. Larger gives away headroom that is really there: the
/// car (top 2.22 m) would no longer pass under a 2.8 m canopy with 0.6 m.
pub const DEFAULT_OVERHEAD_CLEARANCE_M: f64 = 0.4;

fn default_overhead_clearance_m() -> f64 {
    DEFAULT_OVERHEAD_CLEARANCE_M
}

/// A vehicle's sidecar file.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleSpec {
    /// The vehicle's name (reports, file names).
    pub name: String,
    /// The URDF file, relative to the sidecar's directory.
    pub urdf: PathBuf,
    /// Heights of interest h_0 = 0 < h_1 < ..., metres above the ground: one level each.
    pub heights_of_interest_m: Vec<f64>,
    /// How far above the vehicle's top (the highest point of its collision parts) the map's
    /// ceiling is, metres (>= 0; default [`DEFAULT_OVERHEAD_CLEARANCE_M`]): returns at or above
    /// the ceiling belong to no level, so the vehicle drives under what is higher (CARMEN drops
    /// points above its highest sensor plus `safe_range_above_sensors` the same way), while
    /// anything whose underside is lower is an obstacle.
    #[serde(default = "default_overhead_clearance_m")]
    pub overhead_clearance_m: f64,
    /// The real aircraft's published wingspan, metres, where the URDF's boxes reach a little
    /// beyond it (a swept tip as a box): its ICAO code letter is taken from this. Must be within
    /// 1 m of the parts' span. Default: the parts' span.
    #[serde(default)]
    pub wingspan_m: Option<f64>,
    /// Motion limits.
    pub motion: MotionLimits,
    /// LiDAR mount pose.
    pub lidar: LidarMount,
    /// More LiDARs on the vehicle (default none), each cast, mapped and recorded on its own.
    #[serde(default)]
    pub extra_lidars: Vec<ExtraLidar>,
    /// Default fit options for this vehicle (all optional).
    #[serde(default)]
    pub fit: FitOptions,
}

impl VehicleSpec {
    /// Parses and checks a sidecar; `file` names the source in errors.
    pub fn from_str(text: &str, file: &str) -> Result<Self> {
        let spec: VehicleSpec = toml::from_str(text).map_err(|e| Error::toml(file, text, &e))?;
        let field = |field: &str, message: String| Error::Field {
            file: file.to_string(),
            field: field.to_string(),
            message,
        };
        check_heights(&spec.heights_of_interest_m)
            .map_err(|m| field("heights_of_interest_m", m))?;
        if !(spec.overhead_clearance_m.is_finite() && spec.overhead_clearance_m >= 0.0) {
            return Err(field(
                "overhead_clearance_m",
                format!("{} must be finite and >= 0", spec.overhead_clearance_m),
            ));
        }
        if let Some(span) = spec.wingspan_m
            && !(span.is_finite() && span > 0.0)
        {
            return Err(field(
                "wingspan_m",
                format!("{span} must be finite and > 0"),
            ));
        }
        let m = &spec.motion;
        for (name, v) in [
            ("motion.wheelbase_m", m.wheelbase_m),
            ("motion.max_steering_angle_rad", m.max_steering_angle_rad),
            ("motion.max_steering_rate_rad_s", m.max_steering_rate_rad_s),
            ("motion.max_speed_m_s", m.max_speed_m_s),
            ("motion.max_acceleration_m_s2", m.max_acceleration_m_s2),
            ("motion.max_deceleration_m_s2", m.max_deceleration_m_s2),
            (
                "motion.max_centripetal_acceleration_m_s2",
                m.max_centripetal_acceleration_m_s2,
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(field(name, format!("{v} must be finite and > 0")));
            }
        }
        if !(m.max_reverse_speed_m_s.is_finite() && m.max_reverse_speed_m_s >= 0.0) {
            return Err(field(
                "motion.max_reverse_speed_m_s",
                format!("{} must be finite and >= 0", m.max_reverse_speed_m_s),
            ));
        }
        if m.max_steering_angle_rad >= std::f64::consts::FRAC_PI_2 {
            return Err(field(
                "motion.max_steering_angle_rad",
                format!("{} must be below pi/2", m.max_steering_angle_rad),
            ));
        }
        let l = &spec.lidar;
        if l.xyz_m.iter().chain(&l.rpy_rad).any(|v| !v.is_finite()) {
            return Err(field("lidar", "every value must be finite".into()));
        }
        check_extra_lidars(&spec.extra_lidars).map_err(|(f, m)| field(&f, m))?;
        if spec.fit.max_circles == Some(0) {
            return Err(field("fit.max_circles", "must be at least 1".into()));
        }
        if let Some(t) = spec.fit.max_overshoot_m
            && !(t.is_finite() && t > 0.0)
        {
            return Err(field("fit.max_overshoot_m", format!("{t} must be > 0")));
        }
        Ok(spec)
    }
}
