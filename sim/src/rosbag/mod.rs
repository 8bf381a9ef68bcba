//! A run as a ROS 2 bag (MCAP, with `metadata.yaml` beside it): an [`Observer`] that writes the
//! standard messages a ROS stack would log (crate `ros2`); the mapping drive's bag
//! ([`DriveBag`]); a bag's clouds and poses read back into the offline map ([`map_from_bag`],
//! through the transform tree of [`tf`]). Simulated time `t` is stamped as
//! 2024-01-01T00:00:00Z plus `t` (a stamp of 0 means "latest" to tf2).
//!
//! | topic | type | when |
//! | --- | --- | --- |
//! | `/tf_static` | `tf2_msgs/msg/TFMessage`: `map` -> `odom` (identity), `base_link` -> `velodyne` (the mount) | once, transient local |
//! | `/tf` | `odom` -> `base_link` (the stack's estimate) and `map` -> `ground_truth/base_link` (the truth), kept apart | every revolution |
//! | `/clock` | `rosgraph_msgs/msg/Clock` | 20 Hz |
//! | `/velodyne_points` | `sensor_msgs/msg/PointCloud2`, frame `velodyne`, the ROS Velodyne driver's fields (x, y, z, intensity 0-255, ring, time 0: the loop takes a revolution at one instant) | every revolution, stamped when taken |
//! | `/<name>/velodyne_points` | the same for each of the vehicle's other LiDARs (the sidecar's `extra_lidars`), frame `<name>` (in `/tf_static` from `base_link`) | with `/velodyne_points` |
//! | `/localization/pose` | `geometry_msgs/msg/PoseWithCovarianceStamped` in `map` (x, y, yaw covariance) | every revolution |
//! | `/ground_truth/odom` | `nav_msgs/msg/Odometry`: the true pose and speed | 20 Hz |
//! | `/cmd_drive` | `ackermann_msgs/msg/AckermannDriveStamped`: the command followed | 20 Hz |
//! | `/planner/path` | `nav_msgs/msg/Path`: the chosen path | every revolution |
//! | `/map/level_<k>` | `nav_msgs/msg/OccupancyGrid`: each level's merged occupancy, 60 m around the estimate (transient local) | 1 Hz |
//! | `/map/level_<k>/distance` | `nav_msgs/msg/OccupancyGrid`: each level's distance map as a costmap is shown, the distance in percent of its cap (0 at an obstacle, 100 at the cap or beyond) | 1 Hz |
//! | `/collision_model` | `visualization_msgs/msg/MarkerArray` in `base_link` (frame-locked): a flat cylinder per circle at its level's height, coloured by level | once, transient local |
//! | `/objects` | `visualization_msgs/msg/MarkerArray` in `map`: the world's solids (a parked aircraft's parts as their boxes) | once, transient local |
//! | `/obstacles` | `visualization_msgs/msg/MarkerArray` in `map`: the run-time obstacles where they are (ground truth), after a DELETEALL | every revolution |
//! | `/events` | `std_msgs/msg/String`: JSON `{"t_s": 14.31, "kind": "Stop", "event": "Stop { route_s_m: 28.3 }"}` (the kinds of `engine::Event`) | as they happen |

mod drive;
pub mod from_bag;
mod markers;
pub mod tf;

pub use drive::DriveBag;

pub use from_bag::{BagMapOptions, BagMapReport, PoseSource, map_from_bag};

use std::path::{Path, PathBuf};

use nalgebra::{Isometry2, Isometry3, UnitQuaternion};
use ros2::msgs::{self, Pose, Time, Transform};
use ros2::{BagThread, BagWriter, Qos, TopicId};

use crate::engine::{
    Event, Observer, RevolutionFrame, RunReport, RunStart, SensedFrame, StepFrame,
};
use crate::error::{Error, Result};

pub use crate::engine::{EPOCH_NS, covariance6, stamp_ns};

/// Steps between `/clock`, `/ground_truth/odom` and `/cmd_drive` messages (100 Hz physics).
const STEP_EVERY: u64 = 5;

/// Seconds between the level maps, and the half side of the square written, metres.
const MAP_EVERY_S: f64 = 1.0;
const MAP_HALF_M: f64 = 30.0;

/// The collision model as the bag's `/collision_model` holds it (`visualization_msgs/MarkerArray`
/// in `base_link`, a flat cylinder per circle at its level's height, frame-locked), stamped at
/// simulated time `t_s`: CDR with its encapsulation header, for a live peer to send as it is.
#[must_use]
pub fn collision_model_message(
    model: &mapper::CollisionModel,
    heights_m: &[f64],
    t_s: f64,
) -> Vec<u8> {
    let circles = markers::collision_model(model, heights_m);
    msgs::marker_array(Time::from_ns(stamp_ns(t_s)), "base_link", false, &circles)
}

