//! The stack's online map: the offline multi-height map merged with what the LiDAR sees, kept
//! around the vehicle's estimated pose, and the distance maps the collision checks read.

use mapper::{CollisionModel, MultiHeightMap, Tracker, TrackerConfig, WorldCell};
use nalgebra::Point2;
use serde::{Deserialize, Serialize};

use crate::messages::LidarRevolution;

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
    forgetting: ForgettingConfig,
    scan_period_s: f64,
    tracker: Tracker,
    revolutions: u64,
}

impl OnlineMap {
    /// `map` (its window, offline prior and live store already set), the circles whose
    /// neighbourhood holds the LiDAR's self-hits, forgetting, and the time between revolutions.
    pub fn new(
        map: MultiHeightMap,
        self_filter: CollisionModel,
        forgetting: ForgettingConfig,
        scan_period_s: f64,
    ) -> Self {
        let tracker = Tracker::new(forgetting.tracking.clone(), map.config().resolution_m);
        OnlineMap {
            map,
            self_filter,
            forgetting,
            scan_period_s,
            tracker,
            revolutions: 0,
        }
    }

    /// Takes in one revolution: the window re-centred on the pose it was taken at, (under
    /// `time_decay`) what is no longer seen faded, the revolution inserted (its beams lower
    /// what they pass through, its hits raise what they hit), then what the tracked moving
    /// objects left cleared.
    pub fn update(&mut self, revolution: &LidarRevolution) -> Result<(), mapper::MapError> {
        let at = Point2::from(revolution.world_from_vehicle_estimate.translation.vector);
        self.map.recenter(at)?;
        let f = &self.forgetting;
        if f.rule == ForgettingRule::TimeDecay {
            self.map
                .forget_unseen(at, f.half_size_m, self.scan_period_s, f.time_constant_s);
        }
        self.map
            .insert_scan(&revolution.scan, Some(&self.self_filter))?;
        let hits = self.map.last_scan_hits_by_level();
        let clear = self.tracker.update_with_levels(revolution.t_s, &hits);
        self.map.clear_live(&clear);
        self.revolutions += 1;
        if self.revolutions.is_multiple_of(50) {
            // What the tracker remembers of cells: the window's square.
            let c = self.map.config();
            let half = 0.5 * c.block_m() * c.window_blocks as f64 + c.block_m();
            self.tracker.prune(&at, half);
        }
        Ok(())
    }

    /// When a revolution last hit the world cell `cell` as an obstacle, seconds (`None`: not
    /// since the window last held it - an offline-map obstacle, or never seen).
    pub fn last_hit_s(&self, cell: WorldCell) -> Option<f64> {
        self.tracker.last_hit_s(cell)
    }

    /// The tracked objects whose motion can be predicted, as of the last revolution - but not
    /// those whose hits lie on an obstacle of the offline map (of any level): a static object
    /// the map holds, whose visible part slid as the vehicle drove by, or whose hits a track
    /// took over from another, never moved.
    pub fn movers(&self) -> Vec<mapper::TrackState> {
        let levels = self.map.levels().count();
        let mut movers = self.tracker.movers();
        movers.retain(|t| {
            let ((x0, y0), (x1, y1)) = t.bbox;
            !(x0..=x1).any(|x| {
                (y0..=y1).any(|y| (0..levels).any(|l| self.map.is_prior_obstacle(l, (x, y))))
            })
        });
        movers
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
