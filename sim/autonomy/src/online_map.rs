//! The stack's online map: the offline multi-height map merged with what the LiDAR sees, kept
//! around the vehicle's estimated pose, and the distance maps the collision checks read.

use mapper::{CollisionModel, MultiHeightMap, SeenFrom, Tracker, TrackerConfig, WorldCell};
use nalgebra::{Matrix3, Point2};
use serde::{Deserialize, Serialize};

use crate::beams_through::{ColumnIndex, way_checked, way_seen_empty};
use crate::messages::LidarRevolution;

/// How long a lost track's way seen empty is kept, seconds: longer than a track coasts before
/// the tracker drops it.
const WAYS_KEPT_S: f64 = 30.0;

/// How live occupancy the LiDAR no longer sees fades back to the offline map.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ForgettingRule {
    /// Only on evidence: a beam through a cell lowers it (the map's free-space walks), and the
    /// cells a tracked moving object painted are cleared once it is seen elsewhere
    /// ([`mapper::Tracker`]). What the vehicle's body or another object hides keeps its state,
    /// however long. The default.
    #[default]
    Evidence,
    /// Also by time: live occupancy fades toward the offline map with `time_constant_s`
    /// (CARMEN's decay, `MultiHeightMap::forget_unseen`). Unsafe: an obstacle the airframe
    /// hides after the vehicle stopped for it is forgotten about 7 s later (10 s constant) and
    /// driven into; kept to show it, and for comparison.
    TimeDecay,
}

/// What clears live occupancy.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForgettingConfig {
    /// `evidence` (default) or `time_decay`.
    pub rule: ForgettingRule,
    /// `time_decay` only: the time constant, seconds. Default 10 s: a cell seen occupied once
    /// stops being an obstacle about 7 s after it was last seen.
    pub time_constant_s: f64,
    /// `time_decay` only: fading works over a square of this half side around the vehicle,
    /// metres. Default 50.
    pub half_size_m: f64,
    /// The tracker of moving objects (both rules).
    pub tracking: TrackerConfig,
}

impl Default for ForgettingConfig {
    fn default() -> Self {
        ForgettingConfig {
            rule: ForgettingRule::Evidence,
            time_constant_s: 10.0,
            half_size_m: 50.0,
            tracking: TrackerConfig::default(),
        }
    }
}

/// The map the stack plans over. It is `Send`, so a schedule may update it on another thread
/// while the vehicle moves.
pub struct OnlineMap {
    map: MultiHeightMap,
    self_filter: CollisionModel,
    /// The other LiDARs' self masks, in the order of `LidarRevolution::more_scans`.
    more_masks: Vec<mapper::SelfMask>,
    forgetting: ForgettingConfig,
    scan_period_s: f64,
    max_return_error_m: f64,
    tracker: Tracker,
    revolutions: u64,
    /// Whether the estimate has trusted a revolution out to the obstacle test's range yet.
    started: bool,
    /// The lost tracks whose way a revolution saw empty since they were last seen, and when,
    /// seconds ([`OnlineMap::ways_seen_empty`]).
    ways_seen_empty: Vec<(u32, f64)>,
}

/// The cells a revolution hit, each with the levels it was hit in (bit `l`: level `l`).
type LevelHits = Vec<(WorldCell, u32)>;
/// The cells a revolution hit with an open top, and how high it may reach unseen, metres.
type OpenTops = Vec<(WorldCell, f32)>;

/// How far from the sensor the returns of a revolution taken at an estimate of covariance `c`
/// (x, y, heading) are placed within `max_error_m`: out to where the estimate's 2-sigma error -
/// its position's (largest axis) and its heading's times the range, added in quadrature -
/// reaches it, metres. Infinite for an exact pose; 0 when the position alone errs by that much.
/// [`OnlineMap::update`] starts mapping once this reaches the obstacle test's range.
///
/// A heading 0.05 rad off (the fix's spread) puts a return 70 m away 3.5 m from where it is;
/// such a return, mapped at the height of a wing where no later beam passes, stays an
/// obstacle for good (`tests/found/phantom_from_the_first_revolution.toml`).
pub fn trusted_range_m(c: &Matrix3<f64>, max_error_m: f64) -> f64 {
    let (a, b, d) = (c[(0, 0)], c[(0, 1)], c[(1, 1)]);
    let largest = 0.5 * (a + d) + (0.25 * (a - d) * (a - d) + b * b).sqrt();
    // A NaN (an estimate that knows nothing) makes both NaN: nothing is trusted.
    let position = 2.0 * largest.sqrt();
    let heading = 2.0 * c[(2, 2)].sqrt();
    if position.is_nan() || heading.is_nan() || position >= max_error_m {
        return 0.0;
    }
    let spare = (max_error_m * max_error_m - position * position).sqrt();
    if heading > 0.0 {
        spare / heading
    } else {
        f64::INFINITY
    }
}

