//! Beams that passed through a place: one revolution's evidence that nothing stood there.
//!
//! A track the tracker lost goes on as a prediction (it coasts). Where the sensor cannot see
//! (the airframe's shadow, behind another object) the prediction is all there is; where beams
//! passed low through the place the prediction puts it, and went on beyond it, nothing was
//! there. [`ColumnIndex`] finds those beams in a revolution's scans without reading every
//! return: its columns sorted by azimuth from the sensor.

use mapper::{Scan, TrackState};
use nalgebra::{Point2, Vector2};

use crate::traffic::reach;

/// Only tracks this small or smaller have their way checked, metres (a person, a cart, a
/// cone): a larger vehicle's body may stand clear of the ground between its wheels, where a
/// beam passes under it.
pub const WAY_CHECKED_EXTENT_M: f64 = 2.0;

/// Places along a way are this far apart, metres.
const WAY_STEP_M: f64 = 0.5;

/// Beams that must pass through each place of a way ([`way_seen_empty`]) - with none hitting
/// something there: one beam may pass between a person's legs.
const BEAMS_PER_PLACE: usize = 2;

/// How much farther than its peak speed a lost track's way is checked: it may have gone faster
/// than it was seen going (seen a moment only, its speed is least sure), ...
const WAY_SPEED_MARGIN: f64 = 1.5;

/// A beam passes through a place low enough to meet an object there from this above the
/// ground, metres (the obstacle test's least height, and a little), ...
const LOWEST_M: f64 = 0.15;
/// ... up to the lowest height of the highest level it was hit in, or this at least, metres.
const HIGHEST_AT_LEAST_M: f64 = 0.3;

/// The columns of one revolution's scans, by the azimuth of their first return as seen from
/// their sensor.
pub struct ColumnIndex<'a> {
    scans: Vec<&'a Scan>,
    /// (azimuth in radians, scan, column), sorted by azimuth.
    by_azimuth: Vec<(f64, usize, usize)>,
    /// Where the first sensor was (the others are near it), for a place's azimuth.
    origin: Point2<f64>,
}

/// What a beam must do to have passed through a place ([`ColumnIndex::beams_through`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Through {
    /// Its height where it passes the place, world z: from .. to, metres.
    pub band_z: (f64, f64),
    /// Its track over the ground passes within this of the place, metres.
    pub lateral_m: f64,
    /// Its return lies this much farther from the sensor than the place or more, metres (what
    /// it hit is not what stood there).
    pub beyond_m: f64,
    /// A return within the band this near the place, metres, is something standing there: no
    /// beam passed through it.
    pub veto_m: f64,
}

/// How far a sensor may move in a revolution, metres (a vehicle at 10 m/s, a 10 Hz sensor):
/// a column's azimuth is searched this much wider either side.
const SENSOR_TRAVEL_M: f64 = 1.0;

impl<'a> ColumnIndex<'a> {
    /// The index of `scans`' columns (a column with no return is left out).
    pub fn new(scans: impl IntoIterator<Item = &'a Scan>) -> Self {
        let scans: Vec<&Scan> = scans.into_iter().collect();
        let mut by_azimuth = Vec::new();
        let mut origin = None;
        for (k, scan) in scans.iter().enumerate() {
            for c in 0..scan.column_count() {
                let Some((col, returns)) = scan.column(c) else {
                    continue;
                };
                let Some(first) = returns.iter().flatten().next() else {
                    continue;
                };
                let o = col.world_from_sensor.translation.vector;
                origin.get_or_insert(Point2::new(o.x, o.y));
                let d = first.point_in_world.coords - o;
                by_azimuth.push((d.y.atan2(d.x), k, c));
            }
        }
        by_azimuth.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        ColumnIndex {
            scans,
            by_azimuth,
            origin: origin.unwrap_or_else(Point2::origin),
        }
    }

    /// How many returns passed through the place `p` as `through` says: from their sensor,
    /// their track over the ground passes within `lateral_m` of `p`, at a height within
    /// `band_z` there, and they hit `beyond_m` or more farther on. `None` when a return within
    /// the band hit something within `veto_m` of `p`.
    pub fn beams_through(&self, p: &Point2<f64>, through: &Through) -> Option<usize> {
        let to = p - self.origin;
        let d = to.norm();
        let near = through.lateral_m.max(through.veto_m) + SENSOR_TRAVEL_M;
        let half = if d <= near {
            std::f64::consts::PI
        } else {
            (near / d).asin()
        };
        let az = to.y.atan2(to.x);
        self.columns_within(az - half, az + half)
            .try_fold(0, |n, (k, c)| {
                Some(n + self.through_in_column(k, c, p, through)?)
            })
    }

