//! The driver of the stack under test: it holds the latest pose estimate (dead-reckoned from
//! odometry between estimates), tracks its own progress along the route from that estimate,
//! plans over the online map's distance maps, and turns the plan into a command.
//!
//! The pipeline of a plan ([`Driver::plan`]): the estimate projected onto the route, the
//! planner's candidates over the distance maps, the rules about movers
//! ([`TrafficRules::decide`]: the speed cap and where to stop), the avoider's speed, and the
//! status the driver reports (`status`).

use mapper::{CollisionModel, MapError};
use nalgebra::{Isometry2, Point2, Vector2};

use crate::messages::{Command, Odometry, PoseEstimate};
use crate::online_map::OnlineMap;
use crate::planner::{
    AutonomyConfig, Behaviour, Plan, SpeedLimit, avoid, horizon_for_m, plan, pure_pursuit,
    speed_cap_m_s, stopping_distance_m,
};
use crate::route::{RoutePath, wrap_angle};
use crate::traffic::{Conflict, MoverInputs, Prediction, TrafficRules};

mod start;
mod status;
mod strike;
#[cfg(test)]
mod tests;

pub use start::BlindZone;
use start::StartRule;
pub use status::{DriverStatus, PilotCall};

/// Half length of the stretch of route searched around the last progress when the estimate is
/// projected onto it, metres (so a circuit that passes near itself is followed in order).
const PROGRESS_WINDOW_M: f64 = 30.0;

/// The vehicle the driver drives, as the stack knows it.
#[derive(Clone, Debug)]
pub struct VehicleModel {
    /// The height-tagged circles checked against the distance maps.
    pub collision: CollisionModel,
    /// Wheelbase, metres (pure pursuit and dead reckoning).
    pub wheelbase_m: f64,
    /// Braking the avoider counts on, m/s^2.
    pub deceleration_m_s2: f64,
    /// Acceleration the space-time check expects of it, m/s^2.
    pub acceleration_m_s2: f64,
    /// What the vehicle does about an obstacle in its way.
    pub behaviour: Behaviour,
}

/// Wall time of a plan's two stages, seconds (for the run's time split).
#[derive(Clone, Copy, Debug, Default)]
pub struct PlanTimes {
    /// Distance maps brought up to date around the estimate.
    pub distance_maps_s: f64,
    /// Planner and avoider.
    pub planning_s: f64,
}

/// Planner, avoider, behaviour and follower over a route.
pub struct Driver {
    route: RoutePath,
    vehicle: VehicleModel,
    config: AutonomyConfig,
    wanted_speed_m_s: f64,
    /// Half side of the square of distance maps kept up to date around the estimate, metres.
    distance_map_half_size_m: f64,
    estimate: Option<PoseEstimate>,
    last_odometry: Option<Odometry>,
    /// Arc length of the estimate's projection onto the route at the last plan, metres (`None`:
    /// not planned yet, the whole route is searched).
    route_s_m: Option<f64>,
    plan: Option<Plan>,
    speed_command_m_s: f64,
    status: DriverStatus,
    /// The last plan stood the vehicle short of where its own plan would stop it (yielding, or
    /// short of a map obstacle for a standing mover's reach, a caution line or an obstacle
    /// closing on it - the status then the obstacle's): the conflict check then wants the
    /// resume margin after a mover (a superset of the yielding status: it errs safe).
    stood_for_movers: bool,
    /// When the last revolution arrived, seconds (the watchdog's clock).
    last_revolution_s: Option<f64>,
    /// The farthest any circle of the collision model reaches from the vehicle's origin, metres
    /// (where a heading error moves the vehicle most).
    reach_m: f64,
    /// Since when the plans have stopped the vehicle for obstacles without a pause (`StoppedFor`
    /// or `WaitingForHiddenObstacle`), seconds.
    stopped_since_s: Option<f64>,
    /// The rules about movers and what they remember from plan to plan.
    traffic: TrafficRules,
    /// The start-up rule: the blind zone while it awaits a walk-around.
    start: StartRule,
    /// The unseen ground the start-up rule's first check found, square metres.
    start_unseen_m2: Option<f64>,
    /// Its cells (centres in the world) and their side, metres.
    start_unseen_cells: Option<(Vec<Point2<f64>>, f64)>,
    /// When the airframe felt a strike ([`Driver::on_strike`]), seconds: it stands from then on.
    struck_at_s: Option<f64>,
}

