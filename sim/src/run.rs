//! The closed loop: the world and its sensors, the pose source, the stack under test and the
//! judge, ticked by the schedule.
//!
//! Rates: physics (vehicle motion, ground truth, moving obstacles) at `physics_hz` (100 Hz); one
//! LiDAR revolution, map update and plan every `1 / scan_hz` (10 Hz). The stack gets sensor
//! messages (revolutions stamped with the pose estimate, the estimate, odometry) and nothing else
//! from the world; the judge reads the world. A run is a pure function of (scenario, seed, run
//! configuration).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use autonomy::{
    AutonomyConfig, Behaviour, Driver, DriverStatus, LidarRevolution, OnlineMap, RoutePath,
    VehicleModel,
};
use mapper::{CollisionModel, MultiHeightMap};
use nalgebra::{Isometry2, Point2};

use crate::config::RunConfig;
use crate::error::{Error, Result};
use crate::judge::{EndReason, Judge};
use crate::lidar::{Lidar, SweepPoses};
use crate::motion::{Bicycle, VehicleState};
use crate::observer::{NoObserver, Observer, RunStart, ScanFrame, StepFrame};
use crate::pose_source::PoseSource;
use crate::report::{HiddenObstacle, Progress, RunReport, TimeSplit};
use crate::scenario::Scenario;
use crate::schedule::{Captured, Scheduler, Thought};
use crate::world::World;

pub use crate::judge::{ObstacleReport, Pass, PassOutcome, Stop};
pub use crate::observer::Event;

/// What to run besides the scenario: its offline map, laps and seed, and the configuration.
#[derive(Clone, Debug)]
pub struct RunSetup {
    /// The offline map's directory (built by the mapping drive with the same configuration).
    pub map_dir: std::path::PathBuf,
    /// Laps (default: the scenario's); 0 is refused.
    pub laps: Option<u32>,
    /// Seed (default: the scenario's).
    pub seed: Option<u64>,
    /// The run configuration.
    pub config: RunConfig,
}

impl RunSetup {
    /// The scenario's laps and seed, the default configuration, over the map in `map_dir`.
    pub fn new(map_dir: std::path::PathBuf) -> Self {
        RunSetup {
            map_dir,
            laps: None,
            seed: None,
            config: RunConfig::default(),
        }
    }
}

/// What a run is watched and stopped by from outside; none of it changes what the run does.
pub struct RunHandles<'a> {
    /// Set from outside (Ctrl-C) to end the run with a partial report.
    pub stop: Option<&'a AtomicBool>,
    /// Called about once a simulated second.
    pub progress: &'a mut (dyn FnMut(Progress) + Send),
    /// Shown every step, revolution and event.
    pub observer: &'a mut (dyn Observer + Send),
}

/// The cap of the run's distance maps for a vehicle. No check of the planner or the avoider
/// reads a distance beyond the vehicle's bounding radius plus the planner's safety distance plus
/// the early out's slack (a cell diagonal), so a cap 1 m beyond that changes no decision - and
/// the smaller the cap, the smaller the part of a distance map a change in the map recomputes
/// (`DistanceMap::update`).
pub fn distance_cap_m(model: &CollisionModel, autonomy: &AutonomyConfig) -> f32 {
    let safety = autonomy.planner_safety_m.max(autonomy.avoider_safety_m);
    model.bounding_circle().radius_m as f32 + safety + 1.0 + 0.3
}

/// The half side of the square around the vehicle over which the run's distance maps are
/// computed: no check of the planner or the avoider reads a distance outside it or one that an
/// obstacle outside it could lower. A candidate's pose lies within the horizon plus twice the
/// largest offset of the vehicle (the vehicle may be off the route too); the early out reads the
/// map at the bounding circle's centre up to its radius plus the safety distance plus a cell
/// diagonal, and every circle lies inside the bounding circle; 1 m is kept.
pub fn distance_map_half_size_m(model: &CollisionModel, autonomy: &AutonomyConfig) -> f64 {
    let b = model.bounding_circle();
    let safety = autonomy.planner_safety_m.max(autonomy.avoider_safety_m) as f64;
    autonomy.horizon_m
        + 2.0 * autonomy.max_offset_m
        + b.center.coords.norm()
        + b.radius_m
        + safety
        + 0.3
        + 1.0
}

