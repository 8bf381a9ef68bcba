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
}
