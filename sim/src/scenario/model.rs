//! The scenario, resolved: what a run is given ([`Scenario`]: the [`Ground`], the
//! [`ScenarioVehicle`] at its start pose, the [`Route`], static objects, patches and run-time
//! [`Obstacle`]s with their expectations), read by [`Scenario::from_str`] (which loads the files
//! the text names, a vehicle sidecar or a pose file, relative to the scenario's directory) or
//! [`Scenario::from_file`] (both beside the resolver, in `resolve/`), and turned into the worlds
//! a run drives in ([`Scenario::full_scene`], [`Scenario::static_scene`]). World frame: x east,
//! y north, z up, metres, radians.

use std::path::PathBuf;

use nalgebra::{Isometry2, Point2};

use super::spec::{Expectation, ExpectedEnd};
use crate::world::{Patch, Scene, Solid};

/// The ground.
#[derive(Clone, Debug, PartialEq)]
pub struct Ground {
    /// Lower corner (x, y), metres.
    pub min_m: [f64; 2],
    /// Upper corner (x, y), metres.
    pub max_m: [f64; 2],
    /// Remission of bare ground in [0, 1].
    pub ground_remission: f32,
    /// Amplitude of the pavement's texture (`[world] pavement_texture`).
    pub pavement_texture: f32,
    /// Paved areas (an airport's pavement and runways), over the bare ground.
    pub areas: Vec<crate::world::Area>,
}

/// The vehicle of a scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioVehicle {
    /// The description as written (a shipped name or a sidecar path).
    pub description: String,
    /// The vehicle: sidecar spec and collision parts.
    pub vehicle: aircraft::Vehicle,
    /// Start pose of the vehicle frame in the world.
    pub world_from_start: Isometry2<f64>,
    /// When the crew's walk-around confirms the ground the LiDAR cannot see from the start.
    pub walk_around: WalkAround,
}

/// When the crew's walk-around confirms the ground round the vehicle that its LiDAR cannot see
/// from the start (`[vehicle] walk_around`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum WalkAround {
    /// Before the run starts: the start-up rule has nothing to wait for.
    #[default]
    BeforeStart,
    /// Never: a vehicle whose first plan sweeps ground it cannot see waits, and calls for a pilot.
    Never,
    /// At this simulated time, seconds (> 0): until then it waits as for `Never`.
    At(f64),
}

/// The route.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// Waypoints in the world, metres (the first is not repeated at the end of a closed route).
    pub waypoints_m: Vec<Point2<f64>>,
    /// Headings given by a pose file, one per waypoint (`None` where not given).
    pub yaws_rad: Vec<Option<f64>>,
    /// True when the last waypoint joins the first.
    pub closed: bool,
    /// Target speed, m/s.
    pub speed_m_s: f64,
    /// A speed limit at each waypoint, m/s (a taxi route's turns, braked into), if any.
    pub speed_limits_m_s: Option<Vec<f64>>,
    /// A taxi route from a stand the aircraft faces away from its taxilane: the push-back that
    /// brings it from the stand (the start pose) to the route's first waypoint, towed.
    pub pushback: Option<airport::Tow>,
}

impl Route {
    /// Length of one lap, metres (with the closing segment of a closed route).
    pub fn length_m(&self) -> f64 {
        let open: f64 = self
            .waypoints_m
            .windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .sum();
        match (
            self.closed,
            self.waypoints_m.first(),
            self.waypoints_m.last(),
        ) {
            (true, Some(first), Some(last)) => open + (first - last).norm(),
            _ => open,
        }
    }
}

/// Acceleration of a driver that yields (`yields_to_vehicle_m`) when the file gives none,
/// m/s^2: every speed change of such a driver is at this rate.
pub const REACTIVE_ACCELERATION_M_S2: f64 = 2.0;

/// A stop along a mover's path (`stops = [{ at_m, wait_s }]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionStop {
    /// Arc length along the path where its centre stands, metres.
    pub at_m: f64,
    /// How long it waits there, seconds.
    pub wait_s: f64,
}

