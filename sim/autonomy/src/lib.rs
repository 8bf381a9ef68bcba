//! The stack under test: what would run on the vehicle. It takes sensor messages (LiDAR
//! revolutions stamped with the pose estimate they were taken at, pose estimates, odometry) and
//! gives commands; it keeps the online multi-height map, plans over its distance maps, avoids,
//! behaves and follows.
//!
//! The crate depends on `mapper`, `aircraft`, nalgebra, rayon and rand only: it cannot name Rapier, the
//! simulated world or its ground truth, so "the autonomy never sees ground truth" is checked by
//! the compiler (and by `cargo tree -p autonomy` in CI).
//! - [`messages`]: what crosses the boundary: [`LidarRevolution`], [`PoseEstimate`],
//!   [`Odometry`] in, [`Command`] out.
//! - [`localizer`]: the particle filter over the offline map (remission, likelihood field).
//! - [`online_map`]: the offline map merged with live LiDAR data around the estimate.
//! - [`beams_through`]: which beams of a revolution passed through a place (a lost track's way
//!   seen empty).
//! - [`planner`]: candidates, the avoider, the behaviour, pure pursuit.
//! - [`route`]: route geometry and Frenet projection.
//! - [`traffic`]: movers predicted over the horizon, the space-time check of the path, and the
//!   rules about movers with their memory ([`TrafficRules`]: one plan's inputs in, the speed cap
//!   and where to stop out).
//! - [`stack`]: the [`Driver`], which ties them together and tracks its own route progress.

pub mod beams_through;
pub mod localizer;
pub mod messages;
pub mod online_map;
pub mod planner;
pub mod route;
pub mod stack;
pub mod traffic;

pub use messages::{Command, LidarRevolution, Odometry, PoseEstimate};
pub use online_map::{ForgettingConfig, ForgettingRule, OnlineMap, trusted_range_m};
pub use planner::{AutonomyConfig, Behaviour, Candidate, Plan, avoid, plan, pure_pursuit};
pub use route::{RoutePath, wrap_angle};
pub use stack::{BlindZone, Driver, DriverStatus, PilotCall, PlanTimes, VehicleModel};
pub use traffic::{Conflict, MoverDecision, MoverInputs, Prediction, TrafficConfig, TrafficRules};

impl Behaviour {
    /// The behaviour the thesis gives a vehicle by how it steers: a car (front wheels) deviates,
    /// an aircraft (nose wheel) stops and waits.
    pub fn for_steering(steering: aircraft::spec::Steering) -> Self {
        match steering {
            aircraft::spec::Steering::NoseWheel => Behaviour::StopAndWait,
            aircraft::spec::Steering::FrontWheels => Behaviour::Deviate,
        }
    }
}
