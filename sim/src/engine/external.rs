//! A stack outside the loop: at each control step (each LiDAR revolution) the loop hands the
//! stack what the vehicle's sensors measured, stamped with the simulated time, and moves on only
//! with the command the stack answered for that time (lockstep). A transport - ROS 2 over DDS
//! (crate `ros2-live`), or a stack in the same process in tests - implements [`ExternalStack`];
//! the loop checks every command and keeps the count.

use std::path::Path;

use autonomy::{Command, Odometry, PoseEstimate};
use mapper::CollisionModel;
use nalgebra::{Isometry2, Isometry3, Point2};
use ros2::msgs::VelodynePoint;
use serde::Serialize;

use crate::error::Result;

/// A yaw rate beyond this is absurd for any taxiing vehicle (rad/s), not a choice.
pub const ABSURD_YAW_RATE_RAD_S: f64 = 3.0;

/// What the stack is told once, before step 0.
pub struct StackStart<'a> {
    /// The scenario's name.
    pub scenario: &'a str,
    /// Where the wheel odometry's frame lies in the world: the start pose.
    pub world_from_odom: Isometry2<f64>,
    /// The LiDAR's mount on the vehicle.
    pub vehicle_from_lidar: Isometry3<f64>,
    /// The vehicle's wheelbase (rear axle to the steered wheels), metres.
    pub wheelbase_m: f64,
    /// The route's waypoints, world frame, metres.
    pub route_m: &'a [Point2<f64>],
    /// The vehicle's collision model (height-tagged circles).
    pub model: &'a CollisionModel,
    /// The heights of the map's levels, metres (a circle of level k is checked at the k-th).
    pub level_heights_m: &'a [f64],
    /// The offline map's directory.
    pub map_dir: &'a Path,
}

/// What the stack receives at one control step, all of it stamped `t_s`.
pub struct StackInput<'a> {
    /// Simulated time, seconds.
    pub t_s: f64,
    /// Control step, from 0.
    pub step: u64,
    /// The revolution's returns in the sensor frame; `None` when the faults lost it.
    pub cloud: Option<&'a [VelodynePoint]>,
    /// The wheel odometry dead-reckoned from the start (its noise and bias; not ground truth).
    pub odom_from_vehicle: Isometry2<f64>,
    /// The wheels' speed and steering as measured.
    pub odometry: Odometry,
    /// The pose source's estimate (the particle filter's, or the truth's), for a stack without
    /// its own localizer.
    pub estimate: Option<PoseEstimate>,
    /// The vehicle's true pose in the world, for tools (a transport hands it to the stack only
    /// where asked, and never as the stack's own input).
    pub truth: Isometry2<f64>,
}

/// A velocity command as Nav2 publishes it (`geometry_msgs/Twist`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Twist {
    /// `linear.x`, m/s (negative: reversing).
    pub speed_m_s: f64,
    /// `angular.z`, rad/s (positive: turning left).
    pub yaw_rate_rad_s: f64,
}

/// How one step's exchange went.
#[derive(Clone, Debug, PartialEq)]
pub enum Answer {
    /// The command stamped with the step's time.
    Command(Twist),
    /// None came within the transport's timeout.
    Late {
        /// The topic waited on.
        topic: String,
    },
}

/// A stack driven in lockstep by the loop.
pub trait ExternalStack: Send {
    /// Who it is, for the report ("ROS 2 stack on domain 61").
    fn name(&self) -> String;
    /// Called once before step 0 (a transport waits here until its peers are discovered).
    fn start(&mut self, start: &StackStart<'_>) -> Result<()>;
    /// One control step: deliver `input`, wait for the answer. An error (the stack died, the
    /// transport failed) ends the run.
    fn step(&mut self, input: &StackInput<'_>) -> Result<Answer>;
    /// Commands discarded so far because they answered another step (stale).
    fn stale(&self) -> u64;
}

/// What a late stack costs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LatePolicy {
    /// The run ends `stack_timeout` at the first late step.
    #[default]
    Strict,
    /// The last command is held and the miss counted.
    Lenient,
}

/// What the external stack did, in the run's report.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StackReport {
    /// [`ExternalStack::name`].
    pub name: String,
    /// What a late answer cost.
    pub policy: LatePolicy,
    /// Control steps delivered.
    pub steps: u64,
    /// Commands taken (one per step answered in time).
    pub commands: u64,
    /// Steps with no answer in time.
    pub late: u64,
    /// Commands discarded as stale.
    pub stale: u64,
    /// When the first late step was, seconds, and the topic waited on.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_late: Option<(f64, String)>,
    /// Why the stack ended the run, if it did (a command refused, the stack gone).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The loop's side of an external stack: the command held between steps, the odometry frame.
pub(super) struct External<'a> {
    pub(super) stack: &'a mut dyn ExternalStack,
    pub(super) command: Command,
    pub(super) odom_from_vehicle: Isometry2<f64>,
    /// The wheels as last measured.
    pub(super) odometry: Odometry,
    pub(super) report: StackReport,
}