impl Driver {
    /// A driver of `vehicle` along `route` at `wanted_speed_m_s`, keeping the distance maps up
    /// to date over a square of half side `distance_map_half_size_m` around its estimate.
    pub fn new(
        route: RoutePath,
        vehicle: VehicleModel,
        config: AutonomyConfig,
        wanted_speed_m_s: f64,
        distance_map_half_size_m: f64,
    ) -> Self {
        let reach_m = vehicle
            .collision
            .circles()
            .iter()
            .map(|c| c.x_m.hypot(c.y_m) + c.radius_m)
            .fold(0.0, f64::max);
        let traffic = TrafficRules::new(vehicle.collision.clone(), vehicle.acceleration_m_s2);
        Driver {
            reach_m,
            route,
            vehicle,
            config,
            wanted_speed_m_s,
            distance_map_half_size_m,
            estimate: None,
            last_odometry: None,
            route_s_m: None,
            plan: None,
            speed_command_m_s: 0.0,
            status: DriverStatus::Driving,
            stood_for_movers: false,
            last_revolution_s: None,
            stopped_since_s: None,
            traffic,
            start: StartRule::Done,
            start_unseen_m2: None,
            start_unseen_cells: None,
            struck_at_s: None,
        }
    }

    /// A LiDAR revolution taken at `t_s` arrived (it is mapped and planned from as the schedule
    /// says): the watchdog's clock starts over.
    pub fn on_revolution(&mut self, t_s: f64) {
        self.last_revolution_s = Some(t_s);
    }

    /// Whether the watchdog holds the vehicle now: revolutions have arrived before, but none for
    /// longer than `watchdog_s` (by the odometry's clock).
    pub fn watchdog_tripped(&self) -> bool {
        match (self.last_revolution_s, self.last_odometry) {
            (Some(r), Some(o)) => o.t_s - r > self.config.watchdog_s,
            _ => false,
        }
    }

    /// A new pose estimate: it replaces the dead-reckoned one.
    pub fn on_pose(&mut self, estimate: PoseEstimate) {
        self.estimate = Some(estimate);
    }

    /// New odometry: the estimate is carried forward along the arc the last odometry describes
    /// (kinematic bicycle), until the next pose estimate replaces it.
    pub fn on_odometry(&mut self, odometry: Odometry) {
        if let (Some(last), Some(est)) = (self.last_odometry, self.estimate.as_mut()) {
            let dt = odometry.t_s - last.t_s;
            if dt > 0.0 && est.t_s < odometry.t_s {
                let ds = last.speed_m_s * dt;
                let dyaw = ds * last.steering_rad.tan() / self.vehicle.wheelbase_m;
                let p = est.world_from_vehicle;
                let yaw = p.rotation.angle();
                let mid = yaw + 0.5 * dyaw;
                let step = Vector2::new(mid.cos(), mid.sin()) * ds;
                est.world_from_vehicle =
                    Isometry2::new(p.translation.vector + step, wrap_angle(yaw + dyaw));
                est.t_s = odometry.t_s;
            }
        }
        self.last_odometry = Some(odometry);
    }

    /// The vehicle was put back at the start of an open route (a new lap): progress and estimate
    /// start over.
    pub fn restart(&mut self) {
        self.status = DriverStatus::Driving;
        self.stood_for_movers = false;
        self.stopped_since_s = None;
        self.traffic.restart();
        self.route_s_m = None;
        self.estimate = None;
        self.last_odometry = None;
    }

