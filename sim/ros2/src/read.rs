//! Reading a bag: an MCAP file, or a rosbag2 directory (its `*.mcap` files in name order),
//! streamed from disk record by record (`mcap::sans_io::LinearReader`; chunks decompressed
//! here, bounded: memory holds one chunk, whatever the bag's size). Messages come in file order with their topic, type and index on
//! their topic, so an error can say which message it is about.

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::error::BagError;

/// One message as read.
#[derive(Debug, Clone, Copy)]
pub struct BagMessage<'a> {
    /// The file it is in.
    pub file: &'a Path,
    /// Its topic.
    pub topic: &'a str,
    /// Its type as the schema names it (`sensor_msgs/msg/PointCloud2`), empty when none.
    pub type_name: &'a str,
    /// Its channel's message encoding (`cdr` for ROS 2).
    pub encoding: &'a str,
    /// Its index among its topic's messages (0 first), over all the bag's files.
    pub index: u64,
    /// When it was logged, nanoseconds.
    pub log_time_ns: u64,
    /// Its bytes.
    pub data: &'a [u8],
}

/// A topic of a bag and how many messages it has.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicInfo {
    /// The topic.
    pub name: String,
    /// Its type (the schema's name).
    pub type_name: String,
    /// Messages on it.
    pub count: u64,
}

/// A bag to read: its MCAP files.
#[derive(Debug, Clone)]
pub struct BagReader {
    files: Vec<PathBuf>,
}

impl BagReader {
    /// The bag at `path`: an `.mcap` file, or a directory holding one or more (a rosbag2 bag).
    ///
    /// # Errors
    /// The path does not exist, or a directory holds no `.mcap` file.
    pub fn open(path: &Path) -> Result<Self, BagError> {
        let io = |source| BagError::Io {
            path: path.to_path_buf(),
            source,
        };
        let meta = std::fs::metadata(path).map_err(io)?;
        let files = if meta.is_dir() {
            let mut files: Vec<PathBuf> = std::fs::read_dir(path)
                .map_err(io)?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
                .collect();
            files.sort();
            if files.is_empty() {
                return Err(BagError::Read {
                    path: path.to_path_buf(),
                    at: String::new(),
                    what: "a directory with no .mcap file (taxi-sim reads MCAP bags only)".into(),
                });
            }
            files
        } else {
            vec![path.to_path_buf()]
        };
        Ok(Self { files })
    }

    /// Its MCAP files.
    #[must_use]
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// Every topic with its type and message count, in the order first seen.
    ///
    /// # Errors
    /// As [`BagReader::read`].
    pub fn topics(&self) -> Result<Vec<TopicInfo>, BagError> {
        let mut topics: Vec<TopicInfo> = Vec::new();
        self.read(&|_| true, &mut |m| {
            match topics.iter_mut().find(|t| t.name == m.topic) {
                Some(t) => t.count += 1,
                None => topics.push(TopicInfo {
                    name: m.topic.to_string(),
                    type_name: m.type_name.to_string(),
                    count: 1,
                }),
            }
            Ok(())
        })?;
        Ok(topics)
    }

    /// Calls `f` with every message of the topics `wanted` accepts, in file order.
    ///
    /// # Errors
    /// A file cannot be read, is not MCAP, ends inside a record (truncated: the error says after
    /// which message), or `f` fails.
    pub fn read(
        &self,
        wanted: &dyn Fn(&str) -> bool,
        f: &mut dyn FnMut(&BagMessage<'_>) -> Result<(), BagError>,
    ) -> Result<(), BagError> {
        let mut counts: HashMap<String, u64> = HashMap::new();
        for file in &self.files {
            read_file(file, wanted, &mut counts, f)?;
        }
        Ok(())
    }
}

/// A channel as declared: topic, type, encoding.
struct Channel {
    topic: String,
    type_name: String,
    encoding: String,
}

/// The state of one file's read: schemas and channels as declared, messages per topic so far,
/// the last message read (for errors: "after message 41 of /velodyne_points").
struct FileState<'f> {
    file: &'f Path,
    schemas: HashMap<u16, String>,
    channels: HashMap<u16, Channel>,
    last: Option<(String, u64)>,
}