impl OnlineMap {
    /// `map` (its window, offline prior and live store already set), the circles whose
    /// neighbourhood holds the LiDAR's self-hits, forgetting, and the time between revolutions.
    /// Mapping starts once a revolution is trusted out to the obstacle test's range for
    /// `max_return_error_m` ([`Self::update`]).
    pub fn new(
        map: MultiHeightMap,
        self_filter: CollisionModel,
        forgetting: ForgettingConfig,
        scan_period_s: f64,
        max_return_error_m: f64,
    ) -> Self {
        let tracker = Tracker::new(forgetting.tracking.clone(), map.config().resolution_m);
        OnlineMap {
            map,
            self_filter,
            more_masks: Vec::new(),
            forgetting,
            scan_period_s,
            max_return_error_m,
            tracker,
            revolutions: 0,
            started: false,
            ways_seen_empty: Vec::new(),
        }
    }

    /// The vehicle's other LiDARs' self masks, one per scan of `LidarRevolution::more_scans`
    /// in order: their returns are filtered by their masks alone (the rays that meet the
    /// airframe, at the range they do), not by the circles and their margin, which would hide
    /// the ground beside the gears a low sensor is there to see.
    pub fn with_more_masks(mut self, masks: Vec<mapper::SelfMask>) -> Self {
        self.more_masks = masks;
        self
    }

    /// Takes in one revolution: the window re-centred on the pose it was taken at, (under
    /// `time_decay`) what is no longer seen faded, the revolution inserted (its beams lower
    /// what they pass through, its hits raise what they hit), then what the tracked moving
    /// objects left cleared.
    ///
    /// Mapping starts with the first revolution whose estimate is trusted out to the obstacle
    /// test's range ([`trusted_range_m`] of `max_return_error_m`): the revolutions taken while
    /// a localizer still spreads from its fix are left out whole (a part of one, mapped,
    /// leaves near cells hit without the free-space evidence of the rest). From then on every
    /// revolution is mapped, whatever the estimate: the stack slows and stops for an uncertain
    /// estimate itself.
    pub fn update(&mut self, revolution: &LidarRevolution) -> Result<(), mapper::MapError> {
        let at = Point2::from(revolution.world_from_vehicle_estimate.translation.vector);
        self.map.recenter(at)?;
        let f = &self.forgetting;
        if f.rule == ForgettingRule::TimeDecay {
            self.map
                .forget_unseen(at, f.half_size_m, self.scan_period_s, f.time_constant_s);
        }
        if !self.started {
            let range_m = trusted_range_m(&revolution.estimate_covariance, self.max_return_error_m);
            if range_m < self.map.config().obstacle_test.max_range_m {
                return Ok(());
            }
            self.started = true;
        }
        let (hits, tops) = self.insert_every_sensor(revolution)?;
        // Hits on or beside (one cell: the estimate's error) an offline-map obstacle are no
        // mover's: a lamp post is not tracked, and a truck passing one is tracked on its own.
        let (map, levels) = (&self.map, self.map.levels().count());
        let is_static = |(x, y): WorldCell| {
            (x - 1..=x + 1).any(|x| {
                (y - 1..=y + 1).any(|y| (0..levels).any(|l| map.is_prior_obstacle(l, (x, y))))
            })
        };
        // Where the vehicle was, for low objects' travel as seen from it (`Track::travel_m`):
        // below level 1 (with one level there is no telling what is low).
        let seen_from = (levels > 1).then(|| SeenFrom {
            vehicle: revolution.world_from_vehicle_estimate,
            low_below_m: map.levels().heights_m()[1] as f32,
        });
        let clear = self
            .tracker
            .update_except(revolution.t_s, seen_from, &hits, &tops, is_static);
        self.map.clear_live(&clear);
        self.note_ways_seen_empty(revolution);
        self.revolutions += 1;
        if self.revolutions.is_multiple_of(50) {
            // What the tracker remembers of cells: the window's square.
            let c = self.map.config();
            let half = 0.5 * c.block_m() * c.window_blocks as f64 + c.block_m();
            self.tracker.prune(&at, half);
        }
        Ok(())
    }

