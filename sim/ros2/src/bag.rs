//! A rosbag2 bag in MCAP: the `.mcap` file (profile `ros2`, `ros2msg` schemas, CDR messages,
//! each channel's QoS in its metadata) and, beside it, the `metadata.yaml` that `ros2 bag info`
//! and `ros2 bag play` read (version 8: what Humble, Iron, Jazzy and rosbags all accept). Both
//! are written to temporary files and renamed when the bag is finished, so an interrupted run
//! leaves no half bag behind.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::error::BagError;
use crate::msgs::MsgType;

/// How a topic is offered: reliable and volatile (a stream), or transient local with depth 1
/// (`/tf_static`, maps: a late subscriber still gets the last message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Qos {
    /// Reliable, volatile, keep last 10.
    Stream,
    /// Reliable, transient local, keep last 1.
    Latched,
}

impl Qos {
    /// The `offered_qos_profiles` YAML (rmw's integer enums, as Humble writes them).
    fn yaml(self) -> String {
        let (depth, durability) = match self {
            Qos::Stream => (10, 2),
            Qos::Latched => (1, 1),
        };
        let forever = "\n    sec: 9223372036\n    nsec: 854775807";
        format!(
            "- history: 1\n  depth: {depth}\n  reliability: 1\n  durability: {durability}\n  deadline:{forever}\n  \
             lifespan:{forever}\n  liveliness: 1\n  liveliness_lease_duration:{forever}\n  \
             avoid_ros_namespace_conventions: false"
        )
    }
}

/// A topic of the bag: what [`BagWriter::add_topic`] gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopicId(usize);

impl TopicId {
    /// The `n`th topic added (0 first).
    pub(crate) fn nth(n: usize) -> Self {
        Self(n)
    }
}

#[derive(Debug)]
struct Topic {
    name: String,
    msg: MsgType,
    qos: Qos,
    channel: u16,
    count: u64,
}

/// What a finished bag holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagSummary {
    /// The `.mcap` file.
    pub file: PathBuf,
    /// Its size, bytes.
    pub bytes: u64,
    /// Messages per topic, in the order the topics were added.
    pub topics: Vec<(String, u64)>,
}

/// Writes one bag.
pub struct BagWriter {
    file: PathBuf,
    tmp: PathBuf,
    writer: mcap::Writer<BufWriter<File>>,
    topics: Vec<Topic>,
    schemas: BTreeMap<&'static str, u16>,
    first_ns: Option<u64>,
    last_ns: u64,
}

impl BagWriter {
    /// Starts the bag `file` (a `.mcap`; `metadata.yaml` goes beside it when it is finished).
    /// Chunks are lz4-compressed on the calling thread (zstd's workers would compete with the
    /// run for the cores); [`crate::BagThread`] moves the writer to a thread of its own.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(file: &Path) -> Result<Self, BagError> {
        let tmp = tmp_beside(file);
        let io = |source| BagError::Io {
            path: tmp.clone(),
            source,
        };
        let out = BufWriter::new(File::create(&tmp).map_err(io)?);
        let writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("taxi-sim ", env!("CARGO_PKG_VERSION")))
            .compression(Some(mcap::Compression::Lz4))
            .create(out)
            .map_err(|source| BagError::Mcap {
                path: tmp.clone(),
                source,
            })?;
        Ok(Self {
            file: file.to_path_buf(),
            tmp,
            writer,
            topics: Vec::new(),
            schemas: BTreeMap::new(),
            first_ns: None,
            last_ns: 0,
        })
    }

    /// The topics added so far.
    pub(crate) fn topic_names(&self) -> Vec<String> {
        self.topics.iter().map(|t| t.name.clone()).collect()
    }

    /// The file it writes (renamed into place when finished).
    #[must_use]
    pub fn file(&self) -> &Path {
        &self.file
    }

    fn mcap_error(&self, source: mcap::McapError) -> BagError {
        BagError::Mcap {
            path: self.tmp.clone(),
            source,
        }
    }

    /// Adds the topic `name` of type `msg`, offered as `qos`.
    ///
    /// # Errors
    /// The topic is there already, or MCAP refuses.
    pub fn add_topic(&mut self, name: &str, msg: MsgType, qos: Qos) -> Result<TopicId, BagError> {
        if self.topics.iter().any(|t| t.name == name) {
            return Err(BagError::Topic {
                path: self.file.clone(),
                topic: name.to_string(),
                what: "added twice".to_string(),
            });
        }
        let schema = match self.schemas.get(msg.name) {
            Some(&id) => id,
            None => {
                let id = self
                    .writer
                    .add_schema(msg.name, "ros2msg", msg.schema().as_bytes())
                    .map_err(|e| self.mcap_error(e))?;
                self.schemas.insert(msg.name, id);
                id
            }
        };
        let metadata = BTreeMap::from([
            ("offered_qos_profiles".to_string(), qos.yaml()),
            ("topic_type_hash".to_string(), msg.hash.to_string()),
        ]);
        let channel = self
            .writer
            .add_channel(schema, name, "cdr", &metadata)
            .map_err(|e| self.mcap_error(e))?;
        self.topics.push(Topic {
            name: name.to_string(),
            msg,
            qos,
            channel,
            count: 0,
        });
        Ok(TopicId(self.topics.len() - 1))
    }

    /// Writes one message (its CDR bytes) on `topic`, logged at `stamp_ns`.
    ///
    /// # Errors
    /// MCAP refuses (the disk is full).
    pub fn write(&mut self, topic: TopicId, stamp_ns: u64, cdr: &[u8]) -> Result<(), BagError> {
        let t = &mut self.topics[topic.0];
        let header = mcap::records::MessageHeader {
            channel_id: t.channel,
            sequence: u32::try_from(t.count).unwrap_or(u32::MAX),
            log_time: stamp_ns,
            publish_time: stamp_ns,
        };
        t.count += 1;
        self.first_ns = Some(self.first_ns.map_or(stamp_ns, |f| f.min(stamp_ns)));
        self.last_ns = self.last_ns.max(stamp_ns);
        self.writer
            .write_to_known_channel(&header, cdr)
            .map_err(|e| self.mcap_error(e))
    }

    /// Finishes the bag: the MCAP summary, the file renamed into place, `metadata.yaml` beside it.
    ///
    /// # Errors
    /// MCAP or the file system refuses.
    pub fn finish(mut self) -> Result<BagSummary, BagError> {
        self.writer.finish().map_err(|e| self.mcap_error(e))?;
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| BagError::Io { path, source }
        };
        std::fs::rename(&self.tmp, &self.file).map_err(io(&self.file))?;
        let bytes = std::fs::metadata(&self.file).map_err(io(&self.file))?.len();
        let yaml = self.metadata_yaml();
        let meta = self
            .file
            .parent()
            .unwrap_or(Path::new("."))
            .join("metadata.yaml");
        let tmp = tmp_beside(&meta);
        std::fs::write(&tmp, yaml).map_err(io(&tmp))?;
        std::fs::rename(&tmp, &meta).map_err(io(&meta))?;
        Ok(BagSummary {
            file: self.file.clone(),
            bytes,
            topics: self
                .topics
                .iter()
                .map(|t| (t.name.clone(), t.count))
                .collect(),
        })
    }

    /// rosbag2's `metadata.yaml`, version 8.
    fn metadata_yaml(&self) -> String {
        let start = self.first_ns.unwrap_or(0);
        let duration = self.last_ns.saturating_sub(start);
        let total: u64 = self.topics.iter().map(|t| t.count).sum();
        let name = self
            .file
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let mut y = format!(
            "rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: mcap\n  \
             duration:\n    nanoseconds: {duration}\n  starting_time:\n    nanoseconds_since_epoch: {start}\n  \
             message_count: {total}\n  topics_with_message_count:\n"
        );
        for t in &self.topics {
            y += &format!(
                "    - topic_metadata:\n        name: {}\n        type: {}\n        serialization_format: cdr\n        \
                 offered_qos_profiles: {}\n        type_description_hash: {}\n      message_count: {}\n",
                t.name,
                t.msg.name,
                yaml_quoted(&t.qos.yaml()),
                t.msg.hash,
                t.count
            );
        }
        y += &format!(
            "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - {}\n  files:\n    \
             - path: {}\n      starting_time:\n        nanoseconds_since_epoch: {start}\n      duration:\n        \
             nanoseconds: {duration}\n      message_count: {total}\n  custom_data: ~\n  ros_distro: taxi-sim\n",
            yaml_quoted(&name),
            yaml_quoted(&name)
        );
        y
    }
}