    /// Plans from the current estimate over `map`'s distance maps (brought up to date around the
    /// estimate first): the planner's candidates and choice, then the avoider's speed. Without an
    /// estimate, or before the online map has started mapping (an estimate not yet trusted out
    /// to the obstacle test's range: [`OnlineMap::mapping_started`]), the vehicle is held
    /// (speed 0): blind to what the offline map does not hold, it would drive into it.
    pub fn plan(&mut self, map: &mut OnlineMap) -> Result<PlanTimes, MapError> {
        if let Some(at_s) = self.struck_at_s {
            self.speed_command_m_s = 0.0;
            self.status = DriverStatus::Struck { at_s };
            return Ok(PlanTimes::default());
        }
        let Some(estimate) = self.estimate.filter(|_| map.mapping_started()) else {
            self.speed_command_m_s = 0.0;
            return Ok(PlanTimes::default());
        };
        let t0 = std::time::Instant::now();
        let here = Point2::from(estimate.world_from_vehicle.translation.vector);
        map.map_mut()
            .update_distance_maps_around(here, self.distance_map_half_size_m);
        let t1 = std::time::Instant::now();
        let (s, d) = match self.route_s_m {
            Some(hint) => self.route.project(&here, hint, PROGRESS_WINDOW_M),
            None => self.route.project(&here, 0.0, f64::INFINITY),
        };
        self.route_s_m = Some(s);
        let checker = self.vehicle.collision.checker(map.map().distance_maps())?;
        let previous = self.plan.as_ref().map_or(0.0, |p| p.chosen().offset_m);
        // A less certain estimate: wider margins, a lower speed; never faster than it can stop
        // within the longest horizon and the detection range, and the horizon long enough to
        // stop within at the speed it wants.
        let sigma_m = estimate.lateral_sigma_at_m(self.reach_m);
        let (mut config, speed_factor) = self.config.under_uncertainty(sigma_m);
        let decel = self.vehicle.deceleration_m_s2;
        let wanted = (self.wanted_speed_m_s * speed_factor)
            .min(self.route.speed_limit_at(s))
            .min(speed_cap_m_s(decel, &config).0);
        config.horizon_m = horizon_for_m(wanted, decel, &config);
        let mut p = plan(
            &checker,
            &self.route,
            s,
            d,
            previous,
            self.vehicle.behaviour,
            &config,
        );
        // The tracker's movers, once a plan: the rules about movers read them.
        let movers = map.movers();
        let candidates = map.candidate_movers();
        let standing = map.standing_objects(config.traffic.standing_object_max_m);
        let v0 = self.last_odometry.map_or(0.0, |o| o.speed_m_s.max(0.0));
        let decision = self.traffic.decide(&MoverInputs {
            poses: &p.chosen().poses,
            s_m: s,
            stop_at_m: p.chosen().collision_at_m,
            movers: &movers,
            candidates: &candidates,
            standing: &standing,
            wanted_m_s: wanted,
            pose: estimate.world_from_vehicle,
            now_s: estimate.t_s,
            speed_m_s: v0,
            stopping_m: stopping_distance_m(v0, decel, &config),
            step_m: config.step_m,
            stop_buffer_m: config.stop_buffer_m,
            hidden_after_s: self.config.hidden_after_s,
            yielding: self.stood_for_movers,
            traffic: &config.traffic,
            ways_seen_empty: map.ways_seen_empty(),
        });
        let conflict = decision.conflict;
        let mut chosen = p.chosen().clone();
        chosen.collision_at_m = decision.stop_at_m;
        let (mut v, _) = avoid(&chosen, decision.wanted_m_s, decel, &config);
        let body = decision.body.map(|b| self.body_status(b, estimate.t_s));
        let walk_around =
            self.walk_around_status(&estimate.world_from_vehicle, &chosen.poses, estimate.t_s);
        if body.is_some() || walk_around.is_some() {
            v = 0.0;
        }
        self.speed_command_m_s = v;
        let stood_short = v <= 0.0
            && chosen.collision_at_m != p.chosen().collision_at_m
            && walk_around.is_none()
            && body.is_none()
            && decision.walker.is_none();
        self.stood_for_movers = stood_short;
        self.status = match conflict {
            _ if let Some(waiting) = walk_around => waiting,
            _ if let Some(held) = body => held,
            _ if v > 0.0 => DriverStatus::Driving,
            _ if let Some((obstacle, last_seen_s)) = decision.walker => DriverStatus::StoppedFor {
                obstacle,
                last_seen_s,
            },
            // Standing short of a map obstacle only for a standing mover's reach or a line
            // (no conflict, no line held for one): what holds it is the obstacle, and a minute
            // of it is a blocked way (variant 38 of `traffic_jet.toml` stood so, yielding to
            // nothing, to its time limit).
            _ if stood_short
                && (conflict.is_some()
                    || decision.held_for.is_some()
                    || v0 >= 0.05
                    || p.chosen().collision_at_m.is_none()) =>
            {
                DriverStatus::Yielding {
                    track_id: decision.held_for.unwrap_or(u32::MAX),
                    mover_at: conflict.map_or(here, |c| c.mover_at),
                }
            }
            _ => self.stopped_status(&p, map, estimate.t_s, &config),
        };
        self.stopped_since_s = match self.status {
            DriverStatus::StoppedFor { .. } | DriverStatus::WaitingForHiddenObstacle { .. } => {
                Some(self.stopped_since_s.unwrap_or(estimate.t_s))
            }
            _ => None,
        };
        if let Some(c) = &conflict {
            // The plan shows where the vehicle stops for the mover.
            let k = p.chosen;
            p.candidates[k].collision_at_m = chosen.collision_at_m.or(Some(c.at_m));
        }
        self.plan = Some(p);
        Ok(PlanTimes {
            distance_maps_s: (t1 - t0).as_secs_f64(),
            planning_s: t1.elapsed().as_secs_f64(),
        })
    }