struct Topics {
    tf_static: TopicId,
    tf: TopicId,
    clock: TopicId,
    cloud: TopicId,
    pose: TopicId,
    truth: TopicId,
    cmd: TopicId,
    path: TopicId,
    events: TopicId,
    model: TopicId,
    objects: TopicId,
    obstacles: TopicId,
}

/// Writes a run's bag (see the module's table).
pub struct RosBag {
    bag: Option<BagThread>,
    topics: Topics,
    file: PathBuf,
    steps: u64,
    /// `/map/level_<k>` and `/map/level_<k>/distance`, added at the first revolution; when they
    /// were last written.
    maps: Vec<(TopicId, TopicId)>,
    last_map_s: Option<f64>,
    written: Option<ros2::BagSummary>,
    /// `/<name>/velodyne_points` of each of the vehicle's other LiDARs, with its frame.
    more_clouds: Vec<(TopicId, String)>,
    /// Index of the first run-time obstacle among the scene's solids.
    first_obstacle: usize,
}

/// Lowers the calling thread's priority (nice 10, Linux: per thread): the bag's writer then
/// works in the time the loop leaves idle instead of taking it from the loop.
#[allow(unsafe_code)] // two libc calls; std has no thread priority
fn lower_priority() {
    #[cfg(target_os = "linux")]
    // SAFETY: gettid and setpriority take and return plain integers and touch no memory of ours.
    unsafe {
        let tid = libc::gettid();
        let _ = libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, 10);
    }
}

pub(crate) fn bag_error(e: ros2::BagError) -> Error {
    Error::Invalid(format!("ROS 2 bag: {e}"))
}

impl RosBag {
    /// A revolution's tf (the estimate and the truth), its cloud in the sensor frame and the
    /// pose estimate it went out with, stamped `t`.
    fn write_sensors(
        &mut self,
        t: f64,
        revolution: &autonomy::LidarRevolution,
        truth: &nalgebra::Isometry2<f64>,
        estimate: Option<&autonomy::PoseEstimate>,
    ) -> Result<()> {
        let tf = msgs::tf_message(&[
            transform(
                t,
                "odom",
                "base_link",
                planar(&revolution.world_from_vehicle_estimate, 0.0),
            ),
            transform(t, "map", "ground_truth/base_link", planar(truth, 0.0)),
        ]);
        self.write(|t| t.tf, t, tf)?;
        let stamp = Time::from_ns(stamp_ns(t));
        let cloud = msgs::velodyne_cloud(
            stamp,
            "velodyne",
            &crate::engine::cloud_points(&revolution.scan),
        );
        self.write(|t| t.cloud, t, cloud)?;
        for (k, scan) in revolution.more_scans.iter().enumerate() {
            let Some((topic, frame)) = self.more_clouds.get(k) else {
                break;
            };
            let cloud = msgs::velodyne_cloud(stamp, frame, &crate::engine::cloud_points(scan));
            if let Some(bag) = self.bag.as_mut() {
                bag.write(*topic, stamp_ns(t), cloud).map_err(bag_error)?;
            }
        }
        if let Some(e) = estimate {
            let pose = msgs::pose_with_covariance(
                stamp,
                "map",
                &planar(&e.world_from_vehicle, 0.0),
                &covariance6(&e.covariance),
            );
            self.write(|t| t.pose, t, pose)?;
        }
        Ok(())
    }

    /// The run-time obstacles where they are (ground truth) at `t`: what was drawn before goes.
    fn write_obstacles(&mut self, t: f64, world: &crate::world::World) -> Result<()> {
        let obstacles: Vec<msgs::Marker> = (self.first_obstacle..world.scene().solids.len())
            .filter(|&i| world.object_active(i))
            .map(|i| markers::solid(&world.scene().solids[i], i, "obstacles"))
            .collect();
        let stamp = Time::from_ns(stamp_ns(t));
        let array = msgs::marker_array(stamp, "map", true, &obstacles);
        self.write(|t| t.obstacles, t, array)
    }

