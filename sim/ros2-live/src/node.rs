//! `taxi-sim stack`: the shipped stack as a ROS 2 node. It subscribes to what the simulator
//! publishes (`/odom`, `/localization/pose`, `/velodyne_points`), rebuilds each step's
//! [`WireStep`] from the messages, runs [`ShippedNode`] on it and answers `/cmd_vel` stamped with
//! the step's time: the same numbers as `run --stack node` in the process, so the same report.
//!
//! A step is complete when its odometry, its revolution and its estimate have arrived (DDS keeps
//! no order between topics); a revolution the faults lost, or an estimate not yet made, is waited
//! for `wait_s` after the odometry, then the step goes on without it.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use mio::{Events, Poll, PollOpt, Ready, Token};
use ros2::msgs::VelodynePoint;
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions as RosNodeOptions,
    Subscription,
};
use sim::engine::{ShippedNode, WireStep};
use sim::{Error, Result};

use crate::msgs::{
    self, Header, Odometry, PointCloud2, PoseWithCovarianceStamped, TwistStamped, Vector3,
};
use crate::{dds, publish, qos};

/// How the node waits.
#[derive(Clone, Debug)]
pub struct NodeOptions {
    /// The ROS domain id.
    pub domain_id: u16,
    /// Wall seconds to wait after a step's odometry for its revolution and estimate.
    pub wait_s: f64,
    /// Wall seconds to wait for the simulator to appear.
    pub discovery_timeout_s: f64,
    /// Set from outside to end the node (it also ends when the simulator leaves).
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// What the node did.
#[derive(Clone, Debug, Default)]
pub struct NodeSummary {
    /// Steps answered.
    pub steps: u64,
    /// Steps answered without their revolution (lost, or later than `wait_s`).
    pub without_cloud: u64,
    /// Steps answered without an estimate.
    pub without_estimate: u64,
}

/// A time's stamp in nanoseconds.
fn ns(t: &msgs::Time) -> u64 {
    u64::try_from(t.sec).unwrap_or(0) * 1_000_000_000 + u64::from(t.nanosec)
}

/// The messages heard, by stamp.
#[derive(Default)]
struct Heard {
    odom: BTreeMap<u64, (Odometry, Instant)>,
    poses: BTreeMap<u64, PoseWithCovarianceStamped>,
    clouds: BTreeMap<u64, Vec<VelodynePoint>>,
}

/// Takes every message waiting on `sub` into `into`, keyed by its stamp.
fn drain<M: 'static + serde::de::DeserializeOwned, T>(
    sub: &Subscription<M>,
    topic: &str,
    into: &mut BTreeMap<u64, T>,
    f: impl Fn(M) -> Result<(u64, T)>,
) -> Result<()> {
    while let Some((m, _)) = sub
        .take()
        .map_err(|e| dds(&format!("reading {topic}"), e))?
    {
        let (stamp, value) = f(m)?;
        into.insert(stamp, value);
    }
    Ok(())
}

