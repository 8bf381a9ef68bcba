//! Moving objects, so that what they leave behind can be cleared without forgetting by time:
//! each revolution's obstacle hits are clustered, clusters are associated with tracks, and a
//! track that has travelled well beyond its own size clears the cells it painted and has left.
//!
//! The rule a map needs for permanence is that a cell fades only on evidence: a beam through it
//! (the free-space walks of [`crate::map`]). A vehicle crossing ahead of a jet leaves a trail of
//! cells the airframe then hides, for which no beam ever comes; the evidence here is that the
//! object that painted them is seen elsewhere. Why a static object cannot pass for a moving one:
//! the part of it the sensor sees always lies within the object, so the centre of its hits moves
//! less than the object's extent however it is hidden or revealed. A track is confirmed moving
//! only once its centre has travelled more than [`TrackerConfig::extent_factor`] times the
//! largest extent it was seen with (and at least [`TrackerConfig::min_travel_m`]), steadily
//! (its path no longer than [`TrackerConfig::max_path_ratio`] times that travel, plus a metre),
//! and only objects smaller than [`TrackerConfig::max_object_m`] may move (the visible stretch
//! of a long wall slides along with the vehicle). The extent is the one seen, and a static
//! object the offline map does not hold may show only a sliver of itself, which slides along
//! it as the sensor moves (a parked aircraft's side at grazing incidence): a track seen mostly
//! on or beside cells hit well before it was first seen, by no mover, travels nothing. A track
//! lost from view clears nothing: what it painted keeps its state. A track clears only on a
//! revolution that continued its motion (seen the revolution before, its step where its
//! velocity said, within half its extent), and only cells it hit since its last jump: a step its
//! motion does not explain may be another object's hits taken over, so what it painted before
//! is no longer its to clear, nor what it took over.
//!
//! The files, by job: [`TrackerConfig`] (`config`), the constant-velocity filter on a track's
//! centre (`motion`), a track and how a revolution's cluster moves it on (`track`), one
//! revolution's hits grouped into objects (`clustering`) and matched with tracks
//! (`association`), the cells a mover has left (`clearing`), and what the tracker offers for
//! prediction ([`TrackState`], [`MovingObject`]: `state`); the [`Tracker`] itself here.

mod association;
mod clearing;
mod clustering;
mod config;
mod motion;
mod state;
mod track;

#[cfg(test)]
mod tests;

use foldhash::HashMap;

use nalgebra::{Isometry2, Point2};

use crate::map::WorldCell;

pub use config::TrackerConfig;

/// Where the vehicle was when a revolution was seen, and the height below which an object is
/// low (the vehicle's lowest level above the ground): what a low object's travel is measured
/// against ([`Tracker::update_except`]).
#[derive(Clone, Copy, Debug)]
pub struct SeenFrom {
    /// The vehicle's pose in the world, as the revolution's points were placed with.
    pub vehicle: Isometry2<f64>,
    /// An object seen in level 0 alone, with beams passing over it below this, is low, metres.
    pub low_below_m: f32,
}
pub use state::{MovingObject, TrackState};
use track::Track;

/// A track's peak speed ([`TrackState::peak_speed_m_s`]) is the fastest over this long,
/// seconds.
pub const PEAK_SPEED_S: f64 = 3.0;

/// ... of the velocities within this of its heading now, radians (45 degrees): not a speed it
/// had going another way.
pub const PEAK_HEADING_RAD: f64 = std::f64::consts::FRAC_PI_4;

/// Who painted a cell last, and when a revolution last hit it.
#[derive(Clone, Copy, Debug)]
struct CellRecord {
    owner: u32,
    last_hit_s: f64,
    /// When a revolution first hit it since its record was made (the tracker started, or a
    /// prune or a mover's clearing dropped it), seconds.
    first_hit_s: f64,
    /// Whether a track offered for prediction as of the revolution before (or confirmed
    /// moving) has hit it.
    by_mover: bool,
}

/// The tracker: tracks, and the owner and last hit of every cell hit since it started (pruned
/// to a square around the vehicle).
#[derive(Clone, Debug)]
pub struct Tracker {
    config: TrackerConfig,
    resolution_m: f64,
    tracks: Vec<Track>,
    next_id: u32,
    cells: HashMap<WorldCell, CellRecord>,
    /// Where the vehicle was when the revolution being taken in was seen, and what is low
    /// (`None`: not told).
    seen_from: Option<SeenFrom>,
}

impl Tracker {
    /// A tracker for maps of `resolution_m` cells.
    pub fn new(config: TrackerConfig, resolution_m: f64) -> Self {
        Tracker {
            config,
            resolution_m,
            tracks: Vec::new(),
            next_id: 0,
            cells: HashMap::default(),
            seen_from: None,
        }
    }

