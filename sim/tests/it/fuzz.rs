//! Property-based fuzzing of every parser: arbitrary bytes, byte-level mutations of a valid file
//! and numbers of a valid file swapped for hostile ones (`nan`, `inf`, `1e309`, ...) never panic,
//! never hang, and never load a non-finite number (map blocks excepted, where NaN means unknown:
//! their reader refuses infinities itself). Parsers: scenarios (with the pose files they name),
//! vehicle sidecars, URDFs, campaign files, run configurations, map blocks, map manifests and
//! ROS map YAML + PGM, ROS 2 point clouds, a capture's pose files. `TAXI_SIM_FUZZ_CASES` sets the cases per parser (default 64, the quick
//! budget CI runs; docs/results.md "Faults and hostile input" has the long run).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

fn cases() -> u32 {
    std::env::var("TAXI_SIM_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(rel: &str) -> Vec<u8> {
    std::fs::read(root().join(rel)).unwrap()
}

const HOSTILE_NUMBERS: [&str; 10] = [
    "nan",
    "inf",
    "-inf",
    "1e309",
    "-1e309",
    "NaN",
    "1e-320",
    "18446744073709551616",
    "-0",
    "\"7\"",
];

/// Inputs made from `seed`: arbitrary bytes, byte edits of it, or one of its numbers replaced.
fn inputs(seed: Vec<u8>) -> impl Strategy<Value = Vec<u8>> {
    let edits = {
        let seed = seed.clone();
        proptest::collection::vec((any::<prop::sample::Index>(), 0u8..4, any::<u8>()), 1..8)
            .prop_map(move |ops| {
                let mut b = seed.clone();
                for (at, op, byte) in ops {
                    let i = if b.is_empty() { 0 } else { at.index(b.len()) };
                    match op {
                        0 if !b.is_empty() => b[i] = byte,
                        1 => b.insert(i, byte),
                        2 if !b.is_empty() => {
                            b.remove(i);
                        }
                        _ => {
                            let j = (i + 24).min(b.len());
                            let copy = b[i..j].to_vec();
                            b.splice(i..i, copy);
                        }
                    }
                }
                b
            })
    };
    let numbers = {
        let starts: Vec<usize> = (0..seed.len())
            .filter(|&i| {
                seed[i].is_ascii_digit()
                    && (i == 0 || !seed[i - 1].is_ascii_alphanumeric() && seed[i - 1] != b'_')
            })
            .collect();
        let seed = seed.clone();
        (any::<prop::sample::Index>(), 0..HOSTILE_NUMBERS.len()).prop_map(move |(at, k)| {
            let mut b = seed.clone();
            if starts.is_empty() {
                return b;
            }
            let i = starts[at.index(starts.len())];
            let mut j = i;
            while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.' || b[j] == b'e') {
                j += 1;
            }
            b.splice(i..j, HOSTILE_NUMBERS[k].bytes());
            b
        })
    };
    prop_oneof![
        1 => proptest::collection::vec(any::<u8>(), 0..400),
        3 => edits,
        3 => numbers,
    ]
}

/// `debug` with its quoted strings removed holds no NaN or infinity.
fn all_finite(debug: &str) -> bool {
    let mut bare = String::with_capacity(debug.len());
    let (mut quoted, mut escaped) = (false, false);
    for c in debug.chars() {
        match (quoted, escaped, c) {
            (true, true, _) => escaped = false,
            (true, false, '\\') => escaped = true,
            (_, false, '"') => quoted = !quoted,
            (false, _, c) => bare.push(c),
            _ => {}
        }
    }
    let words: Vec<&str> = bare
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '-'))
        .collect();
    !words.iter().any(|w| matches!(*w, "NaN" | "inf" | "-inf"))
}

