//! The closed loop: world, LiDAR, online multi-height mapping, planner, avoider, behaviour and
//! follower, judged by ground truth, reported per lap and per obstacle pass.
//!
//! Rates: physics (vehicle motion, ground truth, moving obstacles) at `physics_hz` (100 Hz); one
//! LiDAR revolution, map update and plan every `1 / scan_hz` (10 Hz). The autonomy gets the
//! vehicle pose with optional Gaussian noise (a localizer comes later) and nothing else from the
//! world. A run is a pure function of (scenario, seed, options).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::Context as _;
use mapper::{CollisionModel, MultiHeightMap};
use nalgebra::{Isometry2, Point2};
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::autonomy::{AutonomyConfig, Behaviour, Plan, RoutePath, avoid, plan, pure_pursuit};
use crate::lidar::{Lidar, LidarConfig, SweepPoses};
use crate::motion::{Bicycle, Command, VehicleState};
use crate::scenario::{Expectation, Scenario};
use crate::world::{Contact, World};

/// Options of a run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Laps (default: the scenario's).
    pub laps: Option<u32>,
    /// Seed (default: the scenario's).
    pub seed: Option<u64>,
    /// The offline map's directory (built by the mapping drive).
    pub map_dir: std::path::PathBuf,
    /// Physics rate, Hz. Default 100.
    pub physics_hz: f64,
    /// LiDAR, mapping and planning rate, Hz. Default 10.
    pub scan_hz: f64,
    /// Standard deviation of the pose given to the autonomy: position (m) and heading (rad). Default 0.
    pub pose_noise: (f64, f64),
    /// Planner, avoider and follower.
    pub autonomy: AutonomyConfig,
    /// Distance maps are computed over a square of this half side around the vehicle, metres.
    /// Default `None`: [`distance_map_half_size_m`] of the vehicle and planner, so every
    /// collision decision sees the same distances as over the whole window.
    pub distance_map_half_size_m: Option<f64>,
    /// Forgetting works over a square of this half side around the vehicle, metres. Default 50.
    pub forget_half_size_m: f64,
    /// Live occupancy the LiDAR no longer sees fades back to the offline map with this time
    /// constant, seconds (`MultiHeightMap::forget_unseen`, CARMEN's decay to the offline map);
    /// `None`: never (a moving vehicle's trail hidden behind the airframe then stays). Default
    /// 10 s: a cell seen occupied once stops being an obstacle about 7 s after it was last seen.
    pub forget_time_constant_s: Option<f64>,
    /// Map and plan from the revolution taken one scan period ago while the LiDAR takes the
    /// next one, as on the vehicle, where a revolution is mapped while the sensor turns: the map
    /// the planner sees is one revolution (0.1 s) old, the pose is current. Default true; false
    /// maps and plans each revolution the instant it is taken.
    pub overlap_sensing: bool,
    /// Set from outside (Ctrl-C) to end the run with a partial report.
    pub stop: Arc<AtomicBool>,
}

