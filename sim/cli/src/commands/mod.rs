//! The `taxi-sim` commands, one module each: its arguments (clap) and its `run`, which parses
//! them into the library's types and prints what the command shows.

pub mod airport;
pub mod bench;
pub mod campaign;
pub mod check;
pub mod compare_lidar;
pub mod coverage;
pub mod demo;
pub mod figures;
pub mod map;
pub mod model;
pub mod node;
pub mod regress;
pub mod representations;
pub mod run;
pub mod scan;
pub mod small;
pub mod stack;
pub mod tune;
