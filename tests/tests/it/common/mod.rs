//! Helpers shared by the closed-loop test files: a shipped scenario by name, its offline map
//! (one mapping drive per static world for the whole test binary), and a run over it.

use std::path::{Path, PathBuf};
use std::sync::LazyLock;
use std::time::UNIX_EPOCH;

use sim::campaign::MapCache;

use sim::engine::{RunReport, RunSetup, run};
use sim::scenario::{RunConfig, Scenario};

/// The shipped scenario `scenarios/<name>.toml`.
pub fn scenario(name: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// The maps of this test binary: one mapping drive per static world (the campaigns' cache, keyed
/// by what the drive depends on), in `CARGO_TARGET_TMPDIR` under this binary's build stamp so a
/// later run of the same binary reuses them and a rebuilt one (the mapper changed) does not.
/// With `TAXI_SIM_TEST_MAPS=DIR`, the cache under DIR instead, shared with `taxi-sim regress
/// --maps-dir DIR` and `taxi-sim run --maps-dir DIR` of the same build (CI: one mapping drive per
/// static world for the tests and the regression run together).
static MAPS: LazyLock<MapCache> = LazyLock::new(|| {
    if let Some(dir) = std::env::var_os("TAXI_SIM_TEST_MAPS") {
        std::fs::create_dir_all(&dir).unwrap();
        return MapCache::new(PathBuf::from(dir));
    }
    let root = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let exe = std::fs::metadata(std::env::current_exe().unwrap()).unwrap();
    let built = exe.modified().unwrap().duration_since(UNIX_EPOCH).unwrap();
    let stamp = format!("it-maps-{}-{}", exe.len(), built.as_nanos());
    // Older builds' maps go.
    for entry in std::fs::read_dir(root).into_iter().flatten().flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with("it-maps-") && name != stamp {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
    MapCache::new(root.join(stamp))
});

/// The offline map of `s` under `config`: built by its mapping drive on first use, shared by every
/// test whose static world and map settings are the same.
pub fn map_for(s: &Scenario, config: &RunConfig) -> PathBuf {
    MAPS.get_for_file(s, config)
        .unwrap_or_else(|e| panic!("{}: mapping drive: {e:#}", s.name))
}

/// Runs the closed loop over the offline map of `s` under `config` ([`map_for`]).
pub fn run_with(s: &Scenario, config: RunConfig) -> RunReport {
    let setup = RunSetup {
        config: config.clone(),
        ..RunSetup::new(map_for(s, &config))
    };
    run(s, &setup).unwrap_or_else(|e| panic!("{}: {e:#}", s.name))
}