impl RunOptions {
    /// Defaults with the given map directory.
    pub fn new(map_dir: std::path::PathBuf) -> Self {
        RunOptions {
            laps: None,
            seed: None,
            map_dir,
            physics_hz: 100.0,
            scan_hz: 10.0,
            pose_noise: (0.0, 0.0),
            autonomy: AutonomyConfig::default(),
            distance_map_half_size_m: None,
            forget_half_size_m: 50.0,
            forget_time_constant_s: Some(10.0),
            overlap_sensing: true,
            stop: Arc::new(AtomicBool::new(false)),
        }
    }
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

/// One pass of the vehicle by an obstacle.
#[derive(Clone, Debug, Serialize)]
pub struct Pass {
    /// Lap (1-based).
    pub lap: u32,
    /// `passed` (no deviation, no stop), `deviated`, `stopped`, `collided`.
    pub outcome: String,
    /// Smallest ground-truth distance from the obstacle to the vehicle's parts of each level, metres.
    pub min_clearance_m: Vec<f64>,
    /// Largest lateral offset from the route near the obstacle, metres.
    pub max_offset_m: f64,
    /// Whether this pass met the obstacle's expectation: the outcome it expects, no contact, and
    /// no clearance under the scenario's danger distance (when it states one).
    pub met: bool,
}

/// An obstacle and what happened at each pass.
#[derive(Clone, Debug, Serialize)]
pub struct ObstacleReport {
    /// Its id.
    pub id: String,
    /// Its kind.
    pub kind: String,
    /// What the scenario expects.
    pub expected: String,
    /// Every pass.
    pub passes: Vec<Pass>,
}

/// A stop of the vehicle.
#[derive(Clone, Debug, Serialize)]
pub struct Stop {
    /// When it stopped, seconds.
    pub start_s: f64,
    /// When it moved again, seconds (`None`: still stopped at the end).
    pub end_s: Option<f64>,
    /// Where along the route, metres.
    pub route_s_m: f64,
}

/// What a run did.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// Scenario name.
    pub scenario: String,
    /// Seed used.
    pub seed: u64,
    /// True when every expectation held and every lap was completed.
    pub expectations_met: bool,
    /// Laps asked for.
    pub laps: u32,
    /// Laps completed.
    pub laps_completed: u32,
    /// Lap times, seconds.
    pub lap_times_s: Vec<f64>,
    /// Ground-truth contacts.
    pub contacts: Vec<Contact>,
    /// Per run-time obstacle.
    pub obstacles: Vec<ObstacleReport>,
    /// Stops.
    pub stops: Vec<Stop>,
    /// Smallest ground-truth clearance per level to any object, metres.
    pub min_clearance_m: Vec<f64>,
    /// The scenario's danger distance, metres (`None`: not stated): a pass closer than this to
    /// its obstacle, at any level, does not meet its expectation.
    pub danger_distance_m: Option<f64>,
    /// Simulated time, seconds.
    pub sim_time_s: f64,
    /// Wall time, seconds.
    pub wall_time_s: f64,
    /// Simulated seconds per wall second.
    pub real_time_factor: f64,
    /// True when the run was interrupted (Ctrl-C) or timed out.
    pub interrupted: bool,
    /// Where the wall time went, seconds: LiDAR, mapping, distance maps, planning, physics.
    pub time_split_s: TimeSplit,
}

/// Wall time per stage, seconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TimeSplit {
    /// Ray casting.
    pub lidar: f64,
    /// Scan insertion.
    pub mapping: f64,
    /// Distance maps.
    pub distance_maps: f64,
    /// Planner and avoider.
    pub planning: f64,
    /// Motion, ground truth, obstacles.
    pub physics: f64,
}

/// Progress of a run, for a progress bar.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Simulated time, seconds.
    pub sim_time_s: f64,
    /// Laps completed.
    pub laps_completed: u32,
    /// Fraction of the whole run done, 0..1.
    pub fraction: f64,
}

struct PassTracker {
    solid_index: usize,
    route_s: f64,
    expect: Expectation,
    active: bool,
    offset: f64,
    stopped: bool,
    /// Whether the obstacle was in the world at some time in the window (one that appears or
    /// disappears may be absent on some laps: no pass then).
    present: bool,
    clearance: Vec<f64>,
    contacts_before: usize,
}

/// What a run shows as it goes (the replay implements it; see `replay`). Every method has a
/// no-op default; what is passed is borrowed for the call only. An error ends the run.
pub trait Observer {
    /// Once, before the first step.
    fn start(&mut self, _run: &RunStart<'_>) -> anyhow::Result<()> {
        Ok(())
    }
    /// After every LiDAR revolution, map update and plan (10 Hz).
    fn scan(&mut self, _frame: &ScanFrame<'_>) -> anyhow::Result<()> {
        Ok(())
    }
    /// After every physics step (100 Hz).
    fn step(&mut self, _frame: &StepFrame<'_>) -> anyhow::Result<()> {
        Ok(())
    }
    /// Something happened: a stop, a resume, a deviation, a contact, a lap, a pass.
    fn event(&mut self, _t_s: f64, _event: &Event) -> anyhow::Result<()> {
        Ok(())
    }
    /// Once, with the report (also after Ctrl-C).
    fn finish(&mut self, _report: &RunReport) -> anyhow::Result<()> {
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
    pub scene: &'a crate::scene::Scene,
    /// Index of the first run-time obstacle in `scene.solids`.
    pub first_obstacle: usize,
    /// The route as the planner follows it.
    pub route: &'a RoutePath,
    /// The vehicle's circle model (level of each circle, heights of the levels).
    pub model: &'a CollisionModel,
    /// The level of each vehicle part (`scenario.vehicle.vehicle.parts`).
    pub part_levels: &'a [usize],
    /// The LiDAR.
    pub lidar: &'a Lidar,
    /// Laps asked for.
    pub laps: u32,
    /// Seed used.
    pub seed: u64,
}

/// One revolution, map update and plan, given to [`Observer::scan`].
pub struct ScanFrame<'a> {
    /// Simulated time, seconds.
    pub t_s: f64,
    /// True pose of the vehicle.
    pub truth: Isometry2<f64>,
    /// The pose the autonomy used.
    pub estimate: Isometry2<f64>,
    /// The revolution as the LiDAR returned it (with the object each ray hit).
    pub lidar: &'a crate::lidar::LidarScan,
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
}