impl<'a> External<'a> {
    pub(super) fn new(stack: &'a mut dyn ExternalStack, policy: LatePolicy) -> Self {
        let name = stack.name();
        External {
            stack,
            command: Command::default(),
            odom_from_vehicle: Isometry2::identity(),
            odometry: Odometry {
                t_s: 0.0,
                speed_m_s: 0.0,
                steering_rad: 0.0,
            },
            report: StackReport {
                name,
                policy,
                ..StackReport::default()
            },
        }
    }

    /// Dead-reckons the odometry frame over `dt_s` from the wheels as measured.
    pub(super) fn dead_reckon(&mut self, odometry: &Odometry, wheelbase_m: f64, dt_s: f64) {
        self.odometry = *odometry;
        let v = odometry.speed_m_s;
        let yaw_rate = v * odometry.steering_rad.tan() / wheelbase_m;
        let heading = self.odom_from_vehicle.rotation.angle() + 0.5 * yaw_rate * dt_s;
        let step = nalgebra::Vector2::new(heading.cos(), heading.sin()) * (v * dt_s);
        self.odom_from_vehicle = Isometry2::new(
            self.odom_from_vehicle.translation.vector + step,
            self.odom_from_vehicle.rotation.angle() + yaw_rate * dt_s,
        );
    }
}

/// The revolution's returns in the sensor frame (each column's own pose), with their beam. Their
/// `time` is 0: the closed loop takes a revolution at one instant (a consumer that deskews by
/// it moves nothing).
pub fn cloud_points(scan: &mapper::Scan) -> Vec<VelodynePoint> {
    let mut points = Vec::with_capacity(scan.returns().len());
    for c in 0..scan.column_count() {
        let Some((column, returns)) = scan.column(c) else {
            continue;
        };
        let sensor_from_world = column.world_from_sensor.inverse();
        for (beam, r) in returns.iter().enumerate() {
            if let Some(r) = r {
                let p = sensor_from_world * r.point_in_world;
                points.push(VelodynePoint {
                    xyz: [p.x as f32, p.y as f32, p.z as f32],
                    intensity: r.intensity * 255.0,
                    ring: beam as u16,
                    time: 0.0,
                });
            }
        }
    }
    points
}

