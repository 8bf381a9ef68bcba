//! One LiDAR revolution as the mapper takes it: columns (azimuth) x beams (vertical order).
//!
//! The obstacle test compares each beam with the one below it in the same column, so the
//! organisation matters: `returns[column * beams + beam]`, beam 0 the lowest. Each column carries
//! the sensor pose at its firing time (so motion during the sweep is representable) and the
//! vehicle pose (for the self-hit filter). A beam with no echo is `None`.

use nalgebra::{Isometry2, Isometry3, Point3};
use rayon::prelude::*;

use crate::error::{MapError, Result};

/// One echo of one beam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Return {
    /// The hit point in the world frame.
    pub point_in_world: Point3<f64>,
    /// Range along the beam, metres.
    pub range_m: f32,
    /// Calibrated intensity (remission), 0..1 (a scan with another is refused: the map's
    /// remission layer stores 0..1 in fixed steps).
    pub intensity: f32,
}

/// The poses of one column at its firing time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanColumn {
    /// Pose of the sensor in the world.
    pub world_from_sensor: Isometry3<f64>,
    /// Planar pose of the vehicle (rear axle centre) in the world.
    pub world_from_vehicle: Isometry2<f64>,
}

/// One revolution, organised as columns x beams.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scan {
    beams: usize,
    columns: Vec<ScanColumn>,
    returns: Vec<Option<Return>>,
}

/// Beams per column a scan may have (128-beam sensors exist; the mapper indexes beams in 16 bits).
pub const MAX_BEAMS: usize = 4096;

impl Scan {
    /// A scan of `columns.len()` columns of `beams` returns each (`returns[column * beams + beam]`,
    /// beam 0 lowest). Every number must be finite, ranges >= 0, intensities within 0..1.
    pub fn new(
        beams: usize,
        columns: Vec<ScanColumn>,
        returns: Vec<Option<Return>>,
    ) -> Result<Self> {
        if beams == 0 {
            return Err(MapError::invalid("scan", "0 beams per column"));
        }
        if beams > MAX_BEAMS {
            return Err(MapError::invalid(
                "scan",
                format!("{beams} beams per column (at most {MAX_BEAMS})"),
            ));
        }
        if returns.len() != beams * columns.len() {
            return Err(MapError::invalid(
                "scan",
                format!(
                    "{} returns for {} columns x {beams} beams",
                    returns.len(),
                    columns.len()
                ),
            ));
        }
        for (c, col) in columns.iter().enumerate() {
            let t = col.world_from_sensor.translation.vector;
            let v = col.world_from_vehicle.translation.vector;
            if !(t.iter().all(|x| x.is_finite())
                && v.iter().all(|x| x.is_finite())
                && col.world_from_vehicle.rotation.angle().is_finite())
            {
                return Err(MapError::invalid(
                    "scan column pose",
                    format!("column {c}: pose is not finite"),
                ));
            }
        }
        // A revolution is 70,000 returns: checked in parallel by chunks of columns with a plain
        // loop each (rayon's `find_first` tests a shared atomic per item, which cost more than
        // the check: 6 % of the closed loop's CPU time), then, only when one is bad, searched for
        // the first bad one to name it.
        let valid = |r: &Option<Return>| {
            r.is_none_or(|r| {
                r.point_in_world.iter().all(|x| x.is_finite())
                    && r.range_m.is_finite()
                    && r.range_m >= 0.0
                    && (0.0..=1.0).contains(&r.intensity)
            })
        };
        let all_valid = returns
            .par_chunks(beams * 64)
            .all(|chunk| chunk.iter().fold(true, |ok, r| ok & valid(r)));
        let bad = if all_valid {
            None
        } else {
            returns.iter().enumerate().find(|(_, r)| !valid(r))
        };
        if let Some((i, Some(r))) = bad {
            return Err(MapError::invalid(
                "scan return",
                format!(
                    "column {} beam {}: {r:?} has a non-finite value, a negative range or an \
                     intensity outside 0..1 (a calibrated remission; divide a sensor's 0-255 by 255)",
                    i / beams,
                    i % beams
                ),
            ));
        }
        Ok(Scan {
            beams,
            columns,
            returns,
        })
    }

    /// The scan moved rigidly by `correction` (points and sensor poses), each column's vehicle
    /// pose replaced by `world_from_vehicle`: in place, without a copy or a new check (a rigid
    /// motion of finite values is finite, and ranges do not change). `world_from_vehicle` must
    /// be finite.
    pub fn moved(
        mut self,
        correction: &nalgebra::Isometry3<f64>,
        world_from_vehicle: &Isometry2<f64>,
    ) -> Result<Self> {
        let t = world_from_vehicle.translation.vector;
        if !(t.iter().all(|x| x.is_finite()) && world_from_vehicle.rotation.angle().is_finite()) {
            return Err(MapError::invalid(
                "scan column pose",
                "the new vehicle pose is not finite",
            ));
        }
        for c in &mut self.columns {
            c.world_from_sensor = correction * c.world_from_sensor;
            c.world_from_vehicle = *world_from_vehicle;
        }
        self.returns
            .par_chunks_mut(self.beams * 64)
            .for_each(|chunk| {
                for r in chunk.iter_mut().flatten() {
                    r.point_in_world = correction * r.point_in_world;
                }
            });
        Ok(self)
    }

    /// Beams per column.
    pub fn beams(&self) -> usize {
        self.beams
    }
    /// Number of columns.
    pub fn column_count(&self) -> usize {
        self.columns.len()
    }
    /// The columns' poses.
    pub fn columns(&self) -> &[ScanColumn] {
        &self.columns
    }
    /// All returns, column after column.
    pub fn returns(&self) -> &[Option<Return>] {
        &self.returns
    }
    /// One column: its poses and its returns, lowest beam first.
    pub fn column(&self, c: usize) -> Option<(&ScanColumn, &[Option<Return>])> {
        let col = self.columns.get(c)?;
        Some((col, &self.returns[c * self.beams..(c + 1) * self.beams]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

    /// Moving a scan in place gives what building it from the moved points and poses gives.
    #[test]
    fn a_scan_moved_in_place_equals_one_built_from_moved_values() {
        let scan = crate::workloads::parking_lot_scan();
        let correction = Isometry3::from_parts(
            Translation3::new(0.4, -0.3, 0.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.02),
        );
        let vehicle = Isometry2::new(nalgebra::Vector2::new(1.0, 2.0), 0.3);
        let columns = scan
            .columns()
            .iter()
            .map(|c| ScanColumn {
                world_from_sensor: correction * c.world_from_sensor,
                world_from_vehicle: vehicle,
            })
            .collect();
        let returns = scan
            .returns()
            .iter()
            .map(|r| {
                r.map(|r| Return {
                    point_in_world: correction * r.point_in_world,
                    ..r
                })
            })
            .collect();
        let want = Scan::new(scan.beams(), columns, returns).unwrap();
        assert_eq!(scan.clone().moved(&correction, &vehicle).unwrap(), want);
        let nan = Isometry2::new(nalgebra::Vector2::new(f64::NAN, 0.0), 0.0);
        assert!(scan.moved(&correction, &nan).is_err());
    }
}
