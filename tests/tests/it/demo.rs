//! The mapping demo end to end: levels separate cones from containers, files read back, runs
//! repeat (into fresh folders and into the same one).

use mapper::export::{Trinary, read_npy, read_ros_map};
use mapper::synthetic::Solid;
use mapper::workloads;
use sim::studies::demo::{DemoOptions, run};

fn demo(dir: &std::path::Path, seed: u64) -> sim::studies::demo::DemoSummary {
    let options = DemoOptions {
        out: dir.to_path_buf(),
        scans: 40,
        seed,
        range_noise_m: 0.02,
    };
    run(&options, &mut |_, _| {}).unwrap()
}

/// A position on the ground plane, metres.
type Spot = (f64, f64);

/// Distance in the plane from a point to a solid's footprint.
fn footprint_distance(s: &Solid, (x, y): (f64, f64)) -> f64 {
    match *s {
        Solid::Box { min, max } => (min.x - x)
            .max(x - max.x)
            .max(0.0)
            .hypot((min.y - y).max(y - max.y).max(0.0)),
        Solid::Cylinder {
            center, radius_m, ..
        } => ((center.x - x).hypot(center.y - y) - radius_m).max(0.0),
    }
}

/// Cones (0.45 m posts) and containers (1.1 m boxes) within 15 m of the first 20 m of the drive (x in -45..-25),
/// standing clear (1 m) of every other object.
fn near_route() -> (Vec<Spot>, Vec<Spot>) {
    let (mut cones, mut containers) = (Vec::new(), Vec::new());
    let solids = workloads::parking_lot_scene().solids;
    let clear = |me: &Solid, p: (f64, f64)| {
        solids
            .iter()
            .filter(|o| *o != me)
            .all(|o| footprint_distance(o, p) > 1.0)
    };
    for s in &solids {
        let s = *s;
        match s {
            Solid::Cylinder { center, z_max, .. }
                if z_max < 0.5
                    && center.x > -50.0
                    && center.x < -15.0
                    && (center.y + 3.0).abs() < 15.0
                    && clear(&s, (center.x, center.y)) =>
            {
                cones.push((center.x, center.y))
            }
            Solid::Box { min, max } if (max.z - 1.1).abs() < 1e-9 => {
                let c = ((min.x + max.x) / 2.0, (min.y + max.y) / 2.0);
                if c.0 > -50.0 && c.0 < -15.0 && (c.1 + 3.0).abs() < 15.0 && clear(&s, c) {
                    containers.push(c);
                }
            }
            _ => {}
        }
    }
    (cones, containers)
}

#[test]
fn cones_are_mapped_in_level_0_only_and_containers_in_both() {
    let dir = tempfile::tempdir().unwrap();
    let summary = demo(dir.path(), 1);
    assert_eq!(summary.levels.len(), 2);
    assert!(
        summary.levels[0].1 > summary.levels[1].1,
        "level 0 holds more than level 1: {:?}",
        summary.levels
    );
    let level0 = read_ros_map(&dir.path().join("level0.yaml")).unwrap();
    let level1 = read_ros_map(&dir.path().join("level1.yaml")).unwrap();
    let occupied_near = |map: &mapper::Grid<Trinary>, (x, y): (f64, f64), r: f64| {
        let mut found = false;
        for i in -5..=5 {
            for j in -5..=5 {
                let p = nalgebra::Point2::new(x + i as f64 * 0.1, y + j as f64 * 0.1);
                if (i * i + j * j) as f64 * 0.01 <= r * r && map.at(&p) == Some(&Trinary::Occupied)
                {
                    found = true;
                }
            }
        }
        found
    };
    let (cones, containers) = near_route();
    assert!(
        !cones.is_empty() && !containers.is_empty(),
        "the scene has cones and containers near the route: {cones:?} {containers:?}"
    );
    for c in &cones {
        assert!(occupied_near(&level0, *c, 0.5), "cone at {c:?} in level 0");
        assert!(
            !occupied_near(&level1, *c, 0.5),
            "cone at {c:?} not in level 1 (the wing passes over it)"
        );
    }
    for c in &containers {
        assert!(
            occupied_near(&level0, *c, 0.6) && occupied_near(&level1, *c, 0.6),
            "container at {c:?} in both levels"
        );
    }
}

#[test]
fn a_run_is_a_function_of_its_seed() {
    let (a, b, c) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    demo(a.path(), 7);
    demo(b.path(), 7);
    demo(c.path(), 8);
    let read = |d: &tempfile::TempDir| read_npy(&d.path().join("level0_occupancy.npy")).unwrap().2;
    let (ra, rb, rc) = (read(&a), read(&b), read(&c));
    assert!(
        ra.iter().zip(&rb).all(|(x, y)| x.to_bits() == y.to_bits()),
        "same seed, same map bit for bit"
    );
    assert!(
        ra.iter().zip(&rc).any(|(x, y)| x.to_bits() != y.to_bits()),
        "another seed draws other noise"
    );
}

/// Every file of a demo's output folder (the blocks included), by path relative to it, with its bytes.
fn folder_bytes(dir: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                out.push((path.strip_prefix(dir).unwrap().to_path_buf(), bytes));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn demo_run_twice_into_the_same_folder_gives_the_same_map() {
    let dir = tempfile::tempdir().unwrap();
    let options = DemoOptions {
        out: dir.path().to_path_buf(),
        scans: 6,
        seed: 3,
        range_noise_m: 0.02,
    };
    let first = run(&options, &mut |_, _| {}).unwrap();
    let first_files = folder_bytes(dir.path());
    assert!(
        first_files
            .iter()
            .any(|(p, _)| p.starts_with("blocks") && p.extension().is_some_and(|e| e == "tsmb")),
        "the demo writes blocks: {:?}",
        first_files.iter().map(|(p, _)| p).collect::<Vec<_>>()
    );
    let second = run(&options, &mut |_, _| {}).unwrap();
    let second_files = folder_bytes(dir.path());
    assert_eq!(first.levels, second.levels, "occupied cells per level");
    assert_eq!(first.blocks, second.blocks, "blocks written");
    let names = |files: &[(std::path::PathBuf, Vec<u8>)]| {
        files.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>()
    };
    assert_eq!(names(&first_files), names(&second_files), "same files");
    for ((path, a), (_, b)) in first_files.iter().zip(&second_files) {
        assert!(a == b, "{} differs between the two runs", path.display());
    }
}
