//! `taxi-sim run --stack ros2`: which stack drives the vehicle - the shipped one, or the user's
//! as ROS 2 nodes over DDS in lockstep (`ros2-live`; the contract is docs/external-stack.md).

use sim::engine::{
    InProcessNode, LatePolicy, RunHandles, RunReport, RunSetup, StackReport, run_external, run_with,
};
use sim::scenario::Scenario;

/// The stacks `--stack` can pick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum StackKind {
    /// The stack this project ships (`autonomy`), in the process.
    #[default]
    Shipped,
    /// The shipped stack as a node in the process, fed only what the ROS 2 topics carry
    /// (`taxi-sim stack` is the same node over ROS 2: the two reports are equal).
    Node,
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
    /// `--stack ros2`: start the stack as `sh -c CMD` with `ROS_DOMAIN_ID` set to the run's
    /// domain, and stop it (SIGINT, then SIGKILL after 5 s) when the run ends; without it, a
    /// stack already running on the domain is attached to.
    #[arg(long, value_name = "CMD")]
    pub stack_command: Option<String>,
    /// `--stack-command`: write the stack's output to this file (default: this stderr); its
    /// last lines are quoted if the stack exits during the run.
    #[arg(long, value_name = "FILE", requires = "stack_command")]
    pub stack_log: Option<std::path::PathBuf>,
    /// `--stack ros2`: also publish the vehicle's true pose on `/ground_truth/pose`
    /// (PoseStamped in `map`) for tools - a recorder, a visualiser; never the stack's input.
    #[arg(long)]
    pub ros_ground_truth: bool,
}

impl StackArgs {
    /// The live options of `--stack ros2` on `domain_id`; an error names a bad flag.
    pub fn live_options(&self, domain_id: u16) -> anyhow::Result<ros2_live::LiveOptions> {
        for (flag, s) in [
            ("--stack-timeout-s", self.stack_timeout_s),
            ("--discovery-timeout-s", self.discovery_timeout_s),
        ] {
            anyhow::ensure!(
                s.is_finite() && s > 0.0,
                "{flag} {s}: a positive number of seconds"
            );
        }
        if let Some(c) = &self.stack_command {
            anyhow::ensure!(!c.trim().is_empty(), "--stack-command is empty");
        }
        Ok(ros2_live::LiveOptions {
            domain_id,
            discovery_timeout_s: self.discovery_timeout_s,
            stack_timeout_s: self.stack_timeout_s,
            command: self.stack_command.clone(),
            log: self.stack_log.clone(),
            ground_truth: self.ros_ground_truth,
            map_dir: None,
        })
    }

    /// What a late answer costs.
    pub fn policy(&self) -> LatePolicy {
        if self.lenient {
            LatePolicy::Lenient
        } else {
            LatePolicy::Strict
        }
    }
}

/// Runs the scenario with the stack `args` picks.
pub fn drive(
    args: &StackArgs,
    scenario: &Scenario,
    setup: &RunSetup,
    handles: RunHandles<'_>,
) -> anyhow::Result<RunReport> {
    Ok(match args.stack {
        StackKind::Shipped => run_with(scenario, setup, handles)?,
        StackKind::Node => {
            let mut node = InProcessNode::new(scenario, setup)?;
            run_external(scenario, setup, handles, &mut node, args.policy())?
        }
        StackKind::Ros2 => {
            let domain = ros2_live::LiveOptions::domain_id(args.ros_domain_id)?;
            let options = ros2_live::LiveOptions {
                map_dir: Some(setup.map_dir.clone()),
                ..args.live_options(domain)?
            };
            let mut stack = ros2_live::Ros2Stack::new(options)?;
            let wait = format!(
                "waiting up to {} s for it (a subscriber of /velodyne_points, a publisher of /cmd_vel)",
                args.discovery_timeout_s
            );
            match stack.process_id() {
                Some(pid) => {
                    eprintln!("started the stack (pid {pid}) on ROS domain {domain}; {wait}")
                }
                None => eprintln!("attaching to a ROS 2 stack on domain {domain}; {wait}"),
            }
            run_external(scenario, setup, handles, &mut stack, args.policy())?
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
