//! The shipped stack (`autonomy`) as a node: fed only what crosses the boundary to an external
//! stack, in the form the ROS 2 messages carry it ([`WireStep`]: the stamp in nanoseconds,
//! points as f32 in the sensor frame, poses as quaternions, the wheels as a twist). The same
//! [`ShippedNode`] runs in the process behind [`ExternalStack`] (`run --stack node`) and as a
//! ROS 2 node (`taxi-sim stack`, crate `ros2-live`); both see the same numbers, so the two runs'
//! reports are equal field for field (but wall times): the ROS 2 boundary loses nothing.
//!
//! What it takes from the scenario file, as a ROS node takes its parameter file: the vehicle
//! (collision model, wheelbase, LiDAR mount and column count), the route and the run
//! configuration. At run time it knows only the step's messages. It maps and plans each
//! revolution the instant it arrives (the sequential schedule): the simulator's own loop, which
//! maps a revolution while the next is taken, is a different schedule and differs by design.

use std::borrow::Cow;

use autonomy::{Command, Driver, Odometry, OnlineMap, PoseEstimate, RoutePath};
use mapper::organise::{ColumnLayout, SensorPoint, organise};
use nalgebra::{Isometry2, Isometry3, Matrix3};
use ros2::msgs::{Pose, VelodynePoint};

use super::external::{Answer, ExternalStack, StackInput, StackStart, Twist};
use super::rig::{RunSetup, driver, online_map};
use crate::error::{Error, Result};
use crate::scenario::{Scenario, WalkAround};
use crate::world::planar_to_3d;

/// Stamps start here: 2024-01-01T00:00:00Z, nanoseconds (the bags' and the live peer's).
pub const EPOCH_NS: u64 = 1_704_067_200_000_000_000;

/// The stamp of simulated time `t_s`.
#[must_use]
pub fn stamp_ns(t_s: f64) -> u64 {
    EPOCH_NS + (t_s.max(0.0) * 1e9).round() as u64
}

/// A planar covariance (x, y, yaw) as ROS's 6x6 over (x, y, z, roll, pitch, yaw).
pub fn covariance6(c: &nalgebra::Matrix3<f64>) -> [f64; 36] {
    let mut out = [0.0; 36];
    let index = [0, 1, 5];
    for (i, &r) in index.iter().enumerate() {
        for (j, &k) in index.iter().enumerate() {
            out[r * 6 + k] = c[(i, j)];
        }
    }
    out
}

/// One control step as its ROS 2 messages carry it (what [`wire_step`] makes of a
/// [`StackInput`], and what a ROS 2 node reads back from `/odom`, `/localization/pose` and
/// `/velodyne_points`).
#[derive(Clone, Debug, PartialEq)]
pub struct WireStep<'a> {
    /// The headers' stamp, nanoseconds since the epoch.
    pub stamp_ns: u64,
    /// The revolution (`/velodyne_points`); `None` when the faults lost it.
    pub cloud: Option<Cow<'a, [VelodynePoint]>>,
    /// `/odom`'s pose: `base_link` in `odom`, dead-reckoned from the wheels.
    pub odom_pose: Pose,
    /// `/odom`'s `twist.linear.x`, m/s.
    pub speed_m_s: f64,
    /// `/odom`'s `twist.angular.z`, rad/s.
    pub yaw_rate_rad_s: f64,
    /// `/localization/pose`: the pose source's estimate in `map` and its 6x6 covariance.
    pub estimate: Option<(Pose, [f64; 36])>,
}

/// A planar pose on the wire (z = 0).
pub fn pose_on_wire(p: &Isometry2<f64>) -> Pose {
    Pose::planar(p.translation.x, p.translation.y, 0.0, p.rotation.angle())
}

/// A pose off the wire, its heading from the quaternion's rotation about z.
pub fn pose_off_wire(p: &Pose) -> Isometry2<f64> {
    let [_, _, qz, qw] = p.orientation;
    Isometry2::new(
        nalgebra::Vector2::new(p.position[0], p.position[1]),
        2.0 * qz.atan2(qw),
    )
}

