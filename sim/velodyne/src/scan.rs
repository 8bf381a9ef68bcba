//! A revolution as the mapper takes it: a [`mapper::Scan`] of columns (firing sequences: one a
//! block on the HDL-32E, two on the VLP-16) x
//! beams (lasers by vertical angle, beam 0 the lowest), each return in the world frame with its
//! intensity scaled to 0..1 (raw / 255), no echo as `None`.
//!
//! Frames: the decoder's points are VeloView's (`+y` at azimuth 0, azimuth clockwise); the
//! mapper's sensor frame is the simulator's (`+x` forward, `+y` left, `+z` up), so a point
//! `(x, y, z)` becomes `(y, -x, z)`: the sensor's azimuth 0 is taken as forward.

use mapper::{Return, Scan, ScanColumn};
use nalgebra::{Isometry2, Isometry3, Point3};

use crate::{Calibration, Frame};

/// A revolution as a scan, and each return's unit direction in the sensor frame (`[column *
/// beams + beam]`, zero where there is no return).
#[derive(Clone, Debug)]
pub struct SensorScan {
    /// The scan, in the world frame.
    pub scan: Scan,
    /// Unit direction of each return in the sensor frame.
    pub directions_in_sensor: Vec<[f32; 3]>,
}

/// The beams of `calibration`'s lasers: `beam_of[laser]`, beam 0 the lowest.
pub fn beams(calibration: &Calibration) -> Vec<usize> {
    let mut order: Vec<usize> = (0..calibration.lasers()).collect();
    order.sort_by(|&a, &b| calibration.vertical_deg[a].total_cmp(&calibration.vertical_deg[b]));
    let mut beam_of = vec![0; order.len()];
    for (beam, &laser) in order.iter().enumerate() {
        beam_of[laser] = beam;
    }
    beam_of
}

/// `frame` as a scan taken by a sensor at `world_from_sensor` on a vehicle at
/// `world_from_vehicle` (the same for every column: a standing sensor, or one whose motion
/// during the revolution is neglected).
pub fn to_scan(
    frame: &Frame,
    calibration: &Calibration,
    world_from_sensor: &Isometry3<f64>,
    world_from_vehicle: &Isometry2<f64>,
) -> Result<SensorScan, String> {
    let beam_of = beams(calibration);
    let n_beams = beam_of.len();
    let Some(first) = frame.points.first().map(|p| p.firing) else {
        return Err("the revolution has no returns".into());
    };
    let last = frame.points.last().map_or(first, |p| p.firing);
    let columns = (last - first + 1) as usize;
    let mut returns = vec![None; columns * n_beams];
    let mut directions = vec![[0.0f32; 3]; columns * n_beams];
    for p in &frame.points {
        let Some(&beam) = beam_of.get(usize::from(p.laser)) else {
            return Err(format!(
                "laser {} beyond the calibration's {n_beams}",
                p.laser
            ));
        };
        let i = (p.firing - first) as usize * n_beams + beam;
        let [x, y, z] = p.xyz_m.map(f64::from);
        let in_sensor = Point3::new(y, -x, z);
        let d = f64::from(p.distance_m).max(1e-9);
        directions[i] = [(y / d) as f32, (-x / d) as f32, (z / d) as f32];
        // In dual-return mode the nearer echo of a laser's firing is kept.
        if returns[i].is_some_and(|r: Return| r.range_m <= p.distance_m) {
            continue;
        }
        returns[i] = Some(Return {
            point_in_world: world_from_sensor * in_sensor,
            range_m: p.distance_m,
            intensity: f32::from(p.intensity) / 255.0,
        });
    }
    let column = ScanColumn {
        world_from_sensor: *world_from_sensor,
        world_from_vehicle: *world_from_vehicle,
    };
    let scan = Scan::new(n_beams, vec![column; columns], returns).map_err(|e| e.to_string())?;
    Ok(SensorScan {
        scan,
        directions_in_sensor: directions,
    })
}
