//! The ROS 2 bag of a run: read back with the `mcap` crate and decoded field by field with the
//! `ros2` crate's CDR reader, every revolution's cloud holds exactly the revolution's returns,
//! in the sensor frame, stamped when the revolution was taken. The readers nobody here wrote
//! (rosbags, mcap-ros2-support) decode the CI run's bag in `.ci/check_bag.py`.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use ros2::cdr::CdrReader;
use sim::engine::{Observer, Observers, RevolutionFrame, RunHandles, RunSetup, run_with};
use sim::rosbag::{RosBag, stamp_ns};
use sim::scenario::{RunConfig, Scenario};

/// Counts each revolution's returns and the largest range, as the bag should hold them.
#[derive(Default)]
struct Returns(Vec<(u64, usize)>);

impl Observer for Returns {
    fn revolution(&mut self, frame: &RevolutionFrame<'_>) -> sim::error::Result<()> {
        let n = frame.revolution.scan.returns().iter().flatten().count();
        self.0.push((stamp_ns(frame.revolution.t_s), n));
        Ok(())
    }
}

/// A cloud's stamp and its points (x, y, z, ring) read by field, as a ROS reader would.
fn read_cloud(cdr: &[u8]) -> (u64, Vec<([f32; 3], u16)>) {
    let mut r = CdrReader::new(cdr).unwrap();
    let sec = r.i32("sec").unwrap();
    let nanosec = r.u32("nanosec").unwrap();
    assert_eq!(r.string("frame_id").unwrap(), "velodyne");
    assert_eq!(r.u32("height").unwrap(), 1);
    let width = r.u32("width").unwrap() as usize;
    let fields = r.count("fields", 13).unwrap();
    let mut names = Vec::new();
    for _ in 0..fields {
        names.push(r.string("name").unwrap());
        r.u32("offset").unwrap();
        r.u8("datatype").unwrap();
        r.u32("count").unwrap();
    }
    assert_eq!(names, ["x", "y", "z", "intensity", "ring", "time"]);
    assert!(!r.bool("is_bigendian").unwrap());
    let step = r.u32("point_step").unwrap() as usize;
    assert_eq!(r.u32("row_step").unwrap() as usize, step * width);
    let data = r.bytes("data").unwrap();
    assert_eq!(data.len(), step * width);
    let f = |b: &[u8]| f32::from_le_bytes(b.try_into().unwrap());
    let points = data
        .chunks(step)
        .map(|p| {
            (
                [f(&p[0..4]), f(&p[4..8]), f(&p[8..12])],
                u16::from_le_bytes([p[16], p[17]]),
            )
        })
        .collect();
    let stamp = u64::try_from(sec).unwrap() * 1_000_000_000 + u64::from(nanosec);
    (stamp, points)
}

#[test]
fn a_runs_bag_holds_every_revolutions_returns_in_the_sensor_frame() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/straight_cone_under_wing.toml");
    let s = Scenario::from_file(&path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let map_dir = dir.path().join("map");
    sim::offline_map::map_drive(&s, &RunConfig::default(), &map_dir, &mut |_, _| {}).unwrap();
    let file = dir.path().join("bag").join("run.mcap");
    std::fs::create_dir_all(file.parent().unwrap()).unwrap();
    let mut bag = RosBag::create(&file).unwrap();
    let mut returns = Returns::default();
    let stop = AtomicBool::new(false);
    run_with(
        &s,
        &RunSetup::new(map_dir),
        RunHandles {
            stop: Some(&stop),
            progress: &mut |p| {
                if p.sim_time_s >= 3.0 {
                    stop.store(true, Ordering::Relaxed);
                }
            },
            observer: &mut Observers(vec![&mut bag, &mut returns]),
        },
    )
    .unwrap();
    let summary = bag.summary().expect("finished").clone();
    assert!(dir.path().join("bag/metadata.yaml").exists());
    let bytes = std::fs::read(&file).unwrap();
    let mut clouds = Vec::new();
    let mut topics = std::collections::BTreeMap::<String, u64>::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        *topics.entry(m.channel.topic.clone()).or_default() += 1;
        if m.channel.topic == "/velodyne_points" {
            let (stamp, points) = read_cloud(&m.data);
            assert_eq!(stamp, m.log_time);
            clouds.push((stamp, points));
        }
    }
    let written: std::collections::BTreeMap<_, _> =
        summary.topics.iter().filter(|t| t.1 > 0).cloned().collect();
    assert_eq!(topics, written);
    assert!(returns.0.len() >= 25, "{} revolutions", returns.0.len());
    assert_eq!(clouds.len(), returns.0.len());
    for ((stamp, points), (t, n)) in clouds.iter().zip(&returns.0) {
        assert_eq!((stamp, points.len()), (t, *n));
        // In the sensor's frame: within the sensor's 100 m, every ring one of its 32 beams, and
        // the ground (2.15 m below the car's roof sensor) among them.
        assert!(points.iter().all(|(p, ring)| *ring < 32 && p.iter().map(|v| v * v).sum::<f32>() < 100.5 * 100.5));
        assert!(
            points.iter().any(|(p, _)| p[2] < -1.5),
            "no ground below the sensor"
        );
    }
    // The run's bag maps with either pose: the stack's estimate through /tf, or the truth from
    // /ground_truth/odom (the sensor's mount from /tf_static); every cloud has one.
    let levels = sim::offline_map::levels_of(&s, &RunConfig::default()).unwrap();
    for source in [
        sim::rosbag::PoseSource::Tf,
        sim::rosbag::PoseSource::Odom("/ground_truth/odom".into()),
    ] {
        let options = sim::rosbag::BagMapOptions {
            pose_source: source.clone(),
            ..sim::rosbag::BagMapOptions::default()
        };
        let report = sim::rosbag::map_from_bag(
            &file,
            &options,
            &levels,
            sim::offline_map::map_config(&RunConfig::default()),
            None,
            &dir.path().join("from_bag"),
            &mut |_, _| {},
        )
        .unwrap();
        assert_eq!(
            (report.clouds, report.skipped),
            (clouds.len() as u64, 0),
            "{source:?}"
        );
        assert!(report.manifest.occupied_cells[0] > 100, "{source:?}");
    }
}