    /// [`Tracker::update_with_levels`] for hits of level 0.
    pub fn update(&mut self, t_s: f64, hits: &[WorldCell]) -> Vec<WorldCell> {
        let hits: Vec<(WorldCell, u32)> = hits.iter().map(|&c| (c, 1)).collect();
        self.update_with_levels(t_s, &hits)
    }

    /// Takes one revolution's obstacle hits (world cells, each with the levels it was hit in,
    /// bit `l` for level `l`) at `t_s`. Returns the cells to clear: painted by a track
    /// confirmed moving and seen this revolution, whose centre is now farther from them than its
    /// largest extent plus the clear margin, and not hit by anything since.
    pub fn update_with_levels(&mut self, t_s: f64, hits: &[(WorldCell, u32)]) -> Vec<WorldCell> {
        self.update_except(t_s, None, hits, &[], |_| false)
    }

    /// [`Tracker::update_with_levels`], but the hits on cells `is_static` names (an offline
    /// map's obstacles) are only noted as hit: no object is clustered from them, so a static
    /// object never passes for a mover, and a mover passing one (a truck beside a lamp post)
    /// is followed on its own hits. `open_tops` (sorted by cell, as
    /// `MultiHeightMap::last_scan_open_tops` gives them) says how high the object hit in a cell
    /// may reach unseen ([`TrackState::open_top_m`]). `seen_from`: where the vehicle was; a
    /// low track (hit in level 0 alone, beams passing over it below `SeenFrom::low_below_m`)
    /// whose travel as seen from the vehicle is under a quarter of its travel over the ground
    /// does not move (what shows of a low wall slides along with the sensor: `Track::travel_m`).
    pub fn update_except(
        &mut self,
        t_s: f64,
        seen_from: Option<SeenFrom>,
        hits: &[(WorldCell, u32)],
        open_tops: &[(WorldCell, f32)],
        is_static: impl Fn(WorldCell) -> bool,
    ) -> Vec<WorldCell> {
        self.seen_from = seen_from;
        for &(c, _) in hits {
            self.cells
                .entry(c)
                .and_modify(|r| r.last_hit_s = t_s)
                .or_insert(CellRecord {
                    owner: u32::MAX,
                    last_hit_s: t_s,
                    first_hit_s: t_s,
                    by_mover: false,
                });
        }
        if !self.config.enabled {
            return Vec::new();
        }
        let movable: Vec<(WorldCell, u32)> = hits
            .iter()
            .copied()
            .filter(|&(c, _)| !is_static(c))
            .collect();
        let mut clusters = self.clusters(&movable);
        for cl in &mut clusters {
            cl.open_top_m = cl
                .cells
                .iter()
                .filter_map(|c| {
                    let k = open_tops.binary_search_by(|(o, _)| o.cmp(c)).ok()?;
                    Some(open_tops[k].1)
                })
                .reduce(f32::max);
        }
        let assigned = self.associate(t_s, &clusters);
        for t in &mut self.tracks {
            t.bbox = None;
        }
        for (ci, cluster) in clusters.iter().enumerate() {
            let ti = match assigned[ci] {
                Some(ti) => ti,
                None => self.new_track(t_s, cluster),
            };
            self.follow(ti, t_s, cluster);
        }
        let clear = self.clear_left_cells(t_s);
        self.mark_predictable();
        let (lost_after, coast) = (self.config.lost_after_s, self.config.coast_s);
        self.tracks.retain(|t| {
            let unseen = t_s - t.last_t_s;
            unseen <= lost_after || (t.predictable && unseen <= coast)
        });
        clear
    }

    /// When a revolution last hit `cell`, seconds (`None`: never, or pruned).
    pub fn last_hit_s(&self, cell: WorldCell) -> Option<f64> {
        self.cells.get(&cell).map(|r| r.last_hit_s)
    }

    /// The tracks confirmed moving and seen this revolution.
    pub fn moving_objects(&self) -> Vec<MovingObject> {
        self.tracks
            .iter()
            .filter(|t| t.moving && t.bbox.is_some())
            .map(|t| MovingObject {
                id: t.id,
                position: t.last,
                travel_m: t.ground_travel_m(),
            })
            .collect()
    }

    /// Forgets the cells outside the square of half side `half_m` around `center` (they left
    /// the map's window; their state there is the map's, not the tracker's).
    pub fn prune(&mut self, center: &Point2<f64>, half_m: f64) {
        let r = self.resolution_m;
        let (cx, cy) = ((center.x / r).floor() as i64, (center.y / r).floor() as i64);
        let half = (half_m / r).ceil() as i64;
        self.cells
            .retain(|c, _| (c.0 - cx).abs() <= half && (c.1 - cy).abs() <= half);
    }
}
