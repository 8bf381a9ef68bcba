//! Helpers shared by the closed-loop test files: a shipped scenario by name, and a run after its
//! mapping drive.

use std::path::{Path, PathBuf};

use sim::engine::{RunReport, RunSetup, run};
use sim::scenario::{RunConfig, Scenario};

/// The shipped scenario `scenarios/<name>.toml`.
pub fn scenario(name: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Builds the offline map (mapping drive) in `map_dir` with `config`, then runs the closed loop.
pub fn run_with(s: &Scenario, map_dir: &Path, config: RunConfig) -> RunReport {
    sim::offline_map::map_drive(s, &config, map_dir, &mut |_, _| {})
        .unwrap_or_else(|e| panic!("{}: mapping drive: {e:#}", s.name));
    let setup = RunSetup {
        config,
        ..RunSetup::new(map_dir.to_path_buf())
    };
    run(s, &setup).unwrap_or_else(|e| panic!("{}: {e:#}", s.name))
}

/// A pass's nearest approach over the levels, metres.
pub fn nearest_m(pass: &sim::engine::Pass) -> f64 {
    pass.min_clearance_m
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
}
