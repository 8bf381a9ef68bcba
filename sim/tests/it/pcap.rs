//! Real Velodyne captures into the simulator's tools, on a capture these tests build: an
//! HDL-32E standing 2 m above flat ground with a wall 15 m ahead, written as a pcap of UDP
//! packets as the sensor sends them. Its revolutions as scans, the sensor's height found from
//! the ground, and the multi-height map of the capture (`taxi-sim map --pcap`).

use std::path::PathBuf;

use mapper::export::{Trinary, read_ros_map};
use nalgebra::{Isometry2, Point2, Vector2};
use sim::scenario::{RunConfig, Scenario};
use velodyne::packet::{Block, CHANNELS};
use velodyne::{Calibration, DataPacket, Product, ReturnMode};

const HEIGHT_M: f64 = 2.0;
const WALL_M: f64 = 15.0;

/// The distance laser at elevation `w_deg` measures at azimuth `a_cdeg` from a sensor pitched
/// `pitch_deg` nose up: the wall (when there is one: ahead, within 20 degrees) or the ground,
/// whichever is nearer; no echo beyond 100 m.
fn distance_m(w_deg: f64, a_cdeg: u16, pitch_deg: f64, wall: bool) -> Option<f64> {
    let (w, a) = (w_deg.to_radians(), (f64::from(a_cdeg) * 0.01).to_radians());
    // The direction in the simulator's sensor frame (x forward, y left), then pitched.
    let (x, z) = (w.cos() * a.cos(), w.sin());
    let t = pitch_deg.to_radians();
    let down = -(x * t.sin() + z * t.cos());
    let ground = (down > 0.0).then(|| HEIGHT_M / down);
    let ahead = a.cos();
    let wall = (wall && ahead > 20f64.to_radians().cos()).then(|| WALL_M / (w.cos() * ahead));
    let d = match (ground, wall) {
        (Some(g), Some(v)) => g.min(v),
        (g, v) => g.or(v)?,
    };
    (d < 100.0).then_some(d)
}

/// Three revolutions and a bit of the scene (a level sensor, a wall ahead), 1800 firings each,
/// as a pcap's bytes.
fn capture() -> Vec<u8> {
    capture_of(0.0, true)
}

/// The same, the sensor pitched `pitch_deg` nose up, with or without the wall.
fn capture_of(pitch_deg: f64, wall: bool) -> Vec<u8> {
    let table = Calibration::built_in(Product::Hdl32e).unwrap();
    let firings = 1800 * 3 + 600;
    let mut datagrams = Vec::new();
    for p in 0..firings / 12 {
        let blocks: [Block; 12] = std::array::from_fn(|k| {
            let a = (((p * 12 + k) % 1800) * 20) as u16;
            let mut channels = [(0u16, 0u8); CHANNELS];
            for (j, c) in channels.iter_mut().enumerate() {
                if let Some(d) = distance_m(table.vertical_deg[j], a, pitch_deg, wall) {
                    *c = ((d / 0.002).round() as u16, 40);
                }
            }
            Block {
                azimuth_cdeg: a,
                channels,
            }
        });
        let packet = DataPacket {
            blocks,
            timestamp_us: 553 * p as u32,
            return_mode: ReturnMode::Strongest,
            product: Product::Hdl32e,
        };
        datagrams.push((553e-6 * p as f64, 2368, packet.encode()));
    }
    velodyne::pcap_bytes(&datagrams)
}

