//! End-to-end and regression tests of the workspace, one test binary (`cargo test -p tests --test
//! it`): the closed loop on the small scenarios, the thesis' experiments against their goldens,
//! localization, overhead structures, permanence of what is unseen, the failures the campaigns
//! found, traffic, the distance cap and the mapping demo.

mod airports;
mod closed_loop;
mod common;
mod demo;
mod distance_cap;
mod experiments;
mod found;
mod localization;
mod overhead;
mod permanence;
mod regress;
mod traffic;