/// A train car's link to the mover towing the train.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrainLink {
    /// Index of the lead among the scenario's obstacles (always before the car).
    pub lead: usize,
    /// How far the car's centre stays behind the lead's along the path, metres (half the
    /// lengths of the vehicles between and the gaps).
    pub behind_m: f64,
}

/// How a run-time obstacle moves.
#[derive(Clone, Debug, PartialEq)]
pub struct ObstacleMotion {
    /// The polyline followed from its appearance, metres.
    pub path_m: Vec<Point2<f64>>,
    /// Speed along it, m/s.
    pub speed_m_s: f64,
    /// Offset of the obstacle's heading to the heading of the path, radians.
    pub yaw_offset_rad: f64,
    /// Acceleration and braking, m/s^2 (`None`: speed changes are instant, unless it yields).
    pub acceleration_m_s2: Option<f64>,
    /// Where it stops and waits, arc lengths increasing.
    pub stops: Vec<MotionStop>,
    /// A driver that yields to the vehicle within this distance, metres (`None`: it does not
    /// react).
    pub yields_to_vehicle_m: Option<f64>,
    /// A driver that yields and makes room: it pulls aside until its near side is this far
    /// beyond the vehicle's widest part, metres (`None`: it stands where it stopped).
    pub makes_room_m: Option<f64>,
    /// A train's car: its lead (whose profile, stops and reaction the car's motion copies) and
    /// how far behind it the car stays. `None`: it moves on its own.
    pub train: Option<TrainLink>,
}

/// Where a run-time obstacle is and how it moves at an instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoverState {
    /// Position of its axis (box: centre), metres.
    pub x_m: f64,
    /// Position of its axis (box: centre), metres.
    pub y_m: f64,
    /// Heading of the solid, radians (the path's direction plus the yaw offset).
    pub yaw_rad: f64,
    /// Direction of travel, radians (the path's direction where it is).
    pub heading_rad: f64,
    /// Arc length of its centre along its path, metres (negative: a train car not yet on the
    /// path, behind its first point). 0 for a static obstacle.
    pub arc_m: f64,
    /// Speed along the path, m/s (0 standing, static or waiting).
    pub speed_m_s: f64,
}

impl MoverState {
    /// Velocity `[vx, vy]`, m/s.
    pub fn velocity_m_s(&self) -> [f64; 2] {
        let (s, c) = self.heading_rad.sin_cos();
        [self.speed_m_s * c, self.speed_m_s * s]
    }
}

impl ObstacleMotion {
    /// Length of the path, metres.
    pub fn length_m(&self) -> f64 {
        self.path_m.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
    }

    /// The acceleration speed changes happen at: `acceleration_m_s2`, else
    /// [`REACTIVE_ACCELERATION_M_S2`] for a driver that yields, else `None` (instant).
    pub fn acceleration(&self) -> Option<f64> {
        self.acceleration_m_s2
            .or(self.yields_to_vehicle_m.map(|_| REACTIVE_ACCELERATION_M_S2))
    }

    /// True when it moves at `speed_m_s` from its appearance to the path's end without a
    /// speed change on the way (no acceleration, no stops, no reaction): today's mover.
    pub fn is_plain(&self) -> bool {
        self.acceleration().is_none() && self.stops.is_empty()
    }

    /// The state at arc length `arc_m` along the path moving at `speed_m_s`: before the path's
    /// start on the line of its first segment, beyond its end at its last point.
    pub fn state_at_arc(&self, arc_m: f64, speed_m_s: f64) -> MoverState {
        let mut left_m = arc_m;
        let (first, heading0) = match self.path_m.as_slice() {
            [a, b, ..] => (*a, (b.y - a.y).atan2(b.x - a.x)),
            [a] => (*a, 0.0),
            [] => (Point2::origin(), 0.0),
        };
        let mut last = (first.x, first.y, heading0);
        for w in self.path_m.windows(2) {
            let d = w[1] - w[0];
            let len = d.norm();
            let heading = d.y.atan2(d.x);
            if left_m <= len {
                let p = w[0] + d * (left_m / len);
                return MoverState {
                    x_m: p.x,
                    y_m: p.y,
                    yaw_rad: heading + self.yaw_offset_rad,
                    heading_rad: heading,
                    arc_m,
                    speed_m_s,
                };
            }
            left_m -= len;
            last = (w[1].x, w[1].y, heading);
        }
        MoverState {
            x_m: last.0,
            y_m: last.1,
            yaw_rad: last.2 + self.yaw_offset_rad,
            heading_rad: last.2,
            arc_m,
            speed_m_s: 0.0,
        }
    }

