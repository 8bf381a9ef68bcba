//! `taxi-sim bench bridge`: what the ROS 2 boundary costs. A revolution of 70,000 points
//! published with the step's other messages and its command received back over DDS, against the
//! same step handed over in the process (the wire's numbers made, the cloud serialised to CDR:
//! what any transport must do); and our stack's real-time factor over ROS 2 against the same node
//! in the process, on a scenario, in alternation. Both peers in this process, on one domain: run
//! it where DDS can multicast (`deploy/ros2/netns.sh taxi-sim bench bridge`).

use std::time::{Duration, Instant};

use nalgebra::Isometry2;
use ros2::msgs::VelodynePoint;
use ros2_client::{Context, ContextOptions, MessageTypeName, Name, NodeName};
use sim::bench::Figure;
use sim::engine::{
    Answer, ExternalStack, InProcessNode, LatePolicy, NoObserver, RunHandles, RunSetup,
    ShippedNode, StackInput, run_external, wire_step,
};
use sim::scenario::Scenario;
use sim::{Error, Result};

use crate::msgs::{Header, PointCloud2, TwistStamped};
use crate::{LiveOptions, Ros2Stack, dds, publish, qos};

/// Points of the benchmark's revolution: an HDL-32E's full one.
pub const CLOUD_POINTS: usize = 70_000;

/// A revolution of `n` points, 32 rings, spread over the azimuth.
fn cloud(n: usize) -> Vec<VelodynePoint> {
    (0..n)
        .map(|i| {
            let ring = (i % 32) as u16;
            let azimuth = (i / 32) as f32 * 0.003;
            let range = 5.0 + (i % 97) as f32 * 0.3;
            let elevation = -0.53 + f32::from(ring) * 0.023;
            VelodynePoint {
                xyz: [
                    range * elevation.cos() * azimuth.cos(),
                    range * elevation.cos() * azimuth.sin(),
                    range * elevation.sin(),
                ],
                intensity: (i % 255) as f32,
                ring,
                time: 0.0,
            }
        })
        .collect()
}

/// A peer that answers each cloud with a command of its stamp, until `stop`.
fn echo(domain_id: u16, stop: std::sync::Arc<std::sync::atomic::AtomicBool>) -> Result<()> {
    let ctx = Context::with_options(ContextOptions::new().domain_id(domain_id))
        .map_err(|e| dds("joining the ROS domain", e))?;
    let name = NodeName::new("/", "bench_echo").map_err(|e| dds("node name", e))?;
    let mut node = ctx
        .new_node(name, ros2_client::NodeOptions::new().enable_rosout(false))
        .map_err(|e| dds("creating the node", e))?;
    let topic = |node: &mut ros2_client::Node, t: &str, pkg: &str, ty: &str| {
        let name = Name::parse(t).map_err(|e| dds(t, e))?;
        node.create_topic(&name, MessageTypeName::new(pkg, ty), &qos(10, false))
            .map_err(|e| dds(t, e))
    };
    let cloud_t = topic(&mut node, "/velodyne_points", "sensor_msgs", "PointCloud2")?;
    let cmd_t = topic(&mut node, "/cmd_vel", "geometry_msgs", "TwistStamped")?;
    let clouds = node
        .create_subscription::<PointCloud2>(&cloud_t, None)
        .map_err(|e| dds("/velodyne_points", e))?;
    let cmd = node
        .create_publisher::<TwistStamped>(&cmd_t, None)
        .map_err(|e| dds("/cmd_vel", e))?;
    let spinner = node.spinner().map_err(|e| dds("the node's spinner", e))?;
    std::thread::spawn(move || futures::executor::block_on(spinner.spin()));
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        match clouds
            .take()
            .map_err(|e| dds("reading /velodyne_points", e))?
        {
            Some((m, _)) => {
                let answer = TwistStamped {
                    header: Header::new(m.header.stamp, "base_link"),
                    ..TwistStamped::default()
                };
                let deadline = Instant::now() + Duration::from_secs(5);
                publish(&cmd, answer, deadline, "/cmd_vel")?;
            }
            None => std::thread::sleep(Duration::from_micros(200)),
        }
    }
    Ok(())
}

fn input(t_s: f64, step: u64, points: &[VelodynePoint]) -> StackInput<'_> {
    StackInput {
        t_s,
        step,
        cloud: Some(points),
        odom_from_vehicle: Isometry2::new(nalgebra::Vector2::new(t_s, 0.0), 0.1),
        odometry: autonomy::Odometry {
            t_s,
            speed_m_s: 5.0,
            steering_rad: 0.05,
        },
        estimate: Some(autonomy::PoseEstimate::exact(t_s, Isometry2::identity())),
        truth: Isometry2::identity(),
    }
}

