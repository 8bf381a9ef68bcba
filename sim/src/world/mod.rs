//! The simulator's side of the message boundary: what a world is made of ([`Scene`]), the Rapier
//! world holding it with its ground truth ([`World`]: contacts, clearances), the vehicle's motion
//! ([`Bicycle`]), the sensors ([`Lidar`], [`OdometrySensor`]), the faults between the sensors and
//! the stack ([`FaultsConfig`]), what the vehicle's LiDAR cannot see per level ([`coverage`]), and the capture of a revolution ([`Sensor`]: cast, degraded,
//! re-expressed at the pose estimate). The only module of the crate that names Rapier or parry;
//! the one place nalgebra (f64) becomes glam (f32).

mod capture;
pub mod coverage;
mod faults;
mod ground;
mod lidar;
mod motion;
mod odometry;
mod physics;
pub mod ply;
mod scene;

pub use capture::{Captured, NamedLidar, Sensor};
pub use faults::{FaultCounts, FaultsConfig, LostRevolutions, StaleMap, degrade, stale_scene};
pub use ground::GroundTexture;
pub use lidar::{Lidar, LidarConfig, LidarScan, SweepPoses};
pub use motion::{Bicycle, Command, VehicleState, wrap_angle};
pub use odometry::{OdometryConfig, OdometrySensor};
pub use physics::{Contact, Owner, World, planar_to_3d, to_pose};
pub use scene::{Area, ObjectKind, Patch, Scene, Solid, SolidShape, pavement};
