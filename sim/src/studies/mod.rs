//! Studies built on the engine: the mapping demo through the mapper's synthetic parking lot
//! ([`demo`]), the small-obstacle sweep ([`small_obstacles`]) and the synthetic LiDAR against a
//! real one ([`lidar_compare`]), and the thesis' representation against 3D voxels, OctoMap and a
//! 2.5D map ([`representations`]). What a vehicle's LiDAR cannot see per level is
//! [`crate::world::coverage`] (the engine's start-up rule reads it too).

pub mod demo;
pub mod lidar_compare;
pub mod representations;
pub mod small_obstacles;
