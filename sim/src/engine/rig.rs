//! The rig: everything a closed-loop run is made of - the world and its sensors, the pose
//! source, the stack under test, the schedule and the judge - built from a scenario and a run
//! configuration ([`run`], [`run_with`]; with a stack outside the process, [`run_external`]); the
//! loop that ticks it is `closed_loop`.
//!
//! Rates: physics (vehicle motion, ground truth, moving obstacles) at `physics_hz` (100 Hz); one
//! LiDAR revolution, map update and plan every `1 / scan_hz` (10 Hz). The stack gets sensor
//! messages (revolutions stamped with the pose estimate, the estimate, odometry) and nothing else
//! from the world; the judge reads the world. A run is a pure function of (scenario, seed, run
//! configuration).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use autonomy::{
    AutonomyConfig, Behaviour, BlindZone, Driver, DriverStatus, OnlineMap, RoutePath, VehicleModel,
};
use mapper::{CollisionModel, MultiHeightMap};
use nalgebra::{Isometry2, Point2};

use super::external::{External, ExternalStack, LatePolicy, StackReport, StackStart};
use super::judge::Judge;
use super::observer::{NoObserver, Observer, RunStart};
use super::outcome::EndReason;
use super::pose_source::PoseSource;
use super::report::{HiddenObstacle, Progress, RunReport, SpeedLowered, TimeSplit};
use super::schedule::Scheduler;
use crate::error::{Error, Result};
use crate::scenario::{RunConfig, Scenario, WalkAround};
use crate::world::Captured;
use crate::world::Lidar;
use crate::world::World;
use crate::world::coverage::{CoverageOptions, coverage};
use crate::world::{Bicycle, VehicleState};

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
    /// A bound on the simulated time, seconds, under the run's own (60 s plus four times the
    /// route's length over its speed); `None`: the run's own.
    pub time_limit_s: Option<f64>,
}