    /// Arc length (metres) and speed (m/s) of its planned motion `elapsed_s` seconds after it
    /// appeared, as if nothing were in its way: plain, `speed_m_s * elapsed_s` (beyond the
    /// path's end it stands at the end); with a profile, from rest to rest between its stops
    /// and the path's end (the first leg from its start), each leg speeding up and braking at
    /// [`Self::acceleration`] (instantly without one) and cruising at `speed_m_s`, waiting
    /// `wait_s` at each stop.
    pub fn arc_at(&self, elapsed_s: f64) -> (f64, f64) {
        let accel = self.acceleration();
        if accel.is_none() && self.stops.is_empty() {
            let arc_m = self.speed_m_s * elapsed_s;
            let speed = if arc_m < self.length_m() {
                self.speed_m_s
            } else {
                0.0
            };
            return (arc_m, speed);
        }
        let length_m = self.length_m();
        let rests = self
            .stops
            .iter()
            .map(|s| (s.at_m, s.wait_s))
            .chain(std::iter::once((length_m, f64::INFINITY)));
        let (mut t, mut from_m) = (elapsed_s.max(0.0), 0.0);
        for (at_m, wait_s) in rests {
            let leg = Leg::new((at_m - from_m).max(0.0), self.speed_m_s, accel);
            if t < leg.duration_s {
                let (ds, v) = leg.at(t);
                return (from_m + ds, v);
            }
            t -= leg.duration_s;
            if t < wait_s {
                return (at_m, 0.0);
            }
            t -= wait_s;
            from_m = at_m;
        }
        (length_m, 0.0)
    }
}

/// One leg of a speed profile: `length_m` from rest to rest, cruising at `speed` at most,
/// speeding up and braking at `accel` (instantly when `None`).
struct Leg {
    length_m: f64,
    accel: Option<f64>,
    /// Top speed reached, m/s.
    peak: f64,
    /// Time to reach it, seconds (0 without acceleration).
    ramp_s: f64,
    /// Time at the top speed, seconds.
    cruise_s: f64,
    duration_s: f64,
}

impl Leg {
    fn new(length_m: f64, speed: f64, accel: Option<f64>) -> Self {
        let (peak, ramp_s, cruise_s) = match accel {
            None => (speed, 0.0, length_m / speed),
            Some(a) if speed * speed / a <= length_m => {
                (speed, speed / a, (length_m - speed * speed / a) / speed)
            }
            Some(a) => {
                let peak = (a * length_m).sqrt();
                (peak, peak / a, 0.0)
            }
        };
        Leg {
            length_m,
            accel,
            peak,
            ramp_s,
            cruise_s,
            duration_s: 2.0 * ramp_s + cruise_s,
        }
    }

    /// Distance covered (metres) and speed (m/s) `t_s` into the leg, `t_s` < its duration.
    fn at(&self, t_s: f64) -> (f64, f64) {
        let Some(a) = self.accel else {
            return (self.peak * t_s, self.peak);
        };
        if t_s < self.ramp_s {
            (0.5 * a * t_s * t_s, a * t_s)
        } else if t_s < self.ramp_s + self.cruise_s {
            (
                0.5 * self.peak * self.ramp_s + self.peak * (t_s - self.ramp_s),
                self.peak,
            )
        } else {
            let r = (self.duration_s - t_s).max(0.0);
            (self.length_m - 0.5 * a * r * r, a * r)
        }
    }
}

