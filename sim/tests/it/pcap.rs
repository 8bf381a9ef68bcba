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

/// The distance laser `j` at azimuth `a_cdeg` measures: the wall (ahead, within 20 degrees) or
/// the ground, whichever is nearer; no echo beyond 100 m.
fn distance_m(w_deg: f64, a_cdeg: u16) -> Option<f64> {
    let (w, a) = (w_deg.to_radians(), (f64::from(a_cdeg) * 0.01).to_radians());
    let ground = (w < 0.0).then(|| HEIGHT_M / (-w).sin());
    let ahead = a.cos();
    let wall = (ahead > 20f64.to_radians().cos()).then(|| WALL_M / (w.cos() * ahead));
    let d = match (ground, wall) {
        (Some(g), Some(v)) => g.min(v),
        (g, v) => g.or(v)?,
    };
    (d < 100.0).then_some(d)
}

/// Three revolutions and a bit of the scene, 1800 firings each, as a pcap's bytes.
fn capture() -> Vec<u8> {
    let table = Calibration::built_in(Product::Hdl32e).unwrap();
    let firings = 1800 * 3 + 600;
    let mut datagrams = Vec::new();
    for p in 0..firings / 12 {
        let blocks: [Block; 12] = std::array::from_fn(|k| {
            let a = (((p * 12 + k) % 1800) * 20) as u16;
            let mut channels = [(0u16, 0u8); CHANNELS];
            for (j, c) in channels.iter_mut().enumerate() {
                if let Some(d) = distance_m(table.vertical_deg[j], a) {
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
/// the ground returns to the 5-cm bin; a revolution as a scan holds every return, the wall's
/// 15 m ahead of the pose along its heading.
#[test]
fn a_built_capture_reads_as_revolutions_at_the_sensors_height() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("built.pcap");
    std::fs::write(&file, capture()).unwrap();
    let r = sim::pcap::read(&file).unwrap();
    assert_eq!((r.frames.len(), r.full().len()), (4, 2));
    let h = r.ground_height_below_sensor_m(&r.full()[0]).unwrap();
    assert!((h - HEIGHT_M).abs() <= 0.05, "{h}");
    // Standing at (100, 50) facing north: the wall 15 m north.
    let pose = Isometry2::new(Vector2::new(100.0, 50.0), 90f64.to_radians());
    let scan = r.scan(&r.full()[0], &pose, HEIGHT_M).unwrap();
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
    let report = sim::pcap::map_from_pcap(
        &file,
        &pose,
        None,
        &levels,
        sim::offline_map::map_config(&config),
        &out,
        &mut |_, _| {},
    )
    .unwrap();
    assert_eq!(report.revolutions, 2);
    assert!((report.height_m.0 - HEIGHT_M).abs() <= 0.05 && report.height_m.1);
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
