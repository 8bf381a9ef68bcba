//! One object being followed ([`Track`]), and how a revolution's cluster moves it on: a new
//! track, or an old one followed - its motion, what it paints, whether it moves.

use nalgebra::{Point2, Vector2};

use super::clustering::Cluster;
use super::motion::Motion;
use super::{PEAK_SPEED_S, Tracker};
use crate::map::WorldCell;

/// One object being followed.
#[derive(Clone, Debug)]
pub(super) struct Track {
    /// Its id (a new one when it takes over another object's hits beyond its extent).
    pub(super) id: u32,
    /// Where it was first seen (kept when it is seen anew within its extent: it is the same
    /// object).
    pub(super) origin: Point2<f64>,
    /// Where its current motion started (set anew when it starts over).
    pub(super) first: Point2<f64>,
    /// The centre of its hits when last seen.
    pub(super) last: Point2<f64>,
    /// `first` and `last` in the frame of the vehicle that saw them then (`None`: the update
    /// was not told where the vehicle was): see [`Track::travel_m`].
    pub(super) first_rel: Option<Point2<f64>>,
    pub(super) last_rel: Option<Point2<f64>>,
    /// When it was last seen, seconds.
    pub(super) last_t_s: f64,
    /// Sum of the centre's steps, metres.
    pub(super) path_m: f64,
    /// Its velocity on each revolution of the last [`PEAK_SPEED_S`] it was seen moving
    /// steadily, as (time, m/s), oldest first.
    pub(super) recent_velocities: std::collections::VecDeque<(f64, Vector2<f64>)>,
    /// Largest extent (bounding-box diagonal) it was seen with, metres.
    pub(super) max_extent_m: f64,
    /// Its cells this revolution: bounding box (world cells), when seen.
    pub(super) bbox: Option<(WorldCell, WorldCell)>,
    /// The bounding box it was last seen with.
    pub(super) last_bbox: (WorldCell, WorldCell),
    /// Whether it has been offered for prediction (it then coasts when out of view).
    pub(super) predictable: bool,
    /// Revolutions it was seen in since it was created or started over.
    pub(super) seen: u32,
    /// Revolutions in a row whose step its motion explained.
    pub(super) steady: u32,
    /// Where its motion says it is, and its velocity, with their covariance.
    pub(super) motion: Motion,
    /// The levels it was hit in (bit `l`: level `l`), over its life.
    pub(super) levels: u32,
    /// The lowest open top any revolution saw it with (`Cluster::open_top_m`), metres.
    pub(super) open_top_m: Option<f32>,
    /// Confirmed moving: it may clear what it left.
    pub(super) moving: bool,
    /// Whether this revolution's step continued its motion (seen the revolution before, where
    /// its velocity said): only then may a moving track clear.
    pub(super) smooth: bool,
    /// Cells it painted (some may since belong to another track).
    pub(super) painted: Vec<WorldCell>,
    /// When it was created or given a new id, seconds.
    pub(super) born_s: f64,
}

/// A low track whose travel as seen from the vehicle is under this share of its travel over the
/// ground moves along with the sensor ([`Track::travel_m`]).
const ALONG_WITH_THE_SENSOR: f64 = 0.25;

impl Track {
    /// How far its centre has travelled since its current motion started, metres: over the
    /// ground - or, for a low track (`low_below_m`: told where the vehicle was), as the vehicle
    /// saw it move when that is under [`ALONG_WITH_THE_SENSOR`] of it. A low object shows only
    /// where the beams come down to it, so what shows of it slides along with the sensor: a
    /// 0.3 m wall beside the path seemed to move at the jet's speed, cell by cell, and was
    /// predicted into the main gear's path (`tests/found/low_wall_under_the_wing.toml`). Low
    /// means hit in level 0 alone with beams seen passing over it below `low_below_m` (its open
    /// top): a van under the wing is also hit in level 0 alone, the wing stopping the beams
    /// above it, and one seen moving partly along with a braking jet must still become a mover
    /// (`tests/found/van_lost_behind_the_wing_strikes_it.toml`). A low mover keeping pace with
    /// the vehicle is then no mover to the tracker - the map holds it as an obstacle, beams
    /// clear what it leaves, and its travel over the ground still makes it a candidate
    /// ([`Tracker::candidate_movers`]) - but one that closes on it or crosses its path moves as
    /// seen from it too.
    pub(super) fn travel_m(&self, low_below_m: Option<f32>) -> f64 {
        let ground = self.ground_travel_m();
        let low = self.levels == 1
            && low_below_m.is_some_and(|low| self.open_top_m.is_some_and(|top| top < low));
        match (self.first_rel, self.last_rel) {
            (Some(a), Some(b)) if low => {
                let seen = (b - a).norm();
                if seen < ALONG_WITH_THE_SENSOR * ground {
                    seen
                } else {
                    ground
                }
            }
            _ => ground,
        }
    }

