//! The offline map a session needs, made sure of: the map in a directory reused when its
//! manifest is fresh, built there by the mapping drive when it is missing or stale. What
//! `taxi-sim run` and the benchmarks call before they drive (campaigns and `regress` key their
//! shared maps by static world instead: `campaign::MapCache`).

use std::path::Path;

use super::drive::map_drive;
use super::manifest::{MapManifest, fresh_manifest};
use crate::error::Result;
use crate::scenario::{RunConfig, Scenario};

/// What [`ensure`] found or did.
#[derive(Clone, Debug)]
pub enum Ensured {
    /// The map in the directory was fresh: used as it is.
    Fresh(MapManifest),
    /// The map was missing or stale: the mapping drive built it.
    Built(MapManifest),
}

impl Ensured {
    /// The map's manifest, either way.
    pub fn manifest(&self) -> &MapManifest {
        match self {
            Ensured::Fresh(m) | Ensured::Built(m) => m,
        }
    }
}

/// The offline map of `scenario` under `config` in `dir`: the one there when its manifest is
/// fresh ([`fresh_manifest`]); otherwise `on_build()` is called once and the mapping drive builds
/// it into `dir`, calling `progress(done, total)` after each scan. A manifest that exists but
/// cannot be read is an error, not a reason to rebuild.
pub fn ensure(
    scenario: &Scenario,
    config: &RunConfig,
    dir: &Path,
    on_build: &mut dyn FnMut(),
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Ensured> {
    if let Some(manifest) = fresh_manifest(scenario, config, dir)? {
        return Ok(Ensured::Fresh(manifest));
    }
    on_build();
    map_drive(scenario, config, dir, progress).map(Ensured::Built)
}
