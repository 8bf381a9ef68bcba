//! The `ros2` crate's integration tests, one binary, through its public API as a user would:
//! bags written to disk and read back with their `metadata.yaml` (`bag_files`), bags cut short
//! or corrupted (`bag_corruption`), point clouds through a bag (`cloud_files`), and every
//! message type's CDR decoded by its own schema (`cdr_schemas`).

mod bag_corruption;
mod bag_files;
mod cdr_schemas;
mod cloud_files;
mod common;