/// Runs a scenario in closed loop over its offline map (which must exist: see `mapping`).
pub fn run(scenario: &Scenario, setup: &RunSetup) -> Result<RunReport> {
    run_with(
        scenario,
        setup,
        RunHandles {
            stop: None,
            progress: &mut |_| {},
            observer: &mut NoObserver,
        },
    )
}

/// [`run`], watched and stoppable through `handles`.
pub fn run_with(
    scenario: &Scenario,
    setup: &RunSetup,
    handles: RunHandles<'_>,
) -> Result<RunReport> {
    let wall = Instant::now();
    let mut rig = Rig::new(scenario, setup)?;
    let RunHandles {
        stop,
        progress,
        observer,
    } = handles;
    observer.start(&rig.run_start())?;
    let end = rayon::scope(|tasks| rig.drive(tasks, stop, progress, &mut *observer))?;
    let report = rig.report(end, wall.elapsed().as_secs_f64());
    observer.finish(&report)?;
    Ok(report)
}

/// Everything a run is made of.
struct Rig<'a> {
    scenario: &'a Scenario,
    config: RunConfig,
    seed: u64,
    laps: u32,
    scene: crate::scene::Scene,
    world: World,
    lidar: Lidar,
    bicycle: Bicycle,
    model: CollisionModel,
    part_levels: Vec<usize>,
    route: RoutePath,
    pose_source: Box<dyn PoseSource>,
    /// The odometry sensor (noise and bias).
    odometry: crate::odometry::OdometrySensor,
    /// The pose estimates' errors (not kept when the pose source is the truth).
    localization_errors: Option<crate::localization::ErrorLog>,
    driver: Driver,
    scheduler: Scheduler,
    judge: Judge,
    state: VehicleState,
    t_s: f64,
    step: u64,
    steps_per_scan: u64,
    timeout_s: f64,
    split: TimeSplit,
    wall: Instant,
    /// Which revolutions the faults lose.
    lost: crate::faults::LostRevolutions,
    /// What the faults did (the casts run on other threads: atomics, summed at the end).
    dropped_returns: std::sync::atomic::AtomicU64,
    spurious_returns: std::sync::atomic::AtomicU64,
    fault_counts: crate::faults::FaultCounts,
    /// Whether the watchdog held the vehicle at the last step.
    watchdog_holding: bool,
    /// Revolutions taken and not yet delivered (LiDAR latency): when each is due, in order.
    in_transit: std::collections::VecDeque<(f64, Captured)>,
    /// The live map's scratch directory, removed with the rig.
    _live: tempfile::TempDir,
}

