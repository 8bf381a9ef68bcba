//! The validating numbers of a scenario file: newtypes checked while toml reads them, so a bad
//! value's error points at the value ([`Finite`], [`Positive`], [`NonNegative`], [`Remission`],
//! [`Laps`], [`Count`]).

use serde::Deserialize;

/// A finite number (no NaN, no infinity).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct Finite(pub f64);

impl TryFrom<f64> for Finite {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() {
            Ok(Finite(v))
        } else {
            Err(format!("must be a finite number, got {v}"))
        }
    }
}

/// A finite number > 0 (sizes, radii, heights, speeds).
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct Positive(pub f64);

impl TryFrom<f64> for Positive {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() && v > 0.0 {
            Ok(Positive(v))
        } else {
            Err(format!("must be finite and > 0, got {v}"))
        }
    }
}

/// A finite number >= 0 (times, heights above the ground).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct NonNegative(pub f64);

impl TryFrom<f64> for NonNegative {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() && v >= 0.0 {
            Ok(NonNegative(v))
        } else {
            Err(format!("must be finite and >= 0, got {v}"))
        }
    }
}

/// A LiDAR remission (reflectivity) in [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd, Deserialize)]
#[serde(try_from = "f64")]
pub struct Remission(pub f32);

impl TryFrom<f64> for Remission {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if (0.0..=1.0).contains(&v) {
            Ok(Remission(v as f32))
        } else {
            Err(format!("remission must be in [0, 1], got {v}"))
        }
    }
}

/// A number of laps, >= 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(try_from = "i64")]
pub struct Laps(pub u32);

impl Default for Laps {
    fn default() -> Self {
        Laps(1)
    }
}

impl TryFrom<i64> for Laps {
    type Error = String;
    fn try_from(v: i64) -> Result<Self, String> {
        match u32::try_from(v) {
            Ok(n) if n >= 1 => Ok(Laps(n)),
            _ => Err(format!("laps must be an integer >= 1, got {v}")),
        }
    }
}

/// A count of things, an integer >= 1 (a train's cars).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(try_from = "i64")]
pub struct Count(pub u32);

impl TryFrom<i64> for Count {
    type Error = String;
    fn try_from(v: i64) -> Result<Self, String> {
        match u32::try_from(v) {
            Ok(n) if n >= 1 => Ok(Count(n)),
            _ => Err(format!("must be an integer >= 1, got {v}")),
        }
    }
}
