//! `taxi-sim bench`: the README's headline figures, each against its straightforward baseline.
//!
//! Criterion (`cargo bench -p mapper`) gives the same figures with statistics; this module lets
//! a user measure their own machine with the release binary alone. Each figure is the median of
//! `samples` timed batches after one warm-up batch.
//!
//! One module per benchmark (`mapper`, `lidar`, `closed_loop`, `blocks`, `localization`,
//! `campaign`), sharing the timing helpers of `timing`.

pub mod blocks;
pub mod campaign;
mod closed_loop;
mod lidar;
pub mod localization;
pub mod loop_chart;
mod mapper;
mod sensors;
mod timing;

pub use closed_loop::{STAGES, StageSplit, loop_figures, traffic_figures};
pub use lidar::{lidar_figures, lidar_scene};
pub use mapper::mapper_figures;
pub use sensors::vehicle_figures;
pub use timing::{Figure, against, alternating, figure, median, median_seconds};
