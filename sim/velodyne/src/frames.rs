//! Points and revolutions. A return's point in the sensor frame is VeloView's: `x = d cos(w)
//! sin(a)`, `y = d cos(w) cos(a)`, `z = d sin(w)`, with `d` the distance, `w` the laser's
//! vertical angle and `a` the block's azimuth (clockwise from +y; no per-laser azimuth
//! interpolation on the HDL-32E, as VeloView). A revolution ends where a block's azimuth is
//! smaller than the one before it (so the first and last of a capture are partial). Returns of
//! distance 0 (no echo) are skipped; in dual-return mode a pair's first block holds the last
//! echo and its second the strongest (the second strongest where the last is the strongest), each
//! point marked with its [`Echo`]; where both blocks report one distance (a single echo) it is
//! one point, marked [`Echo::LastAndStrongest`]. The VLP-16's second firing sequence of a block is placed at
//! the block's azimuth too (VeloView shifts it by half a step; not done here yet).

use std::path::Path;

use crate::capture::read_datagrams;
use crate::packet::{BLOCKS, CHANNELS, DATA_LEN, DATA_PORT, POSITION_LEN, POSITION_PORT};
use crate::{Calibration, DataPacket, PositionPacket, Product, ReturnMode, VelodyneError};

/// One return.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Position in the sensor frame, metres (+y ahead at azimuth 0, +z up).
    pub xyz_m: [f32; 3],
    /// Distance, metres.
    pub distance_m: f32,
    /// Intensity as the sensor reports it, 0-255.
    pub intensity: u8,
    /// The laser (its channel number within a firing sequence).
    pub laser: u8,
    /// Azimuth of its block, 0.01 degree.
    pub azimuth_cdeg: u16,
    /// Its firing sequence, counted from the capture's first (a column of a scan; a VLP-16
    /// block holds two).
    pub firing: u32,
    /// When it fired, microseconds past the hour (the sensor's clock).
    pub time_us: f64,
    /// Which echo of its firing it is.
    pub echo: Echo,
}

/// Which echo of a laser's firing a point is, as the packet's return mode and block say.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Echo {
    /// Single-return mode `strongest` (0x37), and packets of firmware that name no mode (0x00:
    /// the HDL-32E's only mode before its dual-return firmware).
    Strongest,
    /// Single-return mode `last` (0x38), or a dual-return pair's first block.
    Last,
    /// A dual-return pair's second block where it differs from the first: the strongest echo,
    /// or the second strongest where the last is also the strongest.
    DualStrongest,
    /// Dual return, both blocks the same distance: the one echo, last and strongest.
    LastAndStrongest,
}

/// One revolution's returns, in firing order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// Its returns.
    pub points: Vec<Point>,
}

/// A capture's data packets decoded (with their record indices) and its position packets.
#[derive(Clone, Debug, Default)]
pub struct Capture {
    /// Data packets, with the record index of each.
    pub data: Vec<(usize, DataPacket)>,
    /// Position packets, with the record index of each.
    pub positions: Vec<(usize, PositionPacket)>,
    /// The sensor's packets skipped, by why: unreadable whole, or of a length neither a data nor
    /// a position packet has.
    pub skipped: crate::capture::Skipped,
}

