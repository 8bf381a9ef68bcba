//! taxi-sim as a live ROS 2 peer: a stack written as ROS 2 nodes drives the simulated vehicle in
//! lockstep over real DDS (`ros2-client` on RustDDS; no ROS installation needed on this side).
//! [`Ros2Stack`] implements the engine's [`ExternalStack`]: at each control step it publishes
//! `/clock`, then the sensors stamped with that time, and waits for the `/cmd_vel` stamped with
//! it. The contract (topics, types, frames, QoS, timing) is `docs/external-stack.md`.
//!
//! | topic | type | QoS |
//! | --- | --- | --- |
//! | `/clock` | rosgraph_msgs/Clock | reliable, keep last 1 |
//! | `/velodyne_points` | sensor_msgs/PointCloud2 (x, y, z, intensity, ring, time), frame `velodyne` | reliable, keep last 1 |
//! | `/tf` | tf2_msgs/TFMessage: `odom` -> `base_link` (wheel odometry) | reliable, keep last 10 |
//! | `/tf_static` | `map` -> `odom` (the start pose), `base_link` -> `velodyne` (the mount) | reliable, transient local |
//! | `/odom` | nav_msgs/Odometry (the simulated wheels, not ground truth) | reliable, keep last 10 |
//! | `/localization/pose` | geometry_msgs/PoseWithCovarianceStamped in `map` (the pose source's estimate) | reliable, keep last 10 |
//! | `/route` | nav_msgs/Path in `map` | reliable, transient local |
//! | `/map/level_K` | nav_msgs/OccupancyGrid in `map`: the offline map's level K as `map_server` serves it | reliable, transient local |
//! | `/collision_model` | visualization_msgs/MarkerArray in `base_link`: the bag's, a cylinder per circle at its level's height | reliable, transient local |
//! | `/ground_truth/pose` (only with `ground_truth`) | geometry_msgs/PoseStamped in `map`: the true pose, for tools | reliable, keep last 10 |
//! | `/cmd_vel` (taken) | geometry_msgs/TwistStamped, stamped with the step it answers | reliable, keep last 10 |

pub mod bench;
mod maps;
pub mod msgs;
mod node;
mod process;

pub use node::{NodeOptions, NodeSummary, serve, velodyne_points};
pub use process::StackProcess;

use std::time::{Duration, Instant};

use mio::{Events, Poll, PollOpt, Ready, Token};
use ros2_client::ros2::{QosPolicies, QosPolicyBuilder, WriteError, policy};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions as RosNodeOptions,
    Publisher, Subscription,
};
use serde::Serialize;
use sim::engine::{Answer, ExternalStack, StackInput, StackStart, Twist};
use sim::{Error, Result};

use msgs::{
    Clock, Covariance, Header, Odometry, Path, PointCloud2, Pose, PoseStamped, PoseWithCovariance,
    PoseWithCovarianceStamped, RawCdr, TfMessage, Time, TransformStamped, TwistStamped,
    TwistWithCovariance, Vector3,
};

/// How long after discovery the peer waits for the stack to match its writers.
const SETTLE: Duration = Duration::from_secs(1);

/// The highest ROS domain id a Linux host can use (DDS maps ids to UDP ports).
pub const MAX_DOMAIN_ID: u16 = 232;

/// How the peer finds and waits for the stack.
#[derive(Clone, Debug)]
pub struct LiveOptions {
    /// The ROS domain id.
    pub domain_id: u16,
    /// How long to wait before step 0 for the stack's subscription and command publisher, s.
    pub discovery_timeout_s: f64,
    /// How long to wait at a step for its command, wall seconds.
    pub stack_timeout_s: f64,
    /// The stack to start (`sh -c COMMAND` on the domain) and stop with the run; `None`: one
    /// already running is attached to.
    pub command: Option<String>,
    /// Where a started stack's output goes (default: the simulator's stderr).
    pub log: Option<std::path::PathBuf>,
    /// Publish the true pose on `/ground_truth/pose`, for tools (off: the topic does not exist).
    pub ground_truth: bool,
    /// The offline map whose levels go out on `/map/level_K` (its map server files).
    pub map_dir: Option<std::path::PathBuf>,
}

