//! A stack outside the loop (`run_external`), here in the same process: it gets every control
//! step's revolution, odometry and estimate stamped with the sim time, in order, and drives the
//! vehicle with its answers; a naive one that ignores its LiDAR runs over a cone and the judge
//! says so; a late answer ends the run (strict) or is counted with the last command held
//! (lenient); a command that is not a number ends the run with the field named.

use sim::engine::{
    Answer, ExternalStack, LatePolicy, NoObserver, RunHandles, RunReport, RunSetup, StackInput,
    StackStart, Twist, run_external,
};
use sim::scenario::{RunConfig, Scenario};

/// The IARA car, 40 m east along y = 0, a 0.45 m cone on its path at x = 20 m.
const CONE: &str = r#"
name = "external stack and a cone"
seed = 2

[world]
min_m = [-20.0, -20.0]
max_m = [60.0, 20.0]

[vehicle]
description = "iara_car"

[route]
waypoints_m = [[0.0, 0.0], [40.0, 0.0]]
speed_m_s = 3.0

[expectations]
end = "any"

[[obstacles]]
id = "cone"
kind = "cone"
x_m = 20.0
y_m = 0.0
expect = "no_contact"
"#;

/// What the stack saw at one step.
struct Seen {
    t_s: f64,
    step: u64,
    points: Option<usize>,
    rings_ok: bool,
    odom_x_m: f64,
    estimate_x_m: Option<f64>,
}

/// A stack that follows y = 0 at 3 m/s on the pose estimate and never looks at its cloud;
/// `answer` may replace its answer at a step.
struct Naive<F> {
    seen: Vec<Seen>,
    started: bool,
    answer: F,
}

impl<F: FnMut(u64, Twist) -> Answer + Send> ExternalStack for Naive<F> {
    fn name(&self) -> String {
        "naive test stack".into()
    }
    fn start(&mut self, start: &StackStart<'_>) -> sim::Result<()> {
        assert_eq!(start.route_m.len(), 2);
        self.started = true;
        Ok(())
    }
    fn step(&mut self, input: &StackInput<'_>) -> sim::Result<Answer> {
        assert!(self.started, "stepped before start");
        self.seen.push(Seen {
            t_s: input.t_s,
            step: input.step,
            points: input.cloud.map(<[_]>::len),
            rings_ok: input.cloud.is_some_and(|c| c.iter().all(|p| p.ring < 32)),
            odom_x_m: input.odom_from_vehicle.translation.x,
            estimate_x_m: input.estimate.map(|e| e.world_from_vehicle.translation.x),
        });
        let (y, yaw) = input.estimate.map_or((0.0, 0.0), |e| {
            (
                e.world_from_vehicle.translation.y,
                e.world_from_vehicle.rotation.angle(),
            )
        });
        let twist = Twist {
            speed_m_s: 3.0,
            yaw_rate_rad_s: (-0.3 * y - 1.0 * yaw).clamp(-0.5, 0.5),
        };
        Ok((self.answer)(input.step, twist))
    }
    fn stale(&self) -> u64 {
        0
    }
}

/// The cone scenario written in `dir` and its offline map built there.
fn cone_world(dir: &std::path::Path) -> (Scenario, std::path::PathBuf) {
    let path = dir.join("cone.toml");
    std::fs::write(&path, CONE).unwrap();
    let s = Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let map_dir = dir.join("map");
    sim::offline_map::map_drive(&s, &RunConfig::default(), &map_dir, &mut |_, _| {}).unwrap();
    (s, map_dir)
}

