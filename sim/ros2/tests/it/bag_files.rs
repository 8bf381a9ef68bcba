//! Bags written to disk and read back: every message as written (topic, type, index, stamp,
//! bytes, decoded payload), from the file or from its directory; the `metadata.yaml` beside it;
//! a bag in several files; a bag written on its own thread and dropped unfinished; the caller's
//! error; paths that cannot be written or read.

use ros2::cdr::CdrReader;
use ros2::msgs::{self, Pose};
use ros2::{BagError, BagReader, BagThread, BagWriter, Qos, TopicInfo, read_cloud};

use crate::common::{
    EVENTS, Message, T0, TOPICS, cloud_points, map_from_odom, pose_at, read_all, run_bag,
};

/// Two poses equal but for rounding (a reader normalises the quaternion).
fn assert_pose(got: &Pose, want: &Pose, what: &str) {
    let got_all = got.position.iter().chain(&got.orientation);
    let want_all = want.position.iter().chain(&want.orientation);
    for (a, b) in got_all.zip(want_all) {
        assert!((a - b).abs() < 1e-12, "{what}: {got:?} != {want:?}");
    }
}

/// A message's payload decoded and checked against what the run wrote for it (clouds of
/// `points` points).
fn check_payload(m: &Message, points: usize) {
    let what = format!("{} message {}", m.topic, m.index);
    match m.topic.as_str() {
        "/clock" => {
            let mut r = CdrReader::new(&m.data).unwrap();
            let sec = r.i32("clock.sec").unwrap();
            let nanosec = r.u32("clock.nanosec").unwrap();
            assert_eq!(msgs::Time { sec, nanosec }.ns(), m.log_time_ns, "{what}");
        }
        "/tf_static" => {
            let t = msgs::read_tf_message(&m.data).unwrap();
            let frames: Vec<_> = t
                .iter()
                .map(|t| (t.parent.as_str(), t.child.as_str()))
                .collect();
            assert_eq!(frames, [("base_link", "velodyne")], "{what}");
        }
        "/tf" => {
            let t = msgs::read_tf_message(&m.data).unwrap();
            let frames: Vec<_> = t
                .iter()
                .map(|t| (t.parent.as_str(), t.child.as_str()))
                .collect();
            assert_eq!(frames, [("map", "odom"), ("odom", "base_link")], "{what}");
            assert!(t.iter().all(|t| t.stamp.ns() == m.log_time_ns), "{what}");
            assert_pose(&t[0].pose, &map_from_odom(), &what);
            assert_pose(&t[1].pose, &pose_at(m.index), &what);
        }
        "/odom" => {
            let o = msgs::read_odometry(&m.data).unwrap();
            let head = (o.parent.as_str(), o.child.as_str(), o.stamp.ns());
            assert_eq!(head, ("odom", "base_link", m.log_time_ns), "{what}");
            assert_pose(&o.pose, &pose_at(m.index), &what);
        }
        "/velodyne_points" => {
            let c = read_cloud(&m.data).unwrap();
            let head = (c.stamp_ns, c.frame_id.as_str(), c.xyz.len());
            assert_eq!(head, (m.log_time_ns, "velodyne", points), "{what}");
            for (got, p) in c.xyz.iter().zip(cloud_points(m.index, points)) {
                let same = got
                    .iter()
                    .zip(p.xyz)
                    .all(|(a, b)| *a == f64::from(b) || (a.is_nan() && b.is_nan()));
                assert!(same, "{what}: {got:?} {p:?}");
            }
        }
        "/events" => {
            let text = CdrReader::new(&m.data).unwrap().string("data").unwrap();
            assert_eq!(text, EVENTS[m.index as usize], "{what}");
        }
        other => panic!("a message on {other}"),
    }
}

