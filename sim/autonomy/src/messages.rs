//! What crosses the boundary between the simulated vehicle and the stack under test: sensor
//! messages in (a LiDAR revolution, a pose estimate, odometry), a command out.

use nalgebra::Isometry2;

/// One LiDAR revolution as the stack receives it: the returns placed in the world frame from the
/// pose estimate the revolution was taken at (where the vehicle believes it was), never from the
/// true pose.
#[derive(Clone, Debug)]
pub struct LidarRevolution {
    /// When the revolution was taken, seconds.
    pub t_s: f64,
    /// The returns, columns x beams (`mapper::Scan`), in the estimate's world frame.
    pub scan: mapper::Scan,
    /// The pose estimate the revolution was taken at.
    pub world_from_vehicle_estimate: Isometry2<f64>,
}

/// A pose estimate from the localizer (or the simulator's stand-in for one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseEstimate {
    /// When it holds, seconds.
    pub t_s: f64,
    /// The estimated pose of the vehicle (rear axle centre) in the world frame.
    pub world_from_vehicle: Isometry2<f64>,
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