    /// A bag to be written at `file` (a `.mcap`).
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(file: &Path) -> Result<Self> {
        let mut bag = BagWriter::create(file).map_err(bag_error)?;
        let mut add = |name, msg, qos| bag.add_topic(name, msg, qos).map_err(bag_error);
        let topics = Topics {
            tf_static: add("/tf_static", msgs::TF_MESSAGE, Qos::Latched)?,
            tf: add("/tf", msgs::TF_MESSAGE, Qos::Stream)?,
            clock: add("/clock", msgs::CLOCK, Qos::Stream)?,
            cloud: add("/velodyne_points", msgs::POINT_CLOUD2, Qos::Stream)?,
            pose: add(
                "/localization/pose",
                msgs::POSE_WITH_COVARIANCE_STAMPED,
                Qos::Stream,
            )?,
            truth: add("/ground_truth/odom", msgs::ODOMETRY, Qos::Stream)?,
            cmd: add("/cmd_drive", msgs::ACKERMANN_DRIVE_STAMPED, Qos::Stream)?,
            path: add("/planner/path", msgs::PATH, Qos::Stream)?,
            events: add("/events", msgs::STRING, Qos::Stream)?,
            model: add("/collision_model", msgs::MARKER_ARRAY, Qos::Latched)?,
            objects: add("/objects", msgs::MARKER_ARRAY, Qos::Latched)?,
            obstacles: add("/obstacles", msgs::MARKER_ARRAY, Qos::Stream)?,
        };
        Ok(Self {
            // Compressed and written beside the run.
            bag: Some(BagThread::spawn_with(bag, lower_priority).map_err(bag_error)?),
            topics,
            file: file.to_path_buf(),
            steps: 0,
            maps: Vec::new(),
            last_map_s: None,
            written: None,
            more_clouds: Vec::new(),
            first_obstacle: 0,
        })
    }

    /// What was written, once the run has finished.
    #[must_use]
    pub fn summary(&self) -> Option<&ros2::BagSummary> {
        self.written.as_ref()
    }

    fn write(&mut self, topic: fn(&Topics) -> TopicId, t_s: f64, cdr: Vec<u8>) -> Result<()> {
        let id = topic(&self.topics);
        match self.bag.as_mut() {
            Some(bag) => bag.write(id, stamp_ns(t_s), cdr).map_err(bag_error),
            None => Err(Error::Invalid(format!(
                "ROS 2 bag {}: written after it was finished",
                self.file.display()
            ))),
        }
    }
}

pub(crate) fn planar(p: &Isometry2<f64>, z: f64) -> Pose {
    Pose::planar(p.translation.x, p.translation.y, z, p.rotation.angle())
}

pub(crate) fn pose3(p: &Isometry3<f64>) -> Pose {
    let q: &UnitQuaternion<f64> = &p.rotation;
    Pose {
        position: [p.translation.x, p.translation.y, p.translation.z],
        orientation: [q.i, q.j, q.k, q.w],
    }
}

pub(crate) fn transform(t_s: f64, parent: &str, child: &str, pose: Pose) -> Transform {
    Transform {
        stamp: Time::from_ns(stamp_ns(t_s)),
        parent: parent.to_string(),
        child: child.to_string(),
        pose,
    }
}

impl RosBag {
    /// Each level's occupancy around `at`, the topics added the first time.
    fn write_maps(
        &mut self,
        map: &mapper::MultiHeightMap,
        at: &Isometry2<f64>,
        t: f64,
    ) -> Result<()> {
        let levels = map.levels().count();
        if let Some(bag) = self.bag.as_mut()
            && self.maps.len() < levels
        {
            for k in self.maps.len()..levels {
                let mut add = |name: String| {
                    bag.add_topic(&name, msgs::OCCUPANCY_GRID, Qos::Latched)
                        .map_err(bag_error)
                };
                let topics = (
                    add(format!("/map/level_{k}"))?,
                    add(format!("/map/level_{k}/distance"))?,
                );
                self.maps.push(topics);
            }
        }
        let center = nalgebra::Point2::from(at.translation.vector);
        let stamp = Time::from_ns(stamp_ns(t));
        for k in 0..levels {
            let occupancy = map.ros_occupancy_around(k, &center, MAP_HALF_M);
            let distance = map
                .distance_maps()
                .level(k)
                .and_then(|d| d.ros_distance_around(&center, MAP_HALF_M));
            let (occupancy_topic, distance_topic) = self.maps[k];
            for (topic, crop) in [(occupancy_topic, occupancy), (distance_topic, distance)] {
                let Some(crop) = crop else {
                    continue;
                };
                let grid = msgs::occupancy_grid(
                    stamp,
                    "map",
                    crop.resolution_m as f32,
                    (crop.width as u32, crop.height as u32),
                    &Pose::planar(crop.corner.x, crop.corner.y, 0.0, 0.0),
                    &crop.cells,
                );
                if let Some(bag) = self.bag.as_mut() {
                    bag.write(topic, stamp_ns(t), grid).map_err(bag_error)?;
                }
            }
        }
        Ok(())
    }
}