/// The map's blocks in `dir`, by index.
fn blocks(dir: &std::path::Path, spec: &mapper::BlockSpec) -> Vec<mapper::Block> {
    let store = mapper::BlockStore::open(dir.join("blocks"), spec.clone()).unwrap();
    let mut indices = store.list().unwrap();
    indices.sort_by_key(|b| (b.x, b.y));
    indices
        .into_iter()
        .map(|i| store.load(i).unwrap().unwrap())
        .collect()
}

/// The scan as the bag holds it: each point in its column's sensor frame rounded to `f32`, the
/// intensity as 0-255 in `f32`, the range the rounded point's.
fn as_stored(scan: &mapper::Scan) -> mapper::Scan {
    let mut returns = Vec::with_capacity(scan.returns().len());
    for c in 0..scan.column_count() {
        let (column, rs) = scan.column(c).unwrap();
        let w = column.world_from_sensor;
        for r in rs {
            returns.push(r.map(|r| {
                let local = (w.inverse() * r.point_in_world).map(|v| f64::from(v as f32));
                mapper::Return {
                    point_in_world: w * local,
                    range_m: local.coords.norm() as f32,
                    intensity: ((f64::from(r.intensity * 255.0) / 255.0) as f32).clamp(0.0, 1.0),
                }
            }));
        }
    }
    mapper::Scan::new(scan.beams(), scan.columns().to_vec(), returns).unwrap()
}

