//! How high an object may reach where the sensor cannot see: the beam above each obstacle
//! return, in its column, says whether it passed over the object there (its top is below the
//! beam's height at the object's range) or was stopped nearer (the top is unknown).
//!
//! A mover's height span comes from its hits; a nose sensor 1.55 m up sees a 1.5 m van's side
//! only below 1.1 m from 19 m out (its 0-degree beam passes over the roof, the next one down
//! hits below 1.1 m), so the van seemed a ground-level object a wing passes over. With the
//! open top the tracker knows the van may reach 1.55 m there, and a 1.0 m baggage cart seen
//! at 10 m, where the -2.67-degree beam passes over it at 1.08 m, that it stays below 1.1 m.

use nalgebra::Vector3;

use super::MultiHeightMap;
use super::WorldCell;
use super::classified::{Classified, DROPPED};
use crate::scan::{Return, Scan, ScanColumn};

/// A return the beam above says nothing of (it is not the top of its column's hits on the
/// object: the beam above hit the object too, and claims for it).
pub(super) const NO_CLAIM: f32 = f32::NEG_INFINITY;

/// The beam above on the object itself: its echo within this horizontal range of the return
/// below, metres.
const SAME_OBJECT_M: f64 = 0.5;

/// Each beam's elevation in the sensor frame, radians, from its first return in `scan` (`None`:
/// the beam has no return anywhere). A beam's elevation is fixed in the sensor's frame; the
/// elevation of a beam with no echo in one column is read from another.
pub(super) fn beam_elevations(scan: &Scan) -> Vec<Option<f64>> {
    let beams = scan.beams();
    let mut elevation = vec![None; beams];
    let mut missing = beams;
    for (c, column) in scan.columns().iter().enumerate() {
        if missing == 0 {
            break;
        }
        let sensor_from_world = column.world_from_sensor.inverse();
        for (b, e) in elevation.iter_mut().enumerate() {
            if e.is_none()
                && let Some(r) = scan.returns()[c * beams + b]
            {
                let p = sensor_from_world * r.point_in_world;
                *e = Some(p.z.atan2(p.x.hypot(p.y)));
                missing -= 1;
            }
        }
    }
    elevation
}

/// How many returns of a beam must agree on its elevation, within [`AGREE_RAD`], for the map to
/// remember it across revolutions ([`agreed_elevations`]).
const AGREEING_RETURNS: usize = 3;
/// Radians.
const AGREE_RAD: f64 = 0.002;

/// Each beam's elevation as [`beam_elevations`] read it (`first`), kept only where at least
/// [`AGREEING_RETURNS`] returns of the beam in `scan` agree with it: what the map remembers of a
/// beam's elevation across revolutions. A stray return (a fault's spurious one, placed level
/// ahead of the sensor) on a dead beam does not give it an elevation for good.
pub(super) fn agreed_elevations(scan: &Scan, first: &[Option<f64>]) -> Vec<Option<f64>> {
    let beams = scan.beams();
    let mut agree = vec![0usize; beams];
    let mut pending = first.iter().filter(|e| e.is_some()).count();
    for (c, column) in scan.columns().iter().enumerate() {
        if pending == 0 {
            break;
        }
        let sensor_from_world = column.world_from_sensor.inverse();
        for (b, n) in agree.iter_mut().enumerate() {
            let (Some(e0), Some(r)) = (first[b], scan.returns()[c * beams + b]) else {
                continue;
            };
            if *n >= AGREEING_RETURNS {
                continue;
            }
            let p = sensor_from_world * r.point_in_world;
            if (p.z.atan2(p.x.hypot(p.y)) - e0).abs() <= AGREE_RAD {
                *n += 1;
                if *n == AGREEING_RETURNS {
                    pending -= 1;
                }
            }
        }
    }
    first
        .iter()
        .zip(&agree)
        .map(|(e, &n)| e.filter(|_| n >= AGREEING_RETURNS))
        .collect()
}

