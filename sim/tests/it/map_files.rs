//! The offline map's files in a map directory: a manifest that exists but cannot be read or
//! parsed is an error saying so, where, and what to do; a missing or stale one means "build" -
//! and `ensure` builds it then, once.

use std::path::{Path, PathBuf};

use sim::Error;
use sim::offline_map::{Ensured, ManifestError, MapManifest, ensure, fingerprint, fresh_manifest};
use sim::scenario::{RunConfig, Scenario};

fn scenario() -> Scenario {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .join("scenarios/cone_in_path_car.toml");
    Scenario::from_file(&path).unwrap()
}

fn manifest(fingerprint: String) -> MapManifest {
    MapManifest {
        fingerprint,
        scenario: "cone_in_path_car".into(),
        scans: 1,
        route_m: 1.0,
        blocks: 1,
        level_heights_m: vec![0.0, 0.7],
        occupied_cells: vec![0, 0],
    }
}

#[test]
fn garbage_manifest_is_an_error_not_a_missing_map() {
    let scenario = scenario();
    let config = RunConfig::default();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("manifest.json");

    // Missing: build the map.
    assert!(
        fresh_manifest(&scenario, &config, dir.path())
            .unwrap()
            .is_none()
    );

    // Garbage on line 2: an error naming the file, serde_json's position and the remedy.
    std::fs::write(&path, "{\n  \"fingerprint\": nope\n}\n").unwrap();
    let err = fresh_manifest(&scenario, &config, dir.path()).unwrap_err();
    let text = err.to_string();
    match &err {
        Error::Manifest(ManifestError::Parse { line, column, .. }) => {
            assert_eq!((*line, *column), (2, 19))
        }
        other => panic!("expected a parse error, got {other:?}: {text}"),
    }
    assert!(
        text.starts_with(&format!("{}:2:19: not a map manifest", path.display()))
            && text.contains("expected ident")
            && text.contains("delete it")
            && text.contains("taxi-sim map")
            && text.contains(&dir.path().display().to_string()),
        "{text}"
    );

    // Valid JSON that is not a manifest (a field missing) is refused the same way.
    std::fs::write(&path, "{\"fingerprint\": \"00000000\"}").unwrap();
    let text = fresh_manifest(&scenario, &config, dir.path())
        .unwrap_err()
        .to_string();
    assert!(
        text.contains(&path.display().to_string()) && text.contains("missing field"),
        "{text}"
    );

    // A manifest that cannot be read at all (here a directory) is an error too.
    std::fs::remove_file(&path).unwrap();
    std::fs::create_dir(&path).unwrap();
    let err = fresh_manifest(&scenario, &config, dir.path()).unwrap_err();
    assert!(
        matches!(&err, Error::Manifest(ManifestError::Read { .. })),
        "{err}"
    );
    std::fs::remove_dir(&path).unwrap();

    // A good manifest of another scenario's inputs is stale (build); of this one's, fresh.
    let write = |m: &MapManifest| {
        std::fs::write(&path, serde_json::to_string_pretty(m).unwrap()).unwrap();
    };
    write(&manifest("00000000".into()));
    assert!(
        fresh_manifest(&scenario, &config, dir.path())
            .unwrap()
            .is_none()
    );
    write(&manifest(fingerprint(&scenario, &config).unwrap()));
    assert!(
        fresh_manifest(&scenario, &config, dir.path())
            .unwrap()
            .is_some()
    );
}

#[test]
fn the_fingerprint_changes_with_the_vehicles_ceiling() {
    let mut scenario = scenario();
    let config = RunConfig::default();
    let before = fingerprint(&scenario, &config).unwrap();
    let levels =
        sim::offline_map::levels_of(&scenario, &sim::scenario::RunConfig::default()).unwrap();
    assert!(
        (levels.ceiling_m().unwrap() - 2.622).abs() < 1e-3,
        "{levels:?}"
    );
    scenario.vehicle.vehicle.spec.overhead_clearance_m = 0.3;
    let after = fingerprint(&scenario, &config).unwrap();
    assert_ne!(before, after);
    let levels =
        sim::offline_map::levels_of(&scenario, &sim::scenario::RunConfig::default()).unwrap();
    assert!(
        (levels.ceiling_m().unwrap() - 2.522).abs() < 1e-3,
        "{levels:?}"
    );
}

/// `ensure`: a fresh manifest is used as it is (no drive); a stale one is rebuilt once by the
/// mapping drive, whose map the next call finds fresh; an unreadable one is an error, not a
/// reason to build.
#[test]
fn ensure_reuses_a_fresh_map_and_builds_a_stale_one_once() {
    let scenario = scenario();
    let config = RunConfig::default();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("manifest.json");
    let mut builds = 0;
    let call = |builds: &mut usize| {
        ensure(
            &scenario,
            &config,
            dir.path(),
            &mut || *builds += 1,
            &mut |_, _| {},
        )
    };

    let fresh = manifest(fingerprint(&scenario, &config).unwrap());
    std::fs::write(&path, serde_json::to_string(&fresh).unwrap()).unwrap();
    let got = call(&mut builds).unwrap();
    assert!(matches!(got, Ensured::Fresh(_)), "{got:?}");
    assert_eq!(got.manifest().scans, 1);
    assert_eq!(builds, 0);
    assert!(!dir.path().join("blocks").exists());

    std::fs::write(
        &path,
        serde_json::to_string(&manifest("stale".into())).unwrap(),
    )
    .unwrap();
    let got = call(&mut builds).unwrap();
    assert!(matches!(got, Ensured::Built(_)), "{got:?}");
    assert_eq!(builds, 1);
    let built = got.manifest().clone();
    assert_eq!(built.fingerprint, fresh.fingerprint);
    assert!(built.scans > 100 && built.blocks > 0, "{built:?}");
    let again = call(&mut builds).unwrap();
    assert!(matches!(again, Ensured::Fresh(_)), "{again:?}");
    assert_eq!(again.manifest().scans, built.scans);
    assert_eq!(builds, 1);

    std::fs::write(&path, "{ not json").unwrap();
    assert!(call(&mut builds).is_err());
    assert_eq!(builds, 1);
}
