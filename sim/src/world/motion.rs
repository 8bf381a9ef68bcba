//! Vehicle motion: a kinematic bicycle with steering-rate and acceleration limits, at a fixed step.
//!
//! The reference point is the rear axle centre (car) or the main-gear centre (jet), the vehicle
//! frame's origin. Front-wheel steering (car) and nose-wheel steering (jet) are the same model:
//! one steered wheel set at `wheelbase_m` ahead of the reference point,
//! `yaw_rate = v tan(steering) / wheelbase`. Commands are targets; the state moves towards them
//! no faster than the limits allow.

use aircraft::spec::MotionLimits;
use nalgebra::Isometry2;

pub use autonomy::{Command, wrap_angle};

/// Planar state of the vehicle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VehicleState {
    /// Reference point, metres (world frame).
    pub x_m: f64,
    /// Reference point, metres (world frame).
    pub y_m: f64,
    /// Heading, radians.
    pub yaw_rad: f64,
    /// Signed speed along the heading, m/s.
    pub speed_m_s: f64,
    /// Steering angle of the steered wheels, radians (positive = left).
    pub steering_rad: f64,
}

impl VehicleState {
    /// The state's planar pose.
    pub fn world_from_vehicle(&self) -> Isometry2<f64> {
        Isometry2::new(nalgebra::Vector2::new(self.x_m, self.y_m), self.yaw_rad)
    }
}

/// The kinematic bicycle of one vehicle.
#[derive(Clone, Debug)]
pub struct Bicycle {
    limits: MotionLimits,
}

impl Bicycle {
    /// A model with the vehicle's limits (from its sidecar).
    pub fn new(limits: MotionLimits) -> Self {
        Bicycle { limits }
    }
    /// The limits.
    pub fn limits(&self) -> &MotionLimits {
        &self.limits
    }

    /// Advances `state` by `dt_s` towards `command`.
    pub fn step(&self, state: &mut VehicleState, command: &Command, dt_s: f64) {
        let l = &self.limits;
        // Steering: rate-limited towards the clamped target.
        let target = command
            .steering_rad
            .clamp(-l.max_steering_angle_rad, l.max_steering_angle_rad);
        let max_d = l.max_steering_rate_rad_s * dt_s;
        state.steering_rad += (target - state.steering_rad).clamp(-max_d, max_d);
        // Speed: acceleration-limited towards the clamped target.
        let target_v = command
            .speed_m_s
            .clamp(-l.max_reverse_speed_m_s, l.max_speed_m_s);
        let speeding_up =
            target_v.abs() > state.speed_m_s.abs() && target_v * state.speed_m_s >= 0.0;
        let rate = if speeding_up {
            l.max_acceleration_m_s2
        } else {
            l.max_deceleration_m_s2
        };
        let max_dv = rate * dt_s;
        state.speed_m_s += (target_v - state.speed_m_s).clamp(-max_dv, max_dv);
        // Pose: exact integration along the arc of constant curvature over the step.
        let curvature = state.steering_rad.tan() / l.wheelbase_m;
        let ds = state.speed_m_s * dt_s;
        let dyaw = ds * curvature;
        let (s0, c0) = state.yaw_rad.sin_cos();
        if dyaw.abs() < 1e-9 {
            state.x_m += ds * c0;
            state.y_m += ds * s0;
        } else {
            let (s1, c1) = (state.yaw_rad + dyaw).sin_cos();
            state.x_m += (s1 - s0) / curvature;
            state.y_m += (c0 - c1) / curvature;
        }
        state.yaw_rad = wrap_angle(state.yaw_rad + dyaw);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn car() -> Bicycle {
        let v = aircraft::Vehicle::shipped("iara_car").unwrap_or_else(|e| panic!("{e}"));
        Bicycle::new(v.spec.motion)
    }

    #[test]
    fn accelerates_at_the_limit_then_holds_speed() {
        let m = car();
        let mut s = VehicleState::default();
        let cmd = Command {
            speed_m_s: 5.0,
            steering_rad: 0.0,
        };
        m.step(&mut s, &cmd, 0.01);
        assert!((s.speed_m_s - m.limits().max_acceleration_m_s2 * 0.01).abs() < 1e-12);
        for _ in 0..2000 {
            m.step(&mut s, &cmd, 0.01);
        }
        assert!((s.speed_m_s - 5.0).abs() < 1e-12 && s.y_m.abs() < 1e-12 && s.x_m > 50.0);
    }

    #[test]
    fn a_full_steer_circle_has_the_bicycle_radius() {
        let m = car();
        let l = m.limits().clone();
        let mut s = VehicleState {
            speed_m_s: 2.0,
            steering_rad: l.max_steering_angle_rad,
            ..Default::default()
        };
        let cmd = Command {
            speed_m_s: 2.0,
            steering_rad: l.max_steering_angle_rad,
        };
        let radius = l.wheelbase_m / l.max_steering_angle_rad.tan();
        for _ in 0..500 {
            m.step(&mut s, &cmd, 0.01);
            // The circle's centre is at (0, R) from the start.
            let r = s.x_m.hypot(s.y_m - radius);
            assert!((r - radius).abs() < 1e-9, "{r} vs {radius}");
        }
    }

    #[test]
    fn steering_moves_no_faster_than_its_rate() {
        let m = car();
        let mut s = VehicleState::default();
        m.step(
            &mut s,
            &Command {
                speed_m_s: 0.0,
                steering_rad: 0.5,
            },
            0.1,
        );
        assert!((s.steering_rad - m.limits().max_steering_rate_rad_s * 0.1).abs() < 1e-12);
        assert!((wrap_angle(3.5) - (3.5 - std::f64::consts::TAU)).abs() < 1e-12);
    }
}
