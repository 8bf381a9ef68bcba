//! The offline maps a campaign's variants share: one per static world ([`static_world_key`]),
//! built once behind a `OnceLock` in a scratch directory and renamed into place, so shards on one
//! filesystem share them too (the loser of a race drops its copy).

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, OnceLock};

use crate::error::{Error, Result};
use crate::scenario::{RunConfig, Scenario};

/// The static world's key: what the mapping drive depends on (world, static objects, patches,
/// route, vehicle and start, seed, levels, map and LiDAR settings, a stale map's faults, the
/// map format: a campaign directory of an older build gets new maps, not blocks it cannot read).
/// Variants with the same key share one offline map. An airport's survey (`[airport]
/// surveyed_stands`) depends on what it saw and the legs it drove, not on the run's route,
/// start, seed, speed or parked aircraft: every run at the airport with one vehicle shares it.
pub fn static_world_key(scenario: &Scenario, config: &RunConfig) -> Result<String> {
    let (seed, speed_m_s) = crate::offline_map::drive_seed_and_speed(scenario);
    let drive = match &scenario.survey {
        Some(survey) => format!("survey {:?}|{}", survey.legs, speed_m_s.to_bits()),
        None => format!(
            "{:?}|{:?}",
            scenario.route, scenario.vehicle.world_from_start
        ),
    };
    let mut text = format!(
        "{:?}|{:?}|{:?}|{}|{:?}|{}|{:?}|{:?}|{:?}|{}",
        scenario.world,
        scenario.survey_scene().solids,
        scenario.patches,
        drive,
        scenario.vehicle.vehicle,
        seed,
        crate::offline_map::levels_of(scenario, config)?,
        crate::offline_map::map_config(config),
        config.lidar,
        crate::offline_map::MAP_FORMAT,
    );
    if config.faults.stale_map.any() {
        // A stale map's ghosts stand near the route.
        text.push_str(&format!(
            "|{:?}|{:?}",
            config.faults.stale_map, scenario.route
        ));
    }
    Ok(format!(
        "{:08x}{:06x}",
        crc32fast::hash(text.as_bytes()),
        text.len() & 0xff_ffff
    ))
}

/// One static world's map directory, once built (or why it could not be).
type MapSlot = OnceLock<std::result::Result<PathBuf, String>>;

/// The offline maps of a campaign directory (or of `taxi-sim regress`, or a test binary), built
/// once per static world.
pub struct MapCache {
    dir: PathBuf,
    entries: Mutex<HashMap<String, Arc<MapSlot>>>,
}

impl MapCache {
    /// An empty cache over the map directories under `dir`.
    pub fn new(dir: PathBuf) -> Self {
        MapCache {
            dir,
            entries: Mutex::default(),
        }
    }

    /// The map of `scenario` (whose text is `text`) under `config`, built on first use; other
    /// variants wanting the same map wait for it. Built in a scratch directory and renamed into
    /// place, so a map directory is never seen half written (by this process or another).
    pub(super) fn get(
        &self,
        scenario_text: &str,
        scenario: &Scenario,
        config: &RunConfig,
    ) -> Result<PathBuf> {
        self.get_with(scenario, config, &|scratch| {
            // The map holds the scenario it was driven in: `fingerprint` reads it.
            let file = scratch.join("scenario.toml");
            mapper::write_atomically(&file, scenario_text.as_bytes())?;
            let s = Scenario::from_file(&file)?;
            crate::offline_map::map_drive(&s, config, scratch, &mut |_, _| {}).map(|_| ())
        })
    }

    /// The map of a scenario read from its own file (`taxi-sim regress`): driven as it is, its
    /// relative paths (vehicle sidecar, airport, pose file) resolved where the file lives.
    pub fn get_for_file(&self, scenario: &Scenario, config: &RunConfig) -> Result<PathBuf> {
        self.get_for_file_showing(scenario, config, &|_, _| {})
    }

    /// [`MapCache::get_for_file`], calling `progress(done, total)` after each scan when it
    /// drives the map (`taxi-sim run --maps-dir`'s bar: an airport's survey takes minutes).
    pub fn get_for_file_showing(
        &self,
        scenario: &Scenario,
        config: &RunConfig,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<PathBuf> {
        self.get_with(scenario, config, &|scratch| {
            crate::offline_map::map_drive(scenario, config, scratch, &mut |d, t| progress(d, t))
                .map(|_| ())
        })
    }

    /// The map keyed by [`static_world_key`], made by `drive` into a scratch directory on first
    /// use and renamed into place.
    fn get_with(
        &self,
        scenario: &Scenario,
        config: &RunConfig,
        drive: &(dyn Fn(&std::path::Path) -> Result<()> + Sync),
    ) -> Result<PathBuf> {
        let key = static_world_key(scenario, config)?;
        let cell = self
            .entries
            .lock()
            .map_err(|_| Error::Invalid("map cache poisoned".into()))?
            .entry(key.clone())
            .or_default()
            .clone();
        cell.get_or_init(|| {
            let done = self.dir.join(&key);
            if done.join("manifest.json").exists() {
                return Ok(done);
            }
            // Unique across the machines of a shared filesystem, not only across processes.
            let nonce = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos());
            let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
                .unwrap_or_default()
                .trim()
                .to_string();
            let scratch = self.dir.join(format!(
                "{key}.partial-{host}-{}-{nonce}",
                std::process::id()
            ));
            let build = || -> Result<()> {
                std::fs::create_dir_all(&scratch).map_err(|source| Error::Io {
                    what: "creating a map directory",
                    path: scratch.clone(),
                    source,
                })?;
                drive(&scratch)?;
                match std::fs::rename(&scratch, &done) {
                    Ok(()) => Ok(()),
                    // Another process got there first: theirs is the same map.
                    Err(_) if done.join("manifest.json").exists() => {
                        let _ = std::fs::remove_dir_all(&scratch);
                        Ok(())
                    }
                    Err(source) => Err(Error::Io {
                        what: "moving a map into the cache",
                        path: done.clone(),
                        source,
                    }),
                }
            };
            build().map(|()| done).map_err(|e| e.to_string())
        })
        .clone()
        .map_err(Error::Invalid)
    }
}
