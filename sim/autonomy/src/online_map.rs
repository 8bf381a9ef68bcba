//! The stack's online map: the offline multi-height map merged with what the LiDAR sees, kept
//! around the vehicle's estimated pose, and the distance maps the collision checks read.

use mapper::{CollisionModel, MultiHeightMap};
use nalgebra::Point2;
use serde::{Deserialize, Serialize};

use crate::messages::LidarRevolution;

/// How live occupancy the LiDAR no longer sees fades back to the offline map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForgettingConfig {
    /// Whether live occupancy fades at all; false: never (a moving vehicle's trail hidden behind
    /// the airframe then stays). Default true.
    pub enabled: bool,
    /// Time constant, seconds (`MultiHeightMap::forget_unseen`, CARMEN's decay to the offline
    /// map). Default 10 s: a cell seen occupied once stops being an obstacle about 7 s after it
    /// was last seen.
    pub time_constant_s: f64,
    /// Forgetting works over a square of this half side around the vehicle, metres. Default 50.
    pub half_size_m: f64,
}

impl Default for ForgettingConfig {
    fn default() -> Self {
        ForgettingConfig {
            enabled: true,
            time_constant_s: 10.0,
            half_size_m: 50.0,
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
        OnlineMap {
            map,
            self_filter,
            forgetting,
            scan_period_s,
        }
    }

    /// Takes in one revolution: the window re-centred on the pose it was taken at, what is no
    /// longer seen faded, then the revolution inserted (what is seen again is refreshed).
    pub fn update(&mut self, revolution: &LidarRevolution) -> Result<(), mapper::MapError> {
        let at = Point2::from(revolution.world_from_vehicle_estimate.translation.vector);
        self.map.recenter(at)?;
        let f = &self.forgetting;
        if f.enabled {
            self.map
                .forget_unseen(at, f.half_size_m, self.scan_period_s, f.time_constant_s);
        }
        self.map
            .insert_scan(&revolution.scan, Some(&self.self_filter))?;
        Ok(())
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