/// The round trip: the mapping drive recorded as a bag (`taxi-sim map --record`), the map built
/// from that bag (`--from-bag`: clouds organised by azimuth and ring, poses through `/tf`)
/// equals, cell for cell and bit for bit, the map the same revolutions make when each point is
/// rounded as the bag stores it (f32 in the sensor frame); against the drive's own map, that
/// rounding is the only difference and it moves few cells.
#[test]
fn the_map_from_a_recorded_drive_equals_the_drives_map() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/straight_cone_under_wing.toml");
    let s = Scenario::from_file(&path).unwrap();
    let config = RunConfig::default();
    let levels = sim::offline_map::levels_of(&s, &config).unwrap();
    let filter = sim::offline_map::self_filter_model(&s.vehicle.vehicle).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("drive").join("drive.mcap");
    std::fs::create_dir_all(file.parent().unwrap()).unwrap();
    let mut bag =
        sim::rosbag::DriveBag::create(&file, &s.vehicle.vehicle.vehicle_from_lidar()).unwrap();
    let rounded_dir = dir.path().join("rounded");
    let mut rounded: Option<mapper::MultiHeightMap> = None;
    let drive = sim::offline_map::map_drive_with(
        &s,
        &config,
        &dir.path().join("map"),
        &mut |_, _| {},
        &mut |(t, pose, scan)| {
            bag.revolution(t, pose, scan)?;
            let p = nalgebra::Point2::from(pose.translation.vector);
            let map = rounded.get_or_insert_with(|| {
                mapper::MultiHeightMap::with_stores(
                    sim::offline_map::map_config(&config),
                    levels.clone(),
                    p,
                    None,
                    Some(&rounded_dir.join("blocks")),
                )
                .unwrap()
            });
            map.recenter(p)?;
            map.insert_scan(&as_stored(scan), Some(&filter))?;
            Ok(())
        },
    )
    .unwrap();
    bag.finish().unwrap();
    let rounded = rounded.unwrap();
    rounded.flush().unwrap();
    let report = sim::rosbag::map_from_bag(
        &file,
        &sim::rosbag::BagMapOptions::default(),
        &levels,
        sim::offline_map::map_config(&config),
        Some(&filter),
        &dir.path().join("from_bag"),
        &mut |_, _| {},
    )
    .unwrap();
    assert_eq!((report.clouds, report.skipped), (drive.scans as u64, 0));
    assert_eq!(report.manifest.scans, drive.scans);
    assert_eq!(report.layout.map(|l| l.columns), Some(2187));
    assert!((report.manifest.route_m - drive.route_m).abs() < 0.2);
    let spec = rounded.block_spec();
    let from_bag = blocks(&dir.path().join("from_bag"), spec);
    let expected = blocks(&rounded_dir, spec);
    let original = blocks(&dir.path().join("map"), spec);
    assert_eq!(from_bag.len(), expected.len());
    let bits = |b: &mapper::Block| -> Vec<Vec<u32>> {
        b.levels
            .iter()
            .map(|l| l.iter().map(|v| v.to_bits()).collect())
            .collect()
    };
    for (a, b) in from_bag.iter().zip(&expected) {
        assert_eq!(a.index, b.index);
        assert!(bits(a) == bits(b), "block {:?} differs", a.index);
        assert_eq!(a.remission, b.remission);
    }
    // Against the drive's own map: cells whose log-odds moved, over the cells known.
    let (mut known, mut moved) = (0usize, 0usize);
    assert_eq!(original.len(), from_bag.len());
    for (a, b) in from_bag.iter().zip(&original) {
        for (la, lb) in a.levels.iter().zip(&b.levels) {
            for (x, y) in la.iter().zip(lb) {
                known += usize::from(!y.is_nan());
                moved += usize::from(x.to_bits() != y.to_bits());
            }
        }
    }
    eprintln!("{moved} of {known} known cells moved by the f32 rounding");
    assert!(known > 50_000 && moved * 5000 < known, "{moved} of {known}");
    assert_eq!(report.manifest.occupied_cells, drive.occupied_cells);
}

/// What a hostile bag is made of: which parts it has.
#[derive(Clone, Copy, Default)]
pub(crate) struct Hostile {
    no_tf: bool,
    cloud_topic_type: Option<ros2::msgs::MsgType>,
    point_step: Option<u32>,
    no_ring: bool,
}

/// A cloud of a ring of points around the sensor, written field by field so a test can break
/// its layout.
fn hostile_cloud(stamp: ros2::msgs::Time, h: Hostile) -> Vec<u8> {
    let mut fields = vec![
        ("x", 0u32, 7u8),
        ("y", 4, 7),
        ("z", 8, 7),
        ("intensity", 12, 7),
    ];
    if !h.no_ring {
        fields.push(("ring", 16, 4));
    }
    let step = h.point_step.unwrap_or(18);
    let n = 360u32;
    let mut w = ros2::cdr::CdrWriter::new();
    w.i32(stamp.sec);
    w.u32(stamp.nanosec);
    w.string("velodyne");
    w.u32(1);
    w.u32(n);
    w.count(fields.len());
    for (name, offset, datatype) in &fields {
        w.string(name);
        w.u32(*offset);
        w.u8(*datatype);
        w.u32(1);
    }
    w.bool(false);
    w.u32(step);
    w.u32(step * n);
    let mut data = Vec::new();
    for i in 0..n {
        let a = f64::from(i).to_radians();
        let mut p = Vec::new();
        for v in [5.0 * a.cos() as f32, 5.0 * a.sin() as f32, -1.0, 100.0] {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p.extend_from_slice(&((i % 2) as u16).to_le_bytes());
        p.resize(step as usize, 0);
        data.extend_from_slice(&p);
    }
    w.bytes(&data);
    w.bool(true);
    w.finish()
}

pub(crate) fn hostile_bag(file: &std::path::Path, h: Hostile) {
    use ros2::msgs::{self, Pose, Time, Transform};
    let mut bag = ros2::BagWriter::create(file).unwrap();
    let tf = bag
        .add_topic("/tf", msgs::TF_MESSAGE, ros2::Qos::Stream)
        .unwrap();
    let cloud = bag
        .add_topic(
            "/velodyne_points",
            h.cloud_topic_type.unwrap_or(msgs::POINT_CLOUD2),
            ros2::Qos::Stream,
        )
        .unwrap();
    for k in 0..10u64 {
        let ns = stamp_ns(k as f64 * 0.1);
        let t = Time::from_ns(ns);
        if !h.no_tf {
            let link = |parent: &str, child: &str, x| Transform {
                stamp: t,
                parent: parent.into(),
                child: child.into(),
                pose: Pose::planar(x, 0.0, 0.0, 0.0),
            };
            let m = msgs::tf_message(&[
                link("map", "base_link", k as f64 * 0.5),
                link("base_link", "velodyne", 1.0),
            ]);
            bag.write(tf, ns, &m).unwrap();
        }
        bag.write(cloud, ns, &hostile_cloud(t, h)).unwrap();
    }
    bag.finish().unwrap();
}

/// Bags that cannot be mapped are errors that say which file, topic, message and field - a
/// cloud topic of another type or missing, a cloud whose `point_step` cannot
/// hold its fields or that has no `ring`, a bag with no poses - and a sound one of the same
/// make maps.
/// Maps the bag at `file` for the car of `straight_cone_under_wing`: its revolutions, or the
/// error's text.
fn map_bag(file: &std::path::Path, options: &sim::rosbag::BagMapOptions) -> Result<usize, String> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/straight_cone_under_wing.toml");
    let s = Scenario::from_file(&path).unwrap();
    let config = RunConfig::default();
    let levels = sim::offline_map::levels_of(&s, &config).unwrap();
    sim::rosbag::map_from_bag(
        file,
        options,
        &levels,
        sim::offline_map::map_config(&config),
        None,
        &file.with_extension("map"),
        &mut |_, _| {},
    )
    .map(|r| r.manifest.scans)
    .map_err(|e| e.to_string())
}