/// A run's bag (six topics of five standard types, 152 messages, one stamped before the others
/// but written last) reads back as written, in the order written, from the `.mcap` file or from
/// its directory: topic, type, index on its topic, stamp, bytes, and each payload decoded.
#[test]
fn a_runs_bag_reads_back_message_for_message() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.mcap");
    let (_, written) = run_bag(&file, 300);
    for path in [file.as_path(), dir.path()] {
        let (read, result) = read_all(path);
        result.unwrap();
        assert_eq!(read.len(), written.len(), "{}", path.display());
        // Not assert_eq: a difference would print megabytes.
        assert!(read == written, "{} reads back otherwise", path.display());
        read.iter().for_each(|m| check_payload(m, 300));
    }
    // The topics in the order first written, with their types and counts; `/unused` has none.
    let topics = BagReader::open(&file).unwrap().topics().unwrap();
    let counts = [
        ("/tf_static", 1),
        ("/clock", 100),
        ("/tf", 20),
        ("/odom", 20),
        ("/velodyne_points", 9),
        ("/events", 2),
    ];
    let want: Vec<TopicInfo> = counts
        .iter()
        .map(|&(name, count)| TopicInfo {
            name: name.to_string(),
            type_name: TOPICS.iter().find(|t| t.0 == name).unwrap().1.name.into(),
            count,
        })
        .collect();
    assert_eq!(topics, want);
    // Only the topics asked for, each message with its index among all of its topic's.
    let wanted = |t: &str| t == "/odom" || t == "/events";
    let mut some = Vec::new();
    BagReader::open(&file)
        .unwrap()
        .read(&wanted, &mut |m| {
            some.push((m.topic.to_string(), m.index, m.log_time_ns));
            Ok(())
        })
        .unwrap();
    let want: Vec<_> = written
        .iter()
        .filter(|m| wanted(&m.topic))
        .map(|m| (m.topic.clone(), m.index, m.log_time_ns))
        .collect();
    assert_eq!(some, want);
    // File order, not stamp order: the late event comes last.
    assert_eq!(
        some.last(),
        Some(&("/events".to_string(), 1, T0 - 1_000_000))
    );
}

/// The `[name, type, type hash, QoS, count]` of each topic `metadata.yaml` lists, in its order.
fn yaml_topics(yaml: &str) -> Vec<[String; 5]> {
    let start = yaml
        .find("  topics_with_message_count:\n")
        .expect("a topic list");
    let end = yaml
        .find("  compression_format:")
        .expect("a compression format");
    let mut out: Vec<[String; 5]> = Vec::new();
    for line in yaml[start..end].lines().skip(1) {
        let t = line.trim_start();
        if t == "- topic_metadata:" {
            out.push(Default::default());
            continue;
        }
        let (key, value) = t.split_once(": ").unwrap_or((t, ""));
        let slot = match key {
            "name" => 0,
            "type" => 1,
            "type_description_hash" => 2,
            "offered_qos_profiles" => 3,
            "message_count" => 4,
            _ => continue,
        };
        out.last_mut().expect("a topic first")[slot] = value.to_string();
    }
    out
}

