//! What watches a run as it goes (the replay, a test): the [`Observer`] hook and what it is shown.

use autonomy::{LidarRevolution, Plan, RoutePath};
use mapper::{CollisionModel, MultiHeightMap};
use nalgebra::Isometry2;

use super::outcome::Event;
use super::report::RunReport;
use crate::error::Result;
use crate::scenario::Scenario;
use crate::world::Lidar;
use crate::world::{Command, VehicleState};
use crate::world::{Owner, World};

/// What a run shows as it goes (the replay implements it; see `replay`). Every method has a
/// no-op default; what is passed is borrowed for the call only. An error ends the run.
pub trait Observer {
    /// Once, before the first step.
    fn start(&mut self, _run: &RunStart<'_>) -> Result<()> {
        Ok(())
    }
    /// After every LiDAR revolution, map update and plan (10 Hz).
    fn revolution(&mut self, _frame: &RevolutionFrame<'_>) -> Result<()> {
        Ok(())
    }
    /// A revolution handed to a stack outside the process (`run --stack ros2`, `--stack node`):
    /// what it was sent - no map or plan of the shipped stack's to show.
    fn sensed(&mut self, _frame: &SensedFrame<'_>) -> Result<()> {
        Ok(())
    }
    /// After every physics step (100 Hz).
    fn step(&mut self, _frame: &StepFrame<'_>) -> Result<()> {
        Ok(())
    }
    /// Something happened: a stop, a resume, a deviation, a contact, a lap, a pass.
    fn event(&mut self, _t_s: f64, _event: &Event) -> Result<()> {
        Ok(())
    }
    /// Once, with the report (also after Ctrl-C).
    fn finish(&mut self, _report: &RunReport) -> Result<()> {
        Ok(())
    }
}

/// An observer that looks at nothing.
pub struct NoObserver;

impl Observer for NoObserver {}

/// The run's fixed parts, given to [`Observer::start`].
pub struct RunStart<'a> {
    /// The scenario.
    pub scenario: &'a Scenario,
    /// Every solid of the world, objects first, then run-time obstacles (`first_obstacle..`).
    pub scene: &'a crate::world::Scene,
    /// Index of the first run-time obstacle in `scene.solids`.
    pub first_obstacle: usize,
    /// The route as the planner follows it.
    pub route: &'a RoutePath,
    /// The vehicle's circle model (level of each circle, heights of the levels).
    pub model: &'a CollisionModel,
    /// The level of each vehicle part (`scenario.vehicle.vehicle.parts`).
    pub part_levels: &'a [usize],
    /// The LiDAR (the main one, frame `velodyne`).
    pub lidar: &'a Lidar,
    /// The vehicle's other LiDARs, each with its frame name.
    pub more_lidars: &'a [crate::world::NamedLidar],
    /// Laps asked for.
    pub laps: u32,
    /// Seed used.
    pub seed: u64,
    /// The run's configuration.
    pub config: &'a crate::scenario::RunConfig,
}

/// One revolution, map update and plan, given to [`Observer::scan`].
pub struct RevolutionFrame<'a> {
    /// Simulated time, seconds.
    pub t_s: f64,
    /// True pose of the vehicle when the revolution was taken.
    pub truth: Isometry2<f64>,
    /// The pose estimate the revolution was taken at.
    pub estimate: Isometry2<f64>,
    /// The revolution as the stack received it (in the frame of the estimate).
    pub revolution: &'a LidarRevolution,
    /// What each return of the revolution hit (ground truth, for pictures).
    pub owners: &'a [Option<Owner>],
    /// The same for each of the other LiDARs' scans.
    pub more_owners: &'a [Vec<Option<Owner>>],
    /// The map after the update (occupancy and distance maps per level).
    pub map: &'a MultiHeightMap,
    /// The planner's candidates and its choice.
    pub plan: &'a Plan,
    /// Speed commanded by the avoider, m/s.
    pub speed_cmd_m_s: f64,
    /// The avoider's speed over the wanted speed, 0..1 (0: stopped).
    pub speed_scale: f64,
    /// The world (ground truth: object poses, which ones are active).
    pub world: &'a World,
    /// The pose source's particles, when it has any (the particle filter).
    pub particles: Option<&'a [autonomy::localizer::Particle]>,
    /// The stack's current pose estimate with its covariance.
    pub pose_estimate: Option<autonomy::PoseEstimate>,
    /// The movers the stack predicted, with their footprints over the horizon.
    pub predictions: &'a [autonomy::Prediction],
    /// The conflict with a mover on the chosen path that the stack slowed or stopped for.
    pub conflict: Option<autonomy::Conflict>,
}

/// A revolution as a stack outside the process was sent it.
pub struct SensedFrame<'a> {
    /// Simulated time of the step, seconds.
    pub t_s: f64,
    /// The true pose it was taken at.
    pub truth: Isometry2<f64>,
    /// The pose estimate it went out with, if the pose source had made one.
    pub estimate: Option<autonomy::PoseEstimate>,
    /// The revolution (world frame, at the estimate).
    pub revolution: &'a LidarRevolution,
    /// What each return hit (ground truth, for pictures).
    pub owners: &'a [Option<Owner>],
    /// The same for each of the other LiDARs' scans.
    pub more_owners: &'a [Vec<Option<Owner>>],
    /// The world (the run-time obstacles where they are).
    pub world: &'a World,
}

/// One physics step, given to [`Observer::step`].
pub struct StepFrame<'a> {
    /// Simulated time, seconds.
    pub t_s: f64,
    /// The vehicle's state after the step.
    pub state: &'a VehicleState,
    /// The command it followed.
    pub command: &'a Command,
    /// Smallest ground-truth clearance per level to any object near the vehicle, metres.
    pub clearance_m: &'a [f64],
    /// Simulated seconds per wall second so far.
    pub real_time_factor: f64,
    /// The world (ground truth: object poses, which ones are active).
    pub world: &'a World,
}

/// Several observers, shown everything in turn (a Rerun recording and a ROS 2 bag of one run).
pub struct Observers<'a>(pub Vec<&'a mut (dyn Observer + Send)>);

impl Observer for Observers<'_> {
    fn start(&mut self, run: &RunStart<'_>) -> Result<()> {
        self.0.iter_mut().try_for_each(|o| o.start(run))
    }
    fn revolution(&mut self, frame: &RevolutionFrame<'_>) -> Result<()> {
        self.0.iter_mut().try_for_each(|o| o.revolution(frame))
    }
    fn sensed(&mut self, frame: &SensedFrame<'_>) -> Result<()> {
        self.0.iter_mut().try_for_each(|o| o.sensed(frame))
    }
    fn step(&mut self, frame: &StepFrame<'_>) -> Result<()> {
        self.0.iter_mut().try_for_each(|o| o.step(frame))
    }
    fn event(&mut self, t_s: f64, event: &Event) -> Result<()> {
        self.0.iter_mut().try_for_each(|o| o.event(t_s, event))
    }
    fn finish(&mut self, report: &RunReport) -> Result<()> {
        self.0.iter_mut().try_for_each(|o| o.finish(report))
    }
}
