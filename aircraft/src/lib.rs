//! Vehicle descriptions and their height-tagged circle collision models.
//!
//! A vehicle is a URDF (collision geometry as boxes, cylinders, capsules, spheres) plus a sidecar
//! TOML (motion limits, LiDAR mount, heights of interest). The crate places every collision
//! primitive in the vehicle frame (origin on the ground under the rear axle / main-gear centre,
//! x forward, y left, z up), sorts the parts into height levels by their undersides, and covers
//! each level's footprint with circles: the [`mapper::CollisionModel`] the distance maps are
//! queried with. URDF and files are read at the edge; fitting is pure and deterministic.
//!
//! - [`urdf`]: URDF -> vehicle-frame [`Part`]s.   - [`spec`]: the sidecar.
//! - [`fit`]: levels and circle covers.           - [`report`]: coverage / overshoot by sampling.
//! - [`carmen`]: CARMEN collision files.          - [`svg`]: a picture per model.
//! - [`exact`]: the exact reference (part footprints against the maps) a circle model is measured by.
//! - [`vehicle`]: the shipped vehicles (`praetor600`, `iara_car`, `iara_car_fake_wing`).

pub mod carmen;
pub mod error;
pub mod exact;
pub mod fit;
pub mod footprint;
pub mod io;
pub mod report;
pub mod shapes;
pub mod spec;
pub mod svg;
pub mod urdf;
pub mod vehicle;

pub use error::{Error, Result};
pub use fit::{DEFAULT_MAX_OVERSHOOT_M, FitOptions, FittedModel, LevelFootprint, fit_parts};
pub use report::{LevelReport, evaluate};
pub use shapes::{Part, Shape};
pub use spec::{
    DEFAULT_OVERHEAD_CLEARANCE_M, ExtraLidar, LidarMount, MotionLimits, Steering, VehicleSpec,
};
pub use vehicle::{FIT_MEMO_SIZE, SHIPPED_VEHICLES, Vehicle};
