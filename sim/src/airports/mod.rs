//! Real airports in the simulator: an [`airport::Airport`] summarised and drawn (`taxi-sim
//! airport show`), and taxi routes planned for a vehicle on it.

mod draw;
mod summary;
mod taxi;

pub use draw::{RouteOverlay, draw_airport};
pub use summary::summary;
pub use taxi::{DEFAULT_TAXI_SPEED_M_S, DEFAULT_TURN_RADIUS_M, PlannedTaxi, plan_taxi};
