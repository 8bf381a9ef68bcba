//! An unorganised point cloud (a driver's message: points in the sensor frame, each with its
//! ring) organised into a [`Scan`]'s columns x beams, the layout the obstacle test needs (each
//! beam against the one below it in the same firing).
//!
//! A point's column is its azimuth rounded to the nearest of `columns` firings a revolution
//! starting at `phase_rad`; its beam is its ring (0 lowest, as the ROS Velodyne driver numbers
//! them). [`ColumnLayout::estimate`] finds both from the cloud itself: the firings' spacing is
//! the median azimuth step between neighbouring points of a ring, the phase the circular mean of
//! the azimuths' offsets from that grid. Two points in one cell (a dual-return sensor, a cloud
//! merged from two) keep the nearer.

use nalgebra::{Isometry2, Isometry3, Point3};

use crate::error::{MapError, Result};
use crate::scan::{MAX_BEAMS, Return, Scan, ScanColumn};

/// One point of a driver's cloud.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorPoint {
    /// The point in the sensor frame (x forward, z up), metres.
    pub xyz: [f64; 3],
    /// Its ring: the beam, 0 lowest.
    pub ring: u16,
    /// Calibrated intensity, 0..1.
    pub intensity: f32,
}

/// How a revolution's firings are laid out in azimuth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnLayout {
    /// Firings a revolution.
    pub columns: usize,
    /// Azimuth of firing 0 in the sensor frame, radians, within one step of 0.
    pub phase_rad: f64,
}

/// Columns a revolution may have (a 0.01 degree step).
pub const MAX_COLUMNS: usize = 36_000;

/// Returns a scan may have room for (a 128-beam sensor at 0.05 degrees is 0.9 million): a cloud
/// whose highest ring and firing count ask for more is refused, not allocated.
pub const MAX_CELLS: usize = 1 << 22;

fn azimuth(p: &SensorPoint) -> f64 {
    p.xyz[1].atan2(p.xyz[0]).rem_euclid(std::f64::consts::TAU)
}

impl ColumnLayout {
    /// The layout of the cloud's firings, `None` when it has too few points to tell (fewer than
    /// 16 pairs of neighbours on a ring). `columns` fixes the count (the phase is still found).
    pub fn estimate(points: &[SensorPoint], columns: Option<usize>) -> Option<Self> {
        let columns = match columns {
            Some(c) => c,
            None => {
                let mut by_ring: Vec<Vec<f64>> = Vec::new();
                for p in points {
                    let r = usize::from(p.ring);
                    if by_ring.len() <= r {
                        by_ring.resize_with(r + 1, Vec::new);
                    }
                    by_ring[r].push(azimuth(p));
                }
                let mut steps = Vec::new();
                for ring in &mut by_ring {
                    ring.sort_by(f64::total_cmp);
                    steps.extend(ring.windows(2).map(|w| w[1] - w[0]).filter(|&d| d > 1e-6));
                }
                if steps.len() < 16 {
                    return None;
                }
                let mid = steps.len() / 2;
                let (_, &mut median, _) = steps.select_nth_unstable_by(mid, f64::total_cmp);
                (std::f64::consts::TAU / median).round() as usize
            }
        };
        if !(1..=MAX_COLUMNS).contains(&columns) {
            return None;
        }
        let step = std::f64::consts::TAU / columns as f64;
        let (s, c) = points.iter().fold((0.0, 0.0), |(s, c), p| {
            let (ps, pc) = (azimuth(p) / step * std::f64::consts::TAU).sin_cos();
            (s + ps, c + pc)
        });
        let phase_rad = if s == 0.0 && c == 0.0 {
            0.0
        } else {
            s.atan2(c) / std::f64::consts::TAU * step
        };
        Some(Self { columns, phase_rad })
    }

    /// The column of a point at `azimuth_rad`.
    fn column_of(&self, azimuth_rad: f64) -> usize {
        let step = std::f64::consts::TAU / self.columns as f64;
        (((azimuth_rad - self.phase_rad) / step).round() as i64).rem_euclid(self.columns as i64)
            as usize
    }
}

