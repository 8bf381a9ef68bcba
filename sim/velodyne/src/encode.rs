//! Packets from returns: the data packets a sensor would send for a revolution of firings the
//! simulator cast, in single-return (strongest) mode, with the built-in calibration's channel
//! order and no corrections. What the decoder reads back is the firings' returns at the packet's
//! resolution (2 mm, 0.01 degree, intensity 0-255), placed as the decoder places them: on the
//! VLP-16 each laser at its precision azimuth, up to 15 x 2.304 us of the head's turn past its
//! block's (`frames`).

use crate::packet::{BLOCKS, Block, CHANNELS};
use crate::{Calibration, DataPacket, Product, ReturnMode};

/// One firing sequence: where the head points, when, and each laser's echo.
#[derive(Clone, Debug, PartialEq)]
pub struct Firing {
    /// Azimuth, degrees, clockwise from the sensor's +y (VeloView's), any turn.
    pub azimuth_deg: f64,
    /// When it fired, microseconds past the hour.
    pub time_us: f64,
    /// Each beam's echo, beam 0 the lowest: (distance in metres, intensity 0-255).
    pub by_beam: Vec<Option<(f64, u8)>>,
}

/// The data packets of `firings` for `product` (HDL-32E: a firing a block; VLP-16: two), twelve
/// blocks a packet; a last packet's missing blocks carry no echo, at the azimuths the turn would
/// have reached. Each packet is stamped as the sensor stamps it (the VLP-16 its first firing,
/// the HDL-32E its last).
///
/// # Errors
/// A product the built-in tables lack, a firing with another beam count than the product's
/// lasers, or a distance beyond the packet's 131 m (naming the firing and beam).
pub fn data_packets(product: Product, firings: &[Firing]) -> Result<Vec<DataPacket>, String> {
    let calibration = Calibration::built_in(product)
        .ok_or_else(|| format!("{product:?}: no built-in calibration to encode with"))?;
    let lasers = calibration.lasers();
    let beam_of = crate::scan::beams(&calibration);
    let per_block = CHANNELS / lasers;
    if let Some((i, f)) = firings
        .iter()
        .enumerate()
        .find(|(_, f)| f.by_beam.len() != lasers)
    {
        return Err(format!(
            "firing {i}: {} beams, the {product:?} has {lasers}",
            f.by_beam.len()
        ));
    }
    let step_deg = match firings {
        [a, b, ..] => (b.azimuth_deg - a.azimuth_deg).rem_euclid(360.0),
        _ => 0.0,
    };
    let mut blocks = Vec::new();
    for (b, group) in firings.chunks(per_block).enumerate() {
        let mut channels = [(0u16, 0u8); CHANNELS];
        for (s, firing) in group.iter().enumerate() {
            for laser in 0..lasers {
                let Some((d, intensity)) = firing.by_beam[beam_of[laser]] else {
                    continue;
                };
                let raw = (d / calibration.distance_unit_m).round();
                if !(raw >= 1.0 && raw <= f64::from(u16::MAX)) {
                    return Err(format!(
                        "firing {}: beam {}: distance {d} m not in a packet's 0.002-131 m",
                        b * per_block + s,
                        beam_of[laser]
                    ));
                }
                channels[s * lasers + laser] = (raw as u16, intensity);
            }
        }
        blocks.push((group[0].azimuth_deg, group[0].time_us, channels));
    }
    let per_packet_deg = step_deg * per_block as f64;
    let mut packets = Vec::new();
    for chunk in blocks.chunks(BLOCKS) {
        let (a0, t0, _) = chunk[0];
        let block = |k: usize| {
            let (azimuth_deg, channels) = chunk
                .get(k)
                .map_or((a0 + per_packet_deg * k as f64, [(0, 0); CHANNELS]), |c| {
                    (c.0, c.2)
                });
            Block {
                azimuth_cdeg: ((azimuth_deg.rem_euclid(360.0) * 100.0).round() as u16) % 36_000,
                channels,
            }
        };
        let t_last = chunk.last().map_or(t0, |c| c.1);
        let stamp = if product == Product::Vlp16 {
            t0
        } else {
            t_last
        };
        packets.push(DataPacket {
            blocks: std::array::from_fn(block),
            timestamp_us: (stamp.rem_euclid(3.6e9)).round() as u32,
            return_mode: ReturnMode::Strongest,
            product,
        });
    }
    Ok(packets)
}