    /// Notes the tracks lost from view (not seen in `revolution`) whose way is checked
    /// ([`way_checked`]: small, hit in the lowest level) and which the revolution saw empty
    /// ([`way_seen_empty`]); forgets what is older than [`WAYS_KEPT_S`].
    fn note_ways_seen_empty(&mut self, revolution: &LidarRevolution) {
        let t_s = revolution.t_s;
        self.ways_seen_empty
            .retain(|&(_, s)| t_s - s <= WAYS_KEPT_S);
        let seen = &self.ways_seen_empty;
        let lost: Vec<mapper::TrackState> = (self.tracker.movers().into_iter())
            .filter(|t| t.t_s < t_s && way_checked(t))
            .filter(|t| !seen.iter().any(|&(id, s)| id == t.id && s > t.t_s))
            .collect();
        if lost.is_empty() {
            return;
        }
        let index = ColumnIndex::new(revolution.scans());
        let ground_z = self.map.config().obstacle_test.ground_height_m;
        let heights = self.map.levels().heights_m();
        for t in &lost {
            if way_seen_empty(&index, t, t_s, ground_z, heights) {
                self.ways_seen_empty.retain(|&(id, _)| id != t.id);
                self.ways_seen_empty.push((t.id, t_s));
            }
        }
    }

    /// The tracks lost from view whose way the sensor has seen empty since
    /// ([`crate::beams_through::way_seen_empty`]: neither gone that way nor stopped on it), and
    /// when it last did, seconds; kept for [`WAYS_KEPT_S`], after the tracker drops them too.
    pub fn ways_seen_empty(&self) -> &[(u32, f64)] {
        &self.ways_seen_empty
    }

    /// Each sensor's scan inserted from its own origin (the obstacle test compares beams of one
    /// sensor; the main one's self-hits filtered by the circles, the others' by their masks);
    /// the cells they hit, by level, and their open tops, merged as one scan's are (levels
    /// joined, the highest top kept).
    fn insert_every_sensor(
        &mut self,
        revolution: &LidarRevolution,
    ) -> Result<(LevelHits, OpenTops), mapper::MapError> {
        self.map
            .insert_scan(&revolution.scan, Some(&self.self_filter))?;
        let mut hits = self.map.last_scan_hits_by_level();
        let mut tops = self.map.last_scan_open_tops();
        if revolution.more_scans.is_empty() {
            return Ok((hits, tops));
        }
        for (k, scan) in revolution.more_scans.iter().enumerate() {
            match self.more_masks.get(k) {
                Some(mask) => self.map.insert_scan_masked(scan, None, Some(mask))?,
                None => self.map.insert_scan(scan, Some(&self.self_filter))?,
            };
            hits.extend(self.map.last_scan_hits_by_level());
            tops.extend(self.map.last_scan_open_tops());
        }
        hits.sort_unstable_by_key(|h| h.0);
        hits.dedup_by(|later, first| {
            let same = later.0 == first.0;
            if same {
                first.1 |= later.1;
            }
            same
        });
        tops.sort_unstable_by_key(|t| t.0);
        tops.dedup_by(|later, first| {
            let same = later.0 == first.0;
            if same {
                first.1 = first.1.max(later.1);
            }
            same
        });
        Ok((hits, tops))
    }

    /// Whether mapping has started: a revolution's estimate has been trusted out to the obstacle
    /// test's range ([`Self::update`]). Until then the driver holds the vehicle.
    pub fn mapping_started(&self) -> bool {
        self.started
    }

    /// When a revolution last hit the world cell `cell` as an obstacle, seconds (`None`: not
    /// since the window last held it - an offline-map obstacle, or never seen).
    pub fn last_hit_s(&self, cell: WorldCell) -> Option<f64> {
        self.tracker.last_hit_s(cell)
    }

