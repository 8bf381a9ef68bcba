//! The `taxi-sim` command modules: one per command, each parsing its flags into the library's
//! types and printing what the command shows.

pub mod campaign;
pub mod check;
pub mod model;
pub mod run;
pub mod scan;
pub mod small;
pub mod tune;