impl Capture {
    /// Reads the Velodyne packets of the capture at `path`: UDP datagrams to port 2368 of 1206
    /// bytes and to port 8308 of 512 bytes; others are skipped, and counted when they were for
    /// those ports ([`Capture::skipped`]), as are packets to the data port that cannot be a
    /// sensor's (a block flag, azimuth, return mode or product byte no sensor sends). Data
    /// packets from more than one kind of sensor are an error; so is a capture with no data
    /// packet (saying what was skipped).
    pub fn read(path: &Path) -> Result<Capture, VelodyneError> {
        let mut capture = Capture::default();
        let located = |index: usize, what: String| VelodyneError::Packet {
            file: path.to_path_buf(),
            index,
            what,
        };
        let (datagrams, skipped) = read_datagrams(path)?;
        capture.skipped = skipped;
        for d in datagrams {
            if d.dst_port == DATA_PORT && d.payload.len() == DATA_LEN {
                // A packet that cannot be sensor data is skipped and counted, by kind (VeloView
                // and Wireshark read on past it); so only a capture of none is refused.
                let p = match DataPacket::decode(&d.payload) {
                    Ok(p) => p,
                    Err(fault) => {
                        let why = format!("to port {DATA_PORT} {}", fault.kind);
                        capture.skipped.add(why, d.index);
                        continue;
                    }
                };
                if let Some((first, q)) = capture.data.first()
                    && (q.product, q.return_mode) != (p.product, p.return_mode)
                {
                    return Err(located(
                        d.index,
                        format!(
                            "from another sensor: {:?} in {:?} mode, packet {first} was {:?} in \
                             {:?} mode",
                            p.product, p.return_mode, q.product, q.return_mode
                        ),
                    ));
                }
                capture.data.push((d.index, p));
            } else if d.dst_port == POSITION_PORT && d.payload.len() == POSITION_LEN {
                match PositionPacket::decode(&d.payload) {
                    Ok(p) => capture.positions.push((d.index, p)),
                    Err(_) => capture.skipped.add(
                        format!("to port {POSITION_PORT} not a position packet"),
                        d.index,
                    ),
                }
            } else if d.dst_port == DATA_PORT || d.dst_port == POSITION_PORT {
                let why = format!(
                    "to port {} of neither {DATA_LEN} nor {POSITION_LEN} bytes",
                    d.dst_port
                );
                capture.skipped.add(why, d.index);
            }
        }
        if capture.data.is_empty() {
            let skipped = if capture.skipped.total() > 0 {
                format!("; skipped: {}", capture.skipped)
            } else {
                String::new()
            };
            return Err(VelodyneError::File {
                file: path.to_path_buf(),
                what: format!(
                    "no Velodyne data packets (UDP port {DATA_PORT}, {DATA_LEN} bytes){skipped}"
                ),
            });
        }
        Ok(capture)
    }

    /// The sensor the packets say, if they say.
    pub fn product(&self) -> Product {
        self.data
            .first()
            .map_or(Product::Unspecified, |(_, p)| p.product)
    }
}

