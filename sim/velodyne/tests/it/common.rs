//! What the tests share: a pcap written here, an Ethernet frame of UDP, an HDL-32E packet
//! built field by field, and a file written into a test's directory.

use std::path::{Path, PathBuf};

use velodyne::packet::{Block, CHANNELS};
use velodyne::{DataPacket, Product, ReturnMode};

/// A legacy pcap (little-endian, microseconds) of `link` with `records` as they are.
pub(crate) fn pcap(link: u32, records: &[Vec<u8>]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&0xa1b2_c3d4u32.to_le_bytes());
    out.extend_from_slice(&2u16.to_le_bytes());
    out.extend_from_slice(&4u16.to_le_bytes());
    for w in [0u32, 0, 65535, link] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    for (i, r) in records.iter().enumerate() {
        for w in [
            1_355_263_594u32,
            i as u32 * 553,
            r.len() as u32,
            r.len() as u32,
        ] {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.extend_from_slice(r);
    }
    out
}

/// An Ethernet frame carrying `payload` in UDP to `port`, as the crate writes it.
pub(crate) fn ethernet_udp(port: u16, payload: &[u8]) -> Vec<u8> {
    velodyne::capture::pcap_bytes(&[(0.0, port, payload.to_vec())])[24 + 16..].to_vec()
}

/// An HDL-32E packet whose block `k` is at `azimuths[k]`, every channel `j` at (10 + j) m with
/// intensity `j`, but channel 5 of every block without a return.
pub(crate) fn packet(azimuths: [u16; 12], timestamp_us: u32) -> DataPacket {
    let mut channels = [(0u16, 0u8); CHANNELS];
    for (j, c) in channels.iter_mut().enumerate() {
        *c = if j == 5 {
            (0, 0)
        } else {
            (((10.0 + j as f64) / 0.002) as u16, j as u8)
        };
    }
    DataPacket {
        blocks: azimuths.map(|azimuth_cdeg| Block {
            azimuth_cdeg,
            channels,
        }),
        timestamp_us,
        return_mode: ReturnMode::Strongest,
        product: Product::Hdl32e,
    }
}

pub(crate) fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}