/// A revolution and the poses it was taken from.
struct Captured {
    scan: crate::lidar::LidarScan,
    truth: Isometry2<f64>,
    estimate: Isometry2<f64>,
}

/// A revolution mapped by a rayon task: the map back, the revolution, the wall time it took.
struct Mapped {
    map: MultiHeightMap,
    captured: Captured,
    mapping_s: f64,
}

/// Waits for a mapping task's answer, running other pending rayon work meanwhile (the task's
/// own parallel pieces, typically) instead of blocking a worker.
fn wait_for<T>(rx: &std::sync::mpsc::Receiver<anyhow::Result<T>>) -> anyhow::Result<T> {
    loop {
        match rx.try_recv() {
            Ok(answer) => return answer,
            Err(std::sync::mpsc::TryRecvError::Empty) => {
                if rayon::yield_now() != Some(rayon::Yield::Executed) {
                    std::thread::yield_now();
                }
            }
            Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                anyhow::bail!("the mapping task ended without an answer")
            }
        }
    }
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

/// Something that happened in a run.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// The vehicle stopped at this arc length of the route.
    Stop {
        /// Metres along the route.
        route_s_m: f64,
    },
    /// The vehicle moved again after a stop.
    Resume {
        /// How long it stood, seconds.
        stopped_s: f64,
    },
    /// The planner chose a path off the route.
    Deviate {
        /// Target lateral offset, metres (positive: left).
        offset_m: f64,
    },
    /// The planner came back to the route.
    BackOnRoute,
    /// A ground-truth contact began.
    Contact(Contact),
    /// A lap ended.
    Lap {
        /// Lap number (1-based).
        lap: u32,
        /// Its time, seconds.
        time_s: f64,
    },
    /// The vehicle went by a run-time obstacle.
    Pass {
        /// The obstacle's id.
        id: String,
        /// `passed`, `deviated`, `stopped` or `collided`.
        outcome: String,
        /// Whether the scenario's expectation held.
        met: bool,
    },
}

/// Runs a scenario in closed loop over its offline map (which must exist: see `mapping`).
pub fn run(
    scenario: &Scenario,
    options: &RunOptions,
    progress: &mut (dyn FnMut(Progress) + Send),
) -> anyhow::Result<RunReport> {
    run_observed(scenario, options, progress, &mut NoObserver)
}

