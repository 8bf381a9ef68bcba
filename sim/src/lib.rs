//! taxi-sim: the closed-loop taxi simulator around the multi-height occupancy grid map.
//!
//! This library holds what the `taxi-sim` binary runs; the binary alone knows the terminal.
//! - [`scene`]: what a world is made of (ground, solids, painted patches), independent of Rapier.
//! - [`scenario`]: scenario files (TOML) and their errors, converted to a scene.
//! - [`world`]: the Rapier world and the ground truth (contacts, clearances).
//! - [`motion`]: the kinematic bicycle that moves the vehicle.
//! - [`lidar`]: the synthetic HDL-32E (fast path and Rapier's generic query); [`ply`] writes it.
//! - [`autonomy`]: route geometry, planner, obstacle avoider, behaviour, path follower.
//! - [`mapping`]: the mapping drive that builds a scenario's offline map.
//! - [`run`]: the closed loop and its report.
//! - [`replay`]: the Rerun recording and live view of a run (the only module that knows Rerun).
//! - [`bench`]: the headline performance figures, measured without criterion.
//! - [`demo`]: a mapping drive through a synthetic parking lot, exporting every level.

pub mod autonomy;
pub mod bench;
pub mod demo;
pub mod lidar;
pub mod mapping;
pub mod motion;
pub mod ply;
pub mod replay;
pub mod run;
pub mod scenario;
pub mod scene;
pub mod world;
