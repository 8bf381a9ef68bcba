//! Point clouds through a bag, as a recorder and a mapper use them: Velodyne clouds written with
//! `BagWriter` (empty, small, larger than a chunk, with returns missing) read back with
//! `BagReader` and `read_cloud`, point for point.

use ros2::msgs::{self, Time, VelodynePoint};
use ros2::{BagReader, BagWriter, Qos, read_cloud};

use crate::common::{T0, cloud_points};

/// Clouds of 0, 5, 70 000 (1.5 MB: more than an MCAP chunk) and 1 000 points, the last two
/// with every 97th point without a return (NaN), in two frames, read back from the bag: stamp,
/// frame, size, the fields the driver declares, and every point's x, y, z, intensity, ring and
/// time exactly (NaN where NaN was written).
#[test]
fn point_clouds_in_a_bag_read_back_point_for_point() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("clouds.mcap");
    let sizes = [0, 5, 70_000, 1_000];
    let frames = ["velodyne", "lidar_top"];
    let clouds: Vec<Vec<VelodynePoint>> = sizes
        .iter()
        .enumerate()
        .map(|(k, &n)| cloud_points(k as u64, n))
        .collect();
    let stamp = |k: usize| T0 + k as u64 * 100_000_007;
    let mut bag = BagWriter::create(&file).expect("a bag");
    let topic = bag
        .add_topic("/velodyne_points", msgs::POINT_CLOUD2, Qos::Stream)
        .unwrap();
    for (k, points) in clouds.iter().enumerate() {
        let cdr = msgs::velodyne_cloud(Time::from_ns(stamp(k)), frames[k % 2], points);
        bag.write(topic, stamp(k), &cdr).unwrap();
    }
    let summary = bag.finish().unwrap();
    assert_eq!(summary.topics, [("/velodyne_points".to_string(), 4)]);

    let mut read = 0;
    BagReader::open(&file)
        .unwrap()
        .read(&|_| true, &mut |m| {
            let k = usize::try_from(m.index).unwrap();
            assert_eq!(m.type_name, "sensor_msgs/msg/PointCloud2");
            let c = read_cloud(m.data).unwrap();
            let want = &clouds[k];
            let head = (c.stamp_ns, c.frame_id.as_str(), c.height, c.width);
            assert_eq!(head, (stamp(k), frames[k % 2], 1, want.len() as u32));
            let fields: Vec<_> = c.fields.iter().map(|f| f.name.as_str()).collect();
            assert_eq!(fields, ["x", "y", "z", "intensity", "ring", "time"]);
            let (intensity, ring, time) = (
                c.intensity.as_ref().unwrap(),
                c.ring.as_ref().unwrap(),
                c.time.as_ref().unwrap(),
            );
            assert_eq!(c.xyz.len(), want.len());
            for (i, p) in want.iter().enumerate() {
                let same = c.xyz[i]
                    .iter()
                    .zip(p.xyz)
                    .all(|(a, b)| *a == f64::from(b) || (a.is_nan() && b.is_nan()));
                assert!(same, "cloud {k} point {i}: {:?} {p:?}", c.xyz[i]);
                let rest = (intensity[i], ring[i], time[i]);
                assert_eq!(rest, (f64::from(p.intensity), p.ring, f64::from(p.time)));
            }
            let missing = c
                .xyz
                .iter()
                .filter(|p| p.iter().any(|v| v.is_nan()))
                .count();
            assert_eq!(missing, want.len() / 97, "cloud {k}");
            read += 1;
            Ok(())
        })
        .unwrap();
    assert_eq!(read, clouds.len());
}