    /// How far its centre has travelled over the ground since its current motion started,
    /// metres.
    pub(super) fn ground_travel_m(&self) -> f64 {
        (self.last - self.first).norm()
    }
}

impl Tracker {
    /// Below what an object is low, if the update was told (`SeenFrom::low_below_m`).
    pub(super) fn low_below_m(&self) -> Option<f32> {
        self.seen_from.map(|s| s.low_below_m)
    }

    /// Where `p` lies in the frame of the vehicle this revolution was seen from (`None`: not
    /// told).
    pub(super) fn relative(&self, p: Point2<f64>) -> Option<Point2<f64>> {
        self.seen_from
            .map(|v| v.vehicle.inverse_transform_point(&p))
    }

    /// A new track at a cluster nobody follows; its index.
    pub(super) fn new_track(&mut self, t_s: f64, cluster: &Cluster) -> usize {
        let cfg = &self.config;
        self.tracks.push(Track {
            id: self.next_id,
            origin: cluster.center,
            first: cluster.center,
            last: cluster.center,
            first_rel: self.relative(cluster.center),
            last_rel: self.relative(cluster.center),
            last_t_s: t_s,
            path_m: 0.0,
            recent_velocities: std::collections::VecDeque::new(),
            max_extent_m: 0.0,
            bbox: None,
            last_bbox: cluster.bbox,
            predictable: false,
            seen: 0,
            steady: 0,
            motion: Motion::new(
                cluster.center,
                Vector2::zeros(),
                cfg.position_sigma_m,
                0.5 * cfg.max_speed_m_s,
            ),
            levels: 0,
            open_top_m: None,
            moving: false,
            smooth: false,
            painted: Vec::new(),
            born_s: t_s,
        });
        self.next_id = self.next_id.wrapping_add(1);
        self.tracks.len() - 1
    }

    /// Track `ti` seen at `cluster` at `t_s`: its motion, what it paints, whether it moves.
    pub(super) fn follow(&mut self, ti: usize, t_s: f64, cluster: &Cluster) {
        let rel = self.relative(cluster.center);
        let cfg = &self.config;
        let r = self.resolution_m;
        let (lo, hi) = cluster.bbox;
        let extent = r * (((hi.0 - lo.0 + 1).pow(2) + (hi.1 - lo.1 + 1).pow(2)) as f64).sqrt();
        let track = &mut self.tracks[ti];
        let dt = t_s - track.last_t_s;
        let step = cluster.center - track.last;
        let velocity = track.motion.velocity();
        let miss = (step - velocity * dt).norm();
        let tolerance = cfg.max_step_error_m + 0.5 * track.max_extent_m;
        // A step its velocity does not explain (or after a gap) may be another object's hits
        // taken over, or the same object seen anew. A mover seen again after a longer gap (it
        // walked behind something, or through the blind zone) continues its motion when it is
        // where its velocity said, within what its uncertainty grew by, and its size is its own.
        let regained = track.moving
            && dt > cfg.max_gap_s
            && miss <= tolerance + 0.5 * dt
            && extent <= track.max_extent_m + 2.0 * cfg.max_step_error_m;
        track.smooth = dt > 0.0 && ((dt <= cfg.max_gap_s && miss <= tolerance) || regained);
        if dt > 0.0 && !track.smooth && track.seen > 1 {
            // Perhaps another object's hits now: what it painted so far is no longer its to
            // clear (it keeps its state), and its motion starts over from here. A step beyond
            // its own extent is another object's hits: a new track, under a new id, with no
            // evidence yet that it moves (a crossing car gone from view, its track taken over
            // by a ground return by the jet's wing 22 m away, is no mover there); within it,
            // the same object seen anew (a truck's side coming into view as the nose hides its
            // front).
            track.painted.clear();
            track.steady = 0;
            let another = miss > track.max_extent_m + cfg.max_step_error_m;
            if another {
                track.id = self.next_id;
                self.next_id = self.next_id.wrapping_add(1);
                track.born_s = t_s;
                track.origin = cluster.center;
                track.moving = false;
                track.predictable = false;
                track.levels = 0;
                track.open_top_m = None;
                track.max_extent_m = 0.0;
                track.seen = 0;
            }
            track.first = cluster.center;
            track.first_rel = rel;
            track.path_m = 0.0;
            track.recent_velocities.clear();
            track.motion = Motion::new(
                cluster.center,
                if another { Vector2::zeros() } else { velocity },
                cfg.position_sigma_m,
                0.5 * cfg.max_speed_m_s,
            );
        }
        if dt > 0.0 {
            track.motion.predict(dt, cfg.acceleration_sigma_m_s2);
            track.motion.correct(cluster.center, cfg.position_sigma_m);
            track.path_m += step.norm();
        }
        // Seen on what was hit well before it was, by no mover: the part of a static object
        // the offline map does not hold that shows, sliding along it as the sensor moves, is
        // no travel (a parked A320's side, seen at grazing incidence from 50 m, slid 14 m in
        // 2 s as the airliner rolled 2 m, and was predicted into its wing).
        if !track.moving && on_known_cells(&self.cells, cluster, track.born_s) {
            track.first = cluster.center;
            track.first_rel = rel;
            track.origin = cluster.center;
            track.path_m = 0.0;
        }
        if track.smooth {
            track.steady += 1;
            let velocity = track.motion.velocity();
            track.recent_velocities.push_back((t_s, velocity));
            while track
                .recent_velocities
                .front()
                .is_some_and(|&(t, _)| t_s - t > PEAK_SPEED_S)
            {
                track.recent_velocities.pop_front();
            }
        }
        track.seen += 1;
        track.last = cluster.center;
        track.last_rel = rel;
        track.last_t_s = t_s;
        track.bbox = Some(cluster.bbox);
        track.last_bbox = cluster.bbox;
        track.levels |= cluster.levels;
        if let Some(top) = cluster.open_top_m {
            track.open_top_m = Some(track.open_top_m.map_or(top, |t| t.min(top)));
        }
        track.max_extent_m = track.max_extent_m.max(extent);
        // What it hits on a step its motion does not explain (it took over another object's
        // hits) it owns, so no other track clears it, but never clears itself.
        let paints = track.smooth || track.seen <= 1;
        // Offered for prediction (or confirmed): its cells are no static object's. Not a
        // candidate mover's: a parked car's visible part, sliding, is one (a stale map's cars
        // then passed for movers again, `parking_lot_on_a_stale_map_movers_predicted`).
        let offered = track.moving || track.predictable;
        for &c in &cluster.cells {
            if let Some(rec) = self.cells.get_mut(&c) {
                if rec.owner != track.id && paints {
                    track.painted.push(c);
                }
                rec.owner = track.id;
                rec.by_mover |= offered;
            }
        }
        self.confirm_if_moving(ti);
    }