/// The capture's revolutions are cut where the azimuth wraps; the sensor's height is found from
/// the ground fitted to its returns, to 2 mm; a revolution as a scan holds every return, the wall's
/// 15 m ahead of the pose along its heading.
#[test]
fn a_built_capture_reads_as_revolutions_at_the_sensors_height() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("built.pcap");
    std::fs::write(&file, capture()).unwrap();
    let r = sim::pcap::read(&file, None).unwrap();
    assert_eq!((r.frames.len(), r.full().len()), (4, 2));
    let g = r.ground(&r.full()[..1]).unwrap();
    assert!((g.height_m() - HEIGHT_M).abs() <= 0.002, "{g:?}");
    // Standing at (100, 50) facing north: the wall 15 m north.
    let pose = Isometry2::new(Vector2::new(100.0, 50.0), 90f64.to_radians());
    let mount = nalgebra::Isometry3::translation(0.0, 0.0, HEIGHT_M);
    let scan = r.scan(&r.full()[0], &pose, &mount).unwrap();
    assert_eq!(scan.scan.columns().len(), 1800);
    assert_eq!(
        scan.scan.returns().iter().flatten().count(),
        r.full()[0].points.len()
    );
    // The laser at 0 degrees (beam 23 by elevation: 23 lasers aim lower) at azimuth 0 hits the
    // wall at the sensor's height; the one at -10.67 degrees (beam 15) the ground 10.7 m ahead.
    let wall = scan.scan.returns()[23].expect("the wall");
    let p = wall.point_in_world;
    assert!(
        (p.x - 100.0).abs() < 0.01 && (p.y - 65.0).abs() < 0.01,
        "{p:?}"
    );
    assert!((p.z - HEIGHT_M).abs() < 0.01, "{p:?}");
    let ground = scan.scan.returns()[15].expect("the ground").point_in_world;
    let ahead = HEIGHT_M / 10.67f64.to_radians().tan();
    assert!(
        (ground.y - (50.0 + ahead)).abs() < 0.01 && ground.z.abs() < 0.01,
        "{ground:?}"
    );
}

/// `taxi-sim map SCENARIO --pcap`: the capture's full revolutions mapped for the jet's levels -
/// the wall occupied on both levels, the ground before it free, the height found.
#[test]
fn a_built_capture_maps_its_wall_on_every_level() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("built.pcap");
    std::fs::write(&file, capture()).unwrap();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/straight_cone_under_wing.toml");
    let s = Scenario::from_file(&path).unwrap();
    let config = RunConfig::default();
    let levels = sim::offline_map::levels_of(&s, &config).unwrap();
    let out = dir.path().join("map");
    let pose = Isometry2::new(Vector2::new(10.0, -5.0), 0.0);
    let placement = sim::pcap::Placement {
        pose,
        poses: Vec::new(),
        height_m: None,
        level: false,
    };
    let report = sim::pcap::map_from_pcap(
        &file,
        None,
        &placement,
        &levels,
        sim::offline_map::map_config(&config),
        &out,
        &mut |_, _| {},
    )
    .unwrap();
    assert_eq!(report.revolutions, 2);
    let h = report.vehicle_from_sensor.translation.vector.z;
    assert!((h - HEIGHT_M).abs() <= 0.002, "{h}");
    for k in 0..levels.count() {
        let grid = read_ros_map(&out.join(format!("level{k}.yaml"))).unwrap();
        let at = |x: f64, y: f64| {
            let i = grid.geometry().index_of(&Point2::new(x, y)).unwrap();
            grid.data()[i]
        };
        // The wall 15 m east of the sensor, across its 20-degree fan; the ground 8 m east.
        for y in [-7.0, -5.0, -3.0] {
            assert_eq!(
                at(10.0 + WALL_M + 0.05, y),
                Trinary::Occupied,
                "level {k} y {y}"
            );
        }
        assert_eq!(at(18.0, -5.0), Trinary::Free, "level {k}");
    }
}

/// `compare-lidar`'s figures on built captures: a level sensor 2 m up is found level at 2 m, its
/// flat ground never an obstacle; pitched 2 degrees nose up, the fit finds the pitch, the
/// ground behind it (higher than a level sensor expects) is taken for obstacles, and with the
/// fitted tilt removed none is.
#[test]
fn the_ground_fit_finds_a_sensors_height_and_tilt() {
    let dir = tempfile::tempdir().unwrap();
    let test = RunConfig::default().mapping.map.obstacle_test;
    let figures = |pitch: f64| {
        let file = dir.path().join(format!("pitch{pitch}.pcap"));
        std::fs::write(&file, capture_of(pitch, false)).unwrap();
        let r = sim::pcap::read(&file, None).unwrap();
        sim::studies::lidar_compare::real(&r, "built", test).unwrap()
    };
    let level = figures(0.0);
    assert!((level.height_m - HEIGHT_M).abs() < 0.005, "{level:?}");
    assert!(
        level.pitch_roll_deg.iter().all(|a| a.abs() < 0.02),
        "{level:?}"
    );
    assert_eq!(level.false_obstacles_per_revolution, [0.0, 0.0, 0.0]);
    // 2-mm range steps: the ground's spread about the plane is under a millimetre.
    assert!(
        level.ground_spread_m < 0.001 && level.range_noise_m < 0.002,
        "{level:?}"
    );
    let pitched = figures(2.0);
    assert!(
        (pitched.pitch_roll_deg[0] - 2.0).abs() < 0.02,
        "{pitched:?}"
    );
    assert!(pitched.pitch_roll_deg[1].abs() < 0.02, "{pitched:?}");
    assert!((pitched.height_m - HEIGHT_M).abs() < 0.01, "{pitched:?}");
    let [as_level, untilted, beam_pairs] = pitched.false_obstacles_per_revolution;
    assert!(
        as_level > 1000.0 && untilted == 0.0 && beam_pairs == 0.0,
        "{pitched:?}"
    );
}