impl<'a> Rig<'a> {
    /// The loop: each physics step, as a schedule - obstacles move, the stack hears odometry and
    /// its pose estimate, a revolution is taken and planned from every `1 / scan_hz`, the stack
    /// commands, the vehicle moves, the judge judges.
    fn drive<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        stop: Option<&AtomicBool>,
        progress: &mut (dyn FnMut(Progress) + Send),
        observer: &mut (dyn Observer + Send),
    ) -> Result<EndReason> {
        let dt = 1.0 / self.config.physics_hz;
        while !self.judge.done() {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Ok(EndReason::Interrupted);
            }
            if self.t_s > self.timeout_s {
                return Ok(EndReason::TimedOut);
            }
            if self.driver.calls_for_pilot(self.t_s) {
                return Ok(EndReason::WaitingForHiddenObstacle);
            }
            let physics = Instant::now();
            self.move_obstacles();
            self.split.physics += physics.elapsed().as_secs_f64();
            let truth = self.state.world_from_vehicle();
            self.sense_pose(&truth);
            if self.step.is_multiple_of(self.steps_per_scan) {
                self.revolution(tasks, &truth, observer)?;
            }
            self.deliver_due(tasks, observer)?;
            let holding = self.driver.watchdog_tripped();
            if holding != self.watchdog_holding {
                self.watchdog_holding = holding;
                self.fault_counts.watchdog_stops += u64::from(holding);
                observer.event(self.t_s, &Event::Watchdog { holding })?;
            }
            let physics = Instant::now();
            let command = self.driver.command();
            self.bicycle.step(&mut self.state, &command, dt);
            self.t_s += dt;
            self.step += 1;
            self.world
                .set_vehicle_pose(&self.state.world_from_vehicle(), self.t_s);
            self.split.physics += physics.elapsed().as_secs_f64();
            let verdict =
                self.judge
                    .after_step(self.t_s, &self.state, command.speed_m_s, &self.world);
            for (t, event) in self.judge.drain_events() {
                observer.event(t, &event)?;
            }
            observer.step(&StepFrame {
                t_s: self.t_s,
                state: &self.state,
                command: &command,
                clearance_m: self.judge.clearance_now_m(),
                real_time_factor: self.t_s / self.wall.elapsed().as_secs_f64().max(1e-9),
                world: &self.world,
            })?;
            if verdict.lap_ended && !self.route.closed() && !self.judge.done() {
                self.restart_open_route()?;
            }
            if self.step.is_multiple_of(100) {
                progress(Progress {
                    sim_time_s: self.t_s,
                    laps_completed: self.judge.laps_completed(),
                    fraction: verdict.fraction,
                });
            }
        }
        Ok(EndReason::Completed)
    }

    /// The odometry of this step to the stack and the pose source; the pose source's estimate
    /// (through the pose faults) to the stack, its error logged.
    fn sense_pose(&mut self, truth: &Isometry2<f64>) {
        let odometry =
            self.odometry
                .measure(self.t_s, self.state.speed_m_s, self.state.steering_rad);
        self.driver.on_odometry(odometry);
        let t0 = Instant::now();
        self.pose_source.on_odometry(&odometry);
        let published = self.pose_source.publish(self.t_s, truth);
        self.split.localization += t0.elapsed().as_secs_f64();
        if let Some(mut estimate) = published {
            estimate.world_from_vehicle = self
                .config
                .faults
                .bias_pose(self.t_s, &estimate.world_from_vehicle);
            if let Some(log) = &mut self.localization_errors {
                log.record(self.judge.laps_completed() + 1, truth, &estimate);
            }
            self.driver.on_pose(estimate);
        }
    }

    /// The pose source reads a revolution as the stack receives it.
    fn localize(&mut self, captured: &Captured) -> Result<()> {
        let t0 = Instant::now();
        self.pose_source.on_revolution(&captured.revolution)?;
        self.split.localization += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// A revolution: taken, then (at once, or when its latency has passed) mapped and planned
    /// from as the schedule says, shown to the observer.
    fn revolution<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        truth: &Isometry2<f64>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<()> {
        let Some(estimate) = self.driver.estimate().map(|e| e.world_from_vehicle) else {
            return Ok(());
        };
        let (index, seed, t_s) = (self.step / self.steps_per_scan, self.seed, self.t_s);
        let faults = &self.config.faults;
        if faults.any() && self.lost.is_lost(faults, seed, index) {
            // It never reaches the stack.
            self.fault_counts.lost_revolutions += 1;
            return Ok(());
        }
        let sensor = Sensor {
            world: &self.world,
            lidar: &self.lidar,
            faults,
            seed,
            dropped: &self.dropped_returns,
            spurious: &self.spurious_returns,
        };
        let delay_s = faults.delay_s(seed, index);
        if delay_s > 0.0 {
            // Cast now, in the world as it is now; delivered later, in order.
            let captured = sensor.capture(truth, &estimate, index, t_s)?;
            let last = self.in_transit.back().map_or(0.0, |(at, _)| *at);
            self.in_transit
                .push_back(((t_s + delay_s).max(last), captured));
            self.fault_counts.delayed_revolutions += 1;
            return Ok(());
        }
        self.driver.on_revolution(t_s);
        let capture = || sensor.capture(truth, &estimate, index, t_s);
        let (lidar_s, thought) = self.scheduler.revolution(capture, &mut self.driver)?;
        self.planned(tasks, lidar_s, thought, observer)
    }

    /// Delivers the late revolutions whose time has come.
    fn deliver_due<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<()> {
        while self
            .in_transit
            .front()
            .is_some_and(|(at, _)| *at <= self.t_s + 1e-9)
        {
            let Some((_, captured)) = self.in_transit.pop_front() else {
                break;
            };
            // The watchdog counts a revolution's age from when it was taken.
            self.driver.on_revolution(captured.revolution.t_s);
            let (lidar_s, thought) = self
                .scheduler
                .revolution(move || Ok(captured), &mut self.driver)?;
            self.planned(tasks, lidar_s, thought, observer)?;
        }
        Ok(())
    }

    /// After a revolution's plan: accounts, shows, and (overlapped) starts mapping the next.
    fn planned<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        lidar_s: f64,
        thought: Option<Thought>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<()> {
        self.split.lidar += lidar_s;
        if let Some(thought) = &thought {
            self.show(thought, observer)?;
        }
        self.scheduler.dispatch(tasks);
        if let Some(thought) = &thought {
            // The localizer reads the revolution once the stack has it (overlapped: the one
            // taken a revolution ago, brought forward to now on odometry), beside the mapping
            // of the next.
            self.localize(&thought.captured)?;
        }
        Ok(())
    }

    /// Accounts for a plan and shows it.
    fn show(&mut self, thought: &Thought, observer: &mut (dyn Observer + Send)) -> Result<()> {
        self.split.mapping += thought.mapping_s;
        self.split.distance_maps += thought.times.distance_maps_s;
        self.split.planning += thought.times.planning_s;
        let plan = self.driver.last_plan().ok_or_else(|| {
            Error::Invalid("the driver planned but holds no plan (no pose estimate)".into())
        })?;
        self.judge.on_plan(self.t_s, plan.chosen().offset_m);
        for (t, event) in self.judge.drain_events() {
            observer.event(t, &event)?;
        }
        let map = self
            .scheduler
            .map()
            .ok_or_else(|| Error::Invalid("the online map is not ready".into()))?;
        let v = self.driver.speed_command_m_s();
        let wanted = self.scenario.route.speed_m_s;
        observer.scan(&ScanFrame {
            t_s: self.t_s,
            truth: thought.captured.truth,
            estimate: thought.captured.revolution.world_from_vehicle_estimate,
            revolution: &thought.captured.revolution,
            owners: &thought.captured.owners,
            map: map.map(),
            plan,
            speed_cmd_m_s: v,
            speed_scale: if wanted > 0.0 { v / wanted } else { 0.0 },
            world: &self.world,
            particles: self.pose_source.particles(),
            pose_estimate: self.driver.estimate().copied(),
        })
    }

    /// Run-time obstacles appear, move and go as the scenario says.
    fn move_obstacles(&mut self) {
        let first = self.scenario.objects.len();
        for (k, o) in self.scenario.obstacles.iter().enumerate() {
            let i = first + k;
            match o.pose_at(self.t_s) {
                Some((x, y, yaw)) => {
                    if !self.world.object_active(i) {
                        self.world.set_object_active(i, true);
                    }
                    if o.motion.is_some() {
                        self.world.set_object_pose(i, x, y, yaw);
                    }
                }
                None if self.world.object_active(i) => self.world.set_object_active(i, false),
                None => {}
            }
        }
    }

    /// An open route starts its next lap from its start pose.
    fn restart_open_route(&mut self) -> Result<()> {
        self.state = start_state(&self.scenario.vehicle.world_from_start);
        self.judge.restart_lap();
        self.driver.restart();
        self.pose_source
            .reset(&self.scenario.vehicle.world_from_start)?;
        // Revolutions of the last lap still in transit would carry its poses into this one.
        self.in_transit.clear();
        self.world
            .set_vehicle_pose(&self.state.world_from_vehicle(), self.t_s);
        Ok(())
    }
}

