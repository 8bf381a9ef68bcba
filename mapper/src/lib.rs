//! Quantized multi-height occupancy grid maps (Sarcinelli 2021): one 2D occupancy grid per height
//! of interest, an exact obstacle distance map per grid, and a vehicle as height-tagged circles.
//!
//! This crate is the part of taxi-sim that could run on a real vehicle: in-memory scans in, maps
//! and collision answers out. It knows nothing of the simulator, the renderer or the CLI.
//!
//! - [`grid`]: `Grid<T>` and world <-> cell conversion.
//! - [`levels`]: heights of interest, cumulative or banded.
//! - [`edt`], [`odm`]: exact Euclidean distance transform and per-level obstacle distance maps.
//! - [`collision`]: circle models and pose / trajectory checks.

pub mod collision;
pub mod edt;
pub mod error;
pub mod grid;
pub mod levels;
pub mod odm;

pub use collision::{
    BoundingCircle, Circle, CollisionChecker, CollisionModel, PoseCheck, TrajectoryCheck,
};
pub use error::{MapError, Result};
pub use grid::{Cell, Grid, GridGeometry};
pub use levels::{HeightClass, LevelMode, Levels};
pub use odm::{DistanceMap, DistanceMaps};
