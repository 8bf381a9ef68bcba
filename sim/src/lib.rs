//! taxi-sim: the closed-loop taxi simulator around the multi-height occupancy grid map.
//!
//! This library holds what the `taxi-sim` binary (crate `sim/cli`) runs; the binary alone knows
//! the terminal. The stack under test is the `autonomy` crate; this one is the world around it
//! and the engine. Its modules are layered, each importing only those listed before it (CI
//! checks it, `.ci/check_layers.py`):
//! - the leaves: [`error`] (the library's typed errors), [`toml_file`] (located errors in TOML
//!   files, dotted-path edits), [`chart`] (the charts' font);
//! - [`world`]: the simulator's side of the message boundary - the scene, the Rapier world and
//!   its ground truth, motion, the LiDAR, odometry, faults, the capture of a revolution. The
//!   only module that names Rapier or parry;
//! - [`airports`]: real airports (the `airport` crate's) summarised, drawn and made into worlds;
//! - [`scenario`]: what a run is asked to do - scenario files and run configurations, resolved;
//! - [`offline_map`]: the mapping drive that builds a scenario's offline map, and its manifest;
//! - [`engine`]: one run - the rig, the loop, the schedule, pose sources, the judge, the
//!   observer hook and the report;
//! - [`replay`]: the Rerun recording and live view of a run (the only module that names Rerun);
//! - [`rosbag`]: a run as a ROS 2 bag (MCAP with `metadata.yaml`);
//! - [`pcap`]: real Velodyne captures as scans and offline maps;
//! - [`studies`]: the mapping demo and the small-obstacle sweep;
//! - [`campaign`]: scenario families sampled, run in parallel, searched for failures;
//! - [`tune`]: collision-model tuning on the campaign engine;
//! - [`regress`]: scenario files run against their own expectations, JUnit out (`taxi-sim regress`);
//! - [`bench`]: the headline performance figures, measured without criterion.

pub mod chart;
pub mod error;
pub mod toml_file;

pub mod world;

pub mod airports;

pub mod scenario;

pub mod offline_map;

pub mod engine;

pub mod replay;

pub mod pcap;
pub mod rosbag;

pub mod studies;

pub mod campaign;

pub mod tune;

pub mod regress;

pub mod bench;

pub use error::{Error, Result};

/// The stack under test, re-exported so users of the simulator name one crate.
pub use autonomy;