/// The steering command of a velocity command for a vehicle with `limits`, or why the command
/// is refused (not a number, or beyond what the vehicle can do by half again). At a standstill
/// (|v| < 0.05 m/s) the yaw rate says nothing of the steering: `held` is kept.
pub fn command_of_twist(
    t_s: f64,
    twist: Twist,
    limits: &aircraft::MotionLimits,
    held: f64,
) -> std::result::Result<Command, String> {
    let Twist {
        speed_m_s: v,
        yaw_rate_rad_s: w,
    } = twist;
    let at = format!("the command answering t = {t_s:.3} s");
    if !v.is_finite() {
        return Err(format!("{at}: twist.linear.x = {v}: not a number"));
    }
    if !w.is_finite() {
        return Err(format!("{at}: twist.angular.z = {w}: not a number"));
    }
    let (forward, reverse) = (
        1.5 * limits.max_speed_m_s,
        1.5 * limits.max_reverse_speed_m_s,
    );
    if v > forward || v < -reverse - 0.1 {
        return Err(format!(
            "{at}: twist.linear.x = {v} m/s is beyond the vehicle's limits ({} m/s forward, {} m/s reverse)",
            limits.max_speed_m_s, limits.max_reverse_speed_m_s
        ));
    }
    if w.abs() > ABSURD_YAW_RATE_RAD_S {
        return Err(format!(
            "{at}: twist.angular.z = {w} rad/s is beyond {ABSURD_YAW_RATE_RAD_S} rad/s"
        ));
    }
    let steering_rad = if v.abs() < 0.05 {
        held
    } else {
        (limits.wheelbase_m * w / v).atan()
    };
    let max = limits.max_steering_angle_rad;
    Ok(Command {
        speed_m_s: v,
        steering_rad: steering_rad.clamp(-max, max),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> aircraft::MotionLimits {
        aircraft::MotionLimits {
            steering: aircraft::Steering::NoseWheel,
            wheelbase_m: 8.0,
            max_steering_angle_rad: 1.0,
            max_steering_rate_rad_s: 0.5,
            max_speed_m_s: 10.0,
            max_reverse_speed_m_s: 0.0,
            max_acceleration_m_s2: 1.0,
            max_deceleration_m_s2: 3.0,
            max_centripetal_acceleration_m_s2: 1.0,
        }
    }

    #[test]
    fn a_twist_becomes_the_bicycles_steering() {
        let c = command_of_twist(
            1.0,
            Twist {
                speed_m_s: 4.0,
                yaw_rate_rad_s: 0.1,
            },
            &limits(),
            0.3,
        )
        .unwrap();
        assert_eq!(c.speed_m_s, 4.0);
        assert!((c.steering_rad - (8.0f64 * 0.1 / 4.0).atan()).abs() < 1e-12);
        // At a standstill the steering is held.
        let c = command_of_twist(
            1.0,
            Twist {
                speed_m_s: 0.0,
                yaw_rate_rad_s: 0.2,
            },
            &limits(),
            0.3,
        )
        .unwrap();
        assert_eq!(c.steering_rad, 0.3);
        // Beyond the lock, clamped to it.
        let c = command_of_twist(
            1.0,
            Twist {
                speed_m_s: 1.0,
                yaw_rate_rad_s: 2.0,
            },
            &limits(),
            0.0,
        )
        .unwrap();
        assert_eq!(c.steering_rad, 1.0);
    }

    #[test]
    fn an_absurd_command_is_refused_naming_the_field() {
        let bad = |v, w| {
            command_of_twist(
                2.5,
                Twist {
                    speed_m_s: v,
                    yaw_rate_rad_s: w,
                },
                &limits(),
                0.0,
            )
        };
        let e = bad(f64::NAN, 0.0).unwrap_err();
        assert!(
            e.contains("t = 2.500 s") && e.contains("linear.x = NaN"),
            "{e}"
        );
        assert!(
            bad(0.0, f64::INFINITY)
                .unwrap_err()
                .contains("angular.z = inf")
        );
        assert!(
            bad(15.1, 0.0)
                .unwrap_err()
                .contains("beyond the vehicle's limits")
        );
        assert!(bad(-0.2, 0.0).unwrap_err().contains("0 m/s reverse"));
        assert!(bad(1.0, -3.5).unwrap_err().contains("angular.z = -3.5"));
        assert!(bad(14.9, 0.0).is_ok());
    }

    #[test]
    fn odometry_dead_reckons_a_quarter_circle() {
        let mut stack = Scripted;
        let mut e = External::new(&mut stack, LatePolicy::Strict);
        // 2 m/s on a 10 m radius (wheelbase 8 m): a quarter circle in 5 pi / 2 s.
        let steering = (8.0f64 / 10.0).atan();
        let odometry = Odometry {
            t_s: 0.0,
            speed_m_s: 2.0,
            steering_rad: steering,
        };
        let dt = 0.01;
        let steps = (5.0 * std::f64::consts::PI / 2.0 / dt).round() as usize;
        for _ in 0..steps {
            e.dead_reckon(&odometry, 8.0, dt);
        }
        let p = e.odom_from_vehicle;
        assert!((p.translation.x - 10.0).abs() < 0.01, "{p}");
        assert!((p.translation.y - 10.0).abs() < 0.01, "{p}");
        assert!((p.rotation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-3);
    }

    struct Scripted;
    impl ExternalStack for Scripted {
        fn name(&self) -> String {
            "scripted".into()
        }
        fn start(&mut self, _: &StackStart<'_>) -> Result<()> {
            Ok(())
        }
        fn step(&mut self, _: &StackInput<'_>) -> Result<Answer> {
            Ok(Answer::Command(Twist::default()))
        }
        fn stale(&self) -> u64 {
            0
        }
    }
}
