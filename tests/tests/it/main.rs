//! End-to-end and regression tests of the workspace, one test binary (`cargo test --release
//! --workspace`): the closed loop on the small scenarios under other run configurations,
//! localization, overhead structures, permanence of what is unseen, the failures the campaigns
//! found, traffic, the distance cap and the mapping demo.

mod closed_loop;
mod common;
mod demo;
mod distance_cap;
mod found;
mod localization;
mod overhead;
mod permanence;
mod pilot_calls;
mod regress;
mod traffic;