#[test]
fn hostile_bags_are_located_errors() {
    let dir = tempfile::tempdir().unwrap();
    let map = |name: &str, h: Hostile, options: sim::rosbag::BagMapOptions| {
        let file = dir.path().join(name).join(format!("{name}.mcap"));
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        hostile_bag(&file, h);
        map_bag(&file, &options)
    };
    let default = sim::rosbag::BagMapOptions::default;
    assert_eq!(map("sound", Hostile::default(), default()), Ok(10));
    let e = map(
        "steps",
        Hostile {
            point_step: Some(12),
            ..Hostile::default()
        },
        default(),
    )
    .unwrap_err();
    assert!(
        e.contains("steps.mcap")
            && e.contains("topic /velodyne_points, message 0")
            && e.contains("field `intensity`"),
        "{e}"
    );
    let e = map(
        "ringless",
        Hostile {
            no_ring: true,
            ..Hostile::default()
        },
        default(),
    )
    .unwrap_err();
    assert!(
        e.contains("message 0") && e.contains("field `ring`: missing"),
        "{e}"
    );
    let e = map(
        "typed",
        Hostile {
            cloud_topic_type: Some(ros2::msgs::STRING),
            ..Hostile::default()
        },
        default(),
    )
    .unwrap_err();
    assert!(
        e.contains("topic /velodyne_points is of type `std_msgs/msg/String`"),
        "{e}"
    );
    let e = map(
        "poseless",
        Hostile {
            no_tf: true,
            ..Hostile::default()
        },
        default(),
    )
    .unwrap_err();
    assert!(e.contains("no poses"), "{e}");
    let e = map(
        "elsewhere",
        Hostile::default(),
        sim::rosbag::BagMapOptions {
            cloud_topic: "/points".into(),
            ..default()
        },
    )
    .unwrap_err();
    assert!(
        e.contains("no topic /points")
            && e.contains("/velodyne_points (sensor_msgs/msg/PointCloud2)"),
        "{e}"
    );
    let e = map(
        "odometry",
        Hostile::default(),
        sim::rosbag::BagMapOptions {
            pose_source: sim::rosbag::PoseSource::Odom("/odom".into()),
            ..default()
        },
    )
    .unwrap_err();
    assert!(e.contains("no topic /odom"), "{e}");
}

/// A bag cut short, and a firing count no sensor has, are located errors too.
#[test]
fn a_truncated_bag_and_a_bad_column_count_are_located_errors() {
    let dir = tempfile::tempdir().unwrap();
    let sound = dir.path().join("sound.mcap");
    hostile_bag(&sound, Hostile::default());
    let columns = sim::rosbag::BagMapOptions {
        columns: Some(0),
        ..sim::rosbag::BagMapOptions::default()
    };
    let e = map_bag(&sound, &columns).unwrap_err();
    assert!(e.contains("--columns 0"), "{e}");
    let bytes = std::fs::read(&sound).unwrap();
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let e = map_bag(&cut, &sim::rosbag::BagMapOptions::default()).unwrap_err();
    assert!(e.contains("cut.mcap") && e.contains("truncated"), "{e}");
}
