//! `taxi-sim map`: the mapping drive that builds a scenario's offline multi-height map, with a
//! progress bar.

use std::path::PathBuf;

use sim::offline_map::{default_map_dir, map_drive};
use sim::scenario::{RunConfig, Scenario};

/// Arguments of `taxi-sim map`.
#[derive(Debug, Clone, clap::Args)]
pub struct MapArgs {
    /// The scenario file.
    pub scenario: PathBuf,
    /// Output directory (default: out/maps/<scenario file name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run configuration (TOML) whose LiDAR and mapping settings the map is built with.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
}

pub(crate) fn build_map(
    scenario: &Scenario,
    config: &RunConfig,
    dir: &std::path::Path,
) -> anyhow::Result<sim::offline_map::MapManifest> {
    let progress = crate::bar(0, "mapping");
    let manifest = map_drive(scenario, config, dir, &mut |done, total| {
        progress.set_length(total as u64);
        progress.set_position(done as u64);
    })?;
    progress.finish_and_clear();
    Ok(manifest)
}

/// Runs `taxi-sim map`.
pub fn run(args: &MapArgs) -> anyhow::Result<()> {
    let scenario = Scenario::from_file(&args.scenario)?;
    let config = RunConfig::for_scenario(&scenario, args.config.as_deref())?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_map_dir(&scenario, &config));
    let m = build_map(&scenario, &config, &dir)?;
    crate::emit(&format!(
        "{}: mapped {:.0} m with {} revolutions into {} blocks; occupied cells per level {:?} (levels at {:?} m)\nwrote {}\n",
        scenario.name,
        m.route_m,
        m.scans,
        m.blocks,
        m.occupied_cells,
        m.level_heights_m,
        dir.display()
    ))
}