    /// The (scan, column) pairs whose azimuth lies within `lo..=hi` (radians, wrapped).
    fn columns_within(&self, lo: f64, hi: f64) -> impl Iterator<Item = (usize, usize)> + '_ {
        use std::f64::consts::{PI, TAU};
        let range = |lo: f64, hi: f64| {
            let a = self.by_azimuth.partition_point(|e| e.0 < lo);
            let b = self.by_azimuth.partition_point(|e| e.0 <= hi);
            a..b.max(a)
        };
        let (first, second) = if hi - lo >= TAU {
            (0..self.by_azimuth.len(), 0..0)
        } else if lo < -PI {
            (range(lo + TAU, PI), range(-PI, hi))
        } else if hi > PI {
            (range(lo, PI), range(-PI, hi - TAU))
        } else {
            (range(lo, hi), 0..0)
        };
        (first.chain(second)).map(|i| (self.by_azimuth[i].1, self.by_azimuth[i].2))
    }

    /// How many returns of column `c` of scan `k` passed through `p`; `None` when one hit
    /// something there ([`Self::beams_through`]).
    fn through_in_column(
        &self,
        k: usize,
        c: usize,
        p: &Point2<f64>,
        through: &Through,
    ) -> Option<usize> {
        let (col, returns) = self.scans[k].column(c)?;
        let o = col.world_from_sensor.translation.vector;
        let to_p = Point2::new(p.x - o.x, p.y - o.y);
        let d_p = to_p.coords.norm();
        let in_band = |z: f64| (through.band_z.0..=through.band_z.1).contains(&z);
        let mut n = 0;
        for r in returns.iter().flatten() {
            let w = r.point_in_world;
            if in_band(w.z) && (w.x - p.x).hypot(w.y - p.y) <= through.veto_m {
                return None;
            }
            let h = w.coords - o;
            let d_h = h.x.hypot(h.y);
            if d_h < d_p + through.beyond_m || d_h <= 0.0 {
                continue;
            }
            let (ux, uy) = (h.x / d_h, h.y / d_h);
            let along = to_p.x * ux + to_p.y * uy;
            let aside = (to_p.y * ux - to_p.x * uy).abs();
            if along > 0.0 && aside <= through.lateral_m && in_band(o.z + h.z * along / d_h) {
                n += 1;
            }
        }
        Some(n)
    }
}

/// Whether lost track `t`'s way is checked at all ([`way_seen_empty`]): no larger than
/// [`WAY_CHECKED_EXTENT_M`], and hit in the lowest level - one that is not may be overhead (a
/// wing passing), and beams pass under it.
pub fn way_checked(t: &TrackState) -> bool {
    t.extent_m <= WAY_CHECKED_EXTENT_M && t.levels & 1 != 0
}

/// Whether the way lost track `t` went by `now_s`, as far as [`WAY_SPEED_MARGIN`] times its
/// peak speed takes it, was seen empty by the revolution `index` holds: at every place on it
/// from where it was last seen, and across it as wide as the track, [`WAY_STEP_M`] apart or
/// less, [`BEAMS_PER_PLACE`] beams passed through, none hitting something there, from
/// [`LOWEST_M`] above the ground at `ground_z` up to the lowest height (`level_heights_m`) of the
/// highest level it was hit in, and went on beyond it. Then it neither went that way nor stopped
/// on it: a part of a parked aircraft that seemed to slide as the vehicle went by, not a mover.
/// Not a track larger than [`WAY_CHECKED_EXTENT_M`], nor one not hit in the lowest level (always
/// `false`). `ground_z` is the map's ground (the obstacle test's): on a sloping apron the band
/// sits higher or lower above the ground there.
pub fn way_seen_empty(
    index: &ColumnIndex,
    t: &TrackState,
    now_s: f64,
    ground_z: f64,
    level_heights_m: &[f64],
) -> bool {
    if !way_checked(t) {
        return false;
    }
    let highest = 31 - t.levels.leading_zeros() as usize;
    let top = level_heights_m.get(highest).copied().unwrap_or(0.0);
    let through = Through {
        band_z: (ground_z + LOWEST_M, ground_z + top.max(HIGHEST_AT_LEAST_M)),
        lateral_m: 0.25,
        beyond_m: 0.5 * t.extent_m + 0.25,
        veto_m: (0.5 * t.extent_m).max(0.25),
    };
    // ... and its half-length past that.
    let (_, fast, _) = reach(t, (now_s - t.t_s).max(0.0));
    let peak = fast - t.position;
    let way = match peak.try_normalize(1e-12) {
        Some(u) => peak * WAY_SPEED_MARGIN + u * 0.5 * t.extent_m,
        None => peak,
    };
    let n = (way.norm() / WAY_STEP_M).ceil().max(1.0);
    // Across the way as wide as the track: a walker a little off the line read is still on it.
    let along = if way.norm() > 1e-9 { way } else { t.velocity };
    let across = match along.try_normalize(1e-12) {
        Some(u) => Vector2::new(-u.y, u.x) * 0.5 * t.extent_m,
        None => Vector2::zeros(),
    };
    let m = (0.5 * t.extent_m / WAY_STEP_M).ceil().max(1.0);
    let offsets = (-(m as i64)..=m as i64).map(|j| across * (j as f64 / m));
    let offsets: Vec<Vector2<f64>> = offsets.collect();
    (0..=n as usize).all(|i| {
        let at = t.position + way * (i as f64 / n);
        (offsets.iter()).all(|o| {
            index
                .beams_through(&(at + o), &through)
                .is_some_and(|n| n >= BEAMS_PER_PLACE)
        })
    })
}

#[cfg(test)]
#[path = "beams_through_tests.rs"]
mod tests;
