//! `taxi-sim run --stack ros2`: which stack drives the vehicle - the shipped one, or the user's
//! as ROS 2 nodes over DDS in lockstep (`ros2-live`; the contract is docs/external-stack.md).

use sim::engine::{
    LatePolicy, RunHandles, RunReport, RunSetup, StackReport, run_external, run_with,
};
use sim::scenario::Scenario;

/// The stacks `--stack` can pick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum StackKind {
    /// The stack this project ships (`autonomy`), in the process.
    #[default]
    Shipped,
    /// Yours, as ROS 2 nodes: the simulator publishes the clock and the sensors, and waits for
    /// each step's `/cmd_vel` (geometry_msgs/TwistStamped) over DDS.
    Ros2,
}

/// The options of an external stack.
#[derive(Debug, Clone, clap::Args)]
pub struct StackArgs {
    /// Which stack drives the vehicle.
    #[arg(long, value_enum, default_value_t = StackKind::Shipped)]
    pub stack: StackKind,
    /// `--stack ros2`: the ROS domain id (default: `ROS_DOMAIN_ID`, else 0).
    #[arg(long, value_name = "N")]
    pub ros_domain_id: Option<u16>,
    /// `--stack ros2`: wall seconds to wait at a step for its command.
    #[arg(long, value_name = "S", default_value_t = 10.0)]
    pub stack_timeout_s: f64,
    /// `--stack ros2`: wall seconds to wait before step 0 for the stack to be discovered.
    #[arg(long, value_name = "S", default_value_t = 30.0)]
    pub discovery_timeout_s: f64,
    /// A late stack's last command is held and the miss counted, instead of ending the run
    /// `stack_timeout`.
    #[arg(long)]
    pub lenient: bool,
}

/// Runs the scenario with the stack `args` picks.
pub fn drive(
    args: &StackArgs,
    scenario: &Scenario,
    setup: &RunSetup,
    handles: RunHandles<'_>,
) -> anyhow::Result<RunReport> {
    for (flag, s) in [
        ("--stack-timeout-s", args.stack_timeout_s),
        ("--discovery-timeout-s", args.discovery_timeout_s),
    ] {
        anyhow::ensure!(
            s.is_finite() && s > 0.0,
            "{flag} {s}: a positive number of seconds"
        );
    }
    Ok(match args.stack {
        StackKind::Shipped => run_with(scenario, setup, handles)?,
        StackKind::Ros2 => {
            let options = ros2_live::LiveOptions {
                domain_id: ros2_live::LiveOptions::domain_id(args.ros_domain_id)?,
                discovery_timeout_s: args.discovery_timeout_s,
                stack_timeout_s: args.stack_timeout_s,
            };
            eprintln!(
                "waiting up to {} s for a ROS 2 stack on domain {} (a subscriber of /velodyne_points, a publisher of /cmd_vel)",
                options.discovery_timeout_s, options.domain_id
            );
            let mut stack = ros2_live::Ros2Stack::new(options)?;
            let policy = if args.lenient {
                LatePolicy::Lenient
            } else {
                LatePolicy::Strict
            };
            run_external(scenario, setup, handles, &mut stack, policy)?
        }
    })
}

/// The report's line on an external stack.
pub fn summary(s: &StackReport) -> String {
    let mut line = format!(
        "stack: {}: {} steps, {} commands, {} late, {} stale",
        s.name, s.steps, s.commands, s.late, s.stale
    );
    if let Some((t, topic)) = &s.first_late {
        line += &format!(" (first late at t = {t:.1} s on {topic})");
    }
    if let Some(e) = &s.error {
        line += &format!("; ended: {e}");
    }
    line
}
