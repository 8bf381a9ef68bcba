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
//! of a long wall slides along with the vehicle). A track lost from view clears nothing: what it
//! painted keeps its state. A track clears only on a revolution that continued its motion (seen
//! the revolution before, its step where its velocity said, within half its extent), and only
//! cells it hit since its last jump: a step its motion does not explain may be another object's
//! hits taken over, so what it painted before is no longer its to clear, nor what it took over.

use foldhash::HashMap;

use nalgebra::Point2;
use serde::{Deserialize, Serialize};

use crate::map::WorldCell;

/// What the tracker of moving objects does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrackerConfig {
    /// Track moving objects and clear what they leave. Default true; false: nothing but beams
    /// clears a cell (a moving object's hidden trail stays for ever).
    pub enabled: bool,
    /// Hits closer than this belong to one object (hits up to twice as far apart may), metres.
    /// Default 0.6.
    pub cluster_gap_m: f64,
    /// Fastest object followed from one revolution to the next, m/s. Default 15.
    pub max_speed_m_s: f64,
    /// Objects wider than this (walls, buildings) never count as moving, metres. Default 15.
    pub max_object_m: f64,
    /// A track moves once it has travelled at least this far, metres. Default 2.
    pub min_travel_m: f64,
    /// ... and more than this many times its largest extent. Default 1.5.
    pub extent_factor: f64,
    /// ... along a path at most this many times that travel (plus 1 m). Default 1.5.
    pub max_path_ratio: f64,
    /// Cells a moving track painted are cleared once the centre of its hits is farther from them
    /// than its largest extent plus this, metres. Default 1.
    pub clear_margin_m: f64,
    /// Tracks unseen this long are dropped (what they painted keeps its state), seconds.
    /// Default 2.
    pub lost_after_s: f64,
    /// A track seen again after a longer gap neither clears nor paints on that revolution,
    /// seconds. Default 0.25 (two revolutions at 10 Hz).
    pub max_gap_s: f64,
    /// ... nor one whose step misses where its velocity said by more than this plus half its
    /// largest extent (what hiding or revealing part of it can shift its centre by), metres: a
    /// track that jumped to another object's hits. Default 0.5.
    pub max_step_error_m: f64,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        TrackerConfig {
            enabled: true,
            cluster_gap_m: 0.6,
            max_speed_m_s: 15.0,
            max_object_m: 15.0,
            min_travel_m: 2.0,
            extent_factor: 1.5,
            max_path_ratio: 1.5,
            clear_margin_m: 1.0,
            lost_after_s: 2.0,
            max_gap_s: 0.25,
            max_step_error_m: 0.5,
        }
    }
}

impl TrackerConfig {
    /// The first field out of range, as (name, value).
    pub fn invalid_field(&self) -> Option<(&'static str, f64)> {
        let positive = [
            ("cluster_gap_m", self.cluster_gap_m),
            ("max_speed_m_s", self.max_speed_m_s),
            ("max_object_m", self.max_object_m),
            ("extent_factor", self.extent_factor),
            ("max_path_ratio", self.max_path_ratio),
            ("lost_after_s", self.lost_after_s),
            ("max_gap_s", self.max_gap_s),
            ("max_step_error_m", self.max_step_error_m),
        ];
        let non_negative = [
            ("min_travel_m", self.min_travel_m),
            ("clear_margin_m", self.clear_margin_m),
        ];
        positive
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v > 0.0))
            .or_else(|| {
                non_negative
                    .into_iter()
                    .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
            })
    }
}

/// One object being followed.
#[derive(Clone, Debug)]
struct Track {
    id: u32,
    first: Point2<f64>,
    last: Point2<f64>,
    last_t_s: f64,
    /// Sum of the centre's steps, metres.
    path_m: f64,
    /// Largest extent (bounding-box diagonal) it was seen with, metres.
    max_extent_m: f64,
    /// Its cells this revolution: bounding box (world cells), when seen.
    bbox: Option<(WorldCell, WorldCell)>,
    /// Revolutions it was seen in since it was created or started over.
    seen: u32,
    /// Velocity of its centre, m/s (smoothed).
    velocity: nalgebra::Vector2<f64>,
    moving: bool,
    /// Whether this revolution's step continued its motion (seen the revolution before, where
    /// its velocity said): only then may a moving track clear.
    smooth: bool,
    /// Cells it painted (some may since belong to another track).
    painted: Vec<WorldCell>,
}

/// A moving object as the tracker sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingObject {
    /// Track id.
    pub id: u32,
    /// Centre of its hits, metres.
    pub position: Point2<f64>,
    /// Distance travelled since first seen, metres.
    pub travel_m: f64,
}