/// The returns of `packets` (of one sensor) cut into revolutions.
pub fn frames(packets: &[DataPacket], calibration: &Calibration) -> Vec<Frame> {
    let mut out = vec![Frame::default()];
    let mut last_azimuth: Option<u16> = None;
    let mut firings = 0u32;
    // The last azimuth gap between firings, hundredths of a degree (the last block of a packet
    // has no next one to measure it by: the one before is used, as the ROS driver does).
    let mut gap_cdeg = 0.0f64;
    for p in packets {
        let dual = p.return_mode == ReturnMode::Dual;
        for (k, block) in p.blocks.iter().enumerate() {
            let a = block.azimuth_cdeg;
            // The next firing's block (in dual-return mode blocks come in pairs).
            let step = if dual { 2 } else { 1 };
            if let Some(n) = p.blocks.get(k - k % step + step) {
                gap_cdeg = f64::from((u32::from(n.azimuth_cdeg) + 36_000 - u32::from(a)) % 36_000);
            }
            if last_azimuth.is_some_and(|l| a < l) {
                out.push(Frame::default());
            }
            last_azimuth = Some(a);
            let repeat = (dual && k % 2 == 1).then(|| &p.blocks[k - 1]);
            let firing = if dual { k / 2 } else { k };
            // A VLP-16 block holds two firing sequences: two columns.
            let sequences: u32 = if p.product == Product::Vlp16 { 2 } else { 1 };
            if repeat.is_none() {
                firings += sequences;
            }
            let frame = out.last_mut().expect("one frame at least");
            for (j, &(d, intensity)) in block.channels.iter().enumerate() {
                if d == 0 || repeat.is_some_and(|r| r.channels[j].0 == d) {
                    continue;
                }
                let laser = j % calibration.lasers().max(1);
                let Some(&w) = calibration.vertical_deg.get(laser) else {
                    continue;
                };
                let time_us = firing_time_us(p, firing, j);
                let c = calibration;
                let az = (azimuth_cdeg(p.product, a, gap_cdeg, j) * 0.01 - c.rotation_deg[laser])
                    .to_radians();
                let w = w.to_radians();
                let dist = f64::from(d) * c.distance_unit_m + c.distance_offset_m[laser];
                // VeloView's corrections (all zero in the built-in tables).
                let (v_off, h_off) = (c.vertical_offset_m[laser], c.horizontal_offset_m[laser]);
                let xy = dist * w.cos() - v_off * w.sin();
                let xyz = [
                    xy * az.sin() - h_off * az.cos(),
                    xy * az.cos() + h_off * az.sin(),
                    dist * w.sin() + v_off * w.cos(),
                ];
                let echo = match (p.return_mode, repeat.is_some()) {
                    (ReturnMode::Strongest | ReturnMode::Unspecified, _) => Echo::Strongest,
                    (ReturnMode::Last, _) => Echo::Last,
                    (ReturnMode::Dual, true) => Echo::DualStrongest,
                    (ReturnMode::Dual, false) => {
                        // The pair's second block repeating this distance: one echo.
                        let second = p.blocks.get(k + 1).map(|b| b.channels[j].0);
                        if second == Some(d) {
                            Echo::LastAndStrongest
                        } else {
                            Echo::Last
                        }
                    }
                };
                frame.points.push(Point {
                    xyz_m: xyz.map(|v| v as f32),
                    distance_m: dist as f32,
                    intensity,
                    laser: laser as u8,
                    azimuth_cdeg: a,
                    firing: firings - sequences + j as u32 * sequences / CHANNELS as u32,
                    time_us,
                    echo,
                });
            }
        }
    }
    out
}

/// The azimuth channel `j` of a block at `a` fired at, hundredths of a degree. A VLP-16 block
/// holds two firing sequences of 16 lasers, one after the other, while the head turns by
/// `gap_cdeg` to the next block: its manual's "precision azimuth" (as VeloView and the ROS driver
/// compute it) moves each laser on by the gap times its firing time over the block's 110.592 us:
/// the second sequence half a gap on, each laser 2.304 us after the one before. The HDL-32E's
/// returns keep the block's azimuth (its 32 lasers fire within 1.152 us of each other: VeloView's
/// recording is reproduced so).
fn azimuth_cdeg(product: Product, a: u16, gap_cdeg: f64, j: usize) -> f64 {
    if product == Product::Vlp16 {
        let t_us = (j / 16) as f64 * 55.296 + (j % 16) as f64 * 2.304;
        f64::from(a) + gap_cdeg * t_us / 110.592
    } else {
        f64::from(a)
    }
}

/// When channel `j` of firing `k` of packet `p` fired (manuals, appendix
/// E): the HDL-32E stamps the last firing of the packet (46.08 us a sequence, 1.152 us a
/// laser); the VLP-16 the first (two 16-laser sequences a block, 55.296 us each, 2.304 us a
/// laser).
fn firing_time_us(p: &DataPacket, k: usize, j: usize) -> f64 {
    let t = f64::from(p.timestamp_us);
    let dual = p.return_mode == ReturnMode::Dual;
    if p.product == Product::Vlp16 {
        t + k as f64 * 110.592 + (j / 16) as f64 * 55.296 + (j % 16) as f64 * 2.304
    } else {
        let firings = if dual { BLOCKS / 2 } else { BLOCKS };
        let last = (firings - 1) as f64 * 46.08 + 31.0 * 1.152;
        t - last + k as f64 * 46.08 + j as f64 * 1.152
    }
}