/// A finished bag has its `metadata.yaml` beside the `.mcap` (not in the working directory),
/// naming every topic added - with its type, type hash, QoS and count, the one never written
/// too - the first stamp (the earliest, not the first written), the duration and the file; the
/// summary says the same; no temporary file is left.
#[test]
fn metadata_yaml_beside_the_bag_names_every_topic_and_its_count() {
    let dir = tempfile::tempdir().unwrap();
    let bag_dir = dir.path().join("recorded");
    std::fs::create_dir(&bag_dir).unwrap();
    let file = bag_dir.join("run.mcap");
    let (summary, written) = run_bag(&file, 50);
    let counts = [100u64, 1, 20, 20, 9, 2, 0];
    let total: u64 = counts.iter().sum();
    assert_eq!(total, written.len() as u64);
    assert_eq!(summary.file, file);
    assert_eq!(summary.bytes, std::fs::metadata(&file).unwrap().len());
    let names: Vec<(String, u64)> = TOPICS.iter().map(|t| t.0.to_string()).zip(counts).collect();
    assert_eq!(summary.topics, names);
    let mut listed: Vec<_> = std::fs::read_dir(&bag_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    listed.sort();
    assert_eq!(listed, ["metadata.yaml", "run.mcap"]);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    let yaml = std::fs::read_to_string(bag_dir.join("metadata.yaml")).unwrap();
    let topics = yaml_topics(&yaml);
    assert_eq!(topics.len(), TOPICS.len(), "{yaml}");
    for ((got, (name, msg, qos)), count) in topics.iter().zip(TOPICS).zip(counts) {
        assert_eq!(
            [&got[0], &got[1], &got[2]],
            [name, msg.name, msg.hash],
            "{yaml}"
        );
        assert_eq!(got[4], count.to_string(), "{name}");
        let (depth, durability) = match qos {
            Qos::Stream => (10, 2),
            Qos::Latched => (1, 1),
        };
        let profile = format!(
            "\"- history: 1\\n  depth: {depth}\\n  reliability: 1\\n  durability: {durability}\\n"
        );
        assert!(got[3].starts_with(&profile), "{name}: {}", got[3]);
    }
    assert_eq!(
        yaml.matches("serialization_format: cdr\n").count(),
        TOPICS.len()
    );
    let start = T0 - 1_000_000;
    let duration = 990_000_000 + 1_000_000;
    assert!(
        yaml.starts_with(
            "rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: mcap\n"
        )
    );
    for part in [
        format!("\n  duration:\n    nanoseconds: {duration}\n"),
        format!("\n  starting_time:\n    nanoseconds_since_epoch: {start}\n"),
        format!("\n  message_count: {total}\n"),
        "\n  relative_file_paths:\n    - \"run.mcap\"\n".to_string(),
        format!(
            "\n    - path: \"run.mcap\"\n      starting_time:\n        nanoseconds_since_epoch: \
             {start}\n      duration:\n        nanoseconds: {duration}\n      message_count: {total}\n"
        ),
    ] {
        assert!(yaml.contains(&part), "{part:?} not in\n{yaml}");
    }
}

/// A rosbag2 directory of several `.mcap` files (written out of order) reads in the files'
/// name order, each topic's indices running on from one file to the next; `metadata.yaml` is
/// not taken for a bag.
#[test]
fn a_bag_in_several_files_reads_in_name_order_its_indices_running_on() {
    let dir = tempfile::tempdir().unwrap();
    for (part, range) in [(1, 30..50u64), (0, 0..30u64)] {
        let file = dir.path().join(format!("run_{part}.mcap"));
        let mut bag = BagWriter::create(&file).expect("a bag");
        let clock = bag.add_topic("/clock", msgs::CLOCK, Qos::Stream).unwrap();
        let events = bag
            .add_topic("/events", msgs::STRING, Qos::Latched)
            .unwrap();
        for k in range.clone() {
            let ns = T0 + k * 10_000_000;
            bag.write(clock, ns, &msgs::clock(msgs::Time::from_ns(ns)))
                .unwrap();
        }
        let event = msgs::string(&format!("part {part}"));
        bag.write(events, T0 + range.end * 10_000_000, &event)
            .unwrap();
        bag.finish().unwrap();
    }
    let bag = BagReader::open(dir.path()).unwrap();
    let names: Vec<_> = bag
        .files()
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["run_0.mcap", "run_1.mcap"]);
    let topics = bag.topics().unwrap();
    let counts: Vec<_> = topics.iter().map(|t| (t.name.as_str(), t.count)).collect();
    assert_eq!(counts, [("/clock", 50), ("/events", 2)]);
    let (read, result) = read_all(dir.path());
    result.unwrap();
    let clock: Vec<_> = read
        .iter()
        .filter(|m| m.topic == "/clock")
        .map(|m| (m.index, m.log_time_ns))
        .collect();
    let want: Vec<_> = (0..50u64).map(|k| (k, T0 + k * 10_000_000)).collect();
    assert_eq!(clock, want);
    let events: Vec<_> = read
        .iter()
        .filter(|m| m.topic == "/events")
        .map(|m| {
            (
                m.index,
                CdrReader::new(&m.data).unwrap().string("data").unwrap(),
            )
        })
        .collect();
    assert_eq!(
        events,
        [(0, "part 0".to_string()), (1, "part 1".to_string())]
    );
}