    /// The fastest the driver will go on this route, and why, when it is below the route's
    /// speed (`None`: the route's speed is allowed).
    pub fn route_speed_lowered(&self) -> Option<(f64, SpeedLimit)> {
        let (cap, why) = speed_cap_m_s(self.vehicle.deceleration_m_s2, &self.config);
        (cap < self.wanted_speed_m_s).then_some((cap, why))
    }

    /// The movers predicted at the last plan, with their discs over the horizon.
    pub fn predictions(&self) -> &[Prediction] {
        self.traffic.predictions()
    }

    /// The conflict with a mover found on the chosen path at the last plan.
    pub fn conflict(&self) -> Option<&Conflict> {
        self.traffic.conflict()
    }

    /// The command now: the avoider's speed, and pure pursuit's steering onto the chosen path
    /// from the current estimate (straight ahead before the first plan).
    pub fn command(&self) -> Command {
        let speed = self.last_odometry.map_or(0.0, |o| o.speed_m_s);
        let steering = match (&self.plan, &self.estimate) {
            (Some(p), Some(e)) => pure_pursuit(
                &e.world_from_vehicle,
                p.chosen(),
                speed,
                self.vehicle.wheelbase_m,
                &self.config,
            ),
            _ => 0.0,
        };
        Command {
            // Blind (no fresh revolution), the vehicle stops; it drives on when they return.
            // Struck, it stands.
            speed_m_s: if self.watchdog_tripped() || self.struck_at_s.is_some() {
                0.0
            } else {
                self.speed_command_m_s
            },
            steering_rad: steering,
        }
    }

    /// The last plan (`None` before the first).
    pub fn last_plan(&self) -> Option<&Plan> {
        self.plan.as_ref()
    }

    /// The speed the avoider commands, m/s.
    pub fn speed_command_m_s(&self) -> f64 {
        self.speed_command_m_s
    }

    /// The current pose estimate (dead-reckoned since the last one).
    pub fn estimate(&self) -> Option<&PoseEstimate> {
        self.estimate.as_ref()
    }

    /// The route progress the driver tracks from its estimate, metres (`None` before the first
    /// plan).
    pub fn route_s_m(&self) -> Option<f64> {
        self.route_s_m
    }
}