/// The simulator's side, attached to a stack on `domain_id`.
fn attached(domain_id: u16) -> LiveOptions {
    LiveOptions {
        domain_id,
        discovery_timeout_s: 30.0,
        stack_timeout_s: 10.0,
        command: None,
        log: None,
        ground_truth: false,
        map_dir: None,
    }
}

/// Milliseconds a revolution over DDS against in the process, `samples` batches of 10 steps
/// each way in alternation.
pub fn revolution_figures(domain_id: u16, samples: usize) -> Result<Vec<Figure>> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let peer = {
        let stop = stop.clone();
        std::thread::spawn(move || echo(domain_id, stop))
    };
    let mut stack = Ros2Stack::new(attached(domain_id))?;
    stack.discover()?;
    let points = cloud(CLOUD_POINTS);
    let mut step = 0u64;
    let mut failure: Option<Error> = None;
    let (dds_s, local_s) = sim::bench::alternating(
        samples,
        10,
        || {
            step += 1;
            let t_s = step as f64 * 0.1;
            match stack.step(&input(t_s, step, &points)) {
                Ok(Answer::Command(_)) => {}
                Ok(Answer::Late { topic }) => {
                    failure.get_or_insert(Error::Stack(format!("no {topic} at t = {t_s}")));
                }
                Err(e) => {
                    failure.get_or_insert(e);
                }
            }
        },
        || {
            let w = wire_step(&input(1.0, 10, &points), 1.0);
            let stamp = ros2::msgs::Time::from_ns(w.stamp_ns);
            let cdr =
                ros2::msgs::velodyne_cloud(stamp, "velodyne", w.cloud.as_deref().unwrap_or(&[]));
            std::hint::black_box(cdr);
        },
    );
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = peer.join();
    if let Some(e) = failure {
        return Err(e);
    }
    let local = sim::bench::figure(
        &format!("bridge/revolution_{CLOUD_POINTS}_points/in_process"),
        local_s,
        "ms",
        None,
    );
    let over = sim::bench::figure(
        &format!("bridge/revolution_{CLOUD_POINTS}_points/over_dds"),
        dds_s,
        "ms",
        Some("< 5 ms"),
    );
    Ok(vec![local.clone(), sim::bench::against(over, &local)])
}

/// Real-time factors of our stack over ROS 2 and in the process on `scenario`, one run each way
/// a round, `rounds` rounds in alternation.
pub fn stack_figures(
    scenario: &Scenario,
    setup: &RunSetup,
    domain_id: u16,
    rounds: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Figure>> {
    let (mut local, mut over) = (Vec::new(), Vec::new());
    for k in 0..rounds.max(1) {
        progress(&format!("our stack in the process, {} of {rounds}", k + 1));
        let mut node = InProcessNode::new(scenario, setup)?;
        local.push(rtf(scenario, setup, &mut node)?);
        progress(&format!("our stack over ROS 2, {} of {rounds}", k + 1));
        over.push(over_ros2(scenario, setup, domain_id)?);
    }
    let stem = scenario
        .path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = |how: &str| format!("bridge/{stem}_real_time_factor/{how}");
    let (l, o) = (
        sim::bench::median(&mut local),
        sim::bench::median(&mut over),
    );
    let as_figure = |name: String, rtf: f64, target| Figure {
        name,
        median: rtf,
        unit: "x",
        baseline: None,
        ratio: None,
        target,
    };
    let local = as_figure(name("in_process"), l, None);
    let mut over = as_figure(name("over_dds"), o, Some(">= 10x"));
    over.baseline = Some(local.name.clone());
    over.ratio = Some(o / l);
    Ok(vec![local, over])
}

/// Runs `scenario` with `stack`, unobserved; its real-time factor.
fn rtf(scenario: &Scenario, setup: &RunSetup, stack: &mut dyn ExternalStack) -> Result<f64> {
    let handles = RunHandles {
        stop: None,
        progress: &mut |_| {},
        observer: &mut NoObserver,
    };
    Ok(run_external(scenario, setup, handles, stack, LatePolicy::Strict)?.real_time_factor)
}

/// One run of `scenario` with our stack as a ROS 2 node on another thread; its real-time factor.
fn over_ros2(scenario: &Scenario, setup: &RunSetup, domain_id: u16) -> Result<f64> {
    let mut node = ShippedNode::new(scenario, setup)?;
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let options = crate::NodeOptions {
        domain_id,
        wait_s: 0.5,
        discovery_timeout_s: 30.0,
        stop: Some(stop.clone()),
    };
    let server = std::thread::spawn(move || crate::serve(&options, &mut node));
    let mut stack = Ros2Stack::new(attached(domain_id))?;
    let rtf = rtf(scenario, setup, &mut stack)?;
    drop(stack);
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    server
        .join()
        .map_err(|_| Error::Stack("the stack's thread panicked".into()))??;
    Ok(rtf)
}