/// A bag handed to its own thread (the caller's preparation run there first) and dropped
/// without `finish` - a run that failed - is still closed, renamed into place and described:
/// all 1001 messages, more than its queue holds, read back in order. A topic added twice is an
/// error naming the file and the topic.
#[test]
fn a_bag_thread_dropped_unfinished_leaves_the_whole_bag() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("dropped.mcap");
    let (tx, rx) = std::sync::mpsc::channel();
    let writer = BagWriter::create(&file).expect("a bag");
    let mut bag = BagThread::spawn_with(writer, move || {
        let name = std::thread::current().name().map(str::to_owned);
        tx.send(name).unwrap();
    })
    .expect("a thread");
    let clock = bag.add_topic("/clock", msgs::CLOCK, Qos::Stream).unwrap();
    let e = bag
        .add_topic("/clock", msgs::STRING, Qos::Latched)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("dropped.mcap") && e.contains("/clock") && e.contains("added twice"),
        "{e}"
    );
    let events = bag
        .add_topic("/events", msgs::STRING, Qos::Latched)
        .unwrap();
    for k in 0..1000u64 {
        let ns = T0 + k * 1_000_000;
        bag.write(clock, ns, msgs::clock(msgs::Time::from_ns(ns)))
            .unwrap();
    }
    bag.write(events, T0, msgs::string("{\"failed\":true}"))
        .unwrap();
    drop(bag);
    assert_eq!(rx.recv().unwrap().as_deref(), Some("bag writer"));
    let (read, result) = read_all(&file);
    result.unwrap();
    assert_eq!(read.len(), 1001);
    for (k, m) in read[..1000].iter().enumerate() {
        let ns = T0 + k as u64 * 1_000_000;
        assert_eq!(
            (m.topic.as_str(), m.index, m.log_time_ns),
            ("/clock", k as u64, ns)
        );
        assert_eq!(m.data, msgs::clock(msgs::Time::from_ns(ns)));
    }
    assert_eq!(
        (read[1000].topic.as_str(), read[1000].index),
        ("/events", 0)
    );
    let yaml = std::fs::read_to_string(dir.path().join("metadata.yaml")).unwrap();
    assert!(yaml.contains("\n  message_count: 1001\n"), "{yaml}");
}

/// An error the caller's function returns stops the read there and is the read's error.
#[test]
fn the_callers_error_stops_the_read() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.mcap");
    run_bag(&file, 10);
    let mut seen = 0;
    let e = BagReader::open(&file)
        .unwrap()
        .read(&|t| t == "/odom", &mut |m| {
            seen += 1;
            if m.index < 3 {
                return Ok(());
            }
            Err(BagError::Message {
                path: m.file.to_path_buf(),
                topic: m.topic.to_string(),
                index: m.index,
                what: "a pose off the map".into(),
            })
        })
        .unwrap_err()
        .to_string();
    assert_eq!(seen, 4);
    assert!(
        e.ends_with("run.mcap: topic /odom, message 3: a pose off the map"),
        "{e}"
    );
}

/// A bag in a directory that does not exist, a bag that does not exist and a directory with no
/// `.mcap` file are errors naming the path.
#[test]
fn paths_that_cannot_be_written_or_read_are_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing");
    let e = BagWriter::create(&missing.join("run.mcap"))
        .err()
        .expect("no bag in a missing directory");
    assert!(
        matches!(&e, BagError::Io { path, .. } if path.starts_with(&missing)),
        "{e:?}"
    );
    assert!(e.to_string().contains("run.mcap"), "{e}");
    let e = BagReader::open(&dir.path().join("absent.mcap"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("absent.mcap"), "{e}");
    std::fs::write(
        dir.path().join("metadata.yaml"),
        "rosbag2_bagfile_information: {}\n",
    )
    .unwrap();
    let e = BagReader::open(dir.path()).unwrap_err().to_string();
    assert!(
        e.contains(&*dir.path().to_string_lossy()) && e.contains("no .mcap file"),
        "{e}"
    );
}
