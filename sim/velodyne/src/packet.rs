//! Velodyne UDP packets (HDL-32E and VLP-16 user manuals, appendix B): a 1206-byte data packet
//! holds 12 blocks, each a flag (`FF EE`), the azimuth in 0.01 degree and 32 channels of a
//! 2-mm distance (0: no return) and an intensity; then the timestamp in microseconds past the
//! hour and two factory bytes, the return mode and the product. All little-endian. A 512-byte
//! position packet carries its own timestamp (offset 198) and an NMEA `$GPRMC` sentence
//! (offset 206).

/// The UDP port of data packets (the sensor's default).
pub const DATA_PORT: u16 = 2368;
/// The UDP port of position packets (the sensor's default).
pub const POSITION_PORT: u16 = 8308;
/// A data packet's payload size, bytes.
pub const DATA_LEN: usize = 1206;
/// A position packet's payload size, bytes.
pub const POSITION_LEN: usize = 512;
/// Blocks per data packet.
pub const BLOCKS: usize = 12;
/// Channels per block.
pub const CHANNELS: usize = 32;
/// Metres per distance unit (2 mm).
pub const DISTANCE_UNIT_M: f64 = 0.002;

/// Which echo the sensor reports (factory byte at offset 1204).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReturnMode {
    /// The strongest echo (0x37).
    Strongest,
    /// The last echo (0x38).
    Last,
    /// Both: blocks in pairs of the same azimuth, last then strongest (0x39).
    Dual,
    /// Older firmware writes 0 (reserved): single return.
    Unspecified,
}

/// The sensor model (factory byte at offset 1205).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Product {
    /// HDL-32E (0x21).
    Hdl32e,
    /// VLP-16 or Puck LITE (0x22).
    Vlp16,
    /// Older firmware writes 0: the model must come from the user.
    Unspecified,
}

/// One block: the azimuth at its first firing and its channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block {
    /// Azimuth, 0.01 degree (0..=36000), clockwise seen from above, 0 ahead.
    pub azimuth_cdeg: u16,
    /// Each channel's (distance in 2-mm units, 0 = no return; intensity 0-255).
    pub channels: [(u16, u8); CHANNELS],
}

/// A decoded data packet.
#[derive(Clone, Debug, PartialEq)]
pub struct DataPacket {
    /// The blocks in firing order.
    pub blocks: [Block; BLOCKS],
    /// Microseconds past the hour (the sensor's clock) when the packet was completed.
    pub timestamp_us: u32,
    /// Its return mode.
    pub return_mode: ReturnMode,
    /// Its product.
    pub product: Product,
}

/// Why a payload is not a data packet: its kind (what a capture's summary counts it by) and
/// the detail (which block, which byte).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PacketFault {
    /// The kind, the same for every packet with this fault.
    pub kind: &'static str,
    /// What exactly is wrong.
    pub detail: String,
}

impl std::fmt::Display for PacketFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.detail)
    }
}

