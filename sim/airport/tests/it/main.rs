//! The airport crate's integration tests: the shipped fictional airport read and routed, malformed
//! files refused with located errors, and (ignored unless asked, run by CI) real KSYR data from
//! `../shared/data`.

mod fixture;
mod malformed;
mod paint;
mod routes;
mod shared_data;
mod small_airports;