/// Simulated seconds of a stamp (the bags' epoch is time 0).
pub fn seconds_of_stamp(stamp_ns: u64) -> f64 {
    stamp_ns.saturating_sub(EPOCH_NS) as f64 / 1e9
}

/// What the simulator sends at a step, as the messages carry it: the odometry's yaw rate is the
/// bicycle's (`v tan(steering) / wheelbase`).
pub fn wire_step<'a>(input: &StackInput<'a>, wheelbase_m: f64) -> WireStep<'a> {
    let v = input.odometry.speed_m_s;
    WireStep {
        stamp_ns: stamp_ns(input.t_s),
        cloud: input.cloud.map(Cow::Borrowed),
        odom_pose: pose_on_wire(&input.odom_from_vehicle),
        speed_m_s: v,
        yaw_rate_rad_s: v * input.odometry.steering_rad.tan() / wheelbase_m,
        estimate: input.estimate.map(|e| {
            (
                pose_on_wire(&e.world_from_vehicle),
                covariance6(&e.covariance),
            )
        }),
    }
}

/// The x, y, yaw block of a 6x6 covariance (x, y, z, roll, pitch, yaw).
fn covariance3(c: &[f64; 36]) -> Matrix3<f64> {
    let index = [0, 1, 5];
    Matrix3::from_fn(|i, j| c[index[i] * 6 + index[j]])
}

/// The shipped stack, fed step by step with what the wire carries.
pub struct ShippedNode {
    driver: Driver,
    map: OnlineMap,
    /// The live map's scratch directory, removed with the node.
    _live: tempfile::TempDir,
    vehicle_from_lidar: Isometry3<f64>,
    wheelbase_m: f64,
    beams: usize,
    columns: usize,
    /// When the crew's walk-around comes (`[vehicle] walk_around` at a time), seconds.
    walk_around_at_s: Option<f64>,
    /// The steering last measured (a twist at a standstill does not say it).
    steering_rad: f64,
    steps: u64,
}

impl ShippedNode {
    /// The stack of `scenario` as the simulator's loop builds it (the same driver, online map and
    /// start-up rule), over the offline map of `setup`.
    pub fn new(scenario: &Scenario, setup: &RunSetup) -> Result<Self> {
        let config = setup.config.clone();
        config.validate().map_err(|message| Error::Config {
            origin: "run configuration".into(),
            message,
        })?;
        let vehicle = &scenario.vehicle.vehicle;
        super::rig::one_lidar_on_the_wire(vehicle)?;
        let model = config.collision_model(vehicle)?;
        let route = RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed)
            .with_speed_limits(scenario.route.speed_limits_m_s.clone());
        let start = scenario.vehicle.world_from_start;
        let (map, live) = online_map(scenario, &config, &model, setup, &start)?;
        let mut driver = driver(scenario, &config, &model, &route);
        let walk_around = scenario.vehicle.walk_around;
        if walk_around != WalkAround::BeforeStart {
            driver.await_walk_around(super::rig::blind_zone(vehicle, &config.lidar, &model)?);
        }
        Ok(ShippedNode {
            driver,
            map,
            _live: live,
            vehicle_from_lidar: vehicle.vehicle_from_lidar(),
            wheelbase_m: vehicle.spec.motion.wheelbase_m,
            beams: config.lidar.channels,
            columns: config.lidar.columns,
            walk_around_at_s: match walk_around {
                WalkAround::At(t) => Some(t),
                _ => None,
            },
            steering_rad: 0.0,
            steps: 0,
        })
    }

    /// Steps answered.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// One step: the wheels and the estimate heard, the revolution mapped and planned from; the
    /// command, as a twist (`linear.x`, `angular.z = v tan(steering) / wheelbase`).
    pub fn step(&mut self, w: &WireStep<'_>) -> Result<Twist> {
        let t_s = seconds_of_stamp(w.stamp_ns);
        if let Some(at) = self.walk_around_at_s
            && t_s >= at
        {
            self.walk_around_at_s = None;
            self.driver.on_walk_around();
        }
        let v = w.speed_m_s;
        if v.abs() > 1e-9 {
            self.steering_rad = (self.wheelbase_m * w.yaw_rate_rad_s / v).atan();
        }
        self.driver.on_odometry(Odometry {
            t_s,
            speed_m_s: v,
            steering_rad: self.steering_rad,
        });
        if let Some((pose, covariance)) = &w.estimate {
            self.driver.on_pose(PoseEstimate {
                t_s,
                world_from_vehicle: pose_off_wire(pose),
                covariance: covariance3(covariance),
            });
        }
        if let Some(points) = &w.cloud {
            self.driver.on_revolution(t_s);
            if let Some(estimate) = self.driver.estimate().copied() {
                let revolution = self.revolution(t_s, points, &estimate)?;
                self.map.update(&revolution)?;
            }
            self.driver.plan(&mut self.map)?;
        }
        self.steps += 1;
        let Command {
            speed_m_s,
            steering_rad,
        } = self.driver.command();
        Ok(Twist {
            speed_m_s,
            yaw_rate_rad_s: speed_m_s * steering_rad.tan() / self.wheelbase_m,
        })
    }

    /// The cloud organised into the mapper's columns x beams at `estimate`.
    fn revolution(
        &self,
        t_s: f64,
        points: &[VelodynePoint],
        estimate: &PoseEstimate,
    ) -> Result<autonomy::LidarRevolution> {
        let sensor_points: Vec<SensorPoint> = points
            .iter()
            .map(|p| SensorPoint {
                xyz: p.xyz.map(f64::from),
                ring: p.ring,
                // The driver's 0-255 back to the calibrated 0..1.
                intensity: (p.intensity / 255.0).clamp(0.0, 1.0),
            })
            .collect();
        let world_from_vehicle = estimate.world_from_vehicle;
        let world_from_sensor = planar_to_3d(&world_from_vehicle) * self.vehicle_from_lidar;
        let layout =
            ColumnLayout::estimate(&sensor_points, Some(self.columns)).unwrap_or(ColumnLayout {
                columns: self.columns,
                phase_rad: 0.0,
            });
        let scan = organise(
            &sensor_points,
            self.beams,
            &layout,
            &world_from_sensor,
            &world_from_vehicle,
        )?;
        Ok(autonomy::LidarRevolution {
            t_s,
            scan,
            more_scans: Vec::new(),
            world_from_vehicle_estimate: world_from_vehicle,
            estimate_covariance: estimate.covariance,
        })
    }
}

