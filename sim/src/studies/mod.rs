//! Studies built on the engine: the mapping demo through the mapper's synthetic parking lot
//! ([`demo`]) and the small-obstacle sweep ([`small_obstacles`]).

pub mod demo;
pub mod small_obstacles;