impl FileState<'_> {
    fn error(&self, what: String) -> BagError {
        BagError::Read {
            path: self.file.to_path_buf(),
            at: match &self.last {
                Some((topic, index)) => format!("after message {index} of {topic}: "),
                None => "before its first message: ".into(),
            },
            what,
        }
    }

    /// One record (of the file, or of a chunk).
    fn record(
        &mut self,
        opcode: u8,
        data: &[u8],
        limit: usize,
        counts: &mut HashMap<String, u64>,
        wanted: &dyn Fn(&str) -> bool,
        f: &mut dyn FnMut(&BagMessage<'_>) -> Result<(), BagError>,
    ) -> Result<(), BagError> {
        let record = mcap::parse_record(opcode, data).map_err(|e| self.error(describe(&e)))?;
        match record {
            Record::Schema { header, .. } => {
                self.schemas.insert(header.id, header.name);
            }
            Record::Channel(c) => {
                let type_name = self.schemas.get(&c.schema_id).cloned().unwrap_or_default();
                let channel = Channel {
                    topic: c.topic,
                    type_name,
                    encoding: c.message_encoding,
                };
                self.channels.insert(c.id, channel);
            }
            Record::Message { header, data } => {
                let Some(channel) = self.channels.get(&header.channel_id) else {
                    let what = format!("a message on channel {} never declared", header.channel_id);
                    return Err(self.error(what));
                };
                let count = counts.entry(channel.topic.clone()).or_insert(0);
                let index = *count;
                *count += 1;
                if wanted(&channel.topic) {
                    f(&BagMessage {
                        file: self.file,
                        topic: &channel.topic,
                        type_name: &channel.type_name,
                        encoding: &channel.encoding,
                        index,
                        log_time_ns: header.log_time,
                        data: &data,
                    })?;
                }
                self.last = Some((channel.topic.clone(), index));
            }
            Record::Chunk { header, data } => {
                let body = decompress_chunk(&header, &data, limit).map_err(|w| self.error(w))?;
                let mut at = 0;
                while at < body.len() {
                    let Some(head) = body.get(at..at + 9) else {
                        return Err(self.error("a chunk ends inside a record".into()));
                    };
                    let len = u64::from_le_bytes(head[1..9].try_into().unwrap_or([0xff; 8]));
                    let end = usize::try_from(len)
                        .ok()
                        .and_then(|len| (at + 9).checked_add(len))
                        .filter(|&end| end <= body.len());
                    let Some(end) = end else {
                        return Err(self.error(format!("a chunk's record claims {len} bytes")));
                    };
                    // A chunk holds schemas, channels and messages (the MCAP spec): a chunk in
                    // a chunk would be followed without end.
                    if head[0] == mcap::records::op::CHUNK {
                        return Err(self.error("a chunk inside a chunk".into()));
                    }
                    self.record(head[0], &body[at + 9..end], limit, counts, wanted, f)?;
                    at = end;
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// The largest chunk read, uncompressed (rosbag2 writes chunks of a few MB).
const MAX_CHUNK: usize = 1 << 30;

/// A chunk's records: decompressed here (at most `limit` bytes, the size and CRC its header
/// gives checked) - not by the MCAP reader, whose LZ4 loop spins forever on some corrupt chunks.
fn decompress_chunk(
    header: &mcap::records::ChunkHeader,
    data: &[u8],
    limit: usize,
) -> Result<Vec<u8>, String> {
    let size = usize::try_from(header.uncompressed_size)
        .ok()
        .filter(|&n| n <= limit.min(MAX_CHUNK))
        .ok_or_else(|| format!("a chunk of {} bytes uncompressed", header.uncompressed_size))?;
    let mut body = Vec::new();
    body.try_reserve_exact(size)
        .map_err(|e| format!("a chunk of {size} bytes uncompressed: {e}"))?;
    let bounded = |r: &mut dyn Read, body: &mut Vec<u8>| {
        r.take(size as u64 + 1).read_to_end(body).map_err(|e| {
            format!(
                "a {} chunk that does not decompress: {e}",
                header.compression
            )
        })
    };
    match header.compression.as_str() {
        "" => body.extend_from_slice(data),
        "lz4" => {
            let mut d = lz4::Decoder::new(data).map_err(|e| format!("lz4: {e}"))?;
            bounded(&mut d, &mut body)?;
        }
        "zstd" => {
            let mut d = zstd::stream::read::Decoder::new(data).map_err(|e| format!("zstd: {e}"))?;
            bounded(&mut d, &mut body)?;
        }
        other => {
            return Err(format!(
                "a chunk compressed with `{other}` (lz4, zstd or none)"
            ));
        }
    }
    if body.len() != size {
        return Err(format!(
            "a chunk of {} bytes where its header says {size}",
            body.len()
        ));
    }
    if header.uncompressed_crc != 0 && crc32fast::hash(&body) != header.uncompressed_crc {
        return Err("a chunk whose CRC does not match".into());
    }
    Ok(body)
}

fn read_file(
    file: &Path,
    wanted: &dyn Fn(&str) -> bool,
    counts: &mut HashMap<String, u64>,
    f: &mut dyn FnMut(&BagMessage<'_>) -> Result<(), BagError>,
) -> Result<(), BagError> {
    let mut input = std::fs::File::open(file).map_err(|source| BagError::Io {
        path: file.to_path_buf(),
        source,
    })?;
    // No record is longer than the file, nor a record in a compressed chunk than 64 MiB or the
    // file (a 128-beam cloud is ~13 MB): a corrupt length is refused, not allocated.
    let file_len = input.metadata().map_or(0, |m| m.len());
    let limit = usize::try_from(file_len)
        .unwrap_or(usize::MAX)
        .max(64 << 20);
    let mut position = 0u64;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_record_length_limit(limit)
            .with_emit_chunks(true),
    );
    let mut state = FileState {
        file,
        schemas: HashMap::new(),
        channels: HashMap::new(),
        last: None,
    };
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| state.error(describe(&e)))? {
            LinearReadEvent::ReadRequest(need) => {
                // Never more than the file has left (a corrupt length asks for more).
                let left = usize::try_from(file_len.saturating_sub(position)).unwrap_or(usize::MAX);
                let n = input
                    .read(reader.insert(need.min(left.max(1))))
                    .map_err(|source| BagError::Io {
                        path: file.to_path_buf(),
                        source,
                    })?;
                reader.notify_read(n);
                position += n as u64;
            }
            LinearReadEvent::Record { data, opcode } => {
                state.record(opcode, data, limit, counts, wanted, f)?;
            }
        }
    }
    Ok(())
}

fn describe(e: &mcap::McapError) -> String {
    match e {
        mcap::McapError::UnexpectedEof => {
            "the file ends inside a record (truncated: a recorder stopped before closing it?)"
                .into()
        }
        other => format!("not a readable MCAP file: {other}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::{self, Pose, Time, Transform};
    use crate::{BagWriter, Qos};

    const T0: u64 = 1_704_067_200_000_000_000;

    /// A bag of 40 transforms and 40 odometry messages, the transforms each with its own pose.
    fn write_bag(file: &Path) {
        let mut bag = BagWriter::create(file).unwrap();
        let tf = bag.add_topic("/tf", msgs::TF_MESSAGE, Qos::Stream).unwrap();
        let odom = bag.add_topic("/odom", msgs::ODOMETRY, Qos::Stream).unwrap();
        for k in 0..40u64 {
            let ns = T0 + k * 100_000_000;
            let pose = Pose::planar(k as f64, -(k as f64) / 2.0, 0.5, k as f64 * 0.1);
            let t = Transform {
                stamp: Time::from_ns(ns),
                parent: "odom".into(),
                child: "base_link".into(),
                pose,
            };
            bag.write(tf, ns, &msgs::tf_message(&[t])).unwrap();
            let o = msgs::odometry(
                Time::from_ns(ns),
                "odom",
                "base_link",
                &pose,
                &[0.0; 36],
                [[0.0; 3]; 2],
            );
            bag.write(odom, ns, &o).unwrap();
        }
        bag.finish().unwrap();
    }

    /// What was written reads back: topics, types, counts, indices, stamps and poses, from the
    /// file or from its directory.
    #[test]
    fn a_bag_reads_back_message_for_message() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("run.mcap");
        write_bag(&file);
        for path in [file.as_path(), dir.path()] {
            let bag = BagReader::open(path).unwrap();
            let topics = bag.topics().unwrap();
            assert_eq!(
                topics,
                [
                    TopicInfo {
                        name: "/tf".into(),
                        type_name: "tf2_msgs/msg/TFMessage".into(),
                        count: 40
                    },
                    TopicInfo {
                        name: "/odom".into(),
                        type_name: "nav_msgs/msg/Odometry".into(),
                        count: 40
                    },
                ]
            );
        }
        let mut seen = 0;
        BagReader::open(&file)
            .unwrap()
            .read(&|t| t == "/tf", &mut |m| {
                assert_eq!((m.topic, m.index, m.encoding), ("/tf", seen, "cdr"));
                assert_eq!(m.log_time_ns, T0 + seen * 100_000_000);
                let t = msgs::read_tf_message(m.data).unwrap();
                assert_eq!(t.len(), 1);
                assert_eq!(
                    (t[0].parent.as_str(), t[0].child.as_str()),
                    ("odom", "base_link")
                );
                assert_eq!(t[0].stamp.ns(), m.log_time_ns);
                let expect =
                    Pose::planar(seen as f64, -(seen as f64) / 2.0, 0.5, seen as f64 * 0.1);
                assert_eq!(t[0].pose.position, expect.position);
                for (a, b) in t[0].pose.orientation.iter().zip(expect.orientation) {
                    assert!((a - b).abs() < 1e-15);
                }
                seen += 1;
                Ok(())
            })
            .unwrap();
        assert_eq!(seen, 40);
    }

    /// A bag cut short (a recorder killed) is an error that says after which message it broke;
    /// a directory without a bag and a file that is not MCAP are errors naming the path.
    #[test]
    fn a_truncated_bag_says_after_which_message_it_ends() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("run.mcap");
        write_bag(&file);
        let bytes = std::fs::read(&file).unwrap();
        let cut = dir.path().join("cut.mcap");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let mut read = 0;
        let e = BagReader::open(&cut)
            .unwrap()
            .read(&|_| true, &mut |_| {
                read += 1;
                Ok(())
            })
            .unwrap_err()
            .to_string();
        assert!(e.contains("cut.mcap") && e.contains("truncated"), "{e}");
        assert!(
            e.contains("after message") || e.contains("before its first message"),
            "{e}"
        );
        let empty = tempfile::tempdir().unwrap();
        let e = BagReader::open(empty.path()).unwrap_err().to_string();
        assert!(e.contains("no .mcap file"), "{e}");
        let junk = dir.path().join("junk.mcap");
        std::fs::write(&junk, b"not a bag at all, just some text").unwrap();
        let e = BagReader::open(&junk)
            .unwrap()
            .topics()
            .unwrap_err()
            .to_string();
        assert!(e.contains("junk.mcap") && e.contains("MCAP"), "{e}");
    }

    /// Chunks as other recorders write them - zstd (rosbag2's default preset), uncompressed,
    /// unchunked - read the same.
    #[test]
    fn zstd_and_uncompressed_chunks_read_the_same() {
        let dir = tempfile::tempdir().unwrap();
        let options = [
            (Some(mcap::Compression::Zstd), true),
            (None, true),
            (None, false),
        ];
        for (k, (compression, chunks)) in options.into_iter().enumerate() {
            let file = dir.path().join(format!("{k}.mcap"));
            let mut w = mcap::WriteOptions::new()
                .compression(compression)
                .use_chunks(chunks)
                .profile("ros2")
                .create(std::io::BufWriter::new(
                    std::fs::File::create(&file).unwrap(),
                ))
                .unwrap();
            let schema = w
                .add_schema(
                    "rosgraph_msgs/msg/Clock",
                    "ros2msg",
                    b"builtin_interfaces/Time clock",
                )
                .unwrap();
            let channel = w
                .add_channel(schema, "/clock", "cdr", &Default::default())
                .unwrap();
            for i in 0..100u64 {
                let ns = T0 + i * 1000;
                let header = mcap::records::MessageHeader {
                    channel_id: channel,
                    sequence: i as u32,
                    log_time: ns,
                    publish_time: ns,
                };
                w.write_to_known_channel(&header, &msgs::clock(Time::from_ns(ns)))
                    .unwrap();
            }
            w.finish().unwrap();
            drop(w);
            let topics = BagReader::open(&file).unwrap().topics().unwrap();
            assert_eq!(topics.len(), 1, "{compression:?} {chunks}");
            assert_eq!((topics[0].name.as_str(), topics[0].count), ("/clock", 100));
        }
    }

    /// A transform whose quaternion is not of unit length is refused naming the field.
    #[test]
    fn a_transform_with_a_bad_quaternion_is_refused() {
        let t = Transform {
            stamp: Time::from_ns(T0),
            parent: "map".into(),
            child: "odom".into(),
            pose: Pose {
                position: [0.0; 3],
                orientation: [0.0, 0.0, 0.0, 2.0],
            },
        };
        let e = msgs::read_tf_message(&msgs::tf_message(&[t])).unwrap_err();
        assert_eq!(e.field, "transform");
    }
}