/// The synthetic sensor over flat ground: level at the height asked, every low beam returning
/// but for its general drop-off,
/// the ground's spread about the plane its lasers' biases and range noise seen vertically (times
/// the sine of each ground beam's elevation, root mean square), along the beam only the noise,
/// intensities its remission's.
#[test]
fn the_synthetic_sensors_figures_are_its_models() {
    let config = RunConfig::default();
    let f = sim::studies::lidar_compare::synthetic(
        &config.lidar,
        HEIGHT_M,
        0.2,
        3,
        7,
        config.mapping.map.obstacle_test,
    )
    .unwrap();
    assert!((f.height_m - HEIGHT_M).abs() < 0.005, "{f:?}");
    assert!(f.pitch_roll_deg.iter().all(|a| a.abs() < 0.05), "{f:?}");
    let low: Vec<(f64, f64)> = f
        .elevations_deg
        .iter()
        .zip(&f.no_return)
        .filter(|(w, _)| **w <= -8.0)
        .map(|(w, n)| (*w, *n))
        .collect();
    let rate = config.lidar.dropoff_general_rate;
    assert!(low.iter().all(|(_, n)| (n - rate).abs() < 0.005), "{low:?}");
    // The beams whose ground ring lies 4-30 m away, all with the same returns a revolution:
    // each return's height off by its laser's bias and the noise times the beam's sine; the
    // plane's height takes up the biases' mean.
    let biases = sim::world::Lidar::new(config.lidar.clone(), nalgebra::Isometry3::identity())
        .unwrap()
        .range_biases_m();
    let ground: Vec<(f64, f64)> = low
        .iter()
        .map(|(w, _)| w.to_radians())
        .zip(&biases)
        // The ring's radius with its laser's bias (one lies 3.98 m away unbiased).
        .filter(|(w, b)| (4.0..30.0).contains(&((HEIGHT_M / (-w).sin() + *b) * w.cos())))
        .map(|(w, b)| (w.sin(), b * w.sin()))
        .collect();
    let n = ground.len() as f64;
    let mean_offset = ground.iter().map(|(_, o)| o).sum::<f64>() / n;
    let sigma = config.lidar.noise_stddev_m;
    let expected = (ground
        .iter()
        .map(|(s, o)| (s * sigma).powi(2) + (o - mean_offset).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    assert!(
        (f.ground_spread_m / expected - 1.0).abs() < 0.1,
        "{} against {expected}",
        f.ground_spread_m
    );
    // Along the beam, from one laser's consecutive firings: the configured range noise.
    let noise = config.lidar.noise_stddev_m;
    assert!(
        (f.range_noise_m / noise - 1.0).abs() < 0.1,
        "{} against {noise}",
        f.range_noise_m
    );
    // Remission 0.2 attenuated over 4-30 m: 0.2 x exp(-0.004 d) x 255, about 45-50.
    let d = &f.ground_intensity_deciles;
    assert!(d[0] >= 44.0 && d[8] <= 51.0, "{d:?}");
    assert_eq!(f.false_obstacles_per_revolution, [0.0, 0.0, 0.0]);
}

/// `map --pcap --level`: a sensor pitched 2 degrees nose up over flat, empty ground. Taken as
/// level, the ground behind it seems to rise and is mapped as obstacles; with the fitted tilt
/// removed, no cell is occupied.
#[test]
fn a_tilted_sensors_ground_is_clear_once_levelled() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("pitched.pcap");
    std::fs::write(&file, capture_of(2.0, false)).unwrap();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/straight_cone_under_wing.toml");
    let s = Scenario::from_file(&path).unwrap();
    let config = RunConfig::default();
    let levels = sim::offline_map::levels_of(&s, &config).unwrap();
    let occupied = |level: bool| {
        let placement = sim::pcap::Placement {
            pose: Isometry2::identity(),
            poses: Vec::new(),
            height_m: None,
            level,
        };
        let out = dir.path().join(format!("map-{level}"));
        let r = sim::pcap::map_from_pcap(
            &file,
            None,
            &placement,
            &levels,
            sim::offline_map::map_config(&config),
            &out,
            &mut |_, _| {},
        )
        .unwrap();
        assert!(
            (r.ground.pitch_roll_deg()[0] - 2.0).abs() < 0.02,
            "{:?}",
            r.ground
        );
        r.manifest.occupied_cells[0]
    };
    assert!(occupied(false) > 100);
    assert_eq!(occupied(true), 0);
}

/// The comparison's rows: the synthetic sensor against itself (another seed of its noise) holds
/// every calibrated figure; its low beams miss in no sector; with a 3.3 % general drop-off, the
/// no-return figure outside the shadow is 3.3 % and fails a 0.5-point tolerance against 1.3 %.
#[test]
fn the_comparison_holds_a_sensor_to_itself_and_catches_a_dropout() {
    use sim::studies::lidar_compare::{Verdict, no_return_outside, rows, shadow_sectors};
    let config = RunConfig::default();
    let test = config.mapping.map.obstacle_test;
    let synthetic = |lidar: &sim::world::LidarConfig, seed| {
        sim::studies::lidar_compare::synthetic(lidar, HEIGHT_M, 0.2, 2, seed, test).unwrap()
    };
    let (a, b) = (synthetic(&config.lidar, 1), synthetic(&config.lidar, 2));
    assert!(shadow_sectors(&a).iter().all(|s| !s), "{a:?}");
    let calibrated = |real, other| {
        rows(real, other)
            .into_iter()
            .filter_map(|r| match r.verdict {
                Verdict::Calibrated { holds, .. } => Some((r.figure, holds)),
                Verdict::Not(_) => None,
            })
            .collect::<Vec<_>>()
    };
    let held = calibrated(&a, &b);
    assert_eq!(held.len(), 4, "{held:?}");
    assert!(held.iter().all(|(_, h)| *h), "{held:?}");
    let dropping = sim::world::LidarConfig {
        dropoff_general_rate: config.lidar.dropoff_general_rate + 0.02,
        ..config.lidar.clone()
    };
    let c = synthetic(&dropping, 1);
    let outside = no_return_outside(&c, &shadow_sectors(&a));
    let expected = dropping.dropoff_general_rate;
    assert!(
        (outside - expected).abs() < 0.003,
        "{outside} against {expected}"
    );
    let held = calibrated(&a, &c);
    assert!(
        held.iter()
            .any(|(f, h)| f.contains("outside those sectors") && !h),
        "{held:?}"
    );
}

/// The defaults are calibrated on VeloView's real HDL-32E recording: every figure the comparison
/// calls the sensor's is within its tolerance, and the real sensor's low beams miss only in the
/// sector behind it (its mount's shadow). Reads `../shared/data`; run with `--ignored`, as CI
/// does.
#[test]
#[ignore = "reads ../shared/data"]
fn shared_data_the_default_sensor_is_calibrated_on_monterey() {
    use sim::studies::lidar_compare::{Verdict, real, rows, shadow_sectors, synthetic};
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data/velodyne/monterey-first-100-packets.pcap");
    let recording = sim::pcap::read(&file, None).unwrap();
    let config = RunConfig::default();
    let test = config.mapping.map.obstacle_test;
    let r = real(&recording, "monterey", test).unwrap();
    let s = synthetic(&config.lidar, r.height_m, 0.2, r.revolutions, 1, test).unwrap();
    let shadow: Vec<usize> = shadow_sectors(&r)
        .iter()
        .enumerate()
        .filter(|(_, s)| **s)
        .map(|(k, _)| k)
        .collect();
    // Ahead (0-30 degrees) and behind (150-210): the recording's mount or what stood by it.
    assert_eq!(shadow, [0, 5, 6], "{:?}", r.no_return_low_by_sector);
    for row in rows(&r, &s) {
        if let Verdict::Calibrated { holds, .. } = row.verdict {
            assert!(
                holds,
                "{}: {} against {}",
                row.figure, row.real, row.synthetic
            );
        }
    }
}

/// Writes `text` as `name` in `dir`.
fn write_in(dir: &std::path::Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// `map --pcap --poses`: each full revolution is placed at the pose interpolated at its middle
/// firing - the built capture's revolutions 1 and 2 are timed by their packets (553 us apart,
/// 150 a revolution: middles at 0.1244 and 0.2074 s) - the heading the short way round; poses
/// that all equal one place map as a sensor standing there.
#[test]
fn a_moving_sensor_is_placed_at_each_revolutions_time() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("built.pcap");
    std::fs::write(&file, capture()).unwrap();
    let recording = sim::pcap::read(&file, None).unwrap();
    let csv = "time_s,x_m,y_m,yaw_deg\n0.0,0.0,0.0,170.0\n1.0,10.0,-4.0,-170.0\n";
    let poses = sim::pcap::read_poses_csv(&write_in(dir.path(), "poses.csv", csv)).unwrap();
    let placement = sim::pcap::Placement {
        pose: Isometry2::identity(),
        poses,
        height_m: None,
        level: false,
    };
    let at = sim::pcap::revolution_poses(recording.full(), &placement).unwrap();
    assert_eq!(at.len(), 2);
    for (pose, k) in at.iter().zip([1.0, 2.0]) {
        let t = 553e-6 * (150.0 * k + 75.0);
        let p = pose.translation.vector;
        assert!(
            (p.x - 10.0 * t).abs() < 0.01 && (p.y + 4.0 * t).abs() < 0.005,
            "{p} at {t}"
        );
        let yaw = pose.rotation.angle().to_degrees().rem_euclid(360.0);
        assert!((yaw - (170.0 + 20.0 * t)).abs() < 0.02, "{yaw} at {t}");
    }
    // A revolution before the first pose is an error naming it.
    let late = "time_s,x_m,y_m,yaw_deg\n0.15,0,0,0\n1.0,1,0,0\n";
    let placement = sim::pcap::Placement {
        poses: sim::pcap::read_poses_csv(&write_in(dir.path(), "late.csv", late)).unwrap(),
        ..placement
    };
    let e = sim::pcap::revolution_poses(recording.full(), &placement).unwrap_err();
    assert!(
        e.contains("full revolution 0 (at 0.12") && e.contains("outside the poses"),
        "{e}"
    );
    // Standing at (10, -5) as poses or as a pose: the same map.
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/straight_cone_under_wing.toml");
    let s = Scenario::from_file(&path).unwrap();
    let config = RunConfig::default();
    let levels = sim::offline_map::levels_of(&s, &config).unwrap();
    let pose = Isometry2::new(Vector2::new(10.0, -5.0), 0.0);
    let occupied = |poses: Vec<(f64, Isometry2<f64>)>, out: &str| {
        let placement = sim::pcap::Placement {
            pose,
            poses,
            height_m: None,
            level: false,
        };
        let r = sim::pcap::map_from_pcap(
            &file,
            None,
            &placement,
            &levels,
            sim::offline_map::map_config(&config),
            &dir.path().join(out),
            &mut |_, _| {},
        )
        .unwrap();
        assert_eq!(r.revolutions, 2);
        r.manifest.occupied_cells
    };
    let standing = occupied(Vec::new(), "standing");
    assert!(standing[0] > 0);
    assert_eq!(occupied(vec![(0.0, pose), (1.0, pose)], "posed"), standing);
}

/// A poses file's mistakes are errors naming the file, the line and the field.
#[test]
fn a_wrong_poses_file_is_a_located_error() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "t,x,y,yaw\n0,0,0,0\n1,0,0,0\n",
            "bad.csv: line 1: the header is `t,x,y,yaw`",
        ),
        (
            "time_s,x_m,y_m,yaw_deg\n0,0,0,0\n1,0,north,0\n",
            "line 3: y_m: `north` is not a finite number",
        ),
        (
            "time_s,x_m,y_m,yaw_deg\n0,0,0,0\n0,1,0,0\n",
            "line 3: time_s: 0 is not after 0",
        ),
        (
            "time_s,x_m,y_m,yaw_deg\n0,0,0\n",
            "line 2: 3 fields, want 4",
        ),
        (
            "time_s,x_m,y_m,yaw_deg\n0,0,0,0\n",
            "1 poses, want two or more",
        ),
        (
            "time_s,x_m,y_m,yaw_deg\n0,0,0,NaN\n1,0,0,0\n",
            "line 2: yaw_deg: `NaN` is not a finite number",
        ),
    ];
    for (text, want) in cases {
        let e = sim::pcap::read_poses_csv(&write_in(dir.path(), "bad.csv", text))
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.csv") && e.contains(want), "{e}");
    }
}
