//! Heights of interest and the two interpretations of the thesis: cumulative and banded levels.
//!
//! Level k has the height of interest `h_k` (h_0 = 0 is the ground level, the usual occupancy
//! grid). *Cumulative* (the thesis' choice): level k holds every obstacle point at or above h_k,
//! so a lower level contains all higher ones. *Banded*: level k holds the points with
//! h_k <= z < h_{k+1} (the top level up to the ceiling), which can represent overhangs.
//! Points at or above the ceiling (if any) belong to no level.

use serde::{Deserialize, Serialize};

use crate::error::{MapError, Result};

/// How a level's height range is read from the heights of interest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LevelMode {
    /// Level k = every obstacle point at or above h_k (the thesis' choice; one lookup per circle).
    #[default]
    Cumulative,
    /// Level k = the obstacle points between h_k and h_{k+1}; a part checks every band above its underside.
    Banded,
}

/// Where a point's height stands relative to one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeightClass {
    /// Below the level's height of interest: flat ground for this level.
    Below,
    /// Inside the level's height range: an obstacle point for this level if the obstacle test says so.
    Inside,
    /// Above the level's range (banded levels, or above the ceiling): ignored by this level.
    Above,
}

/// The heights of interest of a map, in metres above the ground, and how to read them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Levels {
    heights_m: Vec<f64>,
    mode: LevelMode,
    ceiling_m: Option<f64>,
}

impl Levels {
    /// Levels with the given heights of interest (strictly increasing, the first >= 0), mode, and
    /// optional ceiling (points at or above it belong to no level; it must be above the last height).
    pub fn new(heights_m: Vec<f64>, mode: LevelMode, ceiling_m: Option<f64>) -> Result<Self> {
        if heights_m.is_empty() {
            return Err(MapError::invalid(
                "level heights",
                "at least one level (h_0 = 0) is needed",
            ));
        }
        if heights_m.len() > u8::MAX as usize {
            return Err(MapError::invalid(
                "level heights",
                format!("{} levels, at most 255", heights_m.len()),
            ));
        }
        for (k, h) in heights_m.iter().enumerate() {
            if !h.is_finite() || *h < 0.0 {
                return Err(MapError::invalid(
                    "level heights",
                    format!("h_{k} = {h}: must be finite and >= 0"),
                ));
            }
            if k > 0 && *h <= heights_m[k - 1] {
                return Err(MapError::invalid(
                    "level heights",
                    format!(
                        "h_{k} = {h} is not above h_{} = {}: heights must increase",
                        k - 1,
                        heights_m[k - 1]
                    ),
                ));
            }
        }
        if let Some(c) = ceiling_m {
            let top = heights_m[heights_m.len() - 1];
            if !c.is_finite() || c <= top {
                return Err(MapError::invalid(
                    "ceiling_m",
                    format!("{c}: must be finite and above the top level ({top})"),
                ));
            }
        }
        Ok(Levels {
            heights_m,
            mode,
            ceiling_m,
        })
    }

    /// Cumulative levels with no ceiling.
    pub fn cumulative(heights_m: Vec<f64>) -> Result<Self> {
        Self::new(heights_m, LevelMode::Cumulative, None)
    }

    /// Number of levels (>= 1).
    pub fn count(&self) -> usize {
        self.heights_m.len()
    }
    /// Heights of interest, metres above the ground.
    pub fn heights_m(&self) -> &[f64] {
        &self.heights_m
    }
    /// The interpretation.
    pub fn mode(&self) -> LevelMode {
        self.mode
    }
    /// Height above which no level holds anything, if any.
    pub fn ceiling_m(&self) -> Option<f64> {
        self.ceiling_m
    }

    /// Upper bound (exclusive) of level k's height range.
    pub fn upper_m(&self, level: usize) -> f64 {
        let ceiling = self.ceiling_m.unwrap_or(f64::INFINITY);
        match self.mode {
            LevelMode::Cumulative => ceiling,
            LevelMode::Banded => self.heights_m.get(level + 1).copied().unwrap_or(ceiling),
        }
    }

    /// Classifies a point `height_m` above the ground for level k.
    #[inline]
    pub fn classify(&self, level: usize, height_m: f64) -> HeightClass {
        if height_m < self.heights_m[level] {
            HeightClass::Below
        } else if height_m < self.upper_m(level) {
            HeightClass::Inside
        } else {
            HeightClass::Above
        }
    }

    /// The levels a vehicle part whose underside is at level `level` must be checked against:
    /// just `level` when cumulative, `level..count` when banded.
    pub fn levels_for_part(&self, level: usize) -> std::ops::Range<usize> {
        match self.mode {
            LevelMode::Cumulative => level..level + 1,
            LevelMode::Banded => level..self.count(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cumulative_levels_hold_everything_above_their_height() {
        let l = Levels::cumulative(vec![0.0, 0.7]).unwrap();
        assert_eq!(l.classify(0, 0.3), HeightClass::Inside);
        assert_eq!(l.classify(1, 0.3), HeightClass::Below);
        assert_eq!(l.classify(1, 5.0), HeightClass::Inside);
        assert_eq!(l.classify(0, 5.0), HeightClass::Inside);
        assert_eq!(l.levels_for_part(1), 1..2);
    }

    #[test]
    fn banded_levels_hold_their_band_only() {
        let l = Levels::new(vec![0.0, 2.0, 3.0], LevelMode::Banded, Some(10.0)).unwrap();
        assert_eq!(l.classify(0, 2.5), HeightClass::Above);
        assert_eq!(l.classify(1, 2.5), HeightClass::Inside);
        assert_eq!(l.classify(2, 2.5), HeightClass::Below);
        assert_eq!(l.classify(2, 10.0), HeightClass::Above);
        assert_eq!(l.levels_for_part(1), 1..3);
    }

    #[test]
    fn bad_heights_are_errors() {
        assert!(Levels::cumulative(vec![]).is_err());
        assert!(Levels::cumulative(vec![0.0, 0.0]).is_err());
        assert!(Levels::cumulative(vec![0.0, f64::NAN]).is_err());
        assert!(Levels::cumulative(vec![-1.0]).is_err());
        assert!(Levels::new(vec![0.0, 1.0], LevelMode::Banded, Some(0.5)).is_err());
    }
}
