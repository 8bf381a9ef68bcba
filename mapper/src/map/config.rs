//! The map's settings: [`MapConfig`] and the choices it names (the live/prior merge, which
//! columns walk free space and which occupied cells stop a walk), checked field by field.

use serde::{Deserialize, Serialize};

use crate::error::{MapError, Result, positive};
use crate::occupancy::{ObstacleTestParams, OccupancyParams};

/// How the live map and the offline prior combine.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MergeMode {
    /// Live value where the live map knows the cell, prior value elsewhere (CARMEN's default).
    #[default]
    Fallback,
    /// Where both know the cell: `(10 p_live + p_prior) / 11`; otherwise as `Fallback`.
    Decay,
}

/// Everything tunable about a map. Defaults are CARMEN's multi-height ones (FACTS.md).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapConfig {
    /// Cell side, metres. Default 0.2.
    pub resolution_m: f64,
    /// Cells per block side. Default 350 (70 m blocks).
    pub block_cells: usize,
    /// Blocks per window side, odd. Default 3 (a 210 m window).
    pub window_blocks: usize,
    /// The window moves once the position is this far past its middle block's edge, metres
    /// (hysteresis: a route along a block edge would otherwise move it back and forth at every
    /// revolution; `the_window_moves_past_a_margin_not_at_every_crossing_of_a_block_edge`).
    /// Default 8 m; at most half a block. What lies beyond the window then starts up to this
    /// much nearer on the side the vehicle crossed.
    pub recenter_margin_m: f64,
    /// Log-odds update.
    pub occupancy: OccupancyParams,
    /// Obstacle test.
    pub obstacle_test: ObstacleTestParams,
    /// Cells left untouched at the end of each free-space walk (the endpoint's cell included). Default 2.
    pub free_space_stop_cells: usize,
    /// Returns within a circle's radius plus this margin are self-hits and dropped, metres. Default 0.8.
    pub self_hit_margin_m: f64,
    /// A cell is an obstacle for the distance map when its probability is above this. Default 0.5.
    pub obstacle_threshold: f32,
    /// Distances are capped here, metres. Default 30 (more than a jet's bounding radius, so the
    /// early out of the collision check can answer far from obstacles).
    pub max_distance_m: f32,
    /// Live / prior merge.
    pub merge: MergeMode,
    /// Which occupied cells end a free-space walk.
    pub free_space_stop: FreeSpaceStop,
    /// Which columns walk free space where.
    pub free_space_walks: FreeSpaceWalks,
    /// With [`FreeSpaceStop::ScanHits`], a beam with no echo that stays above the ground out to
    /// this range counts as crossing what lies within it, metres (0: only beams with an echo
    /// count). Default 30. Evidence for lowering older occupied cells only (`forget.rs`): in the
    /// open, the cells of an object hit only at the sensor's height and above are crossed by no
    /// other beam. Lower it for a sensor that misses dark objects nearer.
    pub no_echo_clears_within_m: f64,
    /// The sensor's intensity calibration: its returns' intensity falls off with range as
    /// `exp(-falloff r)`, per metre, so a return's remission is its intensity times `exp(falloff
    /// r)` (at most 1; [`MapConfig::remission_of`]). The remission layer holds remissions, and the
    /// localizer compares remissions with it: a cell surveyed at 40 m then reads the same seen
    /// from 10 m (a real stack's calibrated reflectivity). The shipped HDL-32E model's falloff
    /// is 0.004 (`[lidar] atmosphere_attenuation_rate`): set that for a map surveyed along other
    /// lines than the run drives (an airport's survey: `tests/found/xtsm_*_survey_*`). Default
    /// 0, intensities as they come: a map driven along the run's own route reads each cell from
    /// about the ranges the run does (docs/results.md, "Airports", for what the default's change
    /// would move).
    pub intensity_falloff_per_m: f64,
}

/// Which columns of a scan walk free space, and where.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FreeSpaceWalks {
    /// Every column walks from the sensor to its farthest return (CARMEN's one update per beam
    /// and cell crossed). Near the sensor the columns are far closer together than a cell (2187
    /// columns at 0.2 m: 7 columns a cell at 10 m), so a cell there is walked many times a scan.
    EveryColumn,
    /// The same free-space evidence with about a third of the cell visits: at range r only the
    /// columns that are multiples of 2^j walk, for the largest 2^j that keeps them within a cell
    /// of each other (`2^j r dtheta <= resolution`), and each adds `2^j l_free`, the share of the
    /// 2^j columns it stands for. A column starts walking where it is first needed - or where
    /// a coarser neighbour stopped short (an obstacle, its last return), so nothing in the
    /// shadow of a coarse column's obstacle is left unwalked. The default.
    #[default]
    CoarseToFine,
}

/// Which occupied cells (p >= 0.5) end a free-space walk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FreeSpaceStop {
    /// Cells hit by the scan being inserted, and older occupied cells the beam passes above
    /// the level's height plus 0.2 m (a beam over a cone is no evidence the cone left). An older
    /// occupied cell the beam passes lower through is lowered by `l_free`, so an obstacle that
    /// moved away (a crossing vehicle) is cleared. The default.
    #[default]
    ScanHits,
    /// Any live cell with p >= 0.5 (CARMEN's rule): what was once occupied and is not hit again
    /// is never walked through, so the cells a moving obstacle left stay occupied.
    AnyOccupied,
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            resolution_m: 0.2,
            block_cells: 350,
            window_blocks: 3,
            recenter_margin_m: 8.0,
            occupancy: OccupancyParams::default(),
            obstacle_test: ObstacleTestParams::default(),
            free_space_stop_cells: 2,
            self_hit_margin_m: 0.8,
            obstacle_threshold: 0.5,
            max_distance_m: 30.0,
            merge: MergeMode::Fallback,
            free_space_stop: FreeSpaceStop::ScanHits,
            free_space_walks: FreeSpaceWalks::CoarseToFine,
            no_echo_clears_within_m: 30.0,
            intensity_falloff_per_m: 0.0,
        }
    }
}

