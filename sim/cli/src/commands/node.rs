//! `taxi-sim stack`: the shipped stack as a ROS 2 node, for `run --stack ros2`.

/// Arguments of `taxi-sim stack`.
#[derive(Debug, Clone, clap::Args)]
pub struct NodeArgs {
    /// The scenario and the run's flags, as `taxi-sim run` takes them: the node's parameters
    /// (the vehicle, the route, the configuration, the offline map).
    #[command(flatten)]
    pub run: super::run::RunArgs,
    /// Wall seconds to wait after a step's odometry for its revolution and estimate before going
    /// on without them (a revolution the faults lost).
    #[arg(long, value_name = "S", default_value_t = 2.0)]
    pub wait_s: f64,
}

/// Runs `taxi-sim stack`: the shipped stack as a ROS 2 node until the simulator leaves.
pub fn serve(args: &NodeArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.wait_s.is_finite() && args.wait_s > 0.0,
        "--wait-s {}: a positive number of seconds",
        args.wait_s
    );
    let (scenario, setup) = super::run::setup(&args.run)?;
    let mut node = sim::engine::ShippedNode::new(&scenario, &setup)?;
    // SIGINT (Ctrl-C, or the simulator ending a run it started the node for) ends the node as
    // the simulator leaving does: its summary said.
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = stop.clone();
    let _ = ctrlc::set_handler(move || flag.store(true, std::sync::atomic::Ordering::Relaxed));
    let options = ros2_live::NodeOptions {
        domain_id: ros2_live::LiveOptions::domain_id(args.run.stack.ros_domain_id)?,
        wait_s: args.wait_s,
        discovery_timeout_s: args.run.stack.discovery_timeout_s,
        stop: Some(stop.clone()),
    };
    eprintln!(
        "the shipped stack as ROS 2 node /taxi_stack on domain {} ({})",
        options.domain_id, scenario.name
    );
    let summary = ros2_live::serve(&options, &mut node)?;
    eprintln!(
        "the node ends: {} steps answered ({} without their revolution, {} without an estimate)",
        summary.steps, summary.without_cloud, summary.without_estimate
    );
    Ok(())
}