/// Runs `node` on the domain until the simulator leaves; what it did.
pub fn serve(options: &NodeOptions, node: &mut ShippedNode) -> Result<NodeSummary> {
    let ctx = Context::with_options(ContextOptions::new().domain_id(options.domain_id))
        .map_err(|e| dds("joining the ROS domain", e))?;
    let name = NodeName::new("/", "taxi_stack").map_err(|e| dds("node name", e))?;
    let mut ros = ctx
        .new_node(name, RosNodeOptions::new().enable_rosout(false))
        .map_err(|e| dds("creating the node", e))?;
    macro_rules! topic {
        ($topic:literal, $pkg:literal, $ty:literal) => {{
            let name = Name::parse($topic).map_err(|e| dds($topic, e))?;
            ros.create_topic(&name, MessageTypeName::new($pkg, $ty), &qos(10, false))
                .map_err(|e| dds($topic, e))?
        }};
    }
    let odom_t = topic!("/odom", "nav_msgs", "Odometry");
    let pose_t = topic!(
        "/localization/pose",
        "geometry_msgs",
        "PoseWithCovarianceStamped"
    );
    let cloud_t = topic!("/velodyne_points", "sensor_msgs", "PointCloud2");
    let cmd_t = topic!("/cmd_vel", "geometry_msgs", "TwistStamped");
    let odom: Subscription<Odometry> = ros
        .create_subscription(&odom_t, None)
        .map_err(|e| dds("/odom", e))?;
    let pose: Subscription<PoseWithCovarianceStamped> = ros
        .create_subscription(&pose_t, None)
        .map_err(|e| dds("/localization/pose", e))?;
    let cloud: Subscription<PointCloud2> = ros
        .create_subscription(&cloud_t, None)
        .map_err(|e| dds("/velodyne_points", e))?;
    let cmd = ros
        .create_publisher::<TwistStamped>(&cmd_t, None)
        .map_err(|e| dds("/cmd_vel", e))?;
    let spinner = ros.spinner().map_err(|e| dds("the node's spinner", e))?;
    std::thread::spawn(move || futures::executor::block_on(spinner.spin()));
    let poll = Poll::new().map_err(|e| dds("poll", e))?;
    for (k, s) in [(0, &odom as &dyn mio::Evented), (1, &pose), (2, &cloud)] {
        poll.register(s, Token(k), Ready::readable(), PollOpt::edge())
            .map_err(|e| dds("poll", e))?;
    }
    let mut events = Events::with_capacity(8);
    let mut heard = Heard::default();
    let mut summary = NodeSummary::default();
    let wait = Duration::from_secs_f64(options.wait_s);
    let appear_by = Instant::now() + Duration::from_secs_f64(options.discovery_timeout_s);
    let mut seen_simulator = false;
    while !options
        .stop
        .as_ref()
        .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
    {
        drain(&odom, "/odom", &mut heard.odom, |m: Odometry| {
            Ok((ns(&m.header.stamp), (m, Instant::now())))
        })?;
        drain(&pose, "/localization/pose", &mut heard.poses, |m| {
            Ok((ns(&m.header.stamp), m))
        })?;
        drain(
            &cloud,
            "/velodyne_points",
            &mut heard.clouds,
            |m: PointCloud2| {
                let stamp = ns(&m.header.stamp);
                let points = velodyne_points(&m).map_err(|why| {
                    Error::Stack(format!("/velodyne_points stamped {stamp} ns: {why}"))
                })?;
                Ok((stamp, points))
            },
        )?;
        if let Some((&t, (_, at))) = heard.odom.iter().next() {
            let complete = heard.clouds.contains_key(&t) && heard.poses.contains_key(&t);
            if complete || at.elapsed() >= wait {
                let answer = answer_step(node, &mut heard, t, &mut summary)?;
                let deadline = Instant::now() + Duration::from_secs(5);
                publish(&cmd, answer, deadline, "/cmd_vel")?;
                continue;
            }
        }
        let simulators = odom.get_publisher_count(&ros);
        if simulators > 0 {
            seen_simulator = true;
        } else if seen_simulator {
            return Ok(summary);
        } else if Instant::now() > appear_by {
            return Err(Error::Stack(format!(
                "no simulator publishing /odom on ROS domain {} within {} s",
                options.domain_id, options.discovery_timeout_s
            )));
        }
        poll.poll(&mut events, Some(Duration::from_millis(20)))
            .map_err(|e| dds("poll", e))?;
    }
    Ok(summary)
}

