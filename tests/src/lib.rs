//! End-to-end and scenario regression tests of the workspace (see `tests/tests/`).
//!
//! The scenario runs of the thesis' experiments land here as the simulator grows; until then it
//! checks the mapping demo end to end: scans in, per-level maps and files out.
