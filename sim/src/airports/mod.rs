//! Real airports in the simulator: an [`airport::Airport`] summarised and drawn (`taxi-sim
//! airport show`), taxi routes planned for a vehicle on it, and the airport made a world (ground
//! areas, painted lines, signs and lights).

mod draw;
mod summary;
mod taxi;
mod world;

pub use draw::{RouteOverlay, draw_airport};
pub use summary::summary;
pub use taxi::{
    DEFAULT_TAXI_SPEED_M_S, DEFAULT_TURN_RADIUS_M, PlannedTaxi, path_options, plan_taxi,
};
pub use world::{
    AirportWorld, EDGE_LIGHT_SPACING_M, Furniture, GRASS_REMISSION, airport_world, sign_glyphs,
};
