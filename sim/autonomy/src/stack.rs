//! The driver of the stack under test: it holds the latest pose estimate (dead-reckoned from
//! odometry between estimates), tracks its own progress along the route from that estimate,
//! plans over the online map's distance maps, and turns the plan into a command.

use mapper::{CollisionModel, MapError, TrackState};
use nalgebra::{Isometry2, Point2, Vector2};

use crate::messages::{Command, Odometry, PoseEstimate};
use crate::online_map::OnlineMap;
use crate::planner::{
    AutonomyConfig, Behaviour, Plan, SpeedLimit, avoid, horizon_for_m, plan, pure_pursuit,
    speed_cap_m_s, stopping_distance_m,
};
use crate::route::{RoutePath, wrap_angle};
use crate::traffic::{
    Conflict, Prediction, SpeedProfile, TimedPath, at_body, first_conflict,
    first_within_standing_reach, may_have_walked_to, may_reach_body, moved_beyond_its_extent,
    predict, predict_keeping, surely_moving,
};

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

/// What the driver is doing about obstacles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DriverStatus {
    /// Driving (perhaps slowing) with no obstacle stopping it.
    Driving,
    /// Stopped for an obstacle the sensor hit within `hidden_after_s`: it resumes when the
    /// obstacle is seen gone.
    StoppedFor {
        /// The obstacle cell nearest the vehicle's first colliding pose, metres.
        obstacle: Point2<f64>,
        /// When a revolution last hit the obstacle, seconds.
        last_seen_s: f64,
    },
    /// Stopped for an obstacle no revolution has hit for longer than `hidden_after_s` (hidden by
    /// the airframe, or only in the offline map): the sensor cannot see it go, so it will wait
    /// for ever; after `pilot_call_after_s` the run calls for a pilot.
    WaitingForHiddenObstacle {
        /// As in `StoppedFor`.
        obstacle: Point2<f64>,
        /// When a revolution last hit it (`None`: never since the window held it).
        last_seen_s: Option<f64>,
        /// When the wait began, seconds.
        since_s: f64,
    },
    /// Stopped short of where a mover is predicted to cross its path: it drives on once the
    /// mover is predicted clear.
    Yielding {
        /// The mover's track id.
        track_id: u32,
        /// Where the mover is predicted to be when the vehicle would meet it, metres.
        mover_at: Point2<f64>,
    },
}

/// Why the driver calls for a pilot (the thesis' pilot intervention).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PilotCall {
    /// It stopped for an obstacle the sensor can no longer see, and cannot see it go.
    HiddenObstacle,
    /// It has stood for obstacles in its path for `blocked_call_after_s`: the way is blocked.
    Blocked,
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
    /// When the last revolution arrived, seconds (the watchdog's clock).
    last_revolution_s: Option<f64>,
    /// The farthest any circle of the collision model reaches from the vehicle's origin, metres
    /// (where a heading error moves the vehicle most).
    reach_m: f64,
    /// The movers predicted at the last plan.
    predictions: Vec<Prediction>,
    /// The conflict with a mover the last plan found on the chosen path.
    conflict: Option<Conflict>,
    /// When a plan last found a conflict with a mover, seconds.
    last_conflict_s: Option<f64>,
    /// When a plan last found a candidate mover's motion meeting the path, seconds.
    last_caution_s: Option<f64>,
    /// Where, on the route, the nearest candidate mover's motion found lately meets the path
    /// (the start of its zone, metres of route progress), and when it was last found, seconds:
    /// a vehicle stopping anyway stops short of it.
    caution_line: Option<(f64, f64)>,
    /// Since when the plans have stopped the vehicle for obstacles without a pause (`StoppedFor`
    /// or `WaitingForHiddenObstacle`), seconds.
    stopped_since_s: Option<f64>,
    /// The line the vehicle holds short of for a mover: its track, the route arc length,
    /// when the conflict was last found.
    hold: Option<(u32, f64, f64)>,
    /// The movers at the vehicle's body ([`at_body`]): released once seen away from the body,
    /// kept for good once lost.
    at_body: Vec<AtBody>,
    /// Movers predicted out of view at the last plan (see `movers_at_body`): one whose track
    /// drops while predicted to reach the standing vehicle's body is waited for.
    coasting: Vec<TrackState>,
    /// The tracks seen and predicted as movers lately.
    streaks: Vec<MoverStreak>,
    /// Movers that went out of view standing, as last seen (see `lost_standing_at`), kept
    /// for [`LOST_STANDING_FOR_S`] after.
    lost_standing: Vec<TrackState>,
    /// The tracks seen moving as movers for [`MOVER_FOR_S`] on end at some time.
    walked: Vec<u32>,
    /// The person standing the last plan stopped short of (see `short_of_walkers`): where, and
    /// when last seen, seconds.
    walker_stop: Option<(Point2<f64>, f64)>,
}

/// A mover at the vehicle's body.
#[derive(Clone, Copy, Debug)]
struct AtBody {
    /// Its track.
    id: u32,
    /// Where it was last seen (the centre of its hits), metres.
    at: Point2<f64>,
    /// When it was last seen, seconds.
    seen_s: f64,
}

/// A mover predicted out of view whose track drops while it may reach the standing vehicle's
/// body within this many seconds, at any speed up to its peak ([`may_reach_body`]), is waited
/// for as one lost there. Short: a static object's parts sliding out of view (a stale map,
/// heavy dropout) seem to move too, and over the whole horizon their predictions would reach
/// the body and call the pilot.
const DROPPED_AT_BODY_S: f64 = 2.0;

/// ... and only once it had been out of view this long, seconds: it coasted out of view. Under
/// heavy faults spurious returns make one-cell tracks that jump at 5-14 m/s and are dropped
/// within a second; a person lost under the wing was dropped 1.9 s after last seen (sample 757
/// of the falsifier on 308acd2), so 2 s let them go.
const COASTED_S: f64 = 1.5;