impl RunSetup {
    /// The scenario's laps and seed, the default configuration, over the map in `map_dir`.
    pub fn new(map_dir: std::path::PathBuf) -> Self {
        RunSetup {
            map_dir,
            laps: None,
            seed: None,
            config: RunConfig::default(),
            time_limit_s: None,
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
/// diagonal, and every circle lies inside the bounding circle; 1 m is kept. `horizon_m` is the
/// longest horizon the planner will check ([`longest_horizon_m`]).
pub fn distance_map_half_size_m(
    model: &CollisionModel,
    autonomy: &AutonomyConfig,
    horizon_m: f64,
) -> f64 {
    let b = model.bounding_circle();
    let safety = autonomy.planner_safety_m.max(autonomy.avoider_safety_m) as f64;
    horizon_m
        + 2.0 * autonomy.max_offset_m
        + b.center.coords.norm()
        + b.radius_m
        + safety
        + 0.3
        + 1.0
}

/// The longest horizon the planner checks on a route at `route_m_s` with braking
/// `deceleration_m_s2`: the horizon grows with the speed it drives (the route's, capped to
/// what it can stop from within the longest horizon and the detection range).
pub fn longest_horizon_m(route_m_s: f64, deceleration_m_s2: f64, autonomy: &AutonomyConfig) -> f64 {
    let cap = autonomy::planner::speed_cap_m_s(deceleration_m_s2, autonomy).0;
    autonomy::planner::horizon_for_m(route_m_s.min(cap), deceleration_m_s2, autonomy)
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
    run_rig(Rig::new(scenario, setup)?, handles)
}

/// [`run_with`], with `stack` - a stack outside the process, through its transport - driving the
/// vehicle in lockstep instead of the shipped one ([`super::external`]); `policy` says what a
/// late answer costs.
pub fn run_external<'a>(
    scenario: &'a Scenario,
    setup: &RunSetup,
    handles: RunHandles<'_>,
    stack: &'a mut dyn ExternalStack,
    policy: LatePolicy,
) -> Result<RunReport> {
    one_lidar_on_the_wire(&scenario.vehicle.vehicle)?;
    let mut rig = Rig::new(scenario, setup)?;
    let route_m: Vec<Point2<f64>> = scenario.route.waypoints_m.clone();
    let levels = crate::offline_map::levels_of(scenario, &setup.config)?;
    stack.start(&StackStart {
        scenario: &scenario.name,
        world_from_odom: scenario.vehicle.world_from_start,
        vehicle_from_lidar: scenario.vehicle.vehicle.vehicle_from_lidar(),
        wheelbase_m: rig.bicycle.limits().wheelbase_m,
        route_m: &route_m,
        model: &rig.model,
        level_heights_m: levels.heights_m(),
        map_dir: &setup.map_dir,
    })?;
    rig.external = Some(External::new(stack, policy));
    run_rig(rig, handles)
}

fn run_rig(mut rig: Rig<'_>, handles: RunHandles<'_>) -> Result<RunReport> {
    let wall = Instant::now();
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
pub(super) struct Rig<'a> {
    pub(super) scenario: &'a Scenario,
    pub(super) config: RunConfig,
    pub(super) seed: u64,
    pub(super) laps: u32,
    pub(super) scene: crate::world::Scene,
    pub(super) world: World,
    pub(super) lidar: Lidar,
    /// The vehicle's other LiDARs (its sidecar's `extra_lidars`).
    pub(super) more_lidars: Vec<crate::world::NamedLidar>,
    pub(super) bicycle: Bicycle,
    pub(super) model: CollisionModel,
    pub(super) part_levels: Vec<usize>,
    pub(super) route: RoutePath,
    pub(super) pose_source: Box<dyn PoseSource>,
    /// The odometry sensor (noise and bias).
    pub(super) odometry: crate::world::OdometrySensor,
    /// The pose estimates' errors (not kept when the pose source is the truth).
    pub(super) localization_errors: Option<super::pose_error::ErrorLog>,
    pub(super) driver: Driver,
    pub(super) scheduler: Scheduler,
    pub(super) judge: Judge,
    /// The run-time obstacles, moved each step (`Rig::move_obstacles`).
    pub(super) traffic: super::traffic::Traffic,
    pub(super) state: VehicleState,
    pub(super) t_s: f64,
    pub(super) step: u64,
    pub(super) steps_per_scan: u64,
    pub(super) timeout_s: f64,
    pub(super) split: TimeSplit,
    pub(super) wall: Instant,
    /// Which revolutions the faults lose.
    pub(super) lost: crate::world::LostRevolutions,
    /// What the faults did (the casts run on other threads: atomics, summed at the end).
    pub(super) dropped_returns: std::sync::atomic::AtomicU64,
    pub(super) spurious_returns: std::sync::atomic::AtomicU64,
    pub(super) fault_counts: crate::world::FaultCounts,
    /// Whether the watchdog held the vehicle at the last step.
    pub(super) watchdog_holding: bool,
    /// Revolutions taken and not yet delivered (LiDAR latency): when each is due, in order.
    pub(super) in_transit: std::collections::VecDeque<(f64, Captured)>,
    /// When the crew's walk-around is still to come (`[vehicle] walk_around` at a time), seconds.
    pub(super) walk_around_at_s: Option<f64>,
    /// Whether the observer has been told of the ground the start-up rule found unseen.
    pub(super) start_unseen_told: bool,
    /// How many of the world's contacts the strike sensor has read.
    pub(super) contacts_felt: usize,
    /// What held the vehicle in the last seconds, for the pilot call's report.
    pub(super) holds: super::pilot_call::HoldLog,
    /// The pilot call that ended the run, if one did.
    pub(super) pilot_call: Option<super::PilotCallReport>,
    /// The push-back under way (a taxi route from a stand the vehicle faces away from its
    /// taxilane), and once the tug let go what it did.
    pub(super) towing: Option<super::pushback::Towing>,
    pub(super) pushback: Option<super::PushbackReport>,
    /// A stack outside the process driving the vehicle instead of `driver`, if any.
    pub(super) external: Option<External<'a>>,
    /// The live map's scratch directory, removed with the rig.
    pub(super) _live: tempfile::TempDir,
}

pub(super) fn start_state(start: &Isometry2<f64>) -> VehicleState {
    VehicleState {
        x_m: start.translation.x,
        y_m: start.translation.y,
        yaw_rad: start.rotation.angle(),
        ..Default::default()
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
        let route = RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed)
            .with_speed_limits(scenario.route.speed_limits_m_s.clone());
        let start = scenario.vehicle.world_from_start;
        let scene = scenario.full_scene();
        let mut world = World::with_obstacles(&scene, vehicle, &start);
        let (lidar, more_lidars) = lidars(vehicle, &config)?;
        let (online, live) = online_map(scenario, &config, &model, setup, &start)?;
        let online = online.with_more_masks(self_masks(&more_lidars, &world)?);
        let mut driver = driver(scenario, &config, &model, &route);
        let walk_around = scenario.vehicle.walk_around;
        if walk_around != WalkAround::BeforeStart {
            driver.await_walk_around(blind_zone(vehicle, &config.lidar, &model)?);
        }
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
        let pose_source = super::pose_source::from_config(
            &config.pose_source,
            seed,
            super::pose_source::LocalizationContext {
                blocks_dir: &setup.map_dir.join("blocks"),
                map: config.mapping.map,
                levels: crate::offline_map::levels_of(scenario, &config)?,
                wheelbase_m: vehicle.spec.motion.wheelbase_m,
                self_filter: crate::offline_map::self_filter_model(vehicle)?,
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
            more_lidars,
            bicycle: Bicycle::new(vehicle.spec.motion.clone()),
            model,
            part_levels,
            route,
            pose_source,
            odometry: crate::world::OdometrySensor::new(config.odometry.clone(), seed),
            localization_errors: (config.pose_source != crate::scenario::PoseSourceConfig::Truth)
                .then(super::pose_error::ErrorLog::default),
            driver,
            scheduler: Scheduler::new(config.schedule, online),
            judge,
            traffic: super::traffic::Traffic::new(&scenario.obstacles, vehicle),
            state,
            t_s: 0.0,
            step: 0,
            steps_per_scan: (config.physics_hz / config.scan_hz).round().max(1.0) as u64,
            timeout_s: (60.0 + 4.0 * total_m / scenario.route.speed_m_s)
                .min(setup.time_limit_s.unwrap_or(f64::INFINITY)),
            split: TimeSplit::default(),
            wall: Instant::now(),
            lost: crate::world::LostRevolutions::default(),
            dropped_returns: Default::default(),
            spurious_returns: Default::default(),
            fault_counts: crate::world::FaultCounts::default(),
            watchdog_holding: false,
            in_transit: std::collections::VecDeque::new(),
            walk_around_at_s: match walk_around {
                WalkAround::At(t) => Some(t),
                _ => None,
            },
            start_unseen_told: false,
            contacts_felt: 0,
            holds: Default::default(),
            pilot_call: None,
            towing: scenario
                .route
                .pushback
                .as_ref()
                .map(|t| super::pushback::Towing::new(t, vehicle.spec.motion.wheelbase_m)),
            pushback: None,
            config,
            external: None,
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
            more_lidars: &self.more_lidars,
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
            EndReason::TimedOut
                | EndReason::WaitingForHiddenObstacle
                | EndReason::Blocked
                | EndReason::WaitingForWalkAround
                | EndReason::StackTimeout
                | EndReason::StackFailed
                | EndReason::Struck
        ) {
            // The vehicle may stand before an obstacle: its pass closes as it stands.
            self.judge.close_open_passes(self.t_s, end);
        }
        let waiting_for = match (end, self.driver.status()) {
            (
                EndReason::WaitingForHiddenObstacle,
                DriverStatus::WaitingForHiddenObstacle {
                    obstacle,
                    last_seen_s,
                    since_s,
                    ..
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
        let localization = self.localization_errors.as_ref().map(|l| l.report());
        let localized =
            super::pose_error::localization_misses(self.scenario, localization.as_ref());
        RunReport {
            scenario: self.scenario.name.clone(),
            seed: self.seed,
            expectations_met: verdict.expectations_met && localized.is_empty(),
            end,
            waiting_for,
            start_unseen_m2: self.driver.start_unseen_m2(),
            pilot_call: self.pilot_call.take(),
            pushback: self.pushback.take(),
            stack: self.external.as_ref().map(|e| StackReport {
                stale: e.stack.stale(),
                ..e.report.clone()
            }),
            laps: self.laps,
            laps_completed: verdict.laps_completed,
            lap_times_s: verdict.lap_times_s,
            contacts,
            contacts_judged: verdict.contacts,
            contacts_at_fault: verdict.contacts_at_fault,
            contacts_struck: verdict.contacts_struck,
            contacts_struck_while_moving: verdict.contacts_struck_while_moving,
            obstacles: verdict.obstacles,
            stops: verdict.stops,
            min_clearance_m: verdict.min_clearance_m,
            closest_static: super::report::closest_static(
                &self.scene,
                self.world.min_clearances_m(),
            ),
            danger_distance_m: self.scenario.danger_distance_m,
            sim_time_s: self.t_s,
            wall_time_s,
            real_time_factor: self.t_s / wall_time_s.max(1e-9),
            time_split_s: self.split,
            faults: crate::world::FaultCounts {
                dropped_returns: self.dropped_returns.load(Ordering::Relaxed),
                spurious_returns: self.spurious_returns.load(Ordering::Relaxed),
                ..self.fault_counts
            },
            localization,
            speed_lowered: self
                .driver
                .route_speed_lowered()
                .map(|(cap_m_s, limit)| SpeedLowered {
                    route_m_s: self.scenario.route.speed_m_s,
                    cap_m_s,
                    limit,
                }),
            config: self.config,
        }
    }
}

/// The stack's online map: the offline map's blocks in `setup.map_dir` under a live store in a
/// scratch directory (removed with the returned guard), the self-hit filter, the forgetting rule.
pub(super) fn online_map(
    scenario: &Scenario,
    config: &RunConfig,
    model: &CollisionModel,
    setup: &RunSetup,
    start: &Isometry2<f64>,
) -> Result<(OnlineMap, tempfile::TempDir)> {
    let vehicle = &scenario.vehicle.vehicle;
    let live = tempfile::tempdir().map_err(|source| Error::Io {
        what: "creating the live map's scratch directory",
        path: std::env::temp_dir(),
        source,
    })?;
    let map_config = mapper::MapConfig {
        max_distance_m: distance_cap_m(model, &config.autonomy),
        ..config.mapping.map
    };
    let map = MultiHeightMap::with_stores(
        map_config,
        crate::offline_map::levels_of(scenario, config)?,
        Point2::from(start.translation.vector),
        Some(&setup.map_dir.join("blocks")),
        Some(live.path()),
    )?;
    let online = OnlineMap::new(
        map,
        crate::offline_map::self_filter_model(vehicle)?,
        config.mapping.forgetting.clone(),
        1.0 / config.scan_hz,
        config.mapping.max_return_error_m,
    );
    Ok((online, live))
}

/// Refuses a vehicle with more than one LiDAR for a stack behind the wire: the messages carry
/// one cloud (`/velodyne_points`), and a stack told of ground only the others see would be
/// judged on what it was never sent.
pub(super) fn one_lidar_on_the_wire(vehicle: &aircraft::Vehicle) -> Result<()> {
    match vehicle.spec.extra_lidars.len() {
        0 => Ok(()),
        n => Err(Error::Invalid(format!(
            "vehicle {} carries {} LiDARs ({n} in extra_lidars); a stack over the wire is sent \
             the main one's cloud only: run it with the shipped stack in the process, or use a \
             vehicle with one LiDAR",
            vehicle.spec.name,
            n + 1
        ))),
    }
}

/// How far a return may fall short of where its ray meets the airframe and still be the
/// airframe's (range noise, 4 mm; a laser's bias, a few cm at most), metres.
pub const SELF_MASK_TOLERANCE_M: f64 = 0.1;

/// Each of `lidars`' self mask: the rays that meet the vehicle in `world`, at the range they do.
pub(super) fn self_masks(
    lidars: &[crate::world::NamedLidar],
    world: &World,
) -> Result<Vec<mapper::SelfMask>> {
    lidars
        .iter()
        .map(|l| {
            let ranges: Vec<Option<f64>> = l
                .lidar
                .rays_in_vehicle(world)
                .into_iter()
                .map(|(_, t)| t)
                .collect();
            let beams = l.lidar.elevations_rad().len();
            Ok(mapper::SelfMask::new(
                beams,
                &ranges,
                SELF_MASK_TOLERANCE_M,
            )?)
        })
        .collect()
}

/// The vehicle's LiDARs: the main one as the run configuration describes it, and the others
/// its sidecar lists ([`crate::world::coverage::vehicle_lidars`]).
pub(super) fn lidars(
    vehicle: &aircraft::Vehicle,
    config: &RunConfig,
) -> Result<(Lidar, Vec<crate::world::NamedLidar>)> {
    let mut all = Vec::new();
    for m in crate::world::coverage::vehicle_lidars(vehicle, &config.lidar)? {
        let lidar =
            Lidar::new(m.config, m.vehicle_from_sensor).map_err(|message| Error::Config {
                origin: format!("lidar {}", m.name),
                message,
            })?;
        all.push(crate::world::NamedLidar {
            name: m.name,
            lidar,
        });
    }
    let main = all.remove(0).lidar;
    Ok((main, all))
}

/// The ground round `vehicle` that its LiDARs (the main one as `lidar`) cannot see, per level of `model` (the
/// levels' heights as the model has them), on 0.2 m cells out to 20 m: what the stack knows of
/// its own sensor layout for the start-up rule.
pub(super) fn blind_zone(
    vehicle: &aircraft::Vehicle,
    lidar: &crate::world::LidarConfig,
    model: &CollisionModel,
) -> Result<BlindZone> {
    let mut v = vehicle.clone();
    v.spec.heights_of_interest_m = model.level_heights_m().to_vec();
    let options = CoverageOptions {
        cell_m: 0.2,
        ..CoverageOptions::default()
    };
    let c = coverage(&v, lidar, &options)?;
    Ok(BlindZone {
        min_m: c.grid.min_m,
        cell_m: c.grid.cell_m,
        cells: c.grid.cells,
        levels: c.levels.into_iter().map(|l| l.blind).collect(),
    })
}

/// The stack under test's driver over `route`, with the vehicle's collision model and motion.
pub(super) fn driver(
    scenario: &Scenario,
    config: &RunConfig,
    model: &CollisionModel,
    route: &RoutePath,
) -> Driver {
    let vehicle = &scenario.vehicle.vehicle;
    let odm_half_size_m = config.mapping.distance_map_half_size_m.unwrap_or_else(|| {
        let horizon = longest_horizon_m(
            scenario.route.speed_m_s,
            vehicle.spec.motion.max_deceleration_m_s2,
            &config.autonomy,
        );
        distance_map_half_size_m(model, &config.autonomy, horizon)
    });
    Driver::new(
        route.clone(),
        VehicleModel {
            collision: model.clone(),
            wheelbase_m: vehicle.spec.motion.wheelbase_m,
            deceleration_m_s2: vehicle.spec.motion.max_deceleration_m_s2,
            acceleration_m_s2: vehicle.spec.motion.max_acceleration_m_s2,
            behaviour: Behaviour::for_steering(vehicle.spec.motion.steering),
        },
        config.autonomy.clone(),
        scenario.route.speed_m_s,
        odm_half_size_m,
    )
}