/// [`ShippedNode`] behind [`ExternalStack`] in the simulator's process: each step goes through
/// [`wire_step`], as over ROS 2 (`run --stack node`).
pub struct InProcessNode {
    node: ShippedNode,
    wheelbase_m: f64,
}

impl InProcessNode {
    /// The node of `scenario` over the offline map of `setup`.
    pub fn new(scenario: &Scenario, setup: &RunSetup) -> Result<Self> {
        Ok(InProcessNode {
            node: ShippedNode::new(scenario, setup)?,
            wheelbase_m: 1.0,
        })
    }
}

impl ExternalStack for InProcessNode {
    fn name(&self) -> String {
        "the shipped stack as a node, in the process".into()
    }

    fn start(&mut self, start: &StackStart<'_>) -> Result<()> {
        self.wheelbase_m = start.wheelbase_m;
        Ok(())
    }

    fn step(&mut self, input: &StackInput<'_>) -> Result<Answer> {
        let wire = wire_step(input, self.wheelbase_m);
        Ok(Answer::Command(self.node.step(&wire)?))
    }

    fn stale(&self) -> u64 {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_and_a_stamp_cross_the_wire() {
        for yaw in [0.0, 1.0, -2.5, 3.1, -3.1] {
            let p = Isometry2::new(nalgebra::Vector2::new(12.5, -3.25), yaw);
            let back = pose_off_wire(&pose_on_wire(&p));
            assert!((back.translation.vector - p.translation.vector).norm() == 0.0);
            assert!((back.rotation.angle() - yaw).abs() < 1e-12, "{yaw}");
        }
        assert_eq!(seconds_of_stamp(stamp_ns(12.34)), 12.34);
        let c = Matrix3::new(1.0, 2.0, 3.0, 2.0, 5.0, 6.0, 3.0, 6.0, 9.0);
        assert_eq!(covariance3(&covariance6(&c)), c);
    }
}