fn start_state(start: &Isometry2<f64>) -> VehicleState {
    VehicleState {
        x_m: start.translation.x,
        y_m: start.translation.y,
        yaw_rad: start.rotation.angle(),
        ..Default::default()
    }
}

/// A scan's points moved from the true pose to the estimated one: where a mapper with a wrong
/// pose would put them.
fn reexpress(
    scan: mapper::Scan,
    truth: &Isometry2<f64>,
    estimate: &Isometry2<f64>,
) -> Result<mapper::Scan> {
    let lift = crate::world::planar_to_3d;
    let correction = lift(estimate) * lift(truth).inverse();
    Ok(scan.moved(&correction, estimate)?)
}

/// What a revolution is cast with: the world, the LiDAR, and the faults between them.
struct Sensor<'r> {
    world: &'r World,
    lidar: &'r Lidar,
    faults: &'r crate::faults::FaultsConfig,
    seed: u64,
    /// Fault counters (the casts may run on another thread).
    dropped: &'r std::sync::atomic::AtomicU64,
    spurious: &'r std::sync::atomic::AtomicU64,
}

impl Sensor<'_> {
    /// Revolution `index`, taken at `t_s` from the true pose, degraded by the faults, its points
    /// where a mapper at `estimate` would put them.
    fn capture(
        &self,
        truth: &Isometry2<f64>,
        estimate: &Isometry2<f64>,
        index: u64,
        t_s: f64,
    ) -> Result<Captured> {
        let t0 = Instant::now();
        let mut taken = self
            .lidar
            .scan(self.world, &SweepPoses::still(*truth), index, self.seed);
        if self.faults.any() {
            let mut counts = crate::faults::FaultCounts::default();
            taken.scan =
                crate::faults::degrade(&taken.scan, self.faults, self.seed, index, &mut counts)?;
            taken.owners.truncate(0);
            self.dropped
                .fetch_add(counts.dropped_returns, Ordering::Relaxed);
            self.spurious
                .fetch_add(counts.spurious_returns, Ordering::Relaxed);
        }
        let scan = if estimate == truth {
            taken.scan
        } else {
            reexpress(taken.scan, truth, estimate)?
        };
        Ok(Captured {
            revolution: LidarRevolution {
                t_s,
                scan,
                world_from_vehicle_estimate: *estimate,
            },
            owners: taken.owners,
            truth: *truth,
            lidar_s: t0.elapsed().as_secs_f64(),
        })
    }
}

