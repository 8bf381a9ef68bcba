//! What crosses the boundary between the simulated vehicle and the stack under test: sensor
//! messages in (a LiDAR revolution, a pose estimate, odometry), a command out.

use nalgebra::{Isometry2, Matrix3, Vector2};

/// One LiDAR revolution as the stack receives it: the returns placed in the world frame from the
/// pose estimate the revolution was taken at (where the vehicle believes it was), never from the
/// true pose.
#[derive(Clone, Debug)]
pub struct LidarRevolution {
    /// When the revolution was taken, seconds.
    pub t_s: f64,
    /// The main LiDAR's returns, columns x beams (`mapper::Scan`), in the estimate's world frame.
    pub scan: mapper::Scan,
    /// The vehicle's other LiDARs' returns of the same revolution, one scan each, in the order
    /// of the sidecar's `extra_lidars`, each column with its own sensor's origin. Empty for a
    /// vehicle with one LiDAR.
    pub more_scans: Vec<mapper::Scan>,
    /// The pose estimate the revolution was taken at.
    pub world_from_vehicle_estimate: Isometry2<f64>,
    /// That estimate's covariance (x, y in metres, heading in radians; zero for an exact pose):
    /// how far the returns may be from where they are placed.
    pub estimate_covariance: Matrix3<f64>,
}

impl LidarRevolution {
    /// Every sensor's scan: the main LiDAR's, then the others'.
    pub fn scans(&self) -> impl Iterator<Item = &mapper::Scan> {
        std::iter::once(&self.scan).chain(&self.more_scans)
    }
}

/// A pose estimate from the localizer (or the simulator's stand-in for one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseEstimate {
    /// When it holds, seconds.
    pub t_s: f64,
    /// The estimated pose of the vehicle (rear axle centre) in the world frame.
    pub world_from_vehicle: Isometry2<f64>,
    /// Covariance of x, y (metres) and heading (radians), world frame; zero for an exact pose.
    pub covariance: Matrix3<f64>,
}

impl PoseEstimate {
    /// An estimate that claims to be exact (zero covariance).
    pub fn exact(t_s: f64, world_from_vehicle: Isometry2<f64>) -> Self {
        PoseEstimate {
            t_s,
            world_from_vehicle,
            covariance: Matrix3::zeros(),
        }
    }

    /// Standard deviation across the vehicle's heading, metres.
    pub fn cross_track_sigma_m(&self) -> f64 {
        let left = self.world_from_vehicle.rotation * Vector2::y();
        let c = self.covariance.fixed_view::<2, 2>(0, 0);
        non_negative_sqrt((left.transpose() * c * left)[(0, 0)])
    }

    /// Standard deviation of the heading, radians.
    pub fn heading_sigma_rad(&self) -> f64 {
        non_negative_sqrt(self.covariance[(2, 2)])
    }

    /// How far a point `reach_m` from the vehicle's origin may be from where the estimate puts
    /// it, one standard deviation across track: `sqrt(sigma_y^2 + (reach sigma_theta)^2)`.
    pub fn lateral_sigma_at_m(&self, reach_m: f64) -> f64 {
        self.cross_track_sigma_m()
            .hypot(reach_m * self.heading_sigma_rad())
    }
}

/// The square root of a variance, rounding's small negatives taken as 0 - and NaN kept (an
/// estimate that knows nothing must not read as exact).
fn non_negative_sqrt(v: f64) -> f64 {
    if v < 0.0 { 0.0 } else { v.sqrt() }
}

/// What the vehicle's own sensors report of its motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Odometry {
    /// When it was measured, seconds.
    pub t_s: f64,
    /// Speed of the rear axle centre, m/s (negative: reversing).
    pub speed_m_s: f64,
    /// Angle of the steered wheel(s), radians (positive: left).
    pub steering_rad: f64,
}

/// What the stack asks the vehicle for.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Command {
    /// Target speed, m/s.
    pub speed_m_s: f64,
    /// Target steering angle, radians.
    pub steering_rad: f64,
}
