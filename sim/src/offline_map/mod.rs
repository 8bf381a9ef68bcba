//! The offline map: the mapping drive that builds a scenario's multi-height map along its route
//! ([`map_drive`]), its settings ([`levels_of`], [`map_config`], [`self_filter_model`]), and the
//! manifest whose fingerprint says whether a map directory is fresh ([`MapManifest`],
//! [`fresh_manifest`]), and [`ensure`]: the map a session needs, reused or built.

mod drive;
mod ensure;
mod manifest;
mod settings;

pub use crate::error::ManifestError;
pub use drive::{DriveRevolution, map_drive, map_drive_with};
pub(crate) use drive::{clear_blocks, finish_map};
pub use ensure::{Ensured, ensure};
pub(crate) use manifest::MAP_FORMAT;
pub use manifest::{MapManifest, default_map_dir, fingerprint, fresh_manifest};
pub use settings::{
    SURVEY_SEED, SURVEY_SPEED_M_S, drive_seed_and_speed, levels_of, levels_of_vehicle, map_config,
    self_filter_model,
};
