//! Studies built on the engine: the mapping demo through the mapper's synthetic parking lot
//! ([`demo`]), the small-obstacle sweep ([`small_obstacles`]) and the synthetic LiDAR against a
//! real one ([`lidar_compare`]).

pub mod demo;
pub mod lidar_compare;
pub mod small_obstacles;