/// A run-time obstacle.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Its solid at its initial pose (`runtime` is true).
    pub solid: Solid,
    /// What the vehicle must do.
    pub expect: Expectation,
    /// When it appears, seconds.
    pub appears_s: f64,
    /// When it disappears, seconds (`None`: never).
    pub disappears_s: Option<f64>,
    /// Its motion (`None`: static).
    pub motion: Option<ObstacleMotion>,
}

impl Obstacle {
    /// True when it is in the world at time `t_s`.
    pub fn present_at(&self, t_s: f64) -> bool {
        t_s >= self.appears_s && !self.disappears_s.is_some_and(|d| t_s >= d)
    }

    /// Its pose `(x_m, y_m, yaw_rad)` at time `t_s`, or `None` when it is absent then. For a
    /// driver that yields (or a car of its train), the pose as if nothing were in its way: the
    /// run moves it with `engine::Traffic`, which reacts.
    pub fn pose_at(&self, t_s: f64) -> Option<(f64, f64, f64)> {
        self.state_at(t_s).map(|m| (m.x_m, m.y_m, m.yaw_rad))
    }

    /// Its state (pose, arc length, speed) at time `t_s`, or `None` when it is absent then; as
    /// [`Self::pose_at`], closed-form, without reaction.
    pub fn state_at(&self, t_s: f64) -> Option<MoverState> {
        if !self.present_at(t_s) {
            return None;
        }
        let Some(motion) = &self.motion else {
            return Some(MoverState {
                x_m: self.solid.x_m,
                y_m: self.solid.y_m,
                yaw_rad: self.solid.yaw_rad,
                heading_rad: self.solid.yaw_rad,
                arc_m: 0.0,
                speed_m_s: 0.0,
            });
        };
        let (arc_m, speed) = motion.arc_at(t_s - self.appears_s);
        Some(match motion.train {
            // The lead stands at the path's end; its cars stay behind it.
            Some(link) => motion.state_at_arc(arc_m.min(motion.length_m()) - link.behind_m, speed),
            None => motion.state_at_arc(arc_m, speed),
        })
    }
}

/// A validated scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// The file it was read from (or the label given to [`Scenario::from_str`]).
    pub path: PathBuf,
    /// Short human name.
    pub name: String,
    /// Free text.
    pub description: Option<String>,
    /// Seed of every random draw of a run.
    pub seed: u64,
    /// Laps of the route, >= 1.
    pub laps: u32,
    /// The ground.
    pub world: Ground,
    /// The vehicle and its start pose.
    pub vehicle: ScenarioVehicle,
    /// The route.
    pub route: Route,
    /// Static objects (`runtime` false): the `[[objects]]` in file order, then the objects of
    /// each `[[rows]]` in file order.
    pub objects: Vec<Solid>,
    /// The airport's survey, when `[airport] surveyed_stands` is not `as_run`: the offline map
    /// is then driven over the airport's whole network through what the survey saw, with the
    /// survey's seed and speed, whatever the run's route, seed, speed and parked aircraft
    /// ([`Scenario::survey_scene`]). `None`: the map is the run's own static world along its
    /// route.
    pub survey: Option<Survey>,
    /// Painted patches.
    pub patches: Vec<Patch>,
    /// Run-time obstacles.
    pub obstacles: Vec<Obstacle>,
    /// The danger distance (`[expectations] danger_distance_m`), metres: the smallest
    /// ground-truth clearance between the vehicle and any run-time obstacle must stay at or
    /// above it. `None`: not checked (only a contact fails).
    pub danger_distance_m: Option<f64>,
    /// How the run must end (`[expectations] end`).
    pub expected_end: ExpectedEnd,
    /// `[expectations] no_contact_at_fault`: a contact while the vehicle moved fails the run.
    pub no_contact_at_fault: bool,
    /// `[expectations] max_stops`: at most this many stops over the run (`None`: not checked).
    pub max_stops: Option<usize>,
    /// `[expectations] max_cross_track_rmse_m`: the pose estimate's cross-track RMSE over the
    /// run at most this, metres (`None`: not checked; nor without an estimate).
    pub max_cross_track_rmse_m: Option<f64>,
    /// `[expectations] max_heading_rmse_rad`: its heading RMSE at most this, radians.
    pub max_heading_rmse_rad: Option<f64>,
    /// The `[config]` table (validated): the run configuration over the defaults.
    pub config: Option<toml::Table>,
    /// `[expectations] known_problem` with its `today`: the run is known not to meet its
    /// expectations, and ends today as stated.
    pub known_problem: Option<KnownProblem>,
    /// `[regress] quick_laps`: laps in `taxi-sim regress`'s quick tier, at most `laps` (`None`:
    /// all).
    pub quick_laps: Option<u32>,
    /// `[regress] full_only`: run only in the full tier.
    pub full_only: bool,
    /// `[regress] golden`: the quick tier's golden numbers (resolved against the file's folder).
    pub golden: Option<PathBuf>,
}

