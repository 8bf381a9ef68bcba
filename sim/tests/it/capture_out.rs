//! The simulator's revolutions written as a Velodyne capture (`sim::pcap::write_capture`,
//! `taxi-sim scan SCENARIO --out FILE.pcap`) and read back by the decoder, VeloView-style: the
//! expected values are the simulator's own returns, each point checked against the return it
//! encodes (its laser, distance, intensity, azimuth - the VLP-16's precision azimuth - and
//! elevation, to the packet's resolution), for a VLP-16 and an HDL-32E; then the capture
//! corrupted at random, which must read or be refused, never panic.

use rand::{RngExt as _, SeedableRng as _};
use sim::scenario::{RunConfig, Scenario};
use sim::world::{Lidar, LidarScan, SweepPoses, World};

/// `revolutions` of the sensor `model` on the straight road with the cone under the wing.
fn cast(model: &str, revolutions: u64) -> (Vec<LidarScan>, f64) {
    let scenario = Scenario::from_file(std::path::Path::new(
        "../scenarios/straight_cone_under_wing.toml",
    ))
    .unwrap();
    let vehicle = &scenario.vehicle.vehicle;
    let pose = scenario.vehicle.world_from_start;
    let world = World::with_obstacles(&scenario.full_scene(), vehicle, &pose);
    let config = RunConfig::default().lidar.with_model(model).unwrap();
    let hz = config.rotation_frequency_hz;
    let lidar = Lidar::new(config, vehicle.vehicle_from_lidar()).unwrap();
    let scans = (0..revolutions)
        .map(|r| lidar.scan(&world, &SweepPoses::still(pose), r, scenario.seed))
        .collect();
    (scans, hz)
}

/// VeloView's azimuth (degrees clockwise from ahead, 0-360) of a direction in the simulator's
/// sensor frame (x ahead, y left).
fn azimuth_deg(x: f64, y: f64) -> f64 {
    (-y).atan2(x).to_degrees().rem_euclid(360.0)
}

/// The smaller angle between two azimuths, degrees.
fn apart_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

/// Writes `scans` as a capture, reads it back and checks every point against its return:
/// as many points as returns, revolution for revolution.
fn round_trip(model: &str, columns: usize) {
    let (scans, hz) = cast(model, 2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("capture.pcap");
    sim::pcap::write_capture(&scans, hz, 0.0, &path).unwrap();
    let recording = sim::pcap::read(&path, None).unwrap();
    assert_eq!(recording.skipped.total(), 0);
    let beam_of = velodyne::scan::beams(&recording.calibration);
    let vlp16 = scans[0].scan.beams() == 16;
    // The first revolution starts at the capture's first firing (straight ahead).
    assert!(recording.frames.len() >= 2, "{}", recording.frames.len());
    for (r, scan) in scans.iter().enumerate() {
        let frame = &recording.frames[r];
        let beams = scan.scan.beams();
        let returns = scan.scan.returns().iter().flatten().count();
        assert_eq!(frame.points.len(), returns, "{model}: revolution {r}");
        for p in &frame.points {
            let k = p.firing as usize - r * columns;
            let column = (columns - k) % columns;
            let beam = beam_of[usize::from(p.laser)];
            let i = column * beams + beam;
            let ret = scan.scan.returns()[i].expect("a point where the simulator had a return");
            let at = format!("{model}: revolution {r} firing {k} laser {}", p.laser);
            assert!(
                (f64::from(p.distance_m) - f64::from(ret.range_m)).abs() <= 0.001 + 1e-6,
                "{at}: {} m against {} m",
                p.distance_m,
                ret.range_m
            );
            let want = (f64::from(ret.intensity) * 255.0).round() as u8;
            assert_eq!(p.intensity, want, "{at}");
            // Where the decoder puts it: the column's azimuth, on the VLP-16 moved on by the head's
            // turn until the laser fired (0.2 degrees a firing sequence, 2.304 us a laser within
            // one), to 0.01 degree.
            let d = scan.directions_in_sensor[i];
            let column_deg = azimuth_deg(f64::from(d[0]), f64::from(d[1]));
            let sequence_deg = 360.0 / columns as f64;
            let fired_deg = if vlp16 {
                2.0 * sequence_deg * f64::from(p.laser) * 2.304 / 110.592
            } else {
                0.0
            };
            let [x, y, z] = p.xyz_m.map(f64::from);
            let got_deg = x.atan2(y).to_degrees();
            let off = apart_deg(got_deg, column_deg + fired_deg);
            assert!(
                off < 0.0051,
                "{at}: azimuth {got_deg} against {column_deg} + {fired_deg}"
            );
            let elevation = |h: f64, v: f64| v.atan2(h).to_degrees();
            let (got, want) = (
                elevation(x.hypot(y), z),
                elevation(f64::from(d[0]).hypot(f64::from(d[1])), f64::from(d[2])),
            );
            assert!(
                (got - want).abs() < 0.01,
                "{at}: elevation {got} against {want}"
            );
        }
    }
}

/// A VLP-16's two revolutions: 1800 firings each, 75 packets a revolution, every point where
/// the simulator's return is.
#[test]
fn a_vlp16_capture_of_the_simulator_reads_back_as_its_returns() {
    round_trip("vlp-16", 1800);
}

/// The same for the HDL-32E (2187 firings a revolution, a packet straddling each wrap).
#[test]
fn an_hdl32e_capture_of_the_simulator_reads_back_as_its_returns() {
    round_trip("hdl-32e", 2187);
}

/// The capture with bytes changed, cut short or repeated at random (seeded): each reads (and
/// says what it skipped) or is refused naming the file - never a panic.
#[test]
fn a_corrupted_capture_reads_or_is_refused_never_panics() {
    let (scans, hz) = cast("vlp-16", 1);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("capture.pcap");
    sim::pcap::write_capture(&scans, hz, 0.0, &path).unwrap();
    let good = std::fs::read(&path).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let (mut read, mut refused) = (0, 0);
    for case in 0..300 {
        let mut bytes = good.clone();
        match case % 3 {
            0 => {
                for _ in 0..rng.random_range(1..64) {
                    let at = rng.random_range(0..bytes.len());
                    bytes[at] = rng.random();
                }
            }
            1 => bytes.truncate(rng.random_range(0..bytes.len())),
            _ => {
                let at = rng.random_range(24..bytes.len());
                let len = rng.random_range(1..2_000).min(bytes.len() - at);
                let piece = bytes[at..at + len].to_vec();
                bytes.splice(at..at, piece);
            }
        }
        let file = dir.path().join("bad.pcap");
        std::fs::write(&file, &bytes).unwrap();
        match sim::pcap::read(&file, None) {
            Ok(r) => {
                read += 1;
                assert!(r.frames.iter().map(|f| f.points.len()).sum::<usize>() <= good.len());
            }
            Err(e) => {
                refused += 1;
                assert!(!e.to_string().is_empty());
            }
        }
    }
    // Both outcomes occur: a changed byte or a cut is read round (the packet skipped and
    // counted), a damaged file header is no capture.
    assert!(read > 200 && refused > 0, "{read} read, {refused} refused");
}