fn run(
    answer: impl FnMut(u64, Twist) -> Answer + Send,
    policy: LatePolicy,
) -> (RunReport, Vec<Seen>) {
    let dir = tempfile::tempdir().unwrap();
    let (s, map_dir) = cone_world(dir.path());
    let mut stack = Naive {
        seen: Vec::new(),
        started: false,
        answer,
    };
    let report = run_external(
        &s,
        &RunSetup::new(map_dir),
        RunHandles {
            stop: None,
            progress: &mut |_| {},
            observer: &mut NoObserver,
        },
        &mut stack,
        policy,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    (report, stack.seen)
}

#[test]
fn a_stack_that_ignores_its_lidar_runs_over_the_cone_in_lockstep() {
    let (r, seen) = run(|_, twist| Answer::Command(twist), LatePolicy::Strict);
    assert_eq!(r.end, sim::engine::EndReason::Completed, "{r:?}");
    // Every control step once, in order, stamped k / scan_hz.
    assert!(seen.len() > 100, "{}", seen.len());
    for (k, s) in seen.iter().enumerate() {
        assert_eq!(s.step, k as u64);
        assert!(
            (s.t_s - k as f64 * 0.1).abs() < 1e-9,
            "step {k} at {}",
            s.t_s
        );
        assert!(s.points.is_some_and(|n| n > 1000) && s.rings_ok, "step {k}");
    }
    // The wheel odometry follows the estimate (both from x = 0), drift and all, within 2 %.
    let last = seen.last().unwrap();
    let estimate = last.estimate_x_m.unwrap();
    assert!(estimate > 35.0, "{estimate}");
    assert!(
        (last.odom_x_m - estimate).abs() < 0.02 * estimate,
        "{} vs {estimate}",
        last.odom_x_m
    );
    let stack = r.stack.as_ref().unwrap();
    assert_eq!(
        (stack.steps, stack.commands, stack.late),
        (seen.len() as u64, seen.len() as u64, 0)
    );
    // It drove through the cone: the judge puts the contact on the vehicle.
    assert!(r.contacts_at_fault >= 1, "{:?}", r.contacts_judged);
    assert!(!r.expectations_met);
}

#[test]
fn a_late_answer_ends_a_strict_run_and_is_counted_in_a_lenient_one() {
    let late = |step: u64, twist| {
        if step % 10 == 5 {
            Answer::Late {
                topic: "/cmd_vel".into(),
            }
        } else {
            Answer::Command(twist)
        }
    };
    let (r, seen) = run(late, LatePolicy::Strict);
    assert_eq!(r.end, sim::engine::EndReason::StackTimeout);
    assert_eq!(seen.len(), 6);
    let stack = r.stack.unwrap();
    assert_eq!((stack.steps, stack.commands, stack.late), (6, 5, 1));
    assert_eq!(stack.first_late, Some((0.5, "/cmd_vel".to_string())));
    assert!((r.sim_time_s - 0.5).abs() < 1e-9, "{}", r.sim_time_s);

    let (r, seen) = run(late, LatePolicy::Lenient);
    assert_eq!(r.end, sim::engine::EndReason::Completed);
    let stack = r.stack.unwrap();
    let missed = seen.iter().filter(|s| s.step % 10 == 5).count() as u64;
    assert!(missed > 10);
    assert_eq!(
        (stack.late, stack.commands),
        (missed, seen.len() as u64 - missed)
    );
}

#[test]
fn a_command_that_is_not_a_number_ends_the_run_naming_the_field() {
    let nan = |step: u64, twist: Twist| {
        Answer::Command(if step == 3 {
            Twist {
                speed_m_s: f64::NAN,
                ..twist
            }
        } else {
            twist
        })
    };
    let (r, seen) = run(nan, LatePolicy::Lenient);
    assert_eq!(r.end, sim::engine::EndReason::StackFailed);
    assert_eq!(seen.len(), 4);
    let error = r.stack.unwrap().error.unwrap();
    assert!(
        error.contains("t = 0.300 s") && error.contains("twist.linear.x = NaN"),
        "{error}"
    );
    assert_eq!(r.contacts.len(), 0);
}

#[test]
fn the_shipped_stack_as_a_node_keeps_off_the_cone_and_its_bag_holds_what_it_was_sent() {
    let dir = tempfile::tempdir().unwrap();
    let (s, map_dir) = cone_world(dir.path());
    let setup = RunSetup::new(map_dir);
    let mut node = sim::engine::InProcessNode::new(&s, &setup).unwrap();
    let file = dir.path().join("bag").join("run.mcap");
    std::fs::create_dir_all(file.parent().unwrap()).unwrap();
    let mut bag = sim::rosbag::RosBag::create(&file).unwrap();
    let r = run_external(
        &s,
        &setup,
        RunHandles {
            stop: None,
            progress: &mut |_| {},
            observer: &mut bag,
        },
        &mut node,
        LatePolicy::Strict,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // Where the naive stack ran the cone over, the shipped one, fed only what the wire
    // carries, does not.
    assert_eq!(r.end, sim::engine::EndReason::Completed, "{r:?}");
    assert_eq!(r.contacts_at_fault, 0, "{:?}", r.contacts_judged);
    let stack = r.stack.as_ref().unwrap();
    assert_eq!((stack.commands, stack.late), (stack.steps, 0));
    // Nothing of an external run is lost: the bag holds every revolution the stack was sent,
    // the estimate it went out with, and the commands the vehicle followed.
    let bytes = std::fs::read(&file).unwrap();
    let mut topics = std::collections::BTreeMap::<String, u64>::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        *topics.entry(m.unwrap().channel.topic.clone()).or_default() += 1;
    }
    let count = |t: &str| topics.get(t).copied().unwrap_or(0);
    assert_eq!(count("/velodyne_points"), stack.steps, "{topics:?}");
    assert_eq!(count("/localization/pose"), stack.steps, "{topics:?}");
    assert!(count("/cmd_drive") >= 2 * stack.steps - 2, "{topics:?}");
}