/// Runs `check` on inputs made from `seed`; `check` returns the loaded value's Debug text (or
/// None on a refusal), which must hold no non-finite number.
fn fuzz(name: &str, seed: Vec<u8>, finite: bool, check: impl Fn(&[u8]) -> Option<String>) {
    let mut runner = TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&inputs(seed), |bytes| {
            let t = Instant::now();
            let loaded = check(&bytes);
            prop_assert!(
                t.elapsed() < Duration::from_secs(5),
                "{name}: took {:?}",
                t.elapsed()
            );
            if finite && let Some(d) = loaded {
                prop_assert!(all_finite(&d), "{name} loaded a non-finite number: {d}");
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{name}: {e}"));
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn the_finite_check_sees_what_it_must() {
    assert!(all_finite(
        "Foo { x: 1.0, name: \"inf NaN\", y: [2.0, -3e5] }"
    ));
    assert!(!all_finite("Foo { x: NaN }"));
    assert!(!all_finite("Foo { y: [1.0, inf] }"));
    assert!(!all_finite("Some(-inf)"));
}

#[test]
fn scenarios_and_their_pose_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = root().join("scenarios/fuzz-scenario.toml");
    fuzz(
        "scenario",
        read("scenarios/cone_in_path_car.toml"),
        true,
        |b| {
            sim::scenario::Scenario::from_str(&text(b), &path)
                .ok()
                .map(|s| format!("{:?}{:?}{:?}", s.world, s.route, s.objects))
        },
    );
    let csv = dir.path().join("route.csv");
    let scenario = text(&read("scenarios/cone_in_path_car.toml")).replace(
        "waypoints_m = [[0.0, 0.0], [150.0, 0.0]]",
        "pose_file = \"route.csv\"",
    );
    let at = dir.path().join("s.toml");
    fuzz(
        "pose file",
        b"# x, y, yaw\n0.0,0.0,0.0\n50.0,0.5\n100.0,1.0,0.01\n149.0,0.0\n".to_vec(),
        true,
        |b| {
            std::fs::write(&csv, b).unwrap();
            sim::scenario::Scenario::from_str(&scenario, &at)
                .ok()
                .map(|s| format!("{:?}", s.route))
        },
    );
}

#[test]
fn vehicle_sidecars_and_urdfs() {
    fuzz(
        "sidecar",
        read("aircraft/vehicles/praetor600.toml"),
        true,
        |b| {
            aircraft::VehicleSpec::from_str(&text(b), "fuzz.toml")
                .ok()
                .map(|s| format!("{s:?}"))
        },
    );
    fuzz(
        "urdf",
        read("aircraft/vehicles/iara_car_fake_wing.urdf"),
        true,
        |b| {
            aircraft::urdf::parts_from_str(&text(b), "fuzz.urdf")
                .ok()
                .map(|p| format!("{p:?}"))
        },
    );
}

#[test]
fn campaign_files_and_run_configurations() {
    let path = root().join("scenarios/campaigns/fuzz.toml");
    fuzz(
        "campaign",
        read("scenarios/campaigns/smoke.toml"),
        true,
        |b| {
            sim::campaign::Campaign::from_str(&text(b), &path)
                .ok()
                .map(|c| format!("{:?}{:?}", c.settings, c.layout))
        },
    );
    let config = sim::scenario::RunConfig::default().to_toml().into_bytes();
    fuzz("run configuration", config, true, |b| {
        sim::scenario::RunConfig::from_toml(&text(b), "fuzz.toml")
            .ok()
            .map(|c| format!("{c:?}"))
    });
}

#[test]
fn map_blocks_manifests_and_ros_maps() {
    let dir = tempfile::tempdir().unwrap();
    let scenario =
        sim::scenario::Scenario::from_file(&root().join("scenarios/straight_cone_under_wing.toml"))
            .unwrap();
    let config = sim::scenario::RunConfig::default();
    let map = dir.path().join("map");
    sim::offline_map::map_drive(&scenario, &config, &map, &mut |_, _| {}).unwrap();
    let levels = sim::offline_map::levels_of(&scenario, &config).unwrap();
    let spec = mapper::BlockSpec {
        side: config.mapping.map.block_cells,
        resolution_m: config.mapping.map.resolution_m,
        levels,
        l_max: config.mapping.map.occupancy.l_max,
    };
    let mut blocks: Vec<PathBuf> = std::fs::read_dir(map.join("blocks"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    blocks.sort();
    let block = std::fs::read(&blocks[0]).unwrap();
    // Blocks are compressed (a few kB to a few hundred): the cases edit them in place.
    fuzz("map block", block.clone(), false, |b| {
        mapper::blocks::decode_block(&spec, b, Path::new("fuzz.tsmb"))
            .ok()
            .map(|_| String::new())
    });
    // The same with the checksum made right, so the mutations reach the decompressor (a hostile
    // Zstandard frame) and the value checks.
    fuzz("map block, checksum fixed", block, false, |b| {
        let mut b = b.to_vec();
        if b.len() >= 4 {
            let n = b.len();
            let crc = crc32fast::hash(&b[..n - 4]);
            b[n - 4..].copy_from_slice(&crc.to_le_bytes());
        }
        mapper::blocks::decode_block(&spec, &b, Path::new("fuzz.tsmb"))
            .ok()
            .map(|_| String::new())
    });
    let manifest = std::fs::read(map.join("manifest.json")).unwrap();
    fuzz("manifest", manifest, true, |b| {
        std::fs::write(map.join("manifest.json"), b).unwrap();
        sim::offline_map::fresh_manifest(&scenario, &config, &map)
            .ok()
            .flatten()
            .map(|m| format!("{m:?}"))
    });
    let yaml = std::fs::read(map.join("level0.yaml")).unwrap();
    let ros = dir.path().join("ros");
    std::fs::create_dir_all(&ros).unwrap();
    std::fs::copy(map.join("level0.ros.png"), ros.join("level0.ros.png")).unwrap();
    fuzz("ROS map YAML", yaml.clone(), true, |b| {
        std::fs::write(ros.join("level0.yaml"), b).unwrap();
        mapper::export::read_ros_map(&ros.join("level0.yaml"))
            .ok()
            .map(|g| format!("{:?}", g.geometry()))
    });
    std::fs::write(ros.join("level0.yaml"), &yaml).unwrap();
    let png = std::fs::read(map.join("level0.ros.png")).unwrap();
    fuzz("ROS map PNG", png, true, |b| {
        std::fs::write(ros.join("level0.ros.png"), b).unwrap();
        mapper::export::read_ros_map(&ros.join("level0.yaml"))
            .ok()
            .map(|g| format!("{:?}", g.geometry()))
    });
    // The same level as map_saver writes it, a PGM.
    use mapper::export::Trinary;
    let level = mapper::export::read_ros_map(&map.join("level0.yaml")).unwrap();
    let probabilities = mapper::Grid::from_vec(
        *level.geometry(),
        level
            .data()
            .iter()
            .map(|t| match t {
                Trinary::Occupied => 1.0f32,
                Trinary::Free => 0.0,
                Trinary::Unknown => -1.0,
            })
            .collect(),
    )
    .unwrap();
    let pgm_yaml = ros.join("saved.yaml");
    let pgm_path = mapper::export::write_ros_map(
        &probabilities,
        &pgm_yaml,
        mapper::export::TrinaryThresholds::default(),
    )
    .unwrap();
    let pgm = std::fs::read(&pgm_path).unwrap();
    fuzz("ROS map PGM", pgm, true, |b| {
        std::fs::write(&pgm_path, b).unwrap();
        mapper::export::read_ros_map(&pgm_yaml)
            .ok()
            .map(|g| format!("{:?}", g.geometry()))
    });
}

/// ROS 2 point clouds (`ros2::read_cloud`): arbitrary bytes and byte edits of a valid cloud are
/// read or refused, never a panic (the cloud's numbers are binary: NaN is a driver's "no return").
#[test]
fn ros2_point_clouds() {
    let points: Vec<ros2::msgs::VelodynePoint> = (0..12)
        .map(|i| ros2::msgs::VelodynePoint {
            xyz: [i as f32, 1.0, -2.0],
            intensity: 7.0,
            ring: i as u16,
            time: 0.001 * i as f32,
        })
        .collect();
    let seed = ros2::msgs::velodyne_cloud(ros2::msgs::Time::from_ns(1), "velodyne", &points);
    fuzz("point cloud", seed, false, |b| {
        ros2::read_cloud(b).ok().map(|c| format!("{}", c.xyz.len()))
    });
}

/// Whole bags (`taxi-sim map --from-bag`): byte edits of a small sound bag (transforms and
/// clouds, LZ4 chunks) and arbitrary bytes are mapped or refused, never a panic; and the
/// transform and odometry messages the poses come from, alone.
#[test]
fn ros2_bags_and_their_poses() {
    let dir = tempfile::tempdir().unwrap();
    let sound = dir.path().join("sound.mcap");
    crate::rosbag::hostile_bag(&sound, crate::rosbag::Hostile::default());
    let seed = std::fs::read(&sound).unwrap();
    let levels = mapper::Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let file = dir.path().join("fuzzed.mcap");
    fuzz("bag", seed, false, |b| {
        std::fs::write(&file, b).unwrap();
        sim::rosbag::map_from_bag(
            &file,
            &sim::rosbag::BagMapOptions::default(),
            &levels,
            mapper::MapConfig::default(),
            None,
            &dir.path().join("map"),
            &mut |_, _| {},
        )
        .ok()
        .map(|r| format!("{:?}", r.manifest.occupied_cells))
    });
    let t = ros2::msgs::Transform {
        stamp: ros2::msgs::Time::from_ns(7),
        parent: "map".into(),
        child: "base_link".into(),
        pose: ros2::msgs::Pose::planar(1.0, 2.0, 0.0, 0.3),
    };
    fuzz(
        "transforms",
        ros2::msgs::tf_message(&[t.clone(), t.clone()]),
        true,
        |b| {
            ros2::msgs::read_tf_message(b)
                .ok()
                .map(|t| format!("{t:?}"))
        },
    );
    let odom = ros2::msgs::odometry(
        t.stamp,
        "map",
        "base_link",
        &t.pose,
        &[0.0; 36],
        [[1.0; 3]; 2],
    );
    fuzz("odometry", odom, true, |b| {
        ros2::msgs::read_odometry(b).ok().map(|t| format!("{t:?}"))
    });
}

/// Velodyne captures: a pcap of HDL-32E packets (several revolutions of ground returns) and a
/// position packet, fuzzed; read, cut into revolutions, each made a scan, the ground fitted.
#[test]
fn velodyne_captures() {
    use velodyne::packet::{Block, CHANNELS};
    let mut datagrams: Vec<(f64, u16, Vec<u8>)> = (0..70u16)
        .map(|p| {
            let blocks = std::array::from_fn(|k| {
                let mut channels = [(0u16, 0u8); CHANNELS];
                for (j, c) in channels.iter_mut().enumerate() {
                    *c = ((1000 + 97 * j) as u16, j as u8);
                }
                Block {
                    azimuth_cdeg: ((p * 12 + k as u16) % 120) * 300,
                    channels,
                }
            });
            let packet = velodyne::DataPacket {
                blocks,
                timestamp_us: 553 * u32::from(p),
                return_mode: velodyne::ReturnMode::Strongest,
                product: velodyne::Product::Hdl32e,
            };
            (f64::from(p) * 553e-6, 2368, packet.encode())
        })
        .collect();
    let mut position = vec![0u8; 512];
    position[206..213].copy_from_slice(b"$GPRMC,");
    datagrams.insert(3, (0.001, 8308, position));
    let seed = velodyne::pcap_bytes(&datagrams);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("fuzzed.pcap");
    std::fs::write(&file, &seed).unwrap();
    let sound = sim::pcap::read(&file, None).unwrap();
    assert_eq!((sound.frames.len(), sound.positions), (7, 1));
    fuzz("velodyne capture", seed, true, |b| {
        std::fs::write(&file, b).unwrap();
        let r = sim::pcap::read(&file, None).ok()?;
        let mount = nalgebra::Isometry3::translation(0.0, 0.0, 2.0);
        let pose = nalgebra::Isometry2::identity();
        let returns: usize = r
            .frames
            .iter()
            .filter_map(|f| r.scan(f, &pose, &mount).ok())
            .map(|s| s.scan.returns().iter().flatten().count())
            .sum();
        Some(format!(
            "{} {returns} {:?}",
            r.frames.len(),
            r.ground(r.full())
        ))
    });
}

/// A moving sensor's poses (`map --pcap --poses`), fuzzed: read, then each revolution of a
/// capture placed by them.
#[test]
fn velodyne_pose_files() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("poses.csv");
    // Two revolutions whose middles are 0.25 s and 0.75 s on the sensor's clock.
    let frames: Vec<velodyne::Frame> = [0.25e6, 0.75e6]
        .map(|time_us| velodyne::Frame {
            points: vec![velodyne::Point {
                xyz_m: [1.0, 0.0, 0.0],
                distance_m: 1.0,
                intensity: 10,
                laser: 0,
                azimuth_cdeg: 0,
                firing: 0,
                time_us,
                echo: velodyne::Echo::Strongest,
            }],
        })
        .to_vec();
    fuzz(
        "pose file of a capture",
        b"time_s,x_m,y_m,yaw_deg\n0.0,0.0,0.0,170.0\n0.5,2.0,1.0,-170.0\n1.0,3.0,1.0,0.0\n"
            .to_vec(),
        true,
        |b| {
            std::fs::write(&file, b).unwrap();
            let poses = sim::pcap::read_poses_csv(&file).ok()?;
            let placement = sim::pcap::Placement {
                pose: nalgebra::Isometry2::identity(),
                poses: poses.clone(),
                height_m: None,
                level: false,
            };
            let placed = sim::pcap::revolution_poses(&frames, &placement);
            Some(format!("{poses:?} {placed:?}"))
        },
    );
}