    /// The tracked objects whose motion can be predicted, as of the last revolution. None is
    /// made of hits on or beside an obstacle of the offline map (of any level, [`Self::update`]):
    /// a static object the map holds, whose visible part slides as the vehicle drives by, never
    /// moved.
    ///
    /// A track's levels are those it was hit in and, once it is confirmed moving, those its
    /// open top may reach unseen (the levels starting below it,
    /// [`mapper::TrackState::open_top_m`]): a 1.5 m van seen only below 1.1 m from 19 m out
    /// may reach the wing's level. Not before: static clutter far off, whose visible part
    /// slides, makes short tracks whose tops nothing has bounded (on a stale map, the car
    /// stopped for them until it called a pilot).
    pub fn movers(&self) -> Vec<mapper::TrackState> {
        self.tracker
            .movers()
            .into_iter()
            .map(|t| self.with_open_top(t))
            .collect()
    }

    /// `t` with the levels its open top may reach added, if it is confirmed moving.
    fn with_open_top(&self, mut t: mapper::TrackState) -> mapper::TrackState {
        if let Some(top) = t.open_top_m.filter(|_| t.confirmed) {
            for (k, &lower) in self.map.levels().heights_m().iter().enumerate() {
                if lower < top {
                    t.levels |= 1u32 << k.min(31);
                }
            }
        }
        t
    }

    /// The tracked objects that may be moving but are not yet predictable
    /// ([`mapper::Tracker::candidate_movers`]), as of the last revolution; none made of hits
    /// beside an offline-map obstacle either.
    pub fn candidate_movers(&self) -> Vec<mapper::TrackState> {
        self.tracker
            .candidate_movers()
            .into_iter()
            .map(|t| self.with_open_top(t))
            .collect()
    }

    /// The small objects standing that the offline map does not hold, up to `max_extent_m`
    /// ([`mapper::Tracker::standing_objects`]), as of the last revolution: a person waiting
    /// beside the path is one, seen only standing.
    pub fn standing_objects(&self, max_extent_m: f64) -> Vec<mapper::TrackState> {
        self.tracker.standing_objects(max_extent_m)
    }

    /// The multi-height map (occupancy and distance maps per level).
    pub fn map(&self) -> &MultiHeightMap {
        &self.map
    }

    /// The map, to update its distance maps.
    pub fn map_mut(&mut self) -> &mut MultiHeightMap {
        &mut self.map
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn covariance(sigma_m: f64, sigma_rad: f64) -> Matrix3<f64> {
        Matrix3::from_diagonal(&nalgebra::Vector3::new(
            sigma_m * sigma_m,
            sigma_m * sigma_m,
            sigma_rad * sigma_rad,
        ))
    }

    #[test]
    fn the_trusted_range_shrinks_with_the_estimates_uncertainty() {
        assert_eq!(trusted_range_m(&Matrix3::zeros(), 1.0), f64::INFINITY);
        // At the fix (0.5 m, 0.05 rad): 2 sigma of position alone is the whole bound.
        assert_eq!(trusted_range_m(&covariance(0.5, 0.05), 1.0), 0.0);
        // Settled (0.05 m, 0.005 rad): sqrt(1 - 0.1^2) / 0.01.
        let settled = trusted_range_m(&covariance(0.05, 0.005), 1.0);
        assert!((settled - 0.99_f64.sqrt() / 0.01).abs() < 1e-9, "{settled}");
        // Half-way (0.3 m, 0.008 rad, the filter 0.6 s after its fix): 50 m.
        let r = trusted_range_m(&covariance(0.3, 0.008), 1.0);
        assert!((r - 50.0).abs() < 1e-9, "{r}");
        // The largest axis counts: all the error across, none along.
        let mut c = covariance(0.0, 0.005);
        c[(1, 1)] = 0.3 * 0.3;
        assert!((trusted_range_m(&c, 1.0) - 80.0).abs() < 1e-9);
        // A NaN covariance trusts nothing.
        assert_eq!(trusted_range_m(&covariance(f64::NAN, 0.0), 1.0), 0.0);
        assert_eq!(trusted_range_m(&covariance(0.0, f64::NAN), 1.0), 0.0);
    }
}
