//! The autonomy crate's integration tests, one binary: the particle filter on an analytic scene.

mod localizer;