    /// Confirms track `ti` moving once its centre has travelled more than its extent allows a
    /// static object's (see the module's documentation), steadily.
    fn confirm_if_moving(&mut self, ti: usize) {
        let low_below_m = self.low_below_m();
        let cfg = &self.config;
        let track = &mut self.tracks[ti];
        let travel = track.travel_m(low_below_m);
        if !track.moving
            && track.max_extent_m <= cfg.max_object_m
            && travel >= cfg.min_travel_m.max(cfg.extent_factor * track.max_extent_m)
            && track.path_m <= cfg.max_path_ratio * travel + 1.0
        {
            track.moving = true;
        }
    }
}

/// A cell hit this long before a track was first seen, by no mover, is a static object's to
/// it, seconds: a mover's own cells under a track it had a moment before are not. At 1 s a
/// fuel truck crossing at 1.2 m/s was taken for known cells and the jet moved off into it; at
/// 3 s it is not (`tests/found/fuel_truck_crossing_slowly_taken_for_known_cells.toml`; found,
/// not traced track by track: a bound set by the cases, not derived).
const KNOWN_BEFORE_S: f64 = 3.0;

/// ... within this many cells of a cluster's cell (the part of a curved side that comes into
/// view as the sensor moves lies beside the part seen before).
const KNOWN_WITHIN_CELLS: i64 = 2;

/// Whether more than half of `cluster`'s cells lie on or within [`KNOWN_WITHIN_CELLS`] of a
/// cell known static to a track born at `born_s`: first hit [`KNOWN_BEFORE_S`] or more before
/// it, and never by a track offered for prediction (a tug's path, which its train's carts
/// follow, is not; nor a truck's body under the new track it gets when its hits jump).
fn on_known_cells(
    cells: &foldhash::HashMap<WorldCell, super::CellRecord>,
    cluster: &Cluster,
    born_s: f64,
) -> bool {
    let static_cell = |c: &WorldCell| {
        cells
            .get(c)
            .is_some_and(|r| !r.by_mover && r.first_hit_s <= born_s - KNOWN_BEFORE_S)
    };
    let n = KNOWN_WITHIN_CELLS;
    let known = (cluster.cells.iter())
        .filter(|&&(x, y)| (x - n..=x + n).any(|x| (y - n..=y + n).any(|y| static_cell(&(x, y)))))
        .count();
    2 * known > cluster.cells.len()
}
