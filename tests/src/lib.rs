//! The workspace's end-to-end and scenario regression tests; this library holds no code.
//!
//! The tests are one integration-test binary, `tests/tests/it/` (`cargo test --release -p tests
//! --test it`), with the helpers its files share in `tests/tests/it/common`. They run whole
//! scenarios through the `sim` library: the closed loop on the small scenarios, the thesis'
//! experiments against their goldens (`tests/golden/`, rewritten with `TAXI_SIM_BLESS=1`), the
//! failures the campaigns found (`tests/found/`, plain scenario files asserted as they behave),
//! localization, overhead structures, permanence of what is unseen, the distance cap and the
//! mapping demo. Tests that need the `taxi-sim` binary live in its package (`sim/cli/tests/it`).