impl DataPacket {
    /// Decodes a data packet's payload.
    ///
    /// # Errors
    /// A payload of another length, a block whose flag is not 0xEEFF or whose azimuth is past a
    /// turn, or a return mode or product byte no sensor sends.
    pub fn decode(payload: &[u8]) -> Result<DataPacket, PacketFault> {
        let fault = |kind: &'static str, detail: String| PacketFault { kind, detail };
        if payload.len() != DATA_LEN {
            return Err(fault(
                "of another length than a data packet's",
                format!(
                    "a data packet has {DATA_LEN} bytes, this one {}",
                    payload.len()
                ),
            ));
        }
        let u16_at = |at: usize| u16::from_le_bytes([payload[at], payload[at + 1]]);
        let mut blocks = [Block {
            azimuth_cdeg: 0,
            channels: [(0, 0); CHANNELS],
        }; BLOCKS];
        for (k, block) in blocks.iter_mut().enumerate() {
            let at = 100 * k;
            let flag = u16_at(at);
            if flag != 0xEEFF {
                return Err(fault(
                    "with a block flag other than 0xeeff (an HDL-64E's upper lasers, or not \
                     Velodyne data)",
                    format!(
                        "block {k}: flag {flag:#06x}, not 0xeeff (lasers 32-63 of an HDL-64E, or \
                         not a Velodyne data packet)"
                    ),
                ));
            }
            block.azimuth_cdeg = u16_at(at + 2);
            // 36000 occurs in real captures (the HDL-32E's encoder reading a full turn).
            if block.azimuth_cdeg > 36000 {
                return Err(fault(
                    "with an azimuth beyond 360 degrees",
                    format!(
                        "block {k}: azimuth {} beyond 360 degrees",
                        block.azimuth_cdeg
                    ),
                ));
            }
            for (j, c) in block.channels.iter_mut().enumerate() {
                let a = at + 4 + 3 * j;
                *c = (u16_at(a), payload[a + 2]);
            }
        }
        let return_mode = match payload[1204] {
            0x37 => ReturnMode::Strongest,
            0x38 => ReturnMode::Last,
            0x39 => ReturnMode::Dual,
            0x00 => ReturnMode::Unspecified,
            other => {
                return Err(fault(
                    "with a return mode byte no sensor sends",
                    format!("return mode byte {other:#04x} unknown"),
                ));
            }
        };
        let product = match payload[1205] {
            0x21 => Product::Hdl32e,
            0x22 => Product::Vlp16,
            0x00 => Product::Unspecified,
            other => {
                return Err(fault(
                    "of a sensor not read here (product byte not 0x21 or 0x22)",
                    format!("product byte {other:#04x}: not an HDL-32E (0x21) or a VLP-16 (0x22)"),
                ));
            }
        };
        Ok(DataPacket {
            blocks,
            timestamp_us: u32::from_le_bytes([
                payload[1200],
                payload[1201],
                payload[1202],
                payload[1203],
            ]),
            return_mode,
            product,
        })
    }

    /// Encodes the packet (tests build packets with it).
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(DATA_LEN);
        for b in &self.blocks {
            out.extend_from_slice(&0xEEFFu16.to_le_bytes());
            out.extend_from_slice(&b.azimuth_cdeg.to_le_bytes());
            for (d, i) in b.channels {
                out.extend_from_slice(&d.to_le_bytes());
                out.push(i);
            }
        }
        out.extend_from_slice(&self.timestamp_us.to_le_bytes());
        out.push(match self.return_mode {
            ReturnMode::Strongest => 0x37,
            ReturnMode::Last => 0x38,
            ReturnMode::Dual => 0x39,
            ReturnMode::Unspecified => 0,
        });
        out.push(match self.product {
            Product::Hdl32e => 0x21,
            Product::Vlp16 => 0x22,
            Product::Unspecified => 0,
        });
        out
    }
}

/// A decoded position packet.
#[derive(Clone, Debug, PartialEq)]
pub struct PositionPacket {
    /// Microseconds past the hour (the sensor's clock).
    pub timestamp_us: u32,
    /// The NMEA sentence (`$GPRMC,...`), without its line end; empty without a GPS.
    pub nmea: String,
}

impl PositionPacket {
    /// Decodes a position packet's payload.
    pub fn decode(payload: &[u8]) -> Result<PositionPacket, String> {
        if payload.len() != POSITION_LEN {
            return Err(format!(
                "a position packet has {POSITION_LEN} bytes, this one {}",
                payload.len()
            ));
        }
        let timestamp_us =
            u32::from_le_bytes([payload[198], payload[199], payload[200], payload[201]]);
        let text = &payload[206..];
        let end = text
            .iter()
            .position(|&b| b == 0 || b == b'\r' || b == b'\n')
            .unwrap_or(text.len());
        let nmea = std::str::from_utf8(&text[..end])
            .map_err(|_| "its NMEA sentence is not text".to_string())?
            .to_string();
        if !nmea.is_empty() && !nmea.starts_with('$') {
            return Err(format!(
                "its NMEA sentence starts {:?}, not '$'",
                nmea.chars().take(8).collect::<String>()
            ));
        }
        Ok(PositionPacket { timestamp_us, nmea })
    }
}