/// [`run`], showing every step, scan and event to `observer`.
pub fn run_observed(
    scenario: &Scenario,
    options: &RunOptions,
    progress: &mut (dyn FnMut(Progress) + Send),
    observer: &mut (dyn Observer + Send),
) -> anyhow::Result<RunReport> {
    let wall = Instant::now();
    let laps = options.laps.unwrap_or(scenario.laps).max(1);
    let seed = options.seed.unwrap_or(scenario.seed);
    let vehicle = &scenario.vehicle.vehicle;
    let fitted = vehicle
        .fit()
        .context("fitting the vehicle's circle model")?;
    let model: CollisionModel = fitted.model;
    let self_filter = crate::mapping::self_filter_model(vehicle)?;
    let heights = model.level_heights_m().to_vec();
    let part_levels: Vec<usize> = vehicle
        .parts
        .iter()
        .map(|p| aircraft::fit::level_of(p.underside_m(), &heights))
        .collect();
    let behaviour = match vehicle.spec.motion.steering {
        aircraft::spec::Steering::NoseWheel => Behaviour::StopAndWait,
        aircraft::spec::Steering::FrontWheels => Behaviour::Deviate,
    };
    let route = RoutePath::new(&scenario.route.waypoints_m, scenario.route.closed);
    let start = scenario.vehicle.world_from_start;
    let scene = scenario.scene(true);
    let mut world = World::new(&scene, true, vehicle, &start);
    let lidar = Lidar::new(LidarConfig::default(), vehicle.vehicle_from_lidar())
        .map_err(anyhow::Error::msg)?;
    let live = tempfile::tempdir().context("creating the live map's scratch directory")?;
    let prior = options.map_dir.join("blocks");
    let map_config = mapper::MapConfig {
        max_distance_m: distance_cap_m(&model, &options.autonomy),
        ..crate::mapping::map_config()
    };
    let odm_half_size_m = options
        .distance_map_half_size_m
        .unwrap_or_else(|| distance_map_half_size_m(&model, &options.autonomy));
    let map = MultiHeightMap::with_stores(
        map_config,
        crate::mapping::levels_of(scenario)?,
        Point2::from(start.translation.vector),
        Some(&prior),
        Some(live.path()),
    )?;
    // Map a revolution: re-centre the window, forget, insert. Returns the wall time it took.
    let map_revolution = |map: &mut MultiHeightMap, captured: &Captured| -> anyhow::Result<f64> {
        let t1 = Instant::now();
        let reexpressed;
        let mapper_scan = if captured.estimate != captured.truth {
            reexpressed = reexpress(&captured.scan.scan, &captured.truth, &captured.estimate)?;
            &reexpressed
        } else {
            &captured.scan.scan
        };
        let at = Point2::from(captured.estimate.translation.vector);
        map.recenter(at)?;
        // Fade what is no longer seen, then insert: what is seen again is refreshed.
        if let Some(tau) = options.forget_time_constant_s {
            map.forget_unseen(at, options.forget_half_size_m, 1.0 / options.scan_hz, tau);
        }
        map.insert_scan(mapper_scan, Some(&self_filter))?;
        Ok(t1.elapsed().as_secs_f64())
    };
    let map_revolution = &map_revolution;
    let bicycle = Bicycle::new(vehicle.spec.motion.clone());
    let wheelbase = vehicle.spec.motion.wheelbase_m;
    let decel = vehicle.spec.motion.max_deceleration_m_s2;
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x005E_ED0F_u64);

    let first_obstacle = scenario.objects.len();
    let mut trackers: Vec<PassTracker> = scenario
        .obstacles
        .iter()
        .enumerate()
        .map(|(k, o)| {
            let at = o
                .motion
                .as_ref()
                .and_then(|m| closest_on_route(&route, &m.path_m))
                .unwrap_or(Point2::new(o.solid.x_m, o.solid.y_m));
            PassTracker {
                solid_index: first_obstacle + k,
                route_s: route.project(&at, 0.0, f64::INFINITY).0,
                expect: o.expect,
                active: false,
                offset: 0.0,
                stopped: false,
                present: false,
                clearance: vec![f64::INFINITY; heights.len()],
                contacts_before: 0,
            }
        })
        .collect();
    let mut reports: Vec<ObstacleReport> = scenario
        .obstacles
        .iter()
        .map(|o| ObstacleReport {
            id: o.solid.id.clone(),
            kind: crate::scenario::kind_name(o.solid.kind).to_string(),
            expected: o.expect.as_str().to_string(),
            passes: Vec::new(),
        })
        .collect();

    let dt = 1.0 / options.physics_hz;
    let steps_per_scan = (options.physics_hz / options.scan_hz).round().max(1.0) as u64;
    let mut state = VehicleState {
        x_m: start.translation.x,
        y_m: start.translation.y,
        yaw_rad: start.rotation.angle(),
        ..Default::default()
    };
    let length = route.length_m();
    let total_m = length * laps as f64;
    let timeout_s = 60.0 + 4.0 * total_m / scenario.route.speed_m_s;
    let mut split = TimeSplit::default();
    let (mut s_hint, mut s_total) = (
        route
            .project(&Point2::new(state.x_m, state.y_m), 0.0, f64::INFINITY)
            .0,
        0.0,
    );
    let s_start = s_hint;
    let mut current: Option<Plan> = None;
    let mut speed_cmd = 0.0;
    let mut offset_prev = 0.0;
    let mut laps_completed = 0;
    let mut lap_times = Vec::new();
    let mut lap_start_t = 0.0;
    let mut stops: Vec<Stop> = Vec::new();
    let mut min_clearance = vec![f64::INFINITY; heights.len()];
    let mut t = 0.0;
    let mut step: u64 = 0;
    let mut interrupted = false;
    world.set_vehicle_pose(&state.world_from_vehicle(), 0.0);
    observer.start(&RunStart {
        scenario,
        scene: &scene,
        first_obstacle,
        route: &route,
        model: &model,
        part_levels: &part_levels,
        lidar: &lidar,
        laps,
        seed,
    })?;
    let mut deviating = false;
    let mut contacts_seen = 0;
    // The loop runs in a rayon scope, so on one of rayon's workers: its parallel stages start
    // where it runs instead of being handed to the pool and waited for from outside (a sleep
    // and a wake-up of this thread each time). With `overlap_sensing`, the last revolution's
    // mapping is in flight as a task of that scope, holding the map: it runs beside the physics
    // steps (nothing before the next plan needs it).
    let mut in_flight: Option<std::sync::mpsc::Receiver<anyhow::Result<Mapped>>> = None;
    let mut map = Some(map);
    rayon::scope(|tasks| -> anyhow::Result<()> {
        while laps_completed < laps {
            if options.stop.load(Ordering::Relaxed) || t > timeout_s {
                interrupted = true;
                break;
            }
            let physics = Instant::now();
            for (k, o) in scenario.obstacles.iter().enumerate() {
                let i = first_obstacle + k;
                match o.pose_at(t) {
                    Some((x, y, yaw)) => {
                        if !world.object_active(i) {
                            world.set_object_active(i, true);
                        }
                        if o.motion.is_some() {
                            world.set_object_pose(i, x, y, yaw);
                        }
                    }
                    None if world.object_active(i) => world.set_object_active(i, false),
                    None => {}
                }
            }
            split.physics += physics.elapsed().as_secs_f64();

            // The autonomy's view of the pose.
            let truth = state.world_from_vehicle();
            let estimate = if options.pose_noise.0 > 0.0 || options.pose_noise.1 > 0.0 {
                let (nx, ny, nyaw): (f64, f64, f64) = (
                    rng.sample(StandardNormal),
                    rng.sample(StandardNormal),
                    rng.sample(StandardNormal),
                );
                Isometry2::new(
                    truth.translation.vector
                        + nalgebra::Vector2::new(nx, ny) * options.pose_noise.0,
                    truth.rotation.angle() + nyaw * options.pose_noise.1,
                )
            } else {
                truth
            };
            let (s_est, d_est) =
                route.project(&Point2::from(estimate.translation.vector), s_hint, 30.0);

            if step.is_multiple_of(steps_per_scan) {
                let capture = |world: &World| {
                    let t0 = Instant::now();
                    let scan = lidar.scan(
                        world,
                        &SweepPoses::still(truth),
                        step / steps_per_scan,
                        seed,
                    );
                    (
                        Captured {
                            scan,
                            truth,
                            estimate,
                        },
                        t0.elapsed().as_secs_f64(),
                    )
                };
                // Plan from the pose now over the distance maps updated around it.
                let plan_now = |map: &mut MultiHeightMap| -> anyhow::Result<(Plan, f64, [f64; 2])> {
                    let t2 = Instant::now();
                    map.update_distance_maps_around(
                        Point2::from(estimate.translation.vector),
                        odm_half_size_m,
                    );
                    let t3 = Instant::now();
                    let checker = model.checker(map.distance_maps())?;
                    let p = plan(
                        &checker,
                        &route,
                        s_est,
                        d_est,
                        offset_prev,
                        behaviour,
                        &options.autonomy,
                    );
                    let (v, _) = avoid(
                        p.chosen(),
                        scenario.route.speed_m_s,
                        decel,
                        &options.autonomy,
                    );
                    Ok((p, v, [(t3 - t2).as_secs_f64(), t3.elapsed().as_secs_f64()]))
                };
                // This revolution, to be mapped once the plan from the last one is made.
                let mut to_map = None;
                let thought = if options.overlap_sensing {
                    // The LiDAR's next revolution beside the plan from the last one, which was mapped
                    // while the physics steps ran.
                    let rx = in_flight.take();
                    let held = map.take();
                    let (fresh, planned) = rayon::join(
                        || capture(&world),
                        || -> anyhow::Result<_> {
                            let Some(rx) = rx else {
                                return Ok((held.context("the map is missing")?, None));
                            };
                            let Mapped {
                                map: mut m,
                                captured,
                                mapping_s,
                            } = wait_for(&rx)?;
                            let (p, v, [odm_s, planning_s]) = plan_now(&mut m)?;
                            Ok((m, Some(((p, v, [mapping_s, odm_s, planning_s]), captured))))
                        },
                    );
                    let (m, thought) = planned?;
                    map = Some(m);
                    let (c, lidar_s) = fresh;
                    split.lidar += lidar_s;
                    to_map = Some(c);
                    thought
                } else {
                    let m = map.as_mut().context("the map is missing")?;
                    let (c, lidar_s) = capture(&world);
                    split.lidar += lidar_s;
                    let mapping_s = map_revolution(m, &c)?;
                    let (p, v, [odm_s, planning_s]) = plan_now(m)?;
                    Some(((p, v, [mapping_s, odm_s, planning_s]), c))
                };
                // Until the first revolution is mapped there is nothing to follow (the vehicle waits).
                if let Some(((p, v, [mapping_s, odm_s, planning_s]), captured)) = thought {
                    split.mapping += mapping_s;
                    split.distance_maps += odm_s;
                    split.planning += planning_s;
                    offset_prev = p.chosen().offset_m;
                    speed_cmd = v;
                    if (offset_prev.abs() > 0.5) != deviating {
                        deviating = !deviating;
                        let event = if deviating {
                            Event::Deviate {
                                offset_m: offset_prev,
                            }
                        } else {
                            Event::BackOnRoute
                        };
                        observer.event(t, &event)?;
                    }
                    observer.scan(&ScanFrame {
                        t_s: t,
                        truth: captured.truth,
                        estimate: captured.estimate,
                        lidar: &captured.scan,
                        map: map.as_ref().context("the map is missing")?,
                        plan: &p,
                        speed_cmd_m_s: v,
                        speed_scale: if scenario.route.speed_m_s > 0.0 {
                            v / scenario.route.speed_m_s
                        } else {
                            0.0
                        },
                        world: &world,
                    })?;
                    current = Some(p);
                }
                if let Some(c) = to_map {
                    let mut m = map.take().context("the map is missing")?;
                    let (tx, rx) = std::sync::mpsc::channel();
                    tasks.spawn(move |_| {
                        let mapped = map_revolution(&mut m, &c).map(|mapping_s| Mapped {
                            map: m,
                            captured: c,
                            mapping_s,
                        });
                        // The receiver is gone only if the loop has ended: nothing waits for this.
                        let _ = tx.send(mapped);
                    });
                    in_flight = Some(rx);
                }
            }

            let physics = Instant::now();
            let steering = current.as_ref().map_or(0.0, |p| {
                pure_pursuit(
                    &estimate,
                    p.chosen(),
                    state.speed_m_s,
                    wheelbase,
                    &options.autonomy,
                )
            });
            let command = Command {
                speed_m_s: speed_cmd,
                steering_rad: steering,
            };
            bicycle.step(&mut state, &command, dt);
            t += dt;
            step += 1;
            world.set_vehicle_pose(&state.world_from_vehicle(), t);
            split.physics += physics.elapsed().as_secs_f64();

            // Progress along the route (truth, for judging).
            let (s_now, d_now) = route.project(&Point2::new(state.x_m, state.y_m), s_hint, 30.0);
            let mut ds = s_now - s_hint;
            if route.closed() {
                ds = (ds + length / 2.0).rem_euclid(length) - length / 2.0;
            }
            s_total += ds;
            s_hint = s_now;

            // Stops.
            let stopped = state.speed_m_s.abs() < 0.05 && speed_cmd == 0.0;
            let moving = state.speed_m_s.abs() > 0.3;
            match stops.last_mut() {
                Some(last) if last.end_s.is_none() && moving => {
                    last.end_s = Some(t);
                    observer.event(
                        t,
                        &Event::Resume {
                            stopped_s: t - last.start_s,
                        },
                    )?;
                }
                Some(last) if last.end_s.is_none() => {}
                _ if stopped && t > 1.0 => {
                    stops.push(Stop {
                        start_s: t,
                        end_s: None,
                        route_s_m: s_now,
                    });
                    observer.event(t, &Event::Stop { route_s_m: s_now })?;
                }
                _ => {}
            }
            for c in &world.contacts()[contacts_seen..] {
                observer.event(c.time_s, &Event::Contact(c.clone()))?;
            }
            contacts_seen = world.contacts().len();

            // Obstacle passes: a window from 25 m before to 10 m after each obstacle.
            let lap_s = (s_start + s_total).rem_euclid(if route.closed() {
                length
            } else {
                f64::INFINITY
            });
            for (k, tr) in trackers.iter_mut().enumerate() {
                let rel = if route.closed() {
                    (lap_s - tr.route_s + length / 2.0).rem_euclid(length) - length / 2.0
                } else {
                    lap_s - tr.route_s
                };
                let inside = (-25.0..=10.0).contains(&rel);
                if inside && !tr.active {
                    *tr = PassTracker {
                        active: true,
                        offset: 0.0,
                        stopped: false,
                        present: false,
                        clearance: vec![f64::INFINITY; heights.len()],
                        contacts_before: world.contacts().len(),
                        ..*tr
                    };
                }
                if tr.active {
                    tr.offset = tr.offset.max(d_now.abs());
                    tr.stopped |= stopped && rel < 0.0;
                    tr.present |= world.object_active(tr.solid_index);
                    for (part, d) in world.distances_to(tr.solid_index).into_iter().enumerate() {
                        let level = part_levels[part];
                        tr.clearance[level] = tr.clearance[level].min(d);
                    }
                    if !inside && !tr.present {
                        // Not in the world during this window (appears later or has gone): no pass.
                        tr.active = false;
                    } else if !inside {
                        tr.active = false;
                        let id = &scene.solids[tr.solid_index].id;
                        let collided = world.contacts()[tr.contacts_before..]
                            .iter()
                            .any(|c| &c.object == id);
                        let outcome = if collided {
                            "collided"
                        } else if tr.stopped {
                            "stopped"
                        } else if tr.offset > 0.5 {
                            "deviated"
                        } else {
                            "passed"
                        };
                        let too_close = scenario
                            .danger_distance_m
                            .is_some_and(|danger| tr.clearance.iter().any(|d| *d < danger));
                        let met = !collided
                            && !too_close
                            && match tr.expect {
                                Expectation::PassUnder => outcome == "passed",
                                Expectation::Deviate => outcome == "deviated",
                                Expectation::Stop => outcome == "stopped",
                                Expectation::NoContact => true,
                            };
                        observer.event(
                            t,
                            &Event::Pass {
                                id: id.clone(),
                                outcome: outcome.into(),
                                met,
                            },
                        )?;
                        reports[k].passes.push(Pass {
                            lap: laps_completed + 1,
                            outcome: outcome.into(),
                            min_clearance_m: tr.clearance.clone(),
                            max_offset_m: tr.offset,
                            met,
                        });
                    }
                }
            }
            let clearance_now = clearance_per_level(&world, &part_levels, heights.len());
            for (level, d) in clearance_now.iter().enumerate() {
                min_clearance[level] = min_clearance[level].min(*d);
            }
            observer.step(&StepFrame {
                t_s: t,
                state: &state,
                command: &command,
                clearance_m: &clearance_now,
                real_time_factor: t / wall.elapsed().as_secs_f64().max(1e-9),
                world: &world,
            })?;

            // Laps.
            let done_m = s_total;
            if (route.closed() && done_m >= length * (laps_completed + 1) as f64)
                || (!route.closed() && s_now >= length - 0.5)
            {
                laps_completed += 1;
                lap_times.push(t - lap_start_t);
                observer.event(
                    t,
                    &Event::Lap {
                        lap: laps_completed,
                        time_s: t - lap_start_t,
                    },
                )?;
                lap_start_t = t;
                if !route.closed() && laps_completed < laps {
                    // An open route starts again from its start pose.
                    state = VehicleState {
                        x_m: start.translation.x,
                        y_m: start.translation.y,
                        yaw_rad: start.rotation.angle(),
                        ..Default::default()
                    };
                    (s_hint, s_total) = (s_start, 0.0);
                    world.set_vehicle_pose(&state.world_from_vehicle(), t);
                }
            }
            if step.is_multiple_of(100) {
                let fraction = if route.closed() {
                    s_total / total_m
                } else {
                    (laps_completed as f64 * length + s_now) / total_m
                };
                progress(Progress {
                    sim_time_s: t,
                    laps_completed,
                    fraction: fraction.clamp(0.0, 1.0),
                });
            }
        }
        Ok(())
    })?;
    let wall_time_s = wall.elapsed().as_secs_f64();
    let every_pass_met = reports
        .iter()
        .all(|r| !r.passes.is_empty() && r.passes.iter().all(|p| p.met));
    let report = RunReport {
        scenario: scenario.name.clone(),
        seed,
        expectations_met: !interrupted
            && laps_completed == laps
            && every_pass_met
            && world.contacts().is_empty(),
        laps,
        laps_completed,
        lap_times_s: lap_times,
        contacts: world.contacts().to_vec(),
        obstacles: reports,
        stops,
        min_clearance_m: min_clearance,
        danger_distance_m: scenario.danger_distance_m,
        sim_time_s: t,
        wall_time_s,
        real_time_factor: t / wall_time_s.max(1e-9),
        interrupted,
        time_split_s: split,
    };
    observer.finish(&report)?;
    Ok(report)
}

