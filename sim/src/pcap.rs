//! Real Velodyne captures in the simulator's tools (`velodyne` decodes them): a revolution of a
//! pcap as the simulator's LiDAR scan (`taxi-sim scan --pcap`, PLY), and the offline map of a
//! recording (`taxi-sim map SCENARIO --pcap`: the scenario's vehicle gives the levels), written
//! as the mapping drive writes its map.
//!
//! The sensor stands at a pose the user gives (a standing recording; a moving one needs poses,
//! not read yet), at a height the user gives or that the ground says: the most common height of
//! the returns of the lasers aimed 10 degrees or more below the horizon.

use std::path::Path;

use mapper::{Levels, MapConfig, MultiHeightMap};
use nalgebra::{Isometry2, Isometry3, Point2, Translation3, UnitQuaternion};
use velodyne::{Calibration, Capture, Frame};

use crate::error::{Error, Result};
use crate::offline_map::MapManifest;
use crate::world::LidarScan;

/// A capture decoded: its calibration and its revolutions (the first and last are partial).
pub struct Recording {
    /// The sensor's lasers.
    pub calibration: Calibration,
    /// The revolutions, VeloView's frame numbering.
    pub frames: Vec<Frame>,
    /// Position packets read.
    pub positions: usize,
}

/// Reads the capture at `path` (its sensor from its packets).
pub fn read(path: &Path) -> Result<Recording> {
    let capture = Capture::read(path).map_err(|e| Error::Invalid(e.to_string()))?;
    let calibration = Calibration::built_in(capture.product()).ok_or_else(|| {
        Error::Invalid(format!(
            "{}: the packets do not say which sensor took them (older firmware); only the \
             built-in tables of the HDL-32E and VLP-16 are known",
            path.display()
        ))
    })?;
    let packets: Vec<_> = capture.data.into_iter().map(|(_, p)| p).collect();
    Ok(Recording {
        frames: velodyne::frames(&packets, &calibration),
        calibration,
        positions: capture.positions.len(),
    })
}

impl Recording {
    /// The full revolutions (all but the first and last).
    pub fn full(&self) -> &[Frame] {
        let n = self.frames.len();
        if n > 2 { &self.frames[1..n - 1] } else { &[] }
    }

    /// The sensor's height above the ground, from revolution `frame`: the most common height
    /// (5-cm bins) of the returns of lasers aimed 10 degrees or more below the horizon, within
    /// 30 m. `None` when there are fewer than 100 such returns.
    pub fn ground_height_below_sensor_m(&self, frame: &Frame) -> Option<f64> {
        let mut bins = std::collections::HashMap::<i64, usize>::new();
        let mut n = 0;
        for p in &frame.points {
            let low = self
                .calibration
                .vertical_deg
                .get(usize::from(p.laser))
                .is_some_and(|&w| w <= -10.0);
            if low && p.distance_m < 30.0 {
                *bins
                    .entry((f64::from(p.xyz_m[2]) / 0.05).floor() as i64)
                    .or_default() += 1;
                n += 1;
            }
        }
        if n < 100 {
            return None;
        }
        let (bin, _) = bins.into_iter().max_by_key(|&(b, c)| (c, -b))?;
        Some(-(bin as f64 + 0.5) * 0.05)
    }

    /// Revolution `frame` as the simulator's LiDAR scan, the sensor `height_m` above the ground
    /// at `pose` (azimuth 0 along its heading).
    pub fn scan(&self, frame: &Frame, pose: &Isometry2<f64>, height_m: f64) -> Result<LidarScan> {
        let s = velodyne::to_scan(frame, &self.calibration, &sensor_pose(pose, height_m), pose)
            .map_err(Error::Invalid)?;
        let n = s.scan.returns().len();
        Ok(LidarScan {
            scan: s.scan,
            owners: vec![None; n],
            directions_in_sensor: std::sync::Arc::new(s.directions_in_sensor),
        })
    }
}

/// The sensor's pose in the world: at `pose`, `height_m` up, facing its heading.
pub fn sensor_pose(pose: &Isometry2<f64>, height_m: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(pose.translation.x, pose.translation.y, height_m),
        UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), pose.rotation.angle()),
    )
}

/// What `map --pcap` built.
pub struct PcapMapReport {
    /// The map's manifest (also written as `manifest.json`).
    pub manifest: MapManifest,
    /// Revolutions inserted (the full ones).
    pub revolutions: usize,
    /// The sensor's height used, metres, and whether it came from the ground.
    pub height_m: (f64, bool),
}

/// Builds the offline map of `levels` from the capture at `pcap` (its full revolutions, the
/// sensor standing at `pose`, `height_m` up or as the ground says) into `out`.
pub fn map_from_pcap(
    pcap: &Path,
    pose: &Isometry2<f64>,
    height_m: Option<f64>,
    levels: &Levels,
    config: MapConfig,
    out: &Path,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<PcapMapReport> {
    let recording = read(pcap)?;
    let full = recording.full();
    let Some(first) = full.first() else {
        return Err(Error::Invalid(format!(
            "{}: no full revolution ({} partial)",
            pcap.display(),
            recording.frames.len()
        )));
    };
    let height = match height_m {
        Some(h) => (h, false),
        None => (
            recording
                .ground_height_below_sensor_m(first)
                .ok_or_else(|| {
                    Error::Invalid(format!(
                        "{}: too few ground returns to find the sensor's height; give \
                     --sensor-height",
                        pcap.display()
                    ))
                })?,
            true,
        ),
    };
    let blocks_dir = out.join("blocks");
    crate::offline_map::clear_blocks(&blocks_dir)?;
    let center = Point2::from(pose.translation.vector);
    let mut map =
        MultiHeightMap::with_stores(config, levels.clone(), center, None, Some(&blocks_dir))?;
    for (i, frame) in full.iter().enumerate() {
        let scan = recording.scan(frame, pose, height.0)?;
        map.insert_scan(&scan.scan, None)?;
        progress(i as u64 + 1, full.len() as u64);
    }
    map.flush()?;
    let manifest = crate::offline_map::finish_map(
        &map,
        levels,
        out,
        (
            format!("pcap-{}", pcap.display()),
            format!("pcap {}", pcap.display()),
            full.len(),
            0.0,
        ),
    )?;
    Ok(PcapMapReport {
        manifest,
        revolutions: full.len(),
        height_m: height,
    })
}
