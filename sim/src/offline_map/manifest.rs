//! The offline map's manifest (`manifest.json`): what a mapping drive did, and the fingerprint
//! of its inputs that tells whether a map directory is fresh for a scenario and a run
//! configuration ([`fresh_manifest`]); where a scenario's map lives by default.

use std::path::{Path, PathBuf};

use super::settings::{levels_of, map_config};
use crate::error::{Error, ManifestError, Result};
use crate::scenario::{RunConfig, Scenario};

/// Bumped when the mapping drive changes what it builds (2: the vehicle's ceiling; 3: compressed
/// blocks; 4: the ROS image a PNG; 5: blocks with the remission quantized).
pub(crate) const MAP_FORMAT: u32 = 5;

/// What a mapping drive did.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct MapManifest {
    /// Fingerprint of everything the map depends on (hex CRC-32).
    pub fingerprint: String,
    /// Scenario name.
    pub scenario: String,
    /// Revolutions inserted.
    pub scans: usize,
    /// Route length driven, metres.
    pub route_m: f64,
    /// Block files written.
    pub blocks: usize,
    /// Heights of interest of the levels, metres.
    pub level_heights_m: Vec<f64>,
    /// Occupied cells (p > 0.5) per level over the exported extent.
    pub occupied_cells: Vec<usize>,
}

/// Fingerprint of a scenario's offline map inputs: the scenario and vehicle files, the levels
/// (heights and ceiling), the map and LiDAR settings of `config`, a stale map's faults, the
/// format.
pub fn fingerprint(scenario: &Scenario, config: &RunConfig) -> Result<String> {
    let mut h = crc32fast::Hasher::new();
    h.update(&std::fs::read(&scenario.path).map_err(|source| Error::Io {
        what: "reading the scenario",
        path: scenario.path.clone(),
        source,
    })?);
    // The world as resolved (a default the code changes, like the pavement's texture, is not in
    // the file; an airport's ground and objects come from its apt.dat).
    h.update(
        format!(
            "{:?}{:?}{:?}",
            scenario.world, scenario.patches, scenario.objects
        )
        .as_bytes(),
    );
    h.update(format!("{:?}", scenario.vehicle.vehicle).as_bytes());
    h.update(format!("{:?}", levels_of(scenario, config)?).as_bytes());
    h.update(format!("{:?}{:?}{MAP_FORMAT}", map_config(config), config.lidar).as_bytes());
    if config.faults.stale_map.any() {
        h.update(format!("{:?}", config.faults.stale_map).as_bytes());
    }
    Ok(format!("{:08x}", h.finalize()))
}

/// The manifest of the map in `dir`, if it exists and matches `scenario` and `config`: `None`
/// when it is missing or stale (build the map), a [`ManifestError`] when it exists but is
/// unreadable.
pub fn fresh_manifest(
    scenario: &Scenario,
    config: &RunConfig,
    dir: &Path,
) -> Result<Option<MapManifest>> {
    let path = dir.join("manifest.json");
    let remedy = || {
        format!(
            "delete it, or rebuild the map with `taxi-sim map {} --out {}`",
            scenario.path.display(),
            dir.display()
        )
    };
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(error) => {
            let remedy = remedy();
            return Err(ManifestError::Read {
                path,
                error,
                remedy,
            }
            .into());
        }
    };
    let manifest = match serde_json::from_str::<MapManifest>(&text) {
        Ok(manifest) => manifest,
        Err(e) => {
            let (line, column) = (e.line(), e.column());
            let full = e.to_string();
            let at = format!(" at line {line} column {column}");
            let message = full.strip_suffix(&at).unwrap_or(&full).to_string();
            let remedy = remedy();
            return Err(ManifestError::Parse {
                path,
                line,
                column,
                message,
                remedy,
            }
            .into());
        }
    };
    Ok((manifest.fingerprint == fingerprint(scenario, config)?).then_some(manifest))
}

/// Where a scenario's offline map lives by default: `out/maps/<scenario file stem>`, or
/// `out/maps/<stem>-stale-<digest>` for a stale map's faults (so the good map stays).
pub fn default_map_dir(scenario: &Scenario, config: &RunConfig) -> PathBuf {
    let stem = scenario
        .path
        .file_stem()
        .map_or_else(|| "scenario".into(), |s| s.to_string_lossy().into_owned());
    let stale = &config.faults.stale_map;
    let name = if stale.any() {
        format!(
            "{stem}-stale-{:08x}",
            crc32fast::hash(format!("{stale:?}").as_bytes())
        )
    } else {
        stem
    };
    PathBuf::from("out").join("maps").join(name)
}