/// The step stamped `t` (in nanoseconds) rebuilt from its messages and answered.
fn answer_step(
    node: &mut ShippedNode,
    heard: &mut Heard,
    t: u64,
    summary: &mut NodeSummary,
) -> Result<TwistStamped> {
    let Some((odometry, _)) = heard.odom.remove(&t) else {
        return Err(Error::Stack(format!("no /odom stamped {t} ns")));
    };
    let cloud = heard.clouds.remove(&t);
    let estimate = heard.poses.remove(&t);
    // Anything older belongs to a step already answered.
    heard.clouds.retain(|&s, _| s > t);
    heard.poses.retain(|&s, _| s > t);
    summary.steps += 1;
    summary.without_cloud += u64::from(cloud.is_none());
    summary.without_estimate += u64::from(estimate.is_none());
    let wire = WireStep {
        stamp_ns: t,
        cloud: cloud.map(Cow::Owned),
        odom_pose: odometry.pose.pose.into(),
        speed_m_s: odometry.twist.twist.linear.x,
        yaw_rate_rad_s: odometry.twist.twist.angular.z,
        estimate: estimate.map(|e| (e.pose.pose.into(), e.pose.covariance.0)),
    };
    let twist = node.step(&wire)?;
    Ok(TwistStamped {
        header: Header::new(odometry.header.stamp, "base_link"),
        twist: msgs::Twist {
            linear: Vector3 {
                x: twist.speed_m_s,
                ..Vector3::default()
            },
            angular: Vector3 {
                z: twist.yaw_rate_rad_s,
                ..Vector3::default()
            },
        },
    })
}

/// The points of a cloud laid out as the simulator (and the ROS Velodyne driver) sends them:
/// x, y, z, intensity, ring, time, little-endian; any other layout is refused, naming the field.
pub fn velodyne_points(m: &PointCloud2) -> std::result::Result<Vec<VelodynePoint>, String> {
    let expected = ros2::msgs::VELODYNE_FIELDS;
    if m.fields.len() != expected.len() {
        return Err(format!(
            "{} fields, not the {} of x, y, z, intensity, ring, time",
            m.fields.len(),
            expected.len()
        ));
    }
    for (f, (name, offset, datatype)) in m.fields.iter().zip(expected) {
        if f.name != name || f.offset != offset || f.datatype != datatype || f.count != 1 {
            return Err(format!(
                "field `{}` at offset {} of type {}: expected `{name}` at {offset} of type {datatype}",
                f.name, f.offset, f.datatype
            ));
        }
    }
    let step = ros2::msgs::VELODYNE_POINT_STEP as usize;
    if m.is_bigendian || m.point_step as usize != step {
        return Err(format!(
            "point_step {} (big-endian {}): expected {step}, little-endian",
            m.point_step, m.is_bigendian
        ));
    }
    let n = (m.width as usize).saturating_mul(m.height as usize);
    if m.data.len() != n * step {
        return Err(format!(
            "{} bytes of data for {n} points of {step}",
            m.data.len()
        ));
    }
    let f32_at = |b: &[u8], o: usize| f32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    Ok(m.data
        .chunks_exact(step)
        .map(|b| VelodynePoint {
            xyz: [f32_at(b, 0), f32_at(b, 4), f32_at(b, 8)],
            intensity: f32_at(b, 12),
            ring: u16::from_le_bytes([b[16], b[17]]),
            time: f32_at(b, 18),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cloud_reads_back_point_for_point_and_a_foreign_layout_is_named() {
        let points = vec![
            VelodynePoint {
                xyz: [1.5, -2.25, 0.125],
                intensity: 200.0,
                ring: 31,
                time: 0.0,
            },
            VelodynePoint {
                xyz: [f32::MIN_POSITIVE, 1e7, -3.0],
                intensity: 0.5,
                ring: 0,
                time: 0.05,
            },
        ];
        let t = msgs::Time { sec: 5, nanosec: 7 };
        let m = PointCloud2::velodyne(t, "velodyne", &points);
        assert_eq!(velodyne_points(&m).unwrap(), points);
        let mut other = m.clone();
        other.fields[3].name = "reflectivity".into();
        let e = velodyne_points(&other).unwrap_err();
        assert!(
            e.contains("`reflectivity`") && e.contains("`intensity`"),
            "{e}"
        );
        let mut short = m;
        short.width = 3;
        assert!(
            velodyne_points(&short)
                .unwrap_err()
                .contains("44 bytes of data for 3 points")
        );
    }
}