impl LiveOptions {
    /// The domain id: `flag` if given, else `ROS_DOMAIN_ID`, else 0; an error names a bad one.
    pub fn domain_id(flag: Option<u16>) -> Result<u16> {
        let (id, from) = match flag {
            Some(id) => (id, "--ros-domain-id".to_string()),
            None => match std::env::var("ROS_DOMAIN_ID") {
                Ok(v) if !v.trim().is_empty() => (
                    v.trim().parse::<u16>().map_err(|_| {
                        Error::Invalid(format!(
                            "ROS_DOMAIN_ID = {v:?}: not a domain id (0..={MAX_DOMAIN_ID})"
                        ))
                    })?,
                    "ROS_DOMAIN_ID".to_string(),
                ),
                _ => (0, "the default".to_string()),
            },
        };
        if id > MAX_DOMAIN_ID {
            return Err(Error::Invalid(format!(
                "ROS domain id {id} (from {from}) is beyond {MAX_DOMAIN_ID}"
            )));
        }
        Ok(id)
    }
}

/// The simulator's node and its topics.
pub struct Ros2Stack {
    node: Node,
    clock: Publisher<Clock>,
    cloud: Publisher<PointCloud2>,
    tf: Publisher<TfMessage>,
    tf_static: Publisher<TfMessage>,
    odom: Publisher<Odometry>,
    pose: Publisher<PoseWithCovarianceStamped>,
    route: Publisher<Path>,
    model: Publisher<RawCdr>,
    /// `/map/level_K`, made at the start from the offline map's files.
    maps: Vec<MapWriter>,
    truth: Option<Publisher<PoseStamped>>,
    cmd: Subscription<TwistStamped>,
    poll: Poll,
    events: Events,
    options: LiveOptions,
    wheelbase_m: f64,
    stale: u64,
    /// The stack's process, when the simulator started it.
    process: Option<StackProcess>,
}

fn qos(depth: i32, latched: bool) -> QosPolicies {
    QosPolicyBuilder::new()
        .reliability(policy::Reliability::Reliable {
            max_blocking_time: ros2_client::ros2::Duration::from_millis(100),
        })
        .durability(if latched {
            policy::Durability::TransientLocal
        } else {
            policy::Durability::Volatile
        })
        .history(policy::History::KeepLast { depth })
        .build()
}

fn dds(what: &str, e: impl std::fmt::Display) -> Error {
    Error::Stack(format!("{what}: {e}"))
}

/// The stamp of simulated time `t_s`: the bags' epoch plus `t_s` (0 means "latest" to tf2).
fn stamp(t_s: f64) -> Time {
    ros2::msgs::Time::from_ns(sim::rosbag::stamp_ns(t_s)).into()
}

fn pose2(p: &nalgebra::Isometry2<f64>, z: f64) -> Pose {
    ros2::msgs::Pose::planar(p.translation.x, p.translation.y, z, p.rotation.angle()).into()
}