/// `text` as a double-quoted YAML scalar.
fn yaml_quoted(text: &str) -> String {
    let mut q = String::from("\"");
    for c in text.chars() {
        match c {
            '"' => q.push_str("\\\""),
            '\\' => q.push_str("\\\\"),
            '\n' => q.push_str("\\n"),
            c => q.push(c),
        }
    }
    q.push('"');
    q
}

fn tmp_beside(file: &Path) -> PathBuf {
    let mut name = file
        .file_name()
        .map_or_else(Default::default, ToOwned::to_owned);
    name.push(format!(".tmp{}", std::process::id()));
    file.with_file_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs;

    #[test]
    fn a_bag_is_an_mcap_file_with_its_metadata_beside_it() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("run.mcap");
        let mut bag = BagWriter::create(&file).unwrap();
        let clock = bag.add_topic("/clock", msgs::CLOCK, Qos::Stream).unwrap();
        let events = bag
            .add_topic("/events", msgs::STRING, Qos::Latched)
            .unwrap();
        for k in 0..3u64 {
            let ns = 1_704_067_200_000_000_000 + k * 100_000_000;
            bag.write(clock, ns, &msgs::clock(msgs::Time::from_ns(ns)))
                .unwrap();
        }
        bag.write(
            events,
            1_704_067_200_050_000_000,
            &msgs::string("{\"stop\":1}"),
        )
        .unwrap();
        assert!(bag.add_topic("/clock", msgs::CLOCK, Qos::Stream).is_err());
        let summary = bag.finish().unwrap();
        assert_eq!(
            summary.topics,
            [("/clock".to_string(), 3), ("/events".to_string(), 1)]
        );
        let bytes = std::fs::read(&file).unwrap();
        let messages: Vec<_> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap();
        assert_eq!(messages.len(), 4);
        let clock_schema = messages[0].channel.schema.as_ref().unwrap();
        assert_eq!(
            (clock_schema.name.as_str(), clock_schema.encoding.as_str()),
            ("rosgraph_msgs/msg/Clock", "ros2msg")
        );
        assert_eq!(messages[0].channel.message_encoding, "cdr");
        let yaml = std::fs::read_to_string(dir.path().join("metadata.yaml")).unwrap();
        assert!(yaml.contains("message_count: 4\n"), "{yaml}");
        assert!(
            yaml.contains("duration:\n    nanoseconds: 200000000\n"),
            "{yaml}"
        );
        assert!(
            yaml.contains("offered_qos_profiles: \"- history: 1\\n  depth: 1\\n"),
            "{yaml}"
        );
        // No temporary file is left.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }
}
