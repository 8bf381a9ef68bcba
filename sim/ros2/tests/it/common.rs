//! What the tests share: a run's bag written with the kinds of message a run writes (the
//! messages kept as written, to compare with what is read back), and a bag read whole.

use std::path::Path;

use ros2::msgs::{self, MsgType, Pose, Time, Transform, VelodynePoint};
use ros2::{BagError, BagReader, BagSummary, BagWriter, Qos};

/// The first stamp: 2024-01-01 00:00 UTC, nanoseconds.
pub(crate) const T0: u64 = 1_704_067_200_000_000_000;

/// The run's topics, in the order they are added (`/unused` gets no message).
pub(crate) const TOPICS: [(&str, MsgType, Qos); 7] = [
    ("/clock", msgs::CLOCK, Qos::Stream),
    ("/tf_static", msgs::TF_MESSAGE, Qos::Latched),
    ("/tf", msgs::TF_MESSAGE, Qos::Stream),
    ("/odom", msgs::ODOMETRY, Qos::Stream),
    ("/velodyne_points", msgs::POINT_CLOUD2, Qos::Stream),
    ("/events", msgs::STRING, Qos::Latched),
    ("/unused", msgs::STRING, Qos::Stream),
];

/// The events the run writes: one at 0.5 s, and one written last but stamped 1 ms before
/// everything else.
pub(crate) const EVENTS: [&str; 2] = ["{\"stop\":1}", "{\"note\":\"late\"}"];

/// One message as written, or as read back.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Message {
    pub(crate) topic: String,
    pub(crate) type_name: String,
    pub(crate) index: u64,
    pub(crate) log_time_ns: u64,
    pub(crate) data: Vec<u8>,
}

/// A small deterministic generator (xorshift64*), so every bag is the same bag.
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }

    /// Uniform in [0, 1).
    pub(crate) fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The vehicle's pose at its `k`th odometry message.
pub(crate) fn pose_at(k: u64) -> Pose {
    Pose::planar(0.5 * k as f64, -0.25 * k as f64, 0.0, 0.01 * k as f64)
}

/// The map-to-odom transform every `/tf` message starts with.
pub(crate) fn map_from_odom() -> Pose {
    Pose::planar(1.0, 2.0, 0.0, 0.1)
}

/// The `k`th cloud of `n` points: scattered, every 97th point without a return (NaN).
pub(crate) fn cloud_points(k: u64, n: usize) -> Vec<VelodynePoint> {
    let mut rng = Rng::new(k + 1);
    (0..n)
        .map(|i| {
            let mut xyz = [0f32; 3];
            for v in &mut xyz {
                *v = (200.0 * rng.unit() - 100.0) as f32;
            }
            if i % 97 == 96 {
                xyz = [f32::NAN; 3];
            }
            VelodynePoint {
                xyz,
                intensity: (255.0 * rng.unit()).round() as f32,
                ring: (i % 32) as u16,
                time: (0.1 * rng.unit()) as f32,
            }
        })
        .collect()
}

/// The messages of a run of 1 s at 100 Hz, in the order they are written: `(topic index in
/// [`TOPICS`], stamp, CDR)`. Clouds of `points` points at 8.3 Hz.
fn run_messages(points: usize) -> Vec<(usize, u64, Vec<u8>)> {
    let mut out = Vec::new();
    let (mut tf, mut odom, mut cloud) = (0, 0, 0);
    let transform = |stamp, parent: &str, child: &str, pose| Transform {
        stamp,
        parent: parent.into(),
        child: child.into(),
        pose,
    };
    for k in 0..100u64 {
        let ns = T0 + k * 10_000_000;
        let stamp = Time::from_ns(ns);
        if k == 0 {
            let mount = transform(
                stamp,
                "base_link",
                "velodyne",
                Pose::planar(1.2, 0.0, 1.9, 0.0),
            );
            out.push((1, ns, msgs::tf_message(&[mount])));
        }
        out.push((0, ns, msgs::clock(stamp)));
        if k % 5 == 0 {
            let tfs = [
                transform(stamp, "map", "odom", map_from_odom()),
                transform(stamp, "odom", "base_link", pose_at(tf)),
            ];
            out.push((2, ns, msgs::tf_message(&tfs)));
            tf += 1;
            let covariance: [f64; 36] = std::array::from_fn(|i| i as f64 * 0.01);
            let twist = [[1.5, 0.0, 0.0], [0.0, 0.0, 0.02]];
            let o = msgs::odometry(
                stamp,
                "odom",
                "base_link",
                &pose_at(odom),
                &covariance,
                twist,
            );
            out.push((3, ns, o));
            odom += 1;
        }
        if k % 12 == 0 {
            let c = msgs::velodyne_cloud(stamp, "velodyne", &cloud_points(cloud, points));
            out.push((4, ns, c));
            cloud += 1;
        }
        if k == 50 {
            out.push((5, ns, msgs::string(EVENTS[0])));
        }
    }
    out.push((5, T0 - 1_000_000, msgs::string(EVENTS[1])));
    out
}

/// Writes the run's bag to `file` (clouds of `points` points): its summary and every message
/// as written.
pub(crate) fn run_bag(file: &Path, points: usize) -> (BagSummary, Vec<Message>) {
    let mut bag = BagWriter::create(file).expect("a bag");
    let ids: Vec<_> = TOPICS
        .iter()
        .map(|(name, msg, qos)| bag.add_topic(name, *msg, *qos).unwrap())
        .collect();
    let mut counts = [0u64; TOPICS.len()];
    let mut written = Vec::new();
    for (t, ns, data) in run_messages(points) {
        bag.write(ids[t], ns, &data).unwrap();
        written.push(Message {
            topic: TOPICS[t].0.to_string(),
            type_name: TOPICS[t].1.name.to_string(),
            index: counts[t],
            log_time_ns: ns,
            data,
        });
        counts[t] += 1;
    }
    (bag.finish().unwrap(), written)
}

/// Every message of the bag at `path` read, and how the read ended.
pub(crate) fn read_all(path: &Path) -> (Vec<Message>, Result<(), BagError>) {
    let bag = match BagReader::open(path) {
        Ok(bag) => bag,
        Err(e) => return (Vec::new(), Err(e)),
    };
    let mut read = Vec::new();
    let result = bag.read(&|_| true, &mut |m| {
        assert!(
            m.file == path || m.file.parent() == Some(path),
            "{}",
            m.file.display()
        );
        assert_eq!(m.encoding, "cdr");
        read.push(Message {
            topic: m.topic.to_string(),
            type_name: m.type_name.to_string(),
            index: m.index,
            log_time_ns: m.log_time_ns,
            data: m.data.to_vec(),
        });
        Ok(())
    });
    (read, result)
}