impl Ros2Stack {
    /// Joins the domain as node `/taxi_sim` and makes its topics; nothing is sent yet.
    pub fn new(options: LiveOptions) -> Result<Self> {
        let ctx = Context::with_options(ContextOptions::new().domain_id(options.domain_id))
            .map_err(|e| dds("joining the ROS domain", e))?;
        let name = NodeName::new("/", "taxi_sim").map_err(|e| dds("node name", e))?;
        let mut node = ctx
            .new_node(name, RosNodeOptions::new().enable_rosout(false))
            .map_err(|e| dds("creating the node", e))?;
        macro_rules! publisher {
            ($topic:literal, $pkg:literal, $ty:literal, $depth:expr, $latched:expr) => {{
                let name = Name::parse($topic).map_err(|e| dds($topic, e))?;
                let topic = node
                    .create_topic(
                        &name,
                        MessageTypeName::new($pkg, $ty),
                        &qos($depth, $latched),
                    )
                    .map_err(|e| dds($topic, e))?;
                node.create_publisher(&topic, None)
                    .map_err(|e| dds($topic, e))?
            }};
        }
        let clock = publisher!("/clock", "rosgraph_msgs", "Clock", 1, false);
        let cloud = publisher!("/velodyne_points", "sensor_msgs", "PointCloud2", 1, false);
        let tf = publisher!("/tf", "tf2_msgs", "TFMessage", 10, false);
        let tf_static = publisher!("/tf_static", "tf2_msgs", "TFMessage", 1, true);
        let odom = publisher!("/odom", "nav_msgs", "Odometry", 10, false);
        let pose = publisher!(
            "/localization/pose",
            "geometry_msgs",
            "PoseWithCovarianceStamped",
            10,
            false
        );
        let route = publisher!("/route", "nav_msgs", "Path", 1, true);
        let model = publisher!(
            "/collision_model",
            "visualization_msgs",
            "MarkerArray",
            1,
            true
        );
        let truth = if options.ground_truth {
            Some(publisher!(
                "/ground_truth/pose",
                "geometry_msgs",
                "PoseStamped",
                10,
                false
            ))
        } else {
            None
        };
        let cmd_name = Name::parse("/cmd_vel").map_err(|e| dds("/cmd_vel", e))?;
        let cmd_topic = node
            .create_topic(
                &cmd_name,
                MessageTypeName::new("geometry_msgs", "TwistStamped"),
                &qos(10, false),
            )
            .map_err(|e| dds("/cmd_vel", e))?;
        let cmd = node
            .create_subscription::<TwistStamped>(&cmd_topic, None)
            .map_err(|e| dds("/cmd_vel", e))?;
        // Before the spinner: writers made after the node's first announcement do not show in a
        // ROS 2 peer's graph (rmw's).
        let maps = match &options.map_dir {
            Some(dir) => offline_maps(&mut node, dir)?,
            None => Vec::new(),
        };
        // The matched counts are kept up by the node's spinner.
        let spinner = node.spinner().map_err(|e| dds("the node's spinner", e))?;
        std::thread::spawn(move || futures::executor::block_on(spinner.spin()));
        let poll = Poll::new().map_err(|e| dds("poll", e))?;
        poll.register(&cmd, Token(1), Ready::readable(), PollOpt::edge())
            .map_err(|e| dds("poll /cmd_vel", e))?;
        let mut stack = Ros2Stack {
            node,
            clock,
            cloud,
            tf,
            tf_static,
            odom,
            pose,
            route,
            model,
            maps,
            truth,
            cmd,
            poll,
            events: Events::with_capacity(8),
            options,
            wheelbase_m: 1.0,
            stale: 0,
            process: None,
        };
        // Started once the simulator's endpoints exist, so the stack finds them at once.
        if let Some(c) = &stack.options.command {
            let log = stack.options.log.as_deref();
            stack.process = Some(StackProcess::spawn(c, stack.options.domain_id, log)?);
        }
        Ok(stack)
    }

    /// The process id of the stack the simulator started.
    pub fn process_id(&self) -> Option<u32> {
        self.process.as_ref().map(StackProcess::id)
    }

    /// `Err` when the stack the simulator started has exited.
    fn check_process(&mut self, when: &str) -> Result<()> {
        self.process.as_mut().map_or(Ok(()), |p| p.check(when))
    }

