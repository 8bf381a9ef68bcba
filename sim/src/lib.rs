//! taxi-sim: the closed-loop taxi simulator around the multi-height occupancy grid map.
//!
//! This library holds what the `taxi-sim` binary runs; the binary alone knows the terminal.
//! - [`bench`]: the headline performance figures, measured without criterion.
//! - [`demo`]: a mapping drive through a synthetic parking lot, exporting every level.
//! - [`scene`]: what a world is made of (ground, solids, painted patches), independent of Rapier.

pub mod bench;
pub mod demo;
pub mod lidar;
pub mod motion;
pub mod scene;
pub mod world;