/// ... and only one seen and predicted on consecutive plans for at least this long, seconds
/// (three revolutions): one revolution's jump of a one-cell track is no evidence of a mover (a
/// parked car a stale map does not hold).
const SEEN_MOVING_S: f64 = 0.15;

/// A track seen and predicted as a mover on consecutive plans.
#[derive(Clone, Copy, Debug)]
struct MoverStreak {
    /// Its track.
    id: u32,
    /// The last plan that saw and predicted it, seconds.
    last_s: f64,
    /// Since when without a break, seconds.
    since_s: f64,
    /// The last plan of its last streak, once that lasted [`MOVER_FOR_S`] (`None`: it has not).
    mover_s: Option<f64>,
}

/// A track seen and predicted as a mover without a break for this long, seconds ...
const MOVER_FOR_S: f64 = 1.0;
/// ... this lately, seconds, may arrive at the body ([`Driver::plan`]): one that slowed as it
/// reached it, or walked out of view into it, is still one. A static object's sliding visible
/// part seems to move in bursts, not for a second on end (a row of parked cars a stale map
/// does not hold, on the parking lot).
const MOVER_LATELY_S: f64 = 6.0;
/// A mover lost from view while standing may have walked on at this speed, m/s (a brisk walk)
/// ...
const LOST_STANDING_WALK_M_S: f64 = 1.5;
/// ... for this long after it was last seen, seconds, if no larger than this, metres (a person;
/// a parked car a stale map does not hold, whose visible part slides, is larger).
const LOST_STANDING_FOR_S: f64 = 60.0;
const LOST_STANDING_EXTENT_M: f64 = 2.0;

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
            last_revolution_s: None,
            predictions: Vec::new(),
            conflict: None,
            last_conflict_s: None,
            last_caution_s: None,
            caution_line: None,
            stopped_since_s: None,
            hold: None,
            at_body: Vec::new(),
            coasting: Vec::new(),
            streaks: Vec::new(),
            lost_standing: Vec::new(),
            walked: Vec::new(),
            walker_stop: None,
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
        self.stopped_since_s = None;
        self.last_conflict_s = None;
        self.last_caution_s = None;
        self.caution_line = None;
        self.at_body.clear();
        self.coasting.clear();
        self.streaks.clear();
        self.lost_standing.clear();
        self.walked.clear();
        self.hold = None;
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
        // The tracker's movers, once a plan: the space-time check and the body hold read them.
        let movers = map.movers();
        let candidates = map.candidate_movers();
        let wanted = self.caution(&p, s, &candidates, &movers, wanted, estimate.t_s, &config);
        let mut conflict = self.traffic_conflict(&p, &movers, wanted, estimate.t_s, &config, false);
        let v0 = self.last_odometry.map_or(0.0, |o| o.speed_m_s.max(0.0));
        if conflict.is_some_and(|c| stopping_distance_m(v0, decel, &config) >= c.zone_m) {
            // Too late to stop short of the mover's path: standing in it is the worst choice.
            // Drive on if the vehicle clears the mover with the tighter committed margin.
            let committed = self.traffic_conflict(&p, &movers, wanted, estimate.t_s, &config, true);
            if committed.is_none() {
                conflict = None;
            }
        }
        let mut chosen = p.chosen().clone();
        if let Some(stop_at) =
            self.hold_line(conflict.as_ref(), s, v0, decel, estimate.t_s, &config)
        {
            chosen.collision_at_m = Some(chosen.collision_at_m.map_or(stop_at, |c| c.min(stop_at)));
        }
        if let Some(at) = chosen.collision_at_m {
            chosen.collision_at_m = Some(self.short_of_caution_line(at, s, v0, decel, &config));
        }
        if let Some(at) = chosen.collision_at_m {
            // Stopping - for a mover or the map - never where another mover is predicted to
            // pass, when the vehicle can stop short of its path.
            chosen.collision_at_m =
                Some(self.stand_clear(&p, &movers, at, v0, decel, estimate.t_s, &config));
        }
        chosen.collision_at_m =
            self.short_of_walkers(&p, &movers, chosen.collision_at_m, v0, decel, &config);
        let (mut v, _) = avoid(&chosen, wanted, decel, &config);
        let body = self.movers_at_body(
            &movers,
            &estimate.world_from_vehicle,
            estimate.t_s,
            v0 < 0.05,
            &config,
        );
        // Standing beside a known mover standing within its reach: it may walk or drive on
        // into the airframe (or it touches it already): the vehicle does not move off.
        let body = body.or_else(|| {
            (v0 < 0.05)
                .then(|| {
                    self.standing_at(&movers, &estimate.world_from_vehicle, estimate.t_s, &config)
                })
                .flatten()
        });
        if body.is_some() {
            v = 0.0;
        }
        self.speed_command_m_s = v;
        self.status = match conflict {
            _ if let Some(held) = body => held,
            _ if v > 0.0 => DriverStatus::Driving,
            _ if let Some((obstacle, last_seen_s)) = self.walker_stop => DriverStatus::StoppedFor {
                obstacle,
                last_seen_s,
            },
            _ if chosen.collision_at_m != p.chosen().collision_at_m => DriverStatus::Yielding {
                track_id: self.hold.map_or(u32::MAX, |h| h.0),
                mover_at: conflict.map_or(here, |c| c.mover_at),
            },
            _ => self.stopped_status(&p, map, estimate.t_s, &config),
        };
        self.stopped_since_s = match self.status {
            DriverStatus::StoppedFor { .. } | DriverStatus::WaitingForHiddenObstacle { .. } => {
                Some(self.stopped_since_s.unwrap_or(estimate.t_s))
            }
            _ => None,
        };
        if conflict.is_some() {
            self.last_conflict_s = Some(estimate.t_s);
        }
        self.conflict = conflict;
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

    /// How the vehicle is expected to move: from its speed now to `wanted` m/s.
    fn profile(&self, wanted: f64) -> SpeedProfile {
        SpeedProfile {
            speed_m_s: self.last_odometry.map_or(0.0, |o| o.speed_m_s.max(0.0)),
            target_m_s: wanted,
            acceleration_m_s2: self.vehicle.acceleration_m_s2,
        }
    }

    /// `wanted` capped at the caution speed while the motion so far of a candidate mover (one
    /// not yet predictable, [`mapper::Tracker::candidate_movers`]) would meet `p`'s chosen path,
    /// or the path passes near a known mover standing ([`traffic::passes_standing`]), and for
    /// `conflict_memory_s` after: by the time a candidate is confirmed, or the one standing has
    /// walked on, the vehicle can stop short of it; if it was a static object's parts coming
    /// into view, it only slowed. Where the candidate's motion meets the path is kept as the
    /// caution line ([`Self::short_of_caution_line`]).
    #[allow(clippy::too_many_arguments)]
    fn caution(
        &mut self,
        p: &Plan,
        s: f64,
        candidates: &[TrackState],
        movers: &[TrackState],
        wanted: f64,
        now_s: f64,
        config: &AutonomyConfig,
    ) -> f64 {
        let traffic = &config.traffic;
        if !traffic.enabled {
            return wanted;
        }
        let predictions = predict(candidates, now_s, traffic);
        if !predictions.is_empty() {
            let path = TimedPath {
                poses: &p.chosen().poses,
                step_m: config.step_m,
                profile: self.profile(wanted),
                now_s,
                yielding: false,
            };
            if let Some(c) = first_conflict(&path, &self.vehicle.collision, &predictions, traffic) {
                self.last_caution_s = Some(now_s);
                let line = match self.caution_line {
                    Some((held, t)) if now_s - t < traffic.conflict_memory_s => {
                        held.min(s + c.zone_m)
                    }
                    _ => s + c.zone_m,
                };
                self.caution_line = Some((line, now_s));
            }
        }
        let poses = &p.chosen().poses;
        if movers
            .iter()
            .filter(|t| !surely_moving(t, traffic))
            .any(|t| {
                first_within_standing_reach(&self.vehicle.collision, poses, t, traffic).is_some()
            })
        {
            self.last_caution_s = Some(now_s);
        }
        if self
            .last_caution_s
            .is_some_and(|t| now_s - t < traffic.conflict_memory_s)
        {
            wanted.min(traffic.caution_speed_m_s)
        } else {
            wanted
        }
    }

    /// A known mover of `movers` arriving lately (seen predicted for a second within the last
    /// six, beyond its own extent: not a static object's sliding parts) and standing now (not
    /// [`surely_moving`]) within its reach of the vehicle at `pose`
    /// ([`first_within_standing_reach`]), as what stops the vehicle; `None` with traffic off.
    fn standing_at(
        &self,
        movers: &[TrackState],
        pose: &Isometry2<f64>,
        now_s: f64,
        config: &AutonomyConfig,
    ) -> Option<DriverStatus> {
        let cfg = &config.traffic;
        if !cfg.enabled {
            return None;
        }
        movers
            .iter()
            .filter(|t| {
                !surely_moving(t, cfg) && (self.arriving(t, now_s, cfg) || self.is_walker(t, cfg))
            })
            .find(|t| {
                first_within_standing_reach(
                    &self.vehicle.collision,
                    std::slice::from_ref(pose),
                    t,
                    cfg,
                )
                .is_some()
            })
            .map(|t| DriverStatus::StoppedFor {
                obstacle: t.position,
                last_seen_s: t.t_s,
            })
    }

    /// Whether `t` is a person standing: a small known mover (up to
    /// [`LOST_STANDING_EXTENT_M`]) seen moving for [`MOVER_FOR_S`] on end at some time, not
    /// moving now.
    fn is_walker(&self, t: &TrackState, cfg: &crate::traffic::TrafficConfig) -> bool {
        t.confirmed
            && t.extent_m <= LOST_STANDING_EXTENT_M
            && !surely_moving(t, cfg)
            && self.walked.contains(&t.id)
    }

    /// Where to stop instead of `at_m` ahead (`None`: nothing stops the vehicle) so as not to
    /// pass within reach ([`first_within_standing_reach`]) of a person standing (`is_walker`):
    /// walking on from 2 m off the path, they reach it before the tracker sees them move and
    /// the vehicle can stop - passing slowly is not enough. When the vehicle can stop before the reach;
    /// already inside it, the caution speed applies. The person stopped for is kept as
    /// `walker_stop` (what the stopped vehicle says it stands for).
    fn short_of_walkers(
        &mut self,
        p: &Plan,
        movers: &[TrackState],
        at_m: Option<f64>,
        v0: f64,
        decel: f64,
        config: &AutonomyConfig,
    ) -> Option<f64> {
        self.walker_stop = None;
        let cfg = &config.traffic;
        if !cfg.enabled {
            return at_m;
        }
        let braking_m = stopping_distance_m(v0, decel, config) - config.stop_buffer_m;
        let poses = &p.chosen().poses;
        let mut at_m = at_m;
        let walkers: Vec<&TrackState> = movers.iter().filter(|t| self.is_walker(t, cfg)).collect();
        for t in walkers {
            let reached = first_within_standing_reach(&self.vehicle.collision, poses, t, cfg);
            let Some(k) = reached else { continue };
            let zone_m = k as f64 * config.step_m;
            if zone_m > braking_m && at_m.is_none_or(|a| zone_m < a) {
                at_m = Some(zone_m);
                self.walker_stop = Some((t.position, t.t_s));
            }
        }
        at_m
    }

    /// Where to stop instead of `at_m` ahead of route progress `s`: short of the caution line
    /// while it holds (found within `conflict_memory_s`) and the vehicle can stop before it -
    /// a vehicle stopping anyway (for a tug under its wing) must not stop with its nose across
    /// the way a candidate mover is heading (the tug's train, not yet confirmed); `at_m` else.
    fn short_of_caution_line(
        &mut self,
        at_m: f64,
        s: f64,
        v0: f64,
        decel: f64,
        config: &AutonomyConfig,
    ) -> f64 {
        let Some((line, t)) = self.caution_line else {
            return at_m;
        };
        let now_s = self.estimate.map_or(t, |e| e.t_s);
        if now_s - t >= config.traffic.conflict_memory_s || line - s < -1.0 {
            self.caution_line = None;
            return at_m;
        }
        // Short of the line itself, if not by the whole stop buffer: braking now, it stops
        // before the mover's way.
        let ahead = line - s;
        let braking_m = stopping_distance_m(v0, decel, config) - config.stop_buffer_m;
        if ahead > braking_m && ahead < at_m {
            ahead
        } else {
            at_m
        }
    }

    /// Where the vehicle must stop for movers, as a distance ahead of route progress `s`: before
    /// the conflict zone when it can stop short of it, before the conflict itself otherwise.
    /// Once two plans in a row find the conflict, the line is held on the route - never moved
    /// further on while the conflict lasts, nor for `conflict_memory_s` after it was last
    /// found - so a prediction that flickers or a zone that shifts does not let the vehicle
    /// creep into the mover's path.
    fn hold_line(
        &mut self,
        conflict: Option<&Conflict>,
        s: f64,
        v0: f64,
        decel: f64,
        now_s: f64,
        config: &AutonomyConfig,
    ) -> Option<f64> {
        let previous = self.conflict.map(|c| c.track_id);
        if let Some(c) = conflict {
            let short_of_zone = stopping_distance_m(v0, decel, config) < c.zone_m;
            let line = s + if short_of_zone { c.zone_m } else { c.at_m };
            let held = match self.hold {
                Some((id, held, _)) if id == c.track_id => held.min(line),
                _ => line,
            };
            if previous != Some(c.track_id) && self.hold.is_none() {
                // Found on one plan only (a prediction may flicker): this plan stops short of
                // it; the line is held once the next plan finds it again.
                return Some(line - s);
            }
            self.hold = Some((c.track_id, held, now_s));
        } else if self
            .hold
            .is_some_and(|(_, _, t)| now_s - t >= config.traffic.conflict_memory_s)
        {
            self.hold = None;
        }
        // A line well behind the vehicle (a closed route's lap started over, or it went on
        // committed) holds nothing.
        if self.hold.is_some_and(|(_, line, _)| line - s < -1.0) {
            self.hold = None;
        }
        self.hold.map(|(_, line, _)| (line - s).max(0.0))
    }

    /// Where to stop instead of `at_m` ahead so as not to stand in a predicted mover's path,
    /// nor beside one of `movers` not predicted now - standing, or too slow to predict
    /// ([`traffic::stand_clear`]); `at_m` when it is clear or too late.
    #[allow(clippy::too_many_arguments)]
    fn stand_clear(
        &self,
        p: &Plan,
        movers: &[TrackState],
        at_m: f64,
        v0: f64,
        decel: f64,
        now_s: f64,
        config: &AutonomyConfig,
    ) -> f64 {
        let standing: Vec<TrackState> = movers
            .iter()
            .filter(|t| !self.predictions.iter().any(|q| q.track.id == t.id))
            .cloned()
            .collect();
        if !config.traffic.enabled || (self.predictions.is_empty() && standing.is_empty()) {
            return at_m;
        }
        let path = TimedPath {
            poses: &p.chosen().poses,
            step_m: config.step_m,
            profile: self.profile(0.0),
            now_s,
            yielding: false,
        };
        crate::traffic::stand_clear(
            &path,
            &self.vehicle.collision,
            &self.predictions,
            &standing,
            at_m,
            config.stop_buffer_m,
            stopping_distance_m(v0, decel, config),
            &config.traffic,
        )
        .unwrap_or(at_m)
    }

    /// The `movers` (the online map's tracker's) predicted, and the first conflict on `p`'s
    /// chosen path for a vehicle going from its speed now to `wanted` m/s (`None` with traffic
    /// off); `committed`: with the time margin of a vehicle that can no longer stop short.
    fn traffic_conflict(
        &mut self,
        p: &Plan,
        movers: &[TrackState],
        wanted: f64,
        now_s: f64,
        config: &AutonomyConfig,
        committed: bool,
    ) -> Option<Conflict> {
        let mut traffic = config.traffic.clone();
        if committed {
            traffic.time_margin_s = traffic.committed_margin_s;
            traffic.resume_margin_s = 0.0;
        }
        let traffic = &traffic;
        if !traffic.enabled {
            self.predictions.clear();
            return None;
        }
        // A mover known to move (by the body hold's evidence) and in view stays predicted
        // slower than the floor: its visible part slows as the airframe hides the rest of it.
        let kept: Vec<u32> = movers
            .iter()
            .filter(|t| now_s - t.t_s <= 0.25 && self.arriving(t, now_s, traffic))
            .map(|t| t.id)
            .collect();
        self.predictions = predict_keeping(movers, now_s, traffic, &kept);
        if self.predictions.is_empty() {
            return None;
        }
        let path = TimedPath {
            poses: &p.chosen().poses,
            step_m: config.step_m,
            profile: self.profile(wanted),
            now_s,
            // Yielding, or slowing for a conflict found lately: the margin after grows, so a
            // prediction that flickers does not let the vehicle creep into the mover's path.
            yielding: matches!(self.status, DriverStatus::Yielding { .. })
                || self
                    .last_conflict_s
                    .is_some_and(|t| now_s - t < traffic.conflict_memory_s),
        };
        first_conflict(&path, &self.vehicle.collision, &self.predictions, traffic)
    }

    /// The movers at the body now ([`at_body`]) joined to those lost there before; what holds
    /// the vehicle for them (`None`: nothing at the body): stopped for the one seen last, if
    /// seen within `hidden_after_s`, else waiting for one lost there, as for a hidden obstacle.
    fn movers_at_body(
        &mut self,
        movers: &[TrackState],
        pose: &Isometry2<f64>,
        now_s: f64,
        stopped: bool,
        config: &AutonomyConfig,
    ) -> Option<DriverStatus> {
        if !config.traffic.enabled {
            self.at_body.clear();
            self.coasting.clear();
            return None;
        }
        let cfg = &config.traffic;
        self.note_streaks(now_s);
        self.note_lost_standing(movers, now_s, cfg);
        // A mover arriving at the body, or one held there before and not seen away.
        let mut body: Vec<AtBody> = movers
            .iter()
            .filter(|t| {
                let at = || at_body(&self.vehicle.collision, pose, t, now_s, cfg);
                if self.at_body.iter().any(|r| r.id == t.id) {
                    // Held: released only once seen away (a prediction carrying it on through
                    // the airframe is no evidence that it left).
                    let seen_now = now_s - t.t_s <= 0.25;
                    return !seen_now || at();
                }
                self.arriving(t, now_s, cfg) && at()
            })
            .map(|t| AtBody {
                id: t.id,
                at: t.position,
                seen_s: t.t_s,
            })
            .collect();
        // One lost (its track gone, or renumbered: seen again beyond its own extent from where
        // it was lost) is waited for for good, as a hidden obstacle: the pilot is called. Its
        // cells reading free would prove nothing - within the map's self-hit margin of the
        // body nothing is ever mapped.
        let lost = self
            .at_body
            .iter()
            .filter(|r| !movers.iter().any(|t| t.id == r.id));
        body.extend(lost);
        // A mover that coasted out of view toward a standing vehicle and whose track was then
        // dropped: if it may reach the body within `DROPPED_AT_BODY_S`, it is waited for as
        // one lost there (a van that drove into the blind zone behind the wing has not gone).
        if stopped {
            let dropped = self
                .coasting
                .iter()
                .filter(|t| !movers.iter().any(|m| m.id == t.id))
                .filter(|t| !body.iter().any(|r| r.id == t.id) && now_s - t.t_s >= COASTED_S)
                .filter(|t| {
                    let window = (now_s, now_s + DROPPED_AT_BODY_S);
                    may_reach_body(&self.vehicle.collision, pose, t, window, cfg)
                })
                .map(|t| AtBody {
                    id: t.id,
                    at: t.position,
                    seen_s: t.t_s,
                })
                .collect::<Vec<_>>();
            body.extend(dropped);
            let lost = self.lost_standing_at(pose, now_s, &body, cfg);
            body.extend(lost);
        }
        // Movers predicted out of view now, confirmed, beyond what revealing a static object
        // explains, and seen predicted on a few revolutions on end: checked again if their
        // track drops (seen too briefly for a streak, maybe: a van seen in fragments for under
        // a second each). Others are not: a one-cell track jumping at 7 m/s at the edge of
        // view, lost for 6 s, would be predicted onto the body from 50 m away (one seen longer
        // still is: README, Known problems).
        self.coasting = movers
            .iter()
            .filter(|t| {
                now_s - t.t_s > 0.25
                    && t.confirmed
                    && moved_beyond_its_extent(t, cfg)
                    && self.predictions.iter().any(|p| p.track.id == t.id)
                    && self
                        .streaks
                        .iter()
                        .any(|r| r.id == t.id && r.last_s - r.since_s >= SEEN_MOVING_S)
            })
            .cloned()
            .collect();
        self.at_body = body;
        let seen = self
            .at_body
            .iter()
            .filter(|r| now_s - r.seen_s <= self.config.hidden_after_s);
        if let Some(r) = seen.max_by(|a, b| a.seen_s.total_cmp(&b.seen_s)) {
            return Some(DriverStatus::StoppedFor {
                obstacle: r.at,
                last_seen_s: r.seen_s,
            });
        }
        let r = self.at_body.first()?;
        Some(DriverStatus::WaitingForHiddenObstacle {
            obstacle: r.at,
            last_seen_s: Some(r.seen_s),
            since_s: match self.status {
                DriverStatus::WaitingForHiddenObstacle { since_s, .. } => since_s,
                _ => now_s,
            },
        })
    }

    /// Whether track `t` is a mover that may arrive at the body: one predicted on a streak
    /// lately that has moved beyond its own extent.
    fn arriving(&self, t: &TrackState, now_s: f64, cfg: &crate::traffic::TrafficConfig) -> bool {
        self.streaks
            .iter()
            .any(|r| r.id == t.id && r.mover_s.is_some_and(|m| now_s - m <= MOVER_LATELY_S))
            && moved_beyond_its_extent(t, cfg)
    }

    /// Keeps the known movers out of view while standing (the tracker's confirmed movers, no
    /// larger than [`LOST_STANDING_EXTENT_M`], that were seen moving for [`MOVER_FOR_S`] on end
    /// and travelled more than twice their extent and 3 m: a person who walked up and stopped,
    /// not a static object's sliding parts, which seem to move in bursts), as last seen, after their tracks drop; forgets one seen again,
    /// or lost [`LOST_STANDING_FOR_S`] ago.
    fn note_lost_standing(
        &mut self,
        movers: &[TrackState],
        now_s: f64,
        cfg: &crate::traffic::TrafficConfig,
    ) {
        for r in self.streaks.iter().filter(|r| r.mover_s.is_some()) {
            if !self.walked.contains(&r.id) {
                self.walked.push(r.id);
            }
        }
        // Those neither tracked nor kept are forgotten.
        let lost = &self.lost_standing;
        self.walked
            .retain(|id| movers.iter().any(|t| t.id == *id) || lost.iter().any(|l| l.id == *id));
        self.lost_standing.retain(|l| {
            now_s - l.t_s < LOST_STANDING_FOR_S
                && !movers.iter().any(|t| t.id == l.id && now_s - t.t_s <= 0.25)
        });
        for t in movers.iter().filter(|t| {
            now_s - t.t_s > 0.25
                && t.confirmed
                && self.walked.contains(&t.id)
                && t.extent_m <= LOST_STANDING_EXTENT_M
                && t.travel_m > 2.0 * t.extent_m + 3.0
                && !surely_moving(t, cfg)
        }) {
            match self.lost_standing.iter_mut().find(|l| l.id == t.id) {
                Some(l) => *l = t.clone(),
                None => self.lost_standing.push(t.clone()),
            }
        }
    }

    /// The movers lost standing (see `note_lost_standing`) that may have walked to the body of
    /// the standing vehicle at `pose` since they were last seen, as movers at its body (waited
    /// for, the pilot called): a person the airframe hid may have walked on into the blind zone
    /// at the tail. Not those already in `body`.
    fn lost_standing_at(
        &self,
        pose: &Isometry2<f64>,
        now_s: f64,
        body: &[AtBody],
        cfg: &crate::traffic::TrafficConfig,
    ) -> Vec<AtBody> {
        self.lost_standing
            .iter()
            .filter(|l| !body.iter().any(|r| r.id == l.id))
            .filter(|l| {
                may_have_walked_to(
                    &self.vehicle.collision,
                    pose,
                    l,
                    now_s,
                    LOST_STANDING_WALK_M_S,
                    cfg,
                )
            })
            .map(|l| AtBody {
                id: l.id,
                at: l.position,
                seen_s: l.t_s,
            })
            .collect()
    }

    /// Each track seen (this revolution or the last, 0.25 s) and predicted now continues its
    /// streak, or starts one; its last streak, once it lasted [`MOVER_FOR_S`], makes it a mover
    /// as of the streak's last plan. Streaks not continued are kept for [`MOVER_LATELY_S`].
    fn note_streaks(&mut self, now_s: f64) {
        for p in self
            .predictions
            .iter()
            .filter(|p| now_s - p.track.t_s <= 0.25)
        {
            let id = p.track.id;
            let r = match self.streaks.iter_mut().find(|r| r.id == id) {
                Some(r) => r,
                None => {
                    self.streaks.push(MoverStreak {
                        id,
                        last_s: now_s,
                        since_s: now_s,
                        mover_s: None,
                    });
                    self.streaks.last_mut().expect("just pushed")
                }
            };
            if now_s - r.last_s > 0.25 {
                // A new streak: an earlier one does not count (a row of parked cars the map
                // does not hold, merged into one track, seems to move in bursts).
                r.since_s = now_s;
                r.mover_s = None;
            }
            r.last_s = now_s;
            if now_s - r.since_s >= MOVER_FOR_S {
                r.mover_s = Some(now_s);
            }
        }
        self.streaks.retain(|r| now_s - r.last_s <= MOVER_LATELY_S);
    }

    /// The fastest the driver will go on this route, and why, when it is below the route's
    /// speed (`None`: the route's speed is allowed).
    pub fn route_speed_lowered(&self) -> Option<(f64, SpeedLimit)> {
        let (cap, why) = speed_cap_m_s(self.vehicle.deceleration_m_s2, &self.config);
        (cap < self.wanted_speed_m_s).then_some((cap, why))
    }

    /// The movers predicted at the last plan, with their discs over the horizon.
    pub fn predictions(&self) -> &[Prediction] {
        &self.predictions
    }

    /// The conflict with a mover found on the chosen path at the last plan.
    pub fn conflict(&self) -> Option<&Conflict> {
        self.conflict.as_ref()
    }

    /// Why the vehicle is stopped by the chosen candidate's first colliding pose: the obstacle
    /// cells within each circle's radius plus the avoider's margin there (as `config`, the plan's,
    /// widened for the estimate's uncertainty, has it; a metre more if none is), and when a
    /// revolution last hit any of them.
    fn stopped_status(
        &self,
        p: &Plan,
        map: &OnlineMap,
        now_s: f64,
        config: &AutonomyConfig,
    ) -> DriverStatus {
        let c = p.chosen();
        let Some(at_m) = c.collision_at_m else {
            return DriverStatus::Driving;
        };
        let k = ((at_m / self.config.step_m).round() as usize).min(c.poses.len().saturating_sub(1));
        let Some(pose) = c.poses.get(k) else {
            return DriverStatus::Driving;
        };
        let m = map.map();
        let margin = f64::from(config.avoider_safety_m) + m.config().resolution_m;
        let (mut nearest, mut last_seen): (Option<(f64, Point2<f64>)>, Option<f64>) = (None, None);
        for extra in [0.0, 1.0] {
            for circle in self.vehicle.collision.circles() {
                let center = pose * Point2::new(circle.x_m, circle.y_m);
                let r = circle.radius_m + margin + extra;
                for cell in m.obstacles_within(circle.level, &center, r) {
                    let at = m.world_cell_center(cell);
                    let d = (at - center).norm();
                    if nearest.is_none_or(|(best, _)| d < best) {
                        nearest = Some((d, at));
                    }
                    if let Some(t) = map.last_hit_s(cell) {
                        last_seen = Some(last_seen.map_or(t, |s: f64| s.max(t)));
                    }
                }
            }
            if nearest.is_some() {
                break;
            }
        }
        let Some((_, obstacle)) = nearest else {
            return DriverStatus::Driving;
        };
        match last_seen {
            Some(t) if now_s - t <= self.config.hidden_after_s => DriverStatus::StoppedFor {
                obstacle,
                last_seen_s: t,
            },
            _ => DriverStatus::WaitingForHiddenObstacle {
                obstacle,
                last_seen_s: last_seen,
                since_s: match self.status {
                    DriverStatus::WaitingForHiddenObstacle { since_s, .. } => since_s,
                    _ => now_s,
                },
            },
        }
    }

    /// What the driver is doing about obstacles (as of the last plan).
    pub fn status(&self) -> DriverStatus {
        self.status
    }

    /// Whether the driver calls for a pilot at `now_s`, and why: it has waited for a hidden
    /// obstacle longer than `pilot_call_after_s`, or stood for obstacles longer than
    /// `blocked_call_after_s`.
    pub fn calls_for_pilot(&self, now_s: f64) -> Option<PilotCall> {
        if matches!(self.status, DriverStatus::WaitingForHiddenObstacle { since_s, .. }
            if now_s - since_s >= self.config.pilot_call_after_s)
        {
            return Some(PilotCall::HiddenObstacle);
        }
        self.stopped_since_s
            .filter(|since| now_s - since >= self.config.blocked_call_after_s)
            .map(|_| PilotCall::Blocked)
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
            speed_m_s: if self.watchdog_tripped() {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::online_map::ForgettingConfig;
    use mapper::{Circle, Levels, MapConfig, MultiHeightMap};

    fn driver() -> Driver {
        let route = RoutePath::new(&[Point2::new(0.0, 0.0), Point2::new(200.0, 0.0)], false);
        let circle = |x_m| Circle {
            x_m,
            y_m: 0.0,
            radius_m: 1.0,
            level: 0,
        };
        let collision = CollisionModel::new(vec![circle(0.0), circle(2.0)], vec![0.0]).unwrap();
        Driver::new(
            route,
            VehicleModel {
                collision,
                wheelbase_m: 2.5,
                deceleration_m_s2: 3.0,
                acceleration_m_s2: 1.0,
                behaviour: Behaviour::Deviate,
            },
            AutonomyConfig::default(),
            5.0,
            40.0,
        )
    }

    fn empty_map() -> OnlineMap {
        started(unstarted_map(), 20.0)
    }

    /// An empty map centred at (20, 0) that no revolution has reached.
    fn unstarted_map() -> OnlineMap {
        let config = MapConfig {
            block_cells: 100,
            max_distance_m: 5.0,
            ..MapConfig::default()
        };
        let levels = Levels::cumulative(vec![0.0]).unwrap();
        let map = MultiHeightMap::new(config, levels, Point2::new(20.0, 0.0)).unwrap();
        let self_filter = CollisionModel::new(
            vec![mapper::Circle {
                x_m: 1.0,
                y_m: 0.0,
                radius_m: 1.5,
                level: 0,
            }],
            vec![0.0],
        )
        .unwrap();
        OnlineMap::new(map, self_filter, ForgettingConfig::default(), 0.1, 1.0)
    }

    /// `map` after an empty revolution at an exact pose at `x_m` (where it is centred):
    /// mapping has started.
    fn started(mut map: OnlineMap, x_m: f64) -> OnlineMap {
        assert!(!map.mapping_started());
        map.update(&crate::LidarRevolution {
            t_s: 0.0,
            scan: mapper::Scan::new(1, Vec::new(), Vec::new()).unwrap(),
            world_from_vehicle_estimate: nalgebra::Isometry2::translation(x_m, 0.0),
            estimate_covariance: nalgebra::Matrix3::zeros(),
        })
        .unwrap();
        assert!(map.mapping_started());
        map
    }

    /// Until mapping has started (no revolution yet, or none taken at an estimate trusted out
    /// to the obstacle test's range), the vehicle is held, whatever the estimate.
    #[test]
    fn the_vehicle_is_held_until_mapping_has_started() {
        let mut map = unstarted_map();
        let mut d = driver();
        d.on_pose(at(0.0, 10.0, 0.0, 0.0));
        let revolution = |t_s: f64, sigma_rad: f64| crate::LidarRevolution {
            t_s,
            scan: mapper::Scan::new(1, Vec::new(), Vec::new()).unwrap(),
            world_from_vehicle_estimate: nalgebra::Isometry2::translation(10.0, 0.0),
            estimate_covariance: nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(
                0.0025,
                0.0025,
                sigma_rad * sigma_rad,
            )),
        };
        d.plan(&mut map).unwrap();
        assert_eq!(d.speed_command_m_s(), 0.0);
        // 2 x 0.01 rad x 70 m = 1.4 m: not yet.
        map.update(&revolution(0.0, 0.01)).unwrap();
        d.plan(&mut map).unwrap();
        assert!(!map.mapping_started());
        assert_eq!(d.speed_command_m_s(), 0.0);
        // 2 x 0.004 rad x 70 m = 0.56 m (with 0.1 m of position): mapping starts, the vehicle goes.
        map.update(&revolution(0.1, 0.004)).unwrap();
        d.plan(&mut map).unwrap();
        assert!(map.mapping_started());
        assert!(d.speed_command_m_s() > 0.0);
    }

    fn at(t_s: f64, x: f64, y: f64, yaw: f64) -> PoseEstimate {
        PoseEstimate {
            covariance: nalgebra::Matrix3::zeros(),
            t_s,
            world_from_vehicle: Isometry2::new(Vector2::new(x, y), yaw),
        }
    }

    #[test]
    fn without_an_estimate_the_vehicle_is_held() {
        let mut d = driver();
        let mut map = empty_map();
        d.plan(&mut map).unwrap();
        assert!(d.last_plan().is_none());
        assert_eq!(d.command(), Command::default());
    }

    /// The plan starts where the estimate is, and the route progress is the estimate's: the
    /// driver has nothing else to go by (before, progress came from the true pose every step).
    #[test]
    fn plans_and_tracks_route_progress_from_its_estimate() {
        let mut d = driver();
        let mut map = empty_map();
        d.on_pose(at(0.0, 10.0, 1.0, 0.0));
        d.plan(&mut map).unwrap();
        assert!((d.route_s_m().unwrap() - 10.0).abs() < 1e-9);
        let first = d.last_plan().unwrap().chosen().poses[0];
        assert!(
            (first.translation.y - 1.0).abs() < 1e-9,
            "starts at the estimate's offset: {first}"
        );
        assert_eq!(d.speed_command_m_s(), 5.0, "nothing in the way");
        d.on_pose(at(0.1, 12.5, -0.5, 0.0));
        d.plan(&mut map).unwrap();
        assert!((d.route_s_m().unwrap() - 12.5).abs() < 1e-9);
        // Steering back towards the route from the left: to the right (negative).
        d.on_pose(at(0.2, 13.0, 1.0, 0.0));
        d.plan(&mut map).unwrap();
        d.on_odometry(Odometry {
            t_s: 0.2,
            speed_m_s: 5.0,
            steering_rad: 0.0,
        });
        let c = d.command();
        assert!(c.speed_m_s == 5.0 && c.steering_rad < 0.0, "{c:?}");
    }

    /// A route faster than the vehicle can stop from within its longest horizon (60 m at
    /// 3 m/s^2: 17.5 m/s) is lowered, and the driver says so; one within it is not.
    #[test]
    fn a_route_too_fast_to_stop_within_the_horizon_is_lowered() {
        assert_eq!(driver().route_speed_lowered(), None, "5 m/s is allowed");
        let mut fast = driver();
        fast.wanted_speed_m_s = 20.0;
        let (cap, why) = fast.route_speed_lowered().expect("lowered");
        assert_eq!(why, SpeedLimit::Horizon);
        let stopping = cap * 0.5 + cap * cap / 6.0 + 3.0;
        assert!(
            (stopping - 60.0).abs() < 1e-9,
            "{cap} m/s stops in {stopping} m"
        );
        // Maps wide enough for the 60 m horizon the speed needs (blocks of 60 m).
        fast.distance_map_half_size_m = 80.0;
        let config = MapConfig {
            block_cells: 300,
            max_distance_m: 5.0,
            ..MapConfig::default()
        };
        let levels = Levels::cumulative(vec![0.0]).unwrap();
        let wide = MultiHeightMap::new(config, levels, Point2::new(40.0, 0.0)).unwrap();
        let self_filter = fast.vehicle.collision.clone();
        let mut map = started(
            OnlineMap::new(wide, self_filter, ForgettingConfig::default(), 0.1, 1.0),
            40.0,
        );
        fast.on_pose(at(0.0, 10.0, 0.0, 0.0));
        fast.plan(&mut map).unwrap();
        let v = fast.speed_command_m_s();
        assert!((v - cap).abs() < 1e-9, "{v} against {cap}");
    }

    /// An estimate with a lateral standard deviation `sigma_m` (position only).
    fn uncertain(sigma_m: f64) -> PoseEstimate {
        PoseEstimate {
            covariance: nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(
                sigma_m * sigma_m,
                sigma_m * sigma_m,
                0.0,
            )),
            ..at(0.0, 10.0, 0.0, 0.0)
        }
    }

    /// A less certain estimate means a slower vehicle, then a stopped one: full speed up to
    /// 0.15 m, falling linearly to 0 at 0.5 m (the defaults).
    #[test]
    fn an_uncertain_estimate_slows_then_stops_the_vehicle() {
        let speed = |sigma_m| {
            let mut d = driver();
            let mut map = empty_map();
            d.on_pose(uncertain(sigma_m));
            d.plan(&mut map).unwrap();
            d.speed_command_m_s()
        };
        assert_eq!(speed(0.0), 5.0);
        assert_eq!(speed(0.1), 5.0);
        assert!((speed(0.325) - 2.5).abs() < 1e-9, "{}", speed(0.325));
        assert_eq!(speed(0.5), 0.0);
        assert_eq!(
            speed(f64::NAN),
            0.0,
            "an estimate that knows nothing holds the vehicle"
        );
    }

    /// The margins widen by two standard deviations: an obstacle the certain estimate passes
    /// 0.3 m from (beyond the avoider's 0.2 m) is inside the uncertain estimate's 0.2 + 2 x 0.1.
    #[test]
    fn an_uncertain_estimate_widens_the_safety_distances() {
        let c = AutonomyConfig::default();
        let (w, factor) = c.under_uncertainty(0.1);
        assert!((w.avoider_safety_m - 0.4).abs() < 1e-6 && (w.planner_safety_m - 0.8).abs() < 1e-6);
        assert_eq!(factor, 1.0);
        let (w0, _) = c.under_uncertainty(0.0);
        assert_eq!(w0, c);
    }

    /// Between estimates the driver carries its estimate forward on odometry (a localizer slower
    /// than the control loop); a new estimate replaces it.
    #[test]
    fn between_estimates_the_pose_is_dead_reckoned_on_odometry() {
        let mut d = driver();
        d.on_pose(at(0.0, 0.0, 0.0, 0.0));
        let odo = |t_s, steering_rad| Odometry {
            t_s,
            speed_m_s: 2.0,
            steering_rad,
        };
        d.on_odometry(odo(0.0, 0.0));
        d.on_odometry(odo(0.5, 0.2));
        let e = d.estimate().unwrap();
        assert!((e.world_from_vehicle.translation.x - 1.0).abs() < 1e-12 && e.t_s == 0.5);
        // 0.5 s more on the arc of steering 0.2: yaw grows by v t tan(0.2) / wheelbase.
        d.on_odometry(odo(1.0, 0.2));
        let yaw = d.estimate().unwrap().world_from_vehicle.rotation.angle();
        assert!((yaw - 1.0 * 0.2f64.tan() / 2.5).abs() < 1e-12, "{yaw}");
        d.on_pose(at(1.0, 7.0, 0.0, 0.0));
        assert_eq!(d.estimate().unwrap().world_from_vehicle.translation.x, 7.0);
    }
}