/// Who painted a cell last, and when a revolution last hit it.
#[derive(Clone, Copy, Debug)]
struct CellRecord {
    owner: u32,
    last_hit_s: f64,
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
}

/// A cluster of one revolution's hits.
struct Cluster {
    cells: Vec<WorldCell>,
    center: Point2<f64>,
    bbox: (WorldCell, WorldCell),
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
        }
    }

    /// Takes one revolution's obstacle hits (world cells, any level) at `t_s`. Returns the cells
    /// to clear: painted by a track confirmed moving and seen this revolution, whose centre is
    /// now farther from them than its largest extent plus the clear margin, and not hit by
    /// anything since.
    pub fn update(&mut self, t_s: f64, hits: &[WorldCell]) -> Vec<WorldCell> {
        for &c in hits {
            self.cells
                .entry(c)
                .and_modify(|r| r.last_hit_s = t_s)
                .or_insert(CellRecord {
                    owner: u32::MAX,
                    last_hit_s: t_s,
                });
        }
        if !self.config.enabled {
            return Vec::new();
        }
        let clusters = self.clusters(hits);
        let assigned = self.associate(t_s, &clusters);
        for t in &mut self.tracks {
            t.bbox = None;
        }
        let mut clear = Vec::new();
        for (ci, cluster) in clusters.iter().enumerate() {
            let ti = match assigned[ci] {
                Some(ti) => ti,
                None => {
                    self.tracks.push(Track {
                        id: self.next_id,
                        first: cluster.center,
                        last: cluster.center,
                        last_t_s: t_s,
                        path_m: 0.0,
                        max_extent_m: 0.0,
                        bbox: None,
                        seen: 0,
                        velocity: nalgebra::Vector2::zeros(),
                        moving: false,
                        smooth: false,
                        painted: Vec::new(),
                    });
                    self.next_id = self.next_id.wrapping_add(1);
                    self.tracks.len() - 1
                }
            };
            let track = &mut self.tracks[ti];
            let dt = t_s - track.last_t_s;
            let step = cluster.center - track.last;
            // A step its velocity does not explain (or after a gap) may be another object's hits
            // taken over, or the same object seen anew.
            track.smooth = dt > 0.0
                && dt <= self.config.max_gap_s
                && (step - track.velocity * dt).norm()
                    <= self.config.max_step_error_m + 0.5 * track.max_extent_m;
            if dt > 0.0 && !track.smooth && track.seen > 1 {
                // Perhaps another object's hits now: what it painted so far is no longer its
                // to clear (it keeps its state).
                track.painted.clear();
            }
            if dt > 0.0 {
                track.velocity = 0.5 * track.velocity + 0.5 * step / dt;
                track.path_m += step.norm();
            }
            track.seen += 1;
            track.last = cluster.center;
            track.last_t_s = t_s;
            track.bbox = Some(cluster.bbox);
            let (lo, hi) = cluster.bbox;
            let extent = self.resolution_m
                * (((hi.0 - lo.0 + 1).pow(2) + (hi.1 - lo.1 + 1).pow(2)) as f64).sqrt();
            track.max_extent_m = track.max_extent_m.max(extent);
            // What it hits on a step its motion does not explain (it took over another
            // object's hits) it owns, so no other track clears it, but never clears itself.
            let paints = track.smooth || track.seen <= 1;
            for &c in &cluster.cells {
                if let Some(r) = self.cells.get_mut(&c) {
                    if r.owner != track.id && paints {
                        track.painted.push(c);
                    }
                    r.owner = track.id;
                }
            }
            let travel = (track.last - track.first).norm();
            let cfg = &self.config;
            if !track.moving
                && track.max_extent_m <= cfg.max_object_m
                && travel >= cfg.min_travel_m.max(cfg.extent_factor * track.max_extent_m)
                && track.path_m <= cfg.max_path_ratio * travel + 1.0
            {
                track.moving = true;
            }
        }
        let r = self.resolution_m;
        for track in &mut self.tracks {
            if !(track.moving && track.smooth && track.bbox.is_some()) {
                continue;
            }
            // Every cell of the object lies within its extent of any point of it, the centre of
            // the hits seen now included, however much of it is hidden now.
            let reach = track.max_extent_m + self.config.clear_margin_m;
            let center = track.last;
            let cells = &mut self.cells;
            track.painted.retain(|c| {
                let Some(rec) = cells.get(c) else {
                    return false;
                };
                if rec.owner != track.id {
                    return false;
                }
                let at = Point2::new((c.0 as f64 + 0.5) * r, (c.1 as f64 + 0.5) * r);
                if (at - center).norm() <= reach || rec.last_hit_s == t_s {
                    return true;
                }
                clear.push(*c);
                cells.remove(c);
                false
            });
        }
        let lost_after = self.config.lost_after_s;
        self.tracks.retain(|t| t_s - t.last_t_s <= lost_after);
        clear.sort_unstable();
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
                travel_m: (t.last - t.first).norm(),
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

    /// Groups hits into objects: cells in buckets of the cluster gap, buckets joined to their
    /// eight neighbours.
    fn clusters(&self, hits: &[WorldCell]) -> Vec<Cluster> {
        let g = ((self.config.cluster_gap_m / self.resolution_m).ceil() as i64).max(1);
        let mut buckets: HashMap<(i64, i64), usize> = HashMap::default();
        let mut bucket_of = Vec::with_capacity(hits.len());
        for &(x, y) in hits {
            let key = (x.div_euclid(g), y.div_euclid(g));
            let n = buckets.len();
            bucket_of.push(*buckets.entry(key).or_insert(n));
        }
        let mut parent: Vec<usize> = (0..buckets.len()).collect();
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for (&(bx, by), &i) in &buckets {
            for (dx, dy) in [(1, -1), (1, 0), (1, 1), (0, 1)] {
                if let Some(&j) = buckets.get(&(bx + dx, by + dy)) {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    if a != b {
                        parent[a.max(b)] = a.min(b);
                    }
                }
            }
        }
        let mut index_of_root: HashMap<usize, usize> = HashMap::default();
        let mut clusters: Vec<Cluster> = Vec::new();
        let r = self.resolution_m;
        for (&c, &b) in hits.iter().zip(&bucket_of) {
            let root = find(&mut parent, b);
            let n = clusters.len();
            let k = *index_of_root.entry(root).or_insert(n);
            if k == n {
                clusters.push(Cluster {
                    cells: Vec::new(),
                    center: Point2::origin(),
                    bbox: (c, c),
                });
            }
            let cl = &mut clusters[k];
            cl.cells.push(c);
            cl.center.coords +=
                nalgebra::Vector2::new((c.0 as f64 + 0.5) * r, (c.1 as f64 + 0.5) * r);
            cl.bbox.0 = (cl.bbox.0.0.min(c.0), cl.bbox.0.1.min(c.1));
            cl.bbox.1 = (cl.bbox.1.0.max(c.0), cl.bbox.1.1.max(c.1));
        }
        for cl in &mut clusters {
            cl.center.coords /= cl.cells.len() as f64;
        }
        clusters
    }

    /// Each cluster's track (index into `tracks`), nearest pairs first, one to one, within what
    /// the fastest object could have covered since the track was last seen plus a metre.
    fn associate(&self, t_s: f64, clusters: &[Cluster]) -> Vec<Option<usize>> {
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (ci, c) in clusters.iter().enumerate() {
            for (ti, t) in self.tracks.iter().enumerate() {
                let gate = self.config.max_speed_m_s * (t_s - t.last_t_s).max(0.0) + 1.0;
                let d = (c.center - t.last).norm();
                if d <= gate {
                    pairs.push((d, ci, ti));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut cluster_track = vec![None; clusters.len()];
        let mut track_taken = vec![false; self.tracks.len()];
        for (_, ci, ti) in pairs {
            if cluster_track[ci].is_none() && !track_taken[ti] {
                cluster_track[ci] = Some(ti);
                track_taken[ti] = true;
            }
        }
        cluster_track
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cells of a `w` x `h` cell box with its lower-left cell at `(x, y)`.
    fn block(x: i64, y: i64, w: i64, h: i64) -> Vec<WorldCell> {
        let mut v = Vec::new();
        for j in y..y + h {
            for i in x..x + w {
                v.push((i, j));
            }
        }
        v
    }

    /// A 4.4 m object driving at 4 m/s: once it has travelled 1.5 times its extent its old cells
    /// are handed back, and never those within its extent plus the margin of where it is now.
    #[test]
    fn a_moving_object_clears_the_cells_it_left() {
        let mut t = Tracker::new(TrackerConfig::default(), 0.2);
        let mut cleared = Vec::new();
        for k in 0..80 {
            let y = k * 2; // 0.4 m a revolution at 0.2 m cells: 4 m/s at 10 Hz
            let now = block(0, y, 9, 22);
            cleared.extend(t.update(k as f64 * 0.1, &now));
            for c in &cleared {
                // The centre is at row y + 11, the extent 4.75 m: 5.75 m (28.75 cells) clear.
                assert!(
                    c.1 < y + 11 - 28,
                    "cleared {c:?} next to the object at row {y}"
                );
            }
        }
        assert!(!cleared.is_empty());
        assert!(cleared.contains(&(4, 0)), "its first cells are cleared");
        assert_eq!(t.moving_objects().len(), 1);
    }

    /// A static object seen from changing sides (its hits jump about within it, as a vehicle
    /// driving by sees first its front, then its side, then its back) never moves.
    #[test]
    fn a_static_object_seen_from_every_side_never_moves() {
        let mut t = Tracker::new(TrackerConfig::default(), 0.2);
        // An 8 x 6 m object.
        let faces = [
            block(0, 0, 40, 1),
            block(39, 0, 1, 30),
            block(0, 29, 40, 1),
            block(0, 0, 1, 30),
        ];
        for k in 0..200 {
            let face = &faces[(k / 10) % 4];
            assert!(t.update(k as f64 * 0.1, face).is_empty(), "revolution {k}");
        }
        assert!(t.moving_objects().is_empty());
    }

    /// A static object hidden little by little (its visible part shrinks towards one end) and
    /// then lost keeps every cell, and so does an object that moved but is no longer seen.
    #[test]
    fn what_is_hidden_is_never_cleared() {
        let mut t = Tracker::new(TrackerConfig::default(), 0.2);
        for k in 0..8 {
            assert!(t.update(k as f64 * 0.1, &block(k, 0, 8 - k, 5)).is_empty());
        }
        for k in 8..100 {
            assert!(t.update(k as f64 * 0.1, &[]).is_empty());
        }
        assert_eq!(t.last_hit_s((0, 0)), Some(0.0));
    }

    /// A moving object passing next to a static one: the static one's cells, hit again every
    /// revolution, are never cleared.
    #[test]
    fn a_mover_passing_a_static_object_leaves_it_alone() {
        let mut t = Tracker::new(TrackerConfig::default(), 0.2);
        let post = block(10, 40, 2, 2); // 0.2 m from the mover's side: one cluster with it
        for k in 0..60 {
            let mut hits = block(0, k * 2, 9, 22);
            hits.extend(&post);
            hits.sort_unstable();
            hits.dedup();
            let cleared = t.update(k as f64 * 0.1, &hits);
            assert!(cleared.iter().all(|c| !post.contains(c)), "{cleared:?}");
        }
    }

    /// Walls and buildings (larger than `max_object_m`) never move, however their visible
    /// stretch slides.
    #[test]
    fn a_long_wall_sliding_into_view_never_moves() {
        let mut t = Tracker::new(TrackerConfig::default(), 0.2);
        for k in 0..100 {
            let wall = block(k * 2, 0, 100, 2); // 20 m of wall, sliding with the vehicle
            assert!(t.update(k as f64 * 0.1, &wall).is_empty());
        }
    }

    /// A moving track (stray hits sliding along ahead of a vehicle) that loses its cluster and
    /// picks up a static box nearby, then jumps back to its stray hits once the box is hidden,
    /// clears nothing of the box: what it took over in a jump is never its to clear.
    #[test]
    fn a_moving_track_that_jumps_to_a_static_object_never_clears_it() {
        let mut t = Tracker::new(TrackerConfig::default(), 0.2);
        // 1.6 m to the side of the stray hits' line, where they are at the 40th revolution.
        let boxed = block(200, 8, 2, 2);
        let mut k = 0;
        // Stray hits sliding at 5 m/s along y = 0 (2 x 2 cells); the box seen all along.
        while k < 40 {
            let mut hits = block(k * 5, 0, 2, 2);
            hits.extend(&boxed);
            t.update(k as f64 * 0.1, &hits);
            k += 1;
        }
        assert_eq!(t.moving_objects().len(), 1);
        // The stray hits vanish for a revolution; only the box is seen.
        t.update(k as f64 * 0.1, &boxed);
        k += 1;
        // The box is hidden; the stray hits come back further on.
        for _ in 0..30 {
            let cleared = t.update(k as f64 * 0.1, &block(k * 5, 0, 2, 2));
            assert!(cleared.iter().all(|c| !boxed.contains(c)), "{cleared:?}");
            k += 1;
        }
    }

    #[test]
    fn a_disabled_tracker_clears_nothing_but_still_records_hits() {
        let cfg = TrackerConfig {
            enabled: false,
            ..TrackerConfig::default()
        };
        let mut t = Tracker::new(cfg, 0.2);
        for k in 0..80 {
            assert!(t.update(k as f64 * 0.1, &block(0, k * 2, 9, 22)).is_empty());
        }
        assert_eq!(t.last_hit_s((0, 0)), Some(0.0));
    }
}
