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
//! - [`scan`], [`occupancy`]: the LiDAR revolution as input and the obstacle test; [`organise`]:
//!   a driver's unorganised cloud into a scan's columns x beams.
//! - [`map`]: `MultiHeightMap`, the local window: insertion, offline/online merge, re-centring.
//! - [`blocks`]: the map block file format and the directory store.
//! - [`remission`]: per-cell intensity statistics.
//! - [`export`]: ROS map_server PGM/YAML, PNG and NumPy `.npy` files; [`ros_occupancy`]: a
//!   square of a map or a distance map in ROS `OccupancyGrid` values.
//! - [`synthetic`]: analytic scenes and a synthetic HDL-32E for tests and benchmarks.
//! - [`tracking`]: moving objects, so what they leave can be cleared on evidence.
//! - [`workloads`]: the inputs of the headline benchmarks.
//! - [`voxel`], [`elevation`]: a dense 3D voxel grid and a 2.5D elevation-interval map, the
//!   representations the multi-height grids are compared against.

pub mod blocks;
pub mod collision;
pub mod edt;
pub mod elevation;
pub mod error;
pub mod export;
pub mod grid;
pub mod levels;
pub mod map;
pub mod occupancy;
pub mod odm;
pub mod organise;
pub mod remission;
pub mod ros_occupancy;
pub mod scan;
pub mod self_hits;
pub mod self_mask;
pub mod synthetic;
pub mod tracking;
pub mod voxel;
pub mod workloads;

pub use blocks::{Block, BlockIndex, BlockSpec, BlockStore, write_atomically};
pub use collision::{
    BoundingCircle, Circle, CollisionChecker, CollisionModel, PoseCheck, TrajectoryCheck,
};
pub use error::{MapError, Result};
pub use grid::{Cell, Grid, GridGeometry};
pub use levels::{HeightClass, LevelMode, Levels};
pub use map::{
    FreeSpaceStop, FreeSpaceWalks, InsertStats, MapConfig, MergeMode, MultiHeightMap, WorldCell,
};
pub use occupancy::{ObstacleTestParams, OccupancyParams};
pub use odm::{DistanceMap, DistanceMaps};
pub use organise::{ColumnLayout, SensorPoint, organise};
pub use remission::RemissionCell;
pub use ros_occupancy::RosOccupancy;
pub use scan::{Return, Scan, ScanColumn};
pub use self_hits::SelfHitFilter;
pub use self_mask::SelfMask;
pub use tracking::{MovingObject, SeenFrom, TrackState, Tracker, TrackerConfig};