/// An airport's survey (`[airport] surveyed_stands`): what it saw and where it drove. One survey
/// serves every run at the airport with one vehicle and one set of map settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Survey {
    /// The static objects it saw: the scenario's, less the aircraft parked after it (and their
    /// equipment).
    pub objects: Vec<Solid>,
    /// Its drive: straight legs, each driven from its first point to its second - every edge of
    /// the airport's taxi network inside the world, then a leg from each stand to the nearest
    /// point of the network.
    pub legs: Vec<[Point2<f64>; 2]>,
}

impl Survey {
    /// The length of its drive, metres.
    pub fn length_m(&self) -> f64 {
        self.legs.iter().map(|[a, b]| (b - a).norm()).sum()
    }
}

/// A scenario's known problem: why it fails today, and how it ends today.
#[derive(Clone, Debug, PartialEq)]
pub struct KnownProblem {
    /// The text: what goes wrong.
    pub text: String,
    /// The outcome as it is today.
    pub today: super::spec::TodaySpec,
}

impl Scenario {
    /// The world as a [`Scene`]: ground, static objects, patches and the run-time obstacles at
    /// their initial poses (`Solid::runtime` true): the closed loop's world.
    pub fn full_scene(&self) -> Scene {
        self.scene(true)
    }

    /// The world as a [`Scene`] without its run-time obstacles: the mapping drive's world.
    pub fn static_scene(&self) -> Scene {
        self.scene(false)
    }

    /// The world the offline map is made in: the surveyed objects when the map is surveyed apart
    /// from the run, else [`Scenario::static_scene`].
    pub fn survey_scene(&self) -> Scene {
        let mut scene = self.static_scene();
        if let Some(survey) = &self.survey {
            scene.solids.clone_from(&survey.objects);
        }
        scene
    }

