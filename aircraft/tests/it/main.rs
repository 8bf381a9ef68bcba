//! The aircraft crate's integration tests, one binary: bad descriptions, CARMEN files, coverage
//! properties, the shipped vehicles, and the coverage helpers they share (`common`).

mod bad_descriptions;
mod carmen;
mod common;
mod coverage_props;
mod shipped;