impl<'a> Rig<'a> {
    /// Builds the world, the sensors, the stack (over the offline map in `setup.map_dir`), the
    /// pose source and the judge.
    fn new(scenario: &'a Scenario, setup: &RunSetup) -> Result<Self> {
        let config = setup.config.clone();
        config.validate().map_err(|message| Error::Config {
            origin: "run configuration".into(),
            message,
        })?;
        let laps = setup.laps.unwrap_or(scenario.laps);
        if laps == 0 {
            return Err(Error::Invalid(
                "laps = 0: a run drives at least one lap".into(),
            ));
        }
        let seed = setup.seed.unwrap_or(scenario.seed);
        let vehicle = &scenario.vehicle.vehicle;
        let model = config.collision_model(vehicle)?;
        let heights = model.level_heights_m().to_vec();
        let part_levels: Vec<usize> = vehicle
            .parts
            .iter()
            .map(|p| aircraft::fit::level_of(p.underside_m(), &heights))
            .collect();
        let route = RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed);
        let start = scenario.vehicle.world_from_start;
        let scene = scenario.scene(true);
        let mut world = World::new(&scene, true, vehicle, &start);
        let lidar =
            Lidar::new(config.lidar.clone(), vehicle.vehicle_from_lidar()).map_err(|e| {
                Error::Config {
                    origin: "lidar".into(),
                    message: e.to_string(),
                }
            })?;
        let live = tempfile::tempdir().map_err(|source| Error::Io {
            what: "creating the live map's scratch directory",
            path: std::env::temp_dir(),
            source,
        })?;
        let map_config = mapper::MapConfig {
            max_distance_m: distance_cap_m(&model, &config.autonomy),
            ..config.mapping.map
        };
        let map = MultiHeightMap::with_stores(
            map_config,
            crate::mapping::levels_of(scenario, &config)?,
            Point2::from(start.translation.vector),
            Some(&setup.map_dir.join("blocks")),
            Some(live.path()),
        )?;
        let online = OnlineMap::new(
            map,
            crate::mapping::self_filter_model(vehicle)?,
            config.mapping.forgetting.clone(),
            1.0 / config.scan_hz,
        );
        let odm_half_size_m = config
            .mapping
            .distance_map_half_size_m
            .unwrap_or_else(|| distance_map_half_size_m(&model, &config.autonomy));
        let driver = Driver::new(
            route.clone(),
            VehicleModel {
                collision: model.clone(),
                wheelbase_m: vehicle.spec.motion.wheelbase_m,
                deceleration_m_s2: vehicle.spec.motion.max_deceleration_m_s2,
                behaviour: Behaviour::for_steering(vehicle.spec.motion.steering),
            },
            config.autonomy.clone(),
            scenario.route.speed_m_s,
            odm_half_size_m,
        );
        let first_obstacle = scenario.objects.len();
        let judge = Judge::new(
            scenario,
            &route,
            laps,
            part_levels.clone(),
            heights.len(),
            first_obstacle,
            Point2::from(start.translation.vector),
        );
        let state = start_state(&start);
        world.set_vehicle_pose(&state.world_from_vehicle(), 0.0);
        let pose_source = crate::pose_source::from_config(
            &config.pose_source,
            seed,
            crate::pose_source::LocalizationContext {
                blocks_dir: &setup.map_dir.join("blocks"),
                map: config.mapping.map,
                levels: crate::mapping::levels_of(scenario, &config)?,
                wheelbase_m: vehicle.spec.motion.wheelbase_m,
                self_filter: crate::mapping::self_filter_model(vehicle)?,
                self_margin_m: config.mapping.map.self_hit_margin_m,
                start,
            },
        )?;
        let total_m = route.length_m() * laps as f64;
        Ok(Rig {
            scenario,
            seed,
            laps,
            scene,
            world,
            lidar,
            bicycle: Bicycle::new(vehicle.spec.motion.clone()),
            model,
            part_levels,
            route,
            pose_source,
            odometry: crate::odometry::OdometrySensor::new(config.odometry.clone(), seed),
            localization_errors: (config.pose_source != crate::config::PoseSourceConfig::Truth)
                .then(crate::localization::ErrorLog::default),
            driver,
            scheduler: Scheduler::new(config.schedule, online),
            judge,
            state,
            t_s: 0.0,
            step: 0,
            steps_per_scan: (config.physics_hz / config.scan_hz).round().max(1.0) as u64,
            timeout_s: 60.0 + 4.0 * total_m / scenario.route.speed_m_s,
            split: TimeSplit::default(),
            wall: Instant::now(),
            lost: crate::faults::LostRevolutions::default(),
            dropped_returns: Default::default(),
            spurious_returns: Default::default(),
            fault_counts: crate::faults::FaultCounts::default(),
            watchdog_holding: false,
            in_transit: std::collections::VecDeque::new(),
            config,
            _live: live,
        })
    }

    /// What the observer is shown before the first step.
    fn run_start(&self) -> RunStart<'_> {
        RunStart {
            scenario: self.scenario,
            scene: &self.scene,
            first_obstacle: self.scenario.objects.len(),
            route: &self.route,
            model: &self.model,
            part_levels: &self.part_levels,
            lidar: &self.lidar,
            laps: self.laps,
            seed: self.seed,
            config: &self.config,
        }
    }

    /// The report, once the loop has ended for `end`.
    fn report(mut self, end: EndReason, wall_time_s: f64) -> RunReport {
        let contacts = self.world.contacts().to_vec();
        if matches!(
            end,
            EndReason::TimedOut | EndReason::WaitingForHiddenObstacle
        ) {
            // The vehicle may stand before an obstacle: its pass closes as it stands.
            self.judge.close_open_passes(self.t_s, &self.world);
        }
        let waiting_for = match (end, self.driver.status()) {
            (
                EndReason::WaitingForHiddenObstacle,
                DriverStatus::WaitingForHiddenObstacle {
                    obstacle,
                    last_seen_s,
                    since_s,
                },
            ) => Some(HiddenObstacle {
                x_m: obstacle.x,
                y_m: obstacle.y,
                last_seen_s,
                since_s,
            }),
            _ => None,
        };
        let verdict = self
            .judge
            .verdict(end, self.scenario.expected_end, &contacts);
        RunReport {
            scenario: self.scenario.name.clone(),
            seed: self.seed,
            expectations_met: verdict.expectations_met,
            end,
            waiting_for,
            laps: self.laps,
            laps_completed: verdict.laps_completed,
            lap_times_s: verdict.lap_times_s,
            contacts,
            obstacles: verdict.obstacles,
            stops: verdict.stops,
            min_clearance_m: verdict.min_clearance_m,
            danger_distance_m: self.scenario.danger_distance_m,
            sim_time_s: self.t_s,
            wall_time_s,
            real_time_factor: self.t_s / wall_time_s.max(1e-9),
            time_split_s: self.split,
            faults: crate::faults::FaultCounts {
                dropped_returns: self.dropped_returns.load(Ordering::Relaxed),
                spurious_returns: self.spurious_returns.load(Ordering::Relaxed),
                ..self.fault_counts
            },
            localization: self.localization_errors.as_ref().map(|l| l.report()),
            config: self.config,
        }
    }
}
