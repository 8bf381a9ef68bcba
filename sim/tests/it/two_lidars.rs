//! A vehicle with two LiDARs in the loop (`praetor600_two_lidars`: the nose LiDAR and a VLP-16
//! low under the nose pod): each revolution carries both sensors' scans, each cast from its own
//! mount with its own beam table; the low one sees the cone the nose one cannot; the bag holds
//! each sensor's cloud on its own topic and frame; a stack over the wire is refused such a
//! vehicle, by name.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use sim::engine::{Observer, Observers, RevolutionFrame, RunHandles, RunSetup, run_with};
use sim::rosbag::RosBag;
use sim::scenario::{RunConfig, Scenario};
use sim::world::Owner;

/// Per revolution: (scans, the low sensor's beams and columns, returns on the cone from the
/// main sensor, from the low one).
#[derive(Default)]
struct Seen {
    cone: usize,
    revolutions: Vec<(usize, usize, usize, usize, usize)>,
}

impl Observer for Seen {
    fn revolution(&mut self, frame: &RevolutionFrame<'_>) -> sim::error::Result<()> {
        let on_cone = |owners: &[Option<Owner>]| {
            owners
                .iter()
                .filter(|o| **o == Some(Owner::Object(self.cone)))
                .count()
        };
        let low = &frame.revolution.more_scans[0];
        self.revolutions.push((
            frame.revolution.scans().count(),
            low.beams(),
            low.column_count(),
            on_cone(frame.owners),
            on_cone(&frame.more_owners[0]),
        ));
        Ok(())
    }
}

#[test]
fn a_second_lidar_is_cast_mapped_and_recorded_in_its_own_frame() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/jet_with_a_low_lidar_sees_the_cone_at_its_nose.toml");
    let s = Scenario::from_file(&path).unwrap();
    assert_eq!(s.vehicle.vehicle.spec.extra_lidars.len(), 1);
    let dir = tempfile::tempdir().unwrap();
    let map_dir = dir.path().join("map");
    sim::offline_map::map_drive(&s, &RunConfig::default(), &map_dir, &mut |_, _| {}).unwrap();
    let file = dir.path().join("bag").join("run.mcap");
    std::fs::create_dir_all(file.parent().unwrap()).unwrap();
    let mut bag = RosBag::create(&file).unwrap();
    let scene = s.full_scene();
    let mut seen = Seen {
        cone: scene
            .solids
            .iter()
            .position(|o| o.id == "cone_left_at_the_nose")
            .unwrap(),
        ..Seen::default()
    };
    let stop = AtomicBool::new(false);
    let report = run_with(
        &s,
        &RunSetup::new(map_dir.clone()),
        RunHandles {
            stop: Some(&stop),
            progress: &mut |p| {
                if p.sim_time_s >= 6.0 {
                    stop.store(true, Ordering::Relaxed);
                }
            },
            observer: &mut Observers(vec![&mut bag, &mut seen]),
        },
    )
    .unwrap();
    assert!(report.contacts.is_empty());
    assert!(seen.revolutions.len() >= 30, "{}", seen.revolutions.len());
    for &(scans, beams, columns, main_on_cone, low_on_cone) in &seen.revolutions {
        assert_eq!((scans, beams, columns), (2, 16, 1800));
        // The cone 1.15 m ahead of both sensors: under every beam of the nose one, in front of
        // the low one.
        assert_eq!(main_on_cone, 0);
        assert!(
            low_on_cone > 20,
            "{low_on_cone} returns of the low LiDAR on the cone"
        );
    }
    // The bag: each sensor's cloud on its own topic, as many as revolutions, in its own frame.
    let bytes = std::fs::read(&file).unwrap();
    let mut clouds = std::collections::BTreeMap::<String, usize>::new();
    let mut frames = std::collections::BTreeSet::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic.ends_with("velodyne_points") {
            *clouds.entry(m.channel.topic.clone()).or_default() += 1;
            let mut r = ros2::cdr::CdrReader::new(&m.data).unwrap();
            let (_, _) = (r.i32("sec").unwrap(), r.u32("nanosec").unwrap());
            frames.insert((m.channel.topic.clone(), r.string("frame_id").unwrap()));
        }
    }
    let n = seen.revolutions.len();
    assert_eq!(
        clouds.into_iter().collect::<Vec<_>>(),
        [
            ("/nose_low/velodyne_points".to_string(), n),
            ("/velodyne_points".to_string(), n)
        ]
    );
    assert_eq!(
        frames.into_iter().map(|(_, f)| f).collect::<Vec<_>>(),
        ["nose_low", "velodyne"]
    );
    // Over the wire, where one cloud goes out, such a vehicle is refused by name.
    let e = sim::engine::ShippedNode::new(&s, &RunSetup::new(map_dir))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("praetor600_two_lidars") && e.contains("2 LiDARs"),
        "{e}"
    );
}
