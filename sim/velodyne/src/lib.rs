//! Velodyne HDL-32E (and VLP-16) packets in, points out: what a vehicle would run on its
//! sensor's UDP stream, here read from pcap captures (what VeloView and the ROS driver record).
//!
//! - [`capture`]: the UDP datagrams of a pcap or pcapng file (`pcap-parser`; Ethernet, VLAN,
//!   Linux cooked v1/v2 and raw IPv4 link layers; IPv4 and UDP parsed, fragments refused).
//! - [`packet`]: a 1206-byte data packet (12 blocks of 32 channels: azimuth in 0.01 degree,
//!   distance in 2 mm, intensity; the timestamp in microseconds past the hour; the factory
//!   bytes: return mode and product) and a 512-byte position packet (its NMEA `$GPRMC`).
//! - [`calibration`]: each laser's vertical angle and corrections, from the sensor's built-in
//!   table or a VeloView calibration file (XML).
//! - [`frames`]: points in the sensor frame with their laser, azimuth, intensity and firing
//!   time, cut into revolutions where the azimuth wraps - VeloView's rule, so its expected
//!   values (`monterey.test`) can be reproduced exactly.
//! - [`scan`]: a revolution as a [`mapper::Scan`] (columns = firing sequences, beams = lasers
//!   by vertical angle), what the mapper inserts.
//! - [`encode`]: the other way, firings into data packets (the simulator's revolutions written
//!   as a capture).

pub mod calibration;
pub mod capture;
pub mod encode;
mod error;
pub mod frames;
pub mod packet;
pub mod scan;

pub use calibration::Calibration;
pub use capture::{Datagram, Skipped, pcap_bytes, read_datagrams};
pub use error::VelodyneError;
pub use frames::{Capture, Echo, Frame, Point, frames};
pub use packet::{DataPacket, PacketFault, PositionPacket, Product, ReturnMode};
pub use scan::{SensorScan, to_scan};