    fn scene(&self, include_runtime: bool) -> Scene {
        let mut solids = self.objects.clone();
        if include_runtime {
            solids.extend(self.obstacles.iter().map(|o| o.solid.clone()));
        }
        Scene {
            min_m: self.world.min_m,
            max_m: self.world.max_m,
            ground_remission: self.world.ground_remission,
            pavement_texture: self.world.pavement_texture,
            solids,
            patches: self.patches.clone(),
            areas: self.world.areas.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn motion(acceleration_m_s2: Option<f64>, stops: &[(f64, f64)]) -> ObstacleMotion {
        ObstacleMotion {
            path_m: vec![
                Point2::new(0.0, 0.0),
                Point2::new(30.0, 0.0),
                Point2::new(30.0, 30.0),
            ],
            speed_m_s: 3.0,
            yaw_offset_rad: 0.0,
            acceleration_m_s2,
            stops: stops
                .iter()
                .map(|&(at_m, wait_s)| MotionStop { at_m, wait_s })
                .collect(),
            yields_to_vehicle_m: None,
            makes_room_m: None,
            train: None,
        }
    }

    fn close(a: (f64, f64), b: (f64, f64)) -> bool {
        (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9
    }

    #[test]
    fn a_mover_with_acceleration_reaches_its_speed_then_brakes_to_its_end() {
        let m = motion(Some(1.0), &[]);
        assert!(close(m.arc_at(0.0), (0.0, 0.0)));
        assert!(close(m.arc_at(1.0), (0.5, 1.0)));
        // 1 m/s^2 from rest: 3 m/s at 3 s, 4.5 m along.
        assert!(close(m.arc_at(3.0), (4.5, 3.0)));
        assert!(close(m.arc_at(5.0), (10.5, 3.0)));
        // 60 m: 4.5 up, 51 cruising (17 s), 4.5 down; it stands at the end from 23 s.
        assert!(close(m.arc_at(22.0), (60.0 - 0.5, 1.0)));
        assert!(close(m.arc_at(23.0), (60.0, 0.0)));
        assert!(close(m.arc_at(100.0), (60.0, 0.0)));
        let s = m.state_at_arc(60.0 - 0.5, 1.0);
        assert!((s.x_m - 30.0).abs() < 1e-12 && (s.y_m - 29.5).abs() < 1e-12);
        assert_eq!(s.velocity_m_s()[1], 1.0);
    }

    #[test]
    fn a_short_leg_never_reaches_full_speed() {
        // 4 m from rest at 1 m/s^2: 2 m up to 2 m/s in 2 s, 2 m down, 4 s.
        let m = motion(Some(1.0), &[(4.0, 1.0)]);
        assert!(close(m.arc_at(1.0), (0.5, 1.0)));
        assert!(close(m.arc_at(2.0), (2.0, 2.0)));
        assert!(close(m.arc_at(3.0), (3.5, 1.0)));
        assert!(close(m.arc_at(4.0), (4.0, 0.0)));
        assert!(close(m.arc_at(4.999), (4.0, 0.0)));
        assert!(m.arc_at(5.1).0 > 4.0);
    }

    #[test]
    fn a_stop_is_waited_for_wait_s() {
        // Instant speed changes: at 20 m after 20/3 s, waits 4 s, goes on at 3 m/s.
        let m = motion(None, &[(20.0, 4.0)]);
        let arrive = 20.0 / 3.0;
        assert!(close(m.arc_at(arrive - 1.0), (17.0, 3.0)));
        assert!(close(m.arc_at(arrive), (20.0, 0.0)));
        assert!(close(m.arc_at(arrive + 3.99), (20.0, 0.0)));
        assert!(close(m.arc_at(arrive + 5.0), (23.0, 3.0)));
        // 40 m left: 40/3 s; then it stands at the end.
        assert!(close(
            m.arc_at(arrive + 4.0 + 40.0 / 3.0 + 1.0),
            (60.0, 0.0)
        ));
        // With 1 m/s^2: it brakes to stand at 20 m (at 3 + 14.5/3 + 3 s), waits 4 s, starts
        // from rest.
        let m = motion(Some(1.0), &[(20.0, 4.0)]);
        let arrive = 6.0 + 11.0 / 3.0;
        assert!(close(m.arc_at(arrive), (20.0, 0.0)));
        assert!(close(m.arc_at(arrive + 3.9), (20.0, 0.0)));
        assert!(close(m.arc_at(arrive + 5.0), (20.5, 1.0)));
    }

    #[test]
    fn a_plain_mover_moves_as_before_and_stands_at_its_end() {
        let m = motion(None, &[]);
        assert!(m.is_plain());
        assert_eq!(m.arc_at(2.0), (6.0, 3.0));
        assert_eq!(m.arc_at(25.0), (75.0, 0.0));
        let end = m.state_at_arc(75.0, 0.0);
        assert_eq!((end.x_m, end.y_m), (30.0, 30.0));
        assert_eq!(end.yaw_rad, std::f64::consts::FRAC_PI_2);
        // Before the start: on the line of the first segment (a train's car waiting to enter).
        let before = m.state_at_arc(-2.0, 0.0);
        assert!(close((before.x_m, before.y_m), (-2.0, 0.0)));
        assert_eq!(before.yaw_rad, 0.0);
    }
}
