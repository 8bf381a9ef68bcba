//! ROS 2 bags for taxi-sim: CDR ([`cdr`]), the standard message types a run is written as
//! ([`msgs`]), rosbag2 bags in MCAP with their `metadata.yaml` ([`bag`]) - what `ros2 bag`,
//! Foxglove and `rosbags` read - point clouds read by field name from any driver ([`cloud`]), and bags read back, streamed
//! from disk ([`read`]).

pub mod bag;
pub mod cdr;
pub mod cloud;
pub mod error;
pub mod msgs;
pub mod read;
pub mod thread;

pub use bag::{BagSummary, BagWriter, Qos, TopicId};
pub use cloud::{Cloud, CloudError, read_cloud};
pub use error::{BagError, CdrError};
pub use read::{BagMessage, BagReader, TopicInfo};
pub use thread::BagThread;