/// The cloud's points as a scan taken at one pose: `beams` beams (rings from 0; a point on a
/// higher ring is an error), columns as `layout` says. Points that are not finite, or at the
/// sensor's origin, are no return.
pub fn organise(
    points: &[SensorPoint],
    beams: usize,
    layout: &ColumnLayout,
    world_from_sensor: &Isometry3<f64>,
    world_from_vehicle: &Isometry2<f64>,
) -> Result<Scan> {
    if beams == 0 || beams > MAX_BEAMS {
        return Err(MapError::invalid(
            "cloud",
            format!("{beams} beams (1 to {MAX_BEAMS})"),
        ));
    }
    if layout.columns.saturating_mul(beams) > MAX_CELLS {
        return Err(MapError::invalid(
            "cloud",
            format!(
                "{} columns x {beams} beams: over {MAX_CELLS} returns a revolution",
                layout.columns
            ),
        ));
    }
    let mut returns: Vec<Option<Return>> = vec![None; layout.columns * beams];
    for p in points {
        let ring = usize::from(p.ring);
        if ring >= beams {
            return Err(MapError::invalid(
                "cloud",
                format!("a point on ring {ring}, with {beams} beams"),
            ));
        }
        let local = Point3::from(p.xyz);
        let range = local.coords.norm();
        if !range.is_finite() || range == 0.0 {
            continue;
        }
        let slot = &mut returns[layout.column_of(azimuth(p)) * beams + ring];
        if slot.is_some_and(|r| f64::from(r.range_m) <= range) {
            continue;
        }
        *slot = Some(Return {
            point_in_world: world_from_sensor * local,
            range_m: range as f32,
            intensity: p.intensity,
        });
    }
    let columns = vec![
        ScanColumn {
            world_from_sensor: *world_from_sensor,
            world_from_vehicle: *world_from_vehicle,
        };
        layout.columns
    ];
    Scan::new(beams, columns, returns)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A revolution of `columns` firings from `phase`, 8 rings, every third firing of the upper
    /// rings without a return; points shuffled.
    fn revolution(columns: usize, phase: f64) -> Vec<SensorPoint> {
        let mut points = Vec::new();
        for c in 0..columns {
            let az = phase + std::f64::consts::TAU * c as f64 / columns as f64;
            for ring in 0..8u16 {
                if ring >= 4 && c % 3 == 0 {
                    continue;
                }
                let el = (-15.0 + 3.0 * f64::from(ring)).to_radians();
                let range = 5.0 + 0.01 * c as f64 + f64::from(ring);
                points.push(SensorPoint {
                    xyz: [
                        range * el.cos() * az.cos(),
                        range * el.cos() * az.sin(),
                        range * el.sin(),
                    ]
                    .map(|v| f64::from(v as f32)),
                    ring,
                    intensity: 0.5,
                });
            }
        }
        // A deterministic shuffle: drivers write firings in their own order.
        let n = points.len();
        (0..n).map(|i| points[(i * 7919) % n]).collect()
    }

    /// The layout is found from the cloud (count and phase), and every point lands in its own
    /// firing's column on its ring, whatever the order it came in.
    #[test]
    fn a_shuffled_cloud_is_organised_into_its_firings() {
        for (columns, phase) in [(2187, 0.0), (1800, 0.001), (900, -0.003)] {
            let points = revolution(columns, phase);
            let layout = ColumnLayout::estimate(&points, None).unwrap();
            assert_eq!(layout.columns, columns);
            assert!((layout.phase_rad - phase).abs() < 1e-6, "{layout:?}");
            let scan = organise(
                &points,
                8,
                &layout,
                &Isometry3::identity(),
                &Isometry2::identity(),
            )
            .unwrap();
            let step = std::f64::consts::TAU / columns as f64;
            for c in 0..columns {
                let (_, col) = scan.column(c).unwrap();
                for (ring, r) in col.iter().enumerate() {
                    assert_eq!(
                        r.is_none(),
                        ring >= 4 && c % 3 == 0,
                        "column {c} ring {ring}"
                    );
                    if let Some(r) = r {
                        let az = r.point_in_world.y.atan2(r.point_in_world.x);
                        let d = (az - phase - c as f64 * step).rem_euclid(std::f64::consts::TAU);
                        assert!(d.min(std::f64::consts::TAU - d) < 1e-5);
                        let expect = 5.0 + 0.01 * c as f64 + ring as f64;
                        assert!((f64::from(r.range_m) - expect).abs() < 1e-4);
                    }
                }
            }
        }
    }

    /// Two points in one cell keep the nearer; a ring beyond the beams is an error; too few
    /// points give no layout.
    #[test]
    fn the_nearer_of_two_points_in_a_cell_is_kept() {
        let mut points = revolution(360, 0.0);
        let mut near = points[0];
        near.xyz = near.xyz.map(|v| v * 0.5);
        points.push(near);
        let layout = ColumnLayout::estimate(&points, Some(360)).unwrap();
        let scan = organise(
            &points,
            8,
            &layout,
            &Isometry3::identity(),
            &Isometry2::identity(),
        )
        .unwrap();
        let kept =
            scan.returns().iter().flatten().filter(|r| {
                (r.point_in_world.coords - Point3::from(near.xyz).coords).norm() < 1e-9
            });
        assert_eq!(kept.count(), 1);
        assert!(
            organise(
                &points,
                7,
                &layout,
                &Isometry3::identity(),
                &Isometry2::identity()
            )
            .is_err()
        );
        assert!(ColumnLayout::estimate(&points[..5], None).is_none());
        // A ring far above the others on a fine layout asks for 147 million returns: refused.
        let fine = ColumnLayout {
            columns: MAX_COLUMNS,
            phase_rad: 0.0,
        };
        let e = organise(
            &points,
            MAX_BEAMS,
            &fine,
            &Isometry3::identity(),
            &Isometry2::identity(),
        );
        assert!(e.is_err_and(|e| e.to_string().contains("returns a revolution")));
    }
}