    /// Waits until the stack subscribes to the cloud and publishes commands.
    fn discover(&mut self) -> Result<()> {
        let deadline = Instant::now() + Duration::from_secs_f64(self.options.discovery_timeout_s);
        loop {
            self.check_process("before it was discovered")?;
            let readers = self.cloud.get_subscription_count(&self.node);
            let writers = self.cmd.get_publisher_count(&self.node);
            if readers > 0 && writers > 0 {
                // Seeing the stack's endpoints is not the stack matching ours yet: without this
                // the first step's messages wait for the next heartbeat, about a second.
                std::thread::sleep(SETTLE);
                return Ok(());
            }
            if Instant::now() > deadline {
                let mut missing = Vec::new();
                if readers == 0 {
                    missing.push("no subscriber of /velodyne_points");
                }
                if writers == 0 {
                    missing.push("no publisher of /cmd_vel");
                }
                return Err(Error::Stack(format!(
                    "no stack found on ROS domain {} within {} s: {}",
                    self.options.domain_id,
                    self.options.discovery_timeout_s,
                    missing.join(", ")
                )));
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

/// A map topic's name, its transient-local writer and the message it holds.
type MapWriter = (String, Publisher<RawCdr>, RawCdr);

/// A transient-local `/map/level_K` writer and its message per level of the offline map in
/// `map_dir` (its map server files); a level too big to send is left out, and said.
fn offline_maps(node: &mut Node, map_dir: &std::path::Path) -> Result<Vec<MapWriter>> {
    let mut out = Vec::new();
    for (k, yaml) in maps::level_files(map_dir).iter().enumerate() {
        let grid = mapper::export::read_ros_map(yaml).map_err(|e| {
            Error::Stack(format!("reading the offline map {}: {e}", yaml.display()))
        })?;
        let topic = format!("/map/level_{k}");
        if grid.data().len() > maps::MAX_CELLS {
            eprintln!(
                "{topic} not published: {} x {} cells, over the {} a message may hold",
                grid.geometry().width(),
                grid.geometry().height(),
                maps::MAX_CELLS
            );
            continue;
        }
        let name = Name::parse(&topic).map_err(|e| dds(&topic, e))?;
        let ros_topic = node
            .create_topic(
                &name,
                MessageTypeName::new("nav_msgs", "OccupancyGrid"),
                &qos(1, true),
            )
            .map_err(|e| dds(&topic, e))?;
        let publisher = node
            .create_publisher(&ros_topic, None)
            .map_err(|e| dds(&topic, e))?;
        let t0 = ros2::msgs::Time::from_ns(sim::rosbag::stamp_ns(0.0));
        let message = RawCdr::from_message(&maps::occupancy_message(&grid, t0));
        out.push((topic, publisher, message));
    }
    Ok(out)
}

/// Publishes `m`, retrying while the reliable writer's window is full, until `deadline`.
fn publish<M: Serialize>(p: &Publisher<M>, mut m: M, deadline: Instant, topic: &str) -> Result<()> {
    loop {
        match p.publish(m) {
            Ok(()) => return Ok(()),
            Err(WriteError::WouldBlock { data }) if Instant::now() < deadline => m = data,
            Err(e) => return Err(dds(&format!("publishing {topic}"), e)),
        }
    }
}

impl ExternalStack for Ros2Stack {
    fn name(&self) -> String {
        format!("ROS 2 stack on domain {}", self.options.domain_id)
    }

    fn start(&mut self, start: &StackStart<'_>) -> Result<()> {
        self.wheelbase_m = start.wheelbase_m;
        self.discover()?;
        let t0 = stamp(0.0);
        let deadline = Instant::now() + Duration::from_secs_f64(self.options.stack_timeout_s);
        let lidar = start.vehicle_from_lidar;
        let (roll, pitch, yaw) = lidar.rotation.euler_angles();
        let q = nalgebra::UnitQuaternion::from_euler_angles(roll, pitch, yaw);
        let mount = Pose {
            position: Vector3 {
                x: lidar.translation.x,
                y: lidar.translation.y,
                z: lidar.translation.z,
            },
            orientation: msgs::Quaternion {
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            },
        };
        let transform = |parent: &str, child: &str, pose: Pose| TransformStamped {
            header: Header::new(t0, parent),
            child_frame_id: child.into(),
            transform: pose,
        };
        let statics = TfMessage {
            transforms: vec![
                transform("map", "odom", pose2(&start.world_from_odom, 0.0)),
                transform("base_link", "velodyne", mount),
            ],
        };
        publish(&self.tf_static, statics, deadline, "/tf_static")?;
        let poses = start
            .route_m
            .iter()
            .map(|p| PoseStamped {
                header: Header::new(t0, "map"),
                pose: pose2(&nalgebra::Isometry2::translation(p.x, p.y), 0.0),
            })
            .collect();
        let route = Path {
            header: Header::new(t0, "map"),
            poses,
        };
        publish(&self.route, route, deadline, "/route")?;
        for (topic, publisher, message) in &self.maps {
            publish(publisher, message.clone(), deadline, topic)?;
        }
        let model = sim::rosbag::collision_model_message(start.model, start.level_heights_m, 0.0);
        publish(
            &self.model,
            RawCdr::from_message(&model),
            deadline,
            "/collision_model",
        )
    }

    fn step(&mut self, input: &StackInput<'_>) -> Result<Answer> {
        // The numbers as the shipped stack's node reads them back (`sim::engine::wire_step`).
        let w = sim::engine::wire_step(input, self.wheelbase_m);
        let t: Time = ros2::msgs::Time::from_ns(w.stamp_ns).into();
        let timeout = Duration::from_secs_f64(self.options.stack_timeout_s);
        let deadline = Instant::now() + timeout;
        publish(&self.clock, Clock { clock: t }, deadline, "/clock")?;
        let base: Pose = w.odom_pose.into();
        let tf = TfMessage {
            transforms: vec![TransformStamped {
                header: Header::new(t, "odom"),
                child_frame_id: "base_link".into(),
                transform: base,
            }],
        };
        publish(&self.tf, tf, deadline, "/tf")?;
        let odom = Odometry {
            header: Header::new(t, "odom"),
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: base,
                covariance: Covariance([0.0; 36]),
            },
            twist: TwistWithCovariance {
                twist: msgs::Twist {
                    linear: Vector3 {
                        x: w.speed_m_s,
                        ..Vector3::default()
                    },
                    angular: Vector3 {
                        z: w.yaw_rate_rad_s,
                        ..Vector3::default()
                    },
                },
                covariance: Covariance([0.0; 36]),
            },
        };
        publish(&self.odom, odom, deadline, "/odom")?;
        if let Some((pose, covariance)) = &w.estimate {
            let m = PoseWithCovarianceStamped {
                header: Header::new(t, "map"),
                pose: PoseWithCovariance {
                    pose: (*pose).into(),
                    covariance: Covariance(*covariance),
                },
            };
            publish(&self.pose, m, deadline, "/localization/pose")?;
        }
        if let Some(truth) = &self.truth {
            let m = PoseStamped {
                header: Header::new(t, "map"),
                pose: pose2(&input.truth, 0.0),
            };
            publish(truth, m, deadline, "/ground_truth/pose")?;
        }
        if let Some(points) = &w.cloud {
            let cloud = PointCloud2::velodyne(t, "velodyne", points);
            publish(&self.cloud, cloud, deadline, "/velodyne_points")?;
        }
        self.answer(t, input.t_s, deadline)
    }

    fn stale(&self) -> u64 {
        self.stale
    }
}

impl Ros2Stack {
    /// Waits for the command stamped `t`, discarding others as stale.
    fn answer(&mut self, t: Time, t_s: f64, deadline: Instant) -> Result<Answer> {
        loop {
            while let Some((m, _)) = self
                .cmd
                .take()
                .map_err(|e| dds(&format!("reading /cmd_vel at t = {t_s:.3} s"), e))?
            {
                if m.header.stamp == t {
                    return Ok(Answer::Command(Twist {
                        speed_m_s: m.twist.linear.x,
                        yaw_rate_rad_s: m.twist.angular.z,
                    }));
                }
                self.stale += 1;
            }
            self.check_process(&format!("at t = {t_s:.3} s"))?;
            if self.cmd.get_publisher_count(&self.node) == 0 {
                return Err(Error::Stack(format!(
                    "the stack's /cmd_vel publisher left at t = {t_s:.3} s"
                )));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(Answer::Late {
                    topic: "/cmd_vel".into(),
                });
            }
            let wait = (deadline - now).min(Duration::from_millis(200));
            self.poll
                .poll(&mut self.events, Some(wait))
                .map_err(|e| dds("poll /cmd_vel", e))?;
        }
    }
}