impl MapConfig {
    /// Checks every field, naming the first wrong one.
    pub fn validate(&self) -> Result<()> {
        positive("resolution_m", self.resolution_m)?;
        if self.block_cells == 0 {
            return Err(MapError::invalid("block_cells", "must be > 0"));
        }
        if self.window_blocks == 0 || self.window_blocks.is_multiple_of(2) {
            return Err(MapError::invalid(
                "window_blocks",
                format!("{}: must be odd", self.window_blocks),
            ));
        }
        let m = self.recenter_margin_m;
        if !(m.is_finite() && m >= 0.0 && m <= 0.5 * self.block_m()) {
            return Err(MapError::invalid(
                "recenter_margin_m",
                format!(
                    "{m}: must be in [0, half a block: {}]",
                    0.5 * self.block_m()
                ),
            ));
        }
        let o = &self.occupancy;
        if !(o.l_occ.is_finite() && o.l_occ > 0.0) {
            return Err(MapError::invalid(
                "occupancy.l_occ",
                format!("{}: must be > 0", o.l_occ),
            ));
        }
        if !(o.l_free.is_finite() && o.l_free < 0.0) {
            return Err(MapError::invalid(
                "occupancy.l_free",
                format!("{}: must be < 0", o.l_free),
            ));
        }
        positive("occupancy.l_max", o.l_max as f64)?;
        positive("obstacle_test.sigma", self.obstacle_test.sigma)?;
        positive("obstacle_test.max_range_m", self.obstacle_test.max_range_m)?;
        crate::error::finite(
            "obstacle_test.ground_height_m",
            self.obstacle_test.ground_height_m,
        )?;
        if let Some(h) = self.obstacle_test.unsafe_height_above_ground_m {
            positive("obstacle_test.unsafe_height_above_ground_m", h)?;
        }
        if !(self.self_hit_margin_m.is_finite() && self.self_hit_margin_m >= 0.0) {
            return Err(MapError::invalid(
                "self_hit_margin_m",
                format!("{}: must be >= 0", self.self_hit_margin_m),
            ));
        }
        if !(self.obstacle_threshold > 0.0 && self.obstacle_threshold < 1.0) {
            return Err(MapError::invalid(
                "obstacle_threshold",
                format!("{}: must be in (0, 1)", self.obstacle_threshold),
            ));
        }
        positive("max_distance_m", self.max_distance_m as f64)?;
        if !(self.no_echo_clears_within_m.is_finite() && self.no_echo_clears_within_m >= 0.0) {
            return Err(MapError::invalid(
                "no_echo_clears_within_m",
                format!("{}: must be >= 0", self.no_echo_clears_within_m),
            ));
        }
        let f = self.intensity_falloff_per_m;
        if !(f.is_finite() && (0.0..=0.1).contains(&f)) {
            return Err(MapError::invalid(
                "intensity_falloff_per_m",
                format!("{f}: must be in [0, 0.1] (per metre)"),
            ));
        }
        Ok(())
    }

    /// The remission of a return of `intensity` at `range_m` from the sensor: the intensity with
    /// the sensor's falloff over that range taken out (`intensity_falloff_per_m`), at most 1.
    pub fn remission_of(&self, intensity: f32, range_m: f32) -> f32 {
        if self.intensity_falloff_per_m == 0.0 {
            return intensity;
        }
        (intensity * (self.intensity_falloff_per_m as f32 * range_m).exp()).min(1.0)
    }

    /// Side of a block in metres.
    pub fn block_m(&self) -> f64 {
        self.block_cells as f64 * self.resolution_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A return's remission is its intensity with the falloff over its range taken out: the same
    /// cell reads the same from 5 m and from 60 m, as it was before the sensor's falloff, and at
    /// most 1; with no falloff the intensity as it came; a falloff out of range is refused.
    #[test]
    fn a_returns_remission_does_not_depend_on_its_range() {
        let config = MapConfig {
            intensity_falloff_per_m: 0.004,
            ..MapConfig::default()
        };
        let falloff = config.intensity_falloff_per_m;
        for remission in [0.05f32, 0.3, 0.8, 1.0] {
            for range in [0.5f32, 5.0, 20.0, 60.0, 100.0] {
                let intensity = remission * (-(falloff as f32) * range).exp();
                let back = config.remission_of(intensity, range);
                assert!(
                    (back - remission).abs() <= 1e-6 && back <= 1.0,
                    "{remission} at {range} m: read {intensity}, taken back to {back}"
                );
                // Without the calibration the far reading is off by the falloff.
                if range >= 60.0 {
                    assert!(remission - intensity > 0.2 * remission);
                }
            }
        }
        assert_eq!(config.remission_of(0.99, 80.0), 1.0, "capped at 1");
        let raw = MapConfig::default();
        assert_eq!(
            raw.intensity_falloff_per_m, 0.0,
            "the default takes them as they come"
        );
        assert_eq!(raw.remission_of(0.37, 80.0), 0.37);
        raw.validate().expect("0 is a falloff");
        for bad in [-0.001, f64::NAN, 0.5] {
            let e = MapConfig {
                intensity_falloff_per_m: bad,
                ..config
            }
            .validate()
            .expect_err("refused");
            assert!(e.to_string().contains("intensity_falloff_per_m"), "{e}");
        }
    }
}
