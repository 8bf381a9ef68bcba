//! One LiDAR revolution as a PLY point cloud (Open3D, CloudCompare, MeshLab open it).
//!
//! Binary little-endian, one vertex per return: `float x y z` (metres, world or sensor frame),
//! `float intensity` (0..1), `ushort beam` (0 = lowest), `ushort column` (0 = first firing).
//! Written atomically.

use std::path::Path;

use super::lidar::LidarScan;

/// Which frame the points are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Frame {
    /// The world frame (x east, y north, z up).
    World,
    /// The sensor frame (x forward, z up), as the sensor reports it.
    Sensor,
}

/// The PLY bytes of a scan.
pub fn encode(scan: &LidarScan, frame: Frame) -> Vec<u8> {
    let beams = scan.scan.beams();
    let n = scan.scan.returns().iter().flatten().count();
    let frame_name = match frame {
        Frame::World => "world",
        Frame::Sensor => "sensor",
    };
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment taxi-sim LiDAR revolution, {frame_name} frame, metres\n\
         element vertex {n}\nproperty float x\nproperty float y\nproperty float z\nproperty float intensity\n\
         property ushort beam\nproperty ushort column\nend_header\n"
    )
    .into_bytes();
    for (i, r) in scan.scan.returns().iter().enumerate() {
        let Some(r) = r else { continue };
        let (column, beam) = (i / beams, i % beams);
        let p = match frame {
            Frame::World => r.point_in_world,
            Frame::Sensor => scan
                .point_in_sensor(column, beam)
                .unwrap_or(r.point_in_world),
        };
        for v in [p.x as f32, p.y as f32, p.z as f32, r.intensity] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&(beam as u16).to_le_bytes());
        out.extend_from_slice(&(column as u16).to_le_bytes());
    }
    out
}

/// Writes a scan as PLY, atomically.
pub fn write(scan: &LidarScan, frame: Frame, path: &Path) -> crate::Result<()> {
    Ok(mapper::write_atomically(path, &encode(scan, frame))?)
}

/// One point read back from a PLY written by [`encode`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlyPoint {
    /// Position, metres.
    pub xyz: [f32; 3],
    /// Intensity.
    pub intensity: f32,
    /// Beam index.
    pub beam: u16,
    /// Column index.
    pub column: u16,
}

/// Reads the points of a PLY written by [`encode`] (for tests and tools).
pub fn decode(bytes: &[u8]) -> crate::Result<Vec<PlyPoint>> {
    const END: &[u8] = b"end_header\n";
    let bad = |m: String| crate::Error::Invalid(format!("PLY: {m}"));
    let header_end = bytes
        .windows(END.len())
        .position(|w| w == END)
        .ok_or_else(|| bad("no end_header".into()))?
        + END.len();
    let header = std::str::from_utf8(&bytes[..header_end])
        .map_err(|e| bad(format!("header is not UTF-8: {e}")))?;
    if !header.starts_with("ply\nformat binary_little_endian 1.0\n") {
        return Err(bad("not a binary little-endian PLY".into()));
    }
    let n: usize = header
        .lines()
        .find_map(|l| l.strip_prefix("element vertex "))
        .ok_or_else(|| bad("no vertex count".into()))?
        .trim()
        .parse()
        .map_err(|e| bad(format!("vertex count: {e}")))?;
    let body = &bytes[header_end..];
    if body.len() != n * 20 {
        return Err(bad(format!(
            "{} bytes for {n} vertices of 20 bytes",
            body.len()
        )));
    }
    Ok(body
        .chunks_exact(20)
        .map(|c| {
            let f = |o: usize| f32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
            PlyPoint {
                xyz: [f(0), f(4), f(8)],
                intensity: f(12),
                beam: u16::from_le_bytes([c[16], c[17]]),
                column: u16::from_le_bytes([c[18], c[19]]),
            }
        })
        .collect())
}
