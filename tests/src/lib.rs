//! The workspace's end-to-end and scenario regression tests; this library holds no code.
//!
//! The tests are one integration-test binary, `tests/tests/it/` (`cargo test --release
//! --workspace`), with the helpers its files share in `tests/tests/it/common`. They run whole
//! scenarios through the `sim` library where a scenario file's expectations and golden numbers
//! (`[regress] golden`, checked by `taxi-sim regress`) cannot say enough: the closed loop under
//! other run configurations, the failures the campaigns
//! found with their fix undone (`tests/found/` holds them as scenario files for `taxi-sim
//! regress`), localization, overhead structures, permanence of what is unseen, the distance cap,
//! the mapping demo and `taxi-sim regress`'s verdicts. Tests that need the `taxi-sim` binary live in its package (`sim/cli/tests/it`).
