//! The mapping drive as a ROS 2 bag: what a mapping node needs and nothing else - `/tf_static`
//! (`map` -> `odom` identity, `base_link` -> `velodyne` the mount), `/tf` (`odom` -> `base_link`:
//! the drive's exact pose), `/velodyne_points` (each revolution in the sensor frame) and
//! `/clock`, one of each per revolution, stamped at the revolution's time.

use std::path::Path;

use nalgebra::{Isometry2, Isometry3};
use ros2::msgs::{self, Pose, Time};
use ros2::{BagWriter, Qos, TopicId};

use super::{bag_error, planar, pose3, stamp_ns, transform};
use crate::engine::cloud_points;
use crate::error::Result;

/// Writes a mapping drive's revolutions.
pub struct DriveBag {
    bag: BagWriter,
    tf: TopicId,
    cloud: TopicId,
    clock: TopicId,
}

impl DriveBag {
    /// A bag at `file` for a sensor mounted at `vehicle_from_sensor`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(file: &Path, vehicle_from_sensor: &Isometry3<f64>) -> Result<Self> {
        let mut bag = BagWriter::create(file).map_err(bag_error)?;
        let mut add = |name, msg, qos| bag.add_topic(name, msg, qos).map_err(bag_error);
        let tf_static = add("/tf_static", msgs::TF_MESSAGE, Qos::Latched)?;
        let tf = add("/tf", msgs::TF_MESSAGE, Qos::Stream)?;
        let cloud = add("/velodyne_points", msgs::POINT_CLOUD2, Qos::Stream)?;
        let clock = add("/clock", msgs::CLOCK, Qos::Stream)?;
        let fixed = msgs::tf_message(&[
            transform(0.0, "map", "odom", Pose::planar(0.0, 0.0, 0.0, 0.0)),
            transform(0.0, "base_link", "velodyne", pose3(vehicle_from_sensor)),
        ]);
        bag.write(tf_static, stamp_ns(0.0), &fixed)
            .map_err(bag_error)?;
        Ok(Self {
            bag,
            tf,
            cloud,
            clock,
        })
    }

    /// One revolution taken at `t_s` with the vehicle at `pose`.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn revolution(
        &mut self,
        t_s: f64,
        pose: &Isometry2<f64>,
        scan: &mapper::Scan,
    ) -> Result<()> {
        let ns = stamp_ns(t_s);
        let tf = msgs::tf_message(&[transform(t_s, "odom", "base_link", planar(pose, 0.0))]);
        self.bag.write(self.tf, ns, &tf).map_err(bag_error)?;
        let cloud = msgs::velodyne_cloud(Time::from_ns(ns), "velodyne", &cloud_points(scan));
        self.bag.write(self.cloud, ns, &cloud).map_err(bag_error)?;
        self.bag
            .write(self.clock, ns, &msgs::clock(Time::from_ns(ns)))
            .map_err(bag_error)
    }

    /// Closes the bag (its summary, then `metadata.yaml` beside it).
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn finish(self) -> Result<ros2::BagSummary> {
        self.bag.finish().map_err(bag_error)
    }
}