/// Ground truth now: per level, the distance from the vehicle's parts of that level to the
/// nearest object in range (infinity if none).
fn clearance_per_level(world: &World, part_levels: &[usize], levels: usize) -> Vec<f64> {
    let mut out = vec![f64::INFINITY; levels];
    for (d, level) in world.part_clearances_m().iter().zip(part_levels) {
        out[*level] = out[*level].min(*d);
    }
    out
}

/// The point of a path closest to the route (where a crossing vehicle crosses it).
fn closest_on_route(route: &RoutePath, path: &[Point2<f64>]) -> Option<Point2<f64>> {
    let mut best: Option<(f64, Point2<f64>)> = None;
    for w in path.windows(2) {
        for k in 0..=50 {
            let p = w[0] + (w[1] - w[0]) * (k as f64 / 50.0);
            let (_, d) = route.project(&p, 0.0, f64::INFINITY);
            if best.is_none_or(|b| d.abs() < b.0) {
                best = Some((d.abs(), p));
            }
        }
    }
    best.map(|b| b.1)
}

/// A scan's points moved from the true pose to the estimated one: where a mapper with a wrong
/// pose would put them.
fn reexpress(
    scan: &mapper::Scan,
    truth: &Isometry2<f64>,
    estimate: &Isometry2<f64>,
) -> anyhow::Result<mapper::Scan> {
    let lift = crate::world::planar_to_3d;
    let correction = lift(estimate) * lift(truth).inverse();
    let columns = scan
        .columns()
        .iter()
        .map(|c| mapper::ScanColumn {
            world_from_sensor: correction * c.world_from_sensor,
            world_from_vehicle: *estimate,
        })
        .collect();
    let returns = scan
        .returns()
        .iter()
        .map(|r| {
            r.map(|r| mapper::Return {
                point_in_world: correction * r.point_in_world,
                ..r
            })
        })
        .collect();
    Ok(mapper::Scan::new(scan.beams(), columns, returns)?)
}
