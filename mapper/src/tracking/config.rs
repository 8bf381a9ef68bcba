//! What the tracker of moving objects does: [`TrackerConfig`], its defaults and its check.

use serde::{Deserialize, Serialize};

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
    /// A track's velocity is offered for prediction ([`Tracker::movers`](super::Tracker::movers)) once it has been seen
    /// on this many revolutions in a row whose steps its motion explained. Default 4.
    pub predict_after_revolutions: u32,
    /// ... and its centre has travelled at least this far, metres. Default 1.
    pub predict_min_travel_m: f64,
    /// ... and more than this many times its largest extent (the centre of a static object's
    /// hits moves within its extent as it is hidden or revealed: up to half its length as it comes into view
    /// from one end). Default 0.6.
    pub predict_extent_factor: f64,
    /// Standard deviation of the centre of an object's hits about where its motion puts it,
    /// metres (the Kalman filter's measurement noise). Default 0.15.
    pub position_sigma_m: f64,
    /// Standard deviation of a mover's acceleration (the filter's process noise), m/s^2.
    /// Default 1.
    pub acceleration_sigma_m_s2: f64,
    /// A track offered for prediction that goes out of view (behind the airframe, another
    /// object) is still offered, from where it was last seen, for this long: a hidden mover is
    /// not gone, seconds. Default 6.
    pub coast_s: f64,
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
            predict_after_revolutions: 4,
            predict_min_travel_m: 1.0,
            predict_extent_factor: 0.6,
            position_sigma_m: 0.15,
            acceleration_sigma_m_s2: 1.0,
            coast_s: 6.0,
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
            ("position_sigma_m", self.position_sigma_m),
            ("acceleration_sigma_m_s2", self.acceleration_sigma_m_s2),
        ];
        let positive = positive.into_iter().chain([("coast_s", self.coast_s)]);
        let non_negative = [
            ("min_travel_m", self.min_travel_m),
            ("clear_margin_m", self.clear_margin_m),
            ("predict_min_travel_m", self.predict_min_travel_m),
            ("predict_extent_factor", self.predict_extent_factor),
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