impl Observer for RosBag {
    fn start(&mut self, run: &RunStart<'_>) -> Result<()> {
        let mount = run.lidar.vehicle_from_sensor();
        let mut mounts = vec![
            transform(0.0, "map", "odom", Pose::planar(0.0, 0.0, 0.0, 0.0)),
            transform(0.0, "base_link", "velodyne", pose3(&mount)),
        ];
        for l in run.more_lidars {
            let mount = pose3(&l.lidar.vehicle_from_sensor());
            mounts.push(transform(0.0, "base_link", &l.name, mount));
            if let Some(bag) = self.bag.as_mut() {
                let name = format!("/{}/velodyne_points", l.name);
                let topic = bag
                    .add_topic(&name, msgs::POINT_CLOUD2, Qos::Stream)
                    .map_err(bag_error)?;
                self.more_clouds.push((topic, l.name.clone()));
            }
        }
        self.write(|t| t.tf_static, 0.0, msgs::tf_message(&mounts))?;
        let stamp = Time::from_ns(stamp_ns(0.0));
        let heights = crate::offline_map::levels_of(run.scenario, run.config)?;
        let circles = markers::collision_model(run.model, heights.heights_m());
        let model = msgs::marker_array(stamp, "base_link", false, &circles);
        self.write(|t| t.model, 0.0, model)?;
        let objects: Vec<msgs::Marker> = run.scene.solids[..run.first_obstacle]
            .iter()
            .enumerate()
            .map(|(i, s)| markers::solid(s, i, "objects"))
            .collect();
        self.first_obstacle = run.first_obstacle;
        self.write(
            |t| t.objects,
            0.0,
            msgs::marker_array(stamp, "map", false, &objects),
        )
    }

    fn revolution(&mut self, frame: &RevolutionFrame<'_>) -> Result<()> {
        // Stamped when it was taken (the stack sees it a revolution later when it plans while
        // the next is taken).
        let t = frame.revolution.t_s;
        self.write_sensors(
            t,
            frame.revolution,
            &frame.truth,
            frame.pose_estimate.as_ref(),
        )?;
        let stamp = Time::from_ns(stamp_ns(t));
        let poses: Vec<(f64, f64, f64)> = frame
            .plan
            .chosen()
            .poses
            .iter()
            .map(|p| (p.translation.x, p.translation.y, p.rotation.angle()))
            .collect();
        self.write(|t| t.path, t, msgs::path(stamp, "map", &poses))?;
        self.write_obstacles(t, frame.world)?;
        if self
            .last_map_s
            .is_none_or(|last| t - last >= MAP_EVERY_S - 1e-9)
        {
            self.last_map_s = Some(t);
            self.write_maps(frame.map, &frame.estimate, t)?;
        }
        Ok(())
    }

    fn sensed(&mut self, frame: &SensedFrame<'_>) -> Result<()> {
        let t = frame.revolution.t_s;
        self.write_sensors(t, frame.revolution, &frame.truth, frame.estimate.as_ref())?;
        self.write_obstacles(t, frame.world)
    }

    fn step(&mut self, frame: &StepFrame<'_>) -> Result<()> {
        self.steps += 1;
        if !self.steps.is_multiple_of(STEP_EVERY) {
            return Ok(());
        }
        let t = frame.t_s;
        let stamp = Time::from_ns(stamp_ns(t));
        self.write(|t| t.clock, t, msgs::clock(stamp))?;
        let s = frame.state;
        let odom = msgs::odometry(
            stamp,
            "map",
            "ground_truth/base_link",
            &Pose::planar(s.x_m, s.y_m, 0.0, s.yaw_rad),
            &[0.0; 36],
            [[s.speed_m_s, 0.0, 0.0], [0.0; 3]],
        );
        self.write(|t| t.truth, t, odom)?;
        let cmd = msgs::ackermann(
            stamp,
            "base_link",
            frame.command.steering_rad as f32,
            frame.command.speed_m_s as f32,
        );
        self.write(|t| t.cmd, t, cmd)
    }

    fn event(&mut self, t_s: f64, event: &Event) -> Result<()> {
        let text = match event {
            // Its cells are the replay's picture, not a line of text.
            Event::StartUnseen {
                area_m2, cells_m, ..
            } => format!(
                "StartUnseen {{ area_m2: {area_m2:.2}, cells: {} }}",
                cells_m.len()
            ),
            _ => format!("{event:?}"),
        };
        let kind = text
            .split(|c: char| !c.is_alphanumeric())
            .next()
            .unwrap_or("");
        let json = serde_json::json!({ "t_s": t_s, "kind": kind, "event": text });
        self.write(|t| t.events, t_s, msgs::string(&json.to_string()))
    }

    fn finish(&mut self, _report: &RunReport) -> Result<()> {
        if let Some(bag) = self.bag.take() {
            self.written = Some(bag.finish().map_err(bag_error)?);
        }
        Ok(())
    }
}
