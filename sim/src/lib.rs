//! taxi-sim: the closed-loop taxi simulator around the multi-height occupancy grid map.
//!
//! This library holds what the `taxi-sim` binary runs; the binary alone knows the terminal. The
//! stack under test is the `autonomy` crate; this one is the world around it and the engine.
//! - [`scene`]: what a world is made of (ground, solids, painted patches), independent of Rapier.
//! - [`scenario`]: scenario files (TOML) and their errors, converted to a scene.
//! - [`world`]: the Rapier world and the ground truth (contacts, clearances).
//! - [`motion`]: the kinematic bicycle that moves the vehicle.
//! - [`lidar`]: the synthetic HDL-32E (fast path and Rapier's generic query); [`ply`] writes it.
//! - [`mapping`]: the mapping drive that builds a scenario's offline map.
//! - The engine: [`config`] (the run configuration), [`pose_source`] (truth, noisy truth),
//!   [`schedule`] (sequential or overlapped sensing), [`judge`] (passes, stops, laps, contacts,
//!   verdicts), [`observer`] (what watches a run), [`report`], and [`run`], the loop.
//! - [`replay`]: the Rerun recording and live view of a run (the only module that knows Rerun).
//! - [`bench`]: the headline performance figures, measured without criterion.
//! - [`campaign`]: campaigns - scenario families sampled, run in parallel, searched for
//!   failures, summarised.
//! - [`small_obstacles`]: the sweep that finds the smallest obstacle seen in time per speed.
//! - [`demo`]: a mapping drive through a synthetic parking lot, exporting every level.
//! - [`error`]: the library's typed errors.

pub mod bench;
pub mod bench_blocks;
pub mod bench_localization;
pub mod campaign;
pub mod config;
pub mod demo;
pub mod error;
pub mod faults;
pub mod judge;
pub mod lidar;
pub mod localization;
pub mod mapping;
pub mod motion;
pub mod observer;
pub mod odometry;
pub mod ply;
pub mod pose_source;
pub mod replay;
pub mod report;
pub mod run;
pub mod scenario;
pub mod scene;
pub mod schedule;
pub mod small_obstacles;
pub mod tune;
pub mod world;

pub use error::{Error, Result};

/// The stack under test, re-exported so users of the simulator name one crate.
pub use autonomy;