/// The open top of each obstacle return of one column (`Classified::open_top_m`, heights above
/// `ground_m`): the beam above passing over the object (no echo, or an echo
/// [`SAME_OBJECT_M`] or more beyond it) says its top there is below the beam's height at its
/// range; stopped nearer (by something before it, or the vehicle itself), or no beam above,
/// the top is unknown (infinity); on the object too, the return above claims for it
/// ([`NO_CLAIM`]) if it is an obstacle return, else (above the ceiling, or a face the obstacle
/// test passed) the top is unknown.
pub(super) fn claim_open_tops(
    out: &mut [Classified],
    returns: &[Option<Return>],
    column: &ScanColumn,
    elevations: &[Option<f64>],
    ground_m: f64,
) {
    let sensor = column.world_from_sensor.translation.vector;
    for b in 0..out.len() {
        let c = out[b];
        if c.cell == DROPPED || !c.obstacle {
            continue;
        }
        let range = f64::from(c.range_xy_m);
        let claim = match (returns.get(b + 1), out.get(b + 1)) {
            (Some(Some(above)), Some(&above_c)) => {
                let p = above.point_in_world;
                let range_above = (p.x - sensor.x).hypot(p.y - sensor.y);
                if range_above >= range + SAME_OBJECT_M {
                    sensor.z + (p.z - sensor.z) * range / range_above - ground_m
                } else if range_above > range - SAME_OBJECT_M
                    && above_c.cell != DROPPED
                    && above_c.obstacle
                {
                    f64::NEG_INFINITY
                } else {
                    f64::INFINITY
                }
            }
            (Some(None), _) => match (elevations[b + 1], returns[b]) {
                (Some(elevation), Some(r)) => {
                    let up = beam_rise(column, &r.point_in_world, elevation);
                    sensor.z + range * up - ground_m
                }
                _ => f64::INFINITY,
            },
            _ => f64::INFINITY,
        };
        out[b].open_top_m = claim as f32;
    }
}

/// The rise per horizontal metre, in the world, of the beam of `elevation` (sensor frame) in
/// the azimuth of the return at `point`.
pub(super) fn beam_rise(column: &ScanColumn, point: &nalgebra::Point3<f64>, elevation: f64) -> f64 {
    BeamRises::new(column, point).rise((elevation.cos(), elevation.sin()))
}

/// [`beam_rise`] of many beams in the azimuth of one return: the azimuth (an inverse transform,
/// an arctangent, a sine and a cosine) found once, each beam given its elevation's cosine and
/// sine ([`beam_rise`] is one of these, so the two agree bit for bit). A column's free-space walk
/// asks it for every beam when it meets an older occupied cell: with the azimuth's work in each
/// beam's rise, the parking lot's run took 1.15-1.18x the wall time (medians of two A/B series,
/// `run scenarios/parking_lot.toml --time-limit-s 120`, whole processes in alternation, the same
/// report); at the aerodrome and KSYR, whose walks meet fewer older obstacles, 1.00.
pub(super) struct BeamRises<'a> {
    column: &'a ScanColumn,
    cos_azimuth: f64,
    sin_azimuth: f64,
}

impl<'a> BeamRises<'a> {
    /// The beams of `column` in the azimuth of the return at `point`.
    pub(super) fn new(column: &'a ScanColumn, point: &nalgebra::Point3<f64>) -> Self {
        let s = column.world_from_sensor.inverse() * point;
        let azimuth = s.y.atan2(s.x);
        BeamRises {
            column,
            cos_azimuth: azimuth.cos(),
            sin_azimuth: azimuth.sin(),
        }
    }

    /// The rise per horizontal metre of the beam whose elevation has this cosine and sine.
    pub(super) fn rise(&self, (cos_e, sin_e): (f64, f64)) -> f64 {
        let d = self.column.world_from_sensor.rotation
            * Vector3::new(cos_e * self.cos_azimuth, cos_e * self.sin_azimuth, sin_e);
        d.z / d.x.hypot(d.y).max(1e-9)
    }
}

impl MultiHeightMap {
    /// The cells the last revolution hit as obstacles with an open top: how high, above the
    /// ground, the object hit there may reach unseen, metres - the beam above passed over it at
    /// that height (the largest of the cell's claims; infinity: a beam above was stopped
    /// nearer, the top is unknown). Cells none of whose hits is the top of its column's hits on
    /// the object are left out. In world-lattice order; empty after a re-centre until the next
    /// insertion.
    pub fn last_scan_open_tops(&self) -> Vec<(WorldCell, f32)> {
        let width = self.geometry.width();
        let (x0, y0) = self.window_cell0();
        let mut all: Vec<(WorldCell, f32)> = self
            .classified
            .iter()
            .filter(|c| c.cell != DROPPED && c.obstacle && c.open_top_m != NO_CLAIM)
            .map(|c| {
                let i = c.cell as usize;
                (
                    ((i % width) as i64 + x0, (i / width) as i64 + y0),
                    c.open_top_m,
                )
            })
            .collect();
        all.sort_unstable_by_key(|a| a.0);
        all.dedup_by(|later, first| {
            if later.0 == first.0 {
                first.1 = first.1.max(later.1);
                true
            } else {
                false
            }
        });
        all
    }
}
