//! Log-odds occupancy parameters and the LiDAR obstacle test between vertically consecutive beams.
//!
//! The test (CARMEN `prob_map.cpp`, FACTS.md): if the lower beam's hit lies on a plane parallel
//! to the ground, the upper beam would reach that plane at an expected horizontal distance. The
//! evidence `e = (expected - measured) / expected` of the horizontal spacing between the two hits
//! (capped at 1; no information when the measured spacing exceeds the expected one) becomes
//! `p = (exp(-(1-e)^2/s) - exp(-1/s)) / (1 - exp(-1/s))`, s = 0.45, and a return is an obstacle
//! hit when p > 0.5. A beam that does not descend cannot reach the ground, so its hit is an
//! obstacle; so is any hit higher than `unsafe_height_above_ground_m` when set.

use nalgebra::Point3;
use serde::{Deserialize, Serialize};

/// Log-odds update of the occupancy grids (CARMEN multi-height defaults).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OccupancyParams {
    /// Added to a cell hit by an obstacle return (the nearest hit of a column gets twice this). Default 5.7.
    pub l_occ: f32,
    /// Added to a cell crossed by a beam (free space). Default -0.6.
    pub l_free: f32,
    /// Cells are clamped to +-`l_max`. Default 37.
    pub l_max: f32,
}

impl Default for OccupancyParams {
    fn default() -> Self {
        OccupancyParams {
            l_occ: 5.7,
            l_free: -0.6,
            l_max: 37.0,
        }
    }
}

/// Parameters of the obstacle test.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ObstacleTestParams {
    /// Width `s` of the evidence-to-probability curve. Default 0.45.
    pub sigma: f64,
    /// A hit at least this high above the ground is an obstacle whatever the test says (metres;
    /// `None` = off). Default 1.0 m: catches thin poles seen by a single beam. The test alone
    /// misses what rises less than about half a beam spacing (evidence ~ height / (range x
    /// spacing): for an HDL-32E, 0.11 m at 10 m, 0.23 m at 20 m), so on a known flat ground a
    /// lower value is what maps short objects at range (the simulator uses 0.1 m).
    pub unsafe_height_above_ground_m: Option<f64>,
    /// Height of the (flat) ground in the world frame, metres. Default 0.
    pub ground_height_m: f64,
    /// A hit lower than this above the ground is never an obstacle, whatever the test says
    /// (CARMEN's `safe_height_from_ground`), metres. Default 0 (off). Near the sensor the beams
    /// fall a few centimetres apart on the ground, and range noise alone tilts a pair of ground
    /// hits enough for the test: the simulator sets 0.05 m (its range noise is 0.02 m).
    pub safe_height_from_ground_m: f64,
    /// Returns farther than this (horizontal distance) are not mapped, metres. Default 70 (CARMEN).
    pub max_range_m: f64,
}

impl Default for ObstacleTestParams {
    fn default() -> Self {
        ObstacleTestParams {
            sigma: 0.45,
            unsafe_height_above_ground_m: Some(1.0),
            ground_height_m: 0.0,
            safe_height_from_ground_m: 0.0,
            max_range_m: 70.0,
        }
    }
}

/// Probability that the upper of two consecutive returns of a column is an obstacle, or `None`
/// when the pair carries no information.
///
/// `sensor` is the sensor origin, `lower` and `upper` the hit points of the lower and upper beam.
pub fn obstacle_probability(
    sensor: &Point3<f64>,
    lower: &Point3<f64>,
    upper: &Point3<f64>,
    params: &ObstacleTestParams,
) -> Option<f64> {
    let d_lower = (lower.x - sensor.x).hypot(lower.y - sensor.y);
    let d_upper = (upper.x - sensor.x).hypot(upper.y - sensor.y);
    match evidence(sensor, lower, d_lower, upper, d_upper, params) {
        Evidence::Certain => Some(1.0),
        Evidence::Nothing => None,
        Evidence::Partial(e) => Some(evidence_to_probability(e, params.sigma)),
    }
}

/// What a pair of consecutive returns says about the upper one.
enum Evidence {
    /// An obstacle for sure (above the unsafe height, or a beam that does not descend).
    Certain,
    /// No information.
    Nothing,
    /// Evidence in (0, 1] for the probability curve.
    Partial(f64),
}

/// The geometry shared by [`obstacle_probability`] and [`ObstacleTest::is_obstacle`]; the
/// horizontal ranges from the sensor to each hit are passed in.
#[inline]
fn evidence(
    sensor: &Point3<f64>,
    lower: &Point3<f64>,
    d_lower: f64,
    upper: &Point3<f64>,
    d_upper: f64,
    params: &ObstacleTestParams,
) -> Evidence {
    if params
        .unsafe_height_above_ground_m
        .is_some_and(|h| upper.z - params.ground_height_m >= h)
    {
        return Evidence::Certain;
    }
    if upper.z - params.ground_height_m < params.safe_height_from_ground_m {
        return Evidence::Nothing;
    }
    let drop_upper = sensor.z - upper.z; // how far below the sensor the upper hit is
    if drop_upper <= 1e-6 {
        return Evidence::Certain; // a beam that does not descend never reaches the ground
    }
    // The upper beam, continued to the plane of the lower hit (height lower.z).
    let expected = d_upper * (sensor.z - lower.z) / drop_upper - d_lower;
    let measured = d_upper - d_lower;
    if expected <= 1e-9 || measured > expected {
        return Evidence::Nothing;
    }
    Evidence::Partial(((expected - measured) / expected).min(1.0))
}

/// The obstacle test of [`obstacle_probability`] answered as `probability > 0.5`, for the hot
/// path: the same answer without the two exponentials of the probability curve (the evidence
/// is compared with the curve's 0.5 crossing, computed once by [`ObstacleTest::new`]) and with
/// the lower beam's horizontal range passed in rather than computed again.
#[derive(Clone, Copy, Debug)]
pub struct ObstacleTest {
    params: ObstacleTestParams,
    /// The evidence above which the probability exceeds 0.5.
    evidence_at_half: f64,
}

impl ObstacleTest {
    /// Prepares the test for `params`.
    pub fn new(params: ObstacleTestParams) -> Self {
        // evidence_to_probability(e) = 0.5  <=>  (1 - e)^2 = -sigma ln((1 + p0) / 2).
        let p0 = (-1.0 / params.sigma).exp();
        let evidence_at_half = 1.0 - (-params.sigma * (0.5 * (1.0 + p0)).ln()).sqrt();
        ObstacleTest {
            params,
            evidence_at_half,
        }
    }

    /// True when `upper` is an obstacle point against `lower` (the beam below it in the same
    /// column), `lower_range_xy` being the horizontal distance from the sensor to `lower` and
    /// `upper_range_xy` to `upper`.
    #[inline]
    pub fn is_obstacle(
        &self,
        sensor: &Point3<f64>,
        lower: &Point3<f64>,
        lower_range_xy: f64,
        upper: &Point3<f64>,
        upper_range_xy: f64,
    ) -> bool {
        match evidence(
            sensor,
            lower,
            lower_range_xy,
            upper,
            upper_range_xy,
            &self.params,
        ) {
            Evidence::Certain => true,
            Evidence::Nothing => false,
            Evidence::Partial(e) => e > self.evidence_at_half,
        }
    }
}

/// CARMEN's evidence-to-probability curve.
#[inline]
pub fn evidence_to_probability(evidence: f64, sigma: f64) -> f64 {
    let p0 = (-1.0 / sigma).exp();
    ((-(1.0 - evidence).powi(2) / sigma).exp() - p0) / (1.0 - p0)
}

/// Log-odds of a probability, clamped to +-`l_max`.
#[inline]
pub fn log_odds(p: f64, l_max: f32) -> f32 {
    let l = (p / (1.0 - p)).ln() as f32;
    l.clamp(-l_max, l_max)
}

/// Probability of a log-odds value.
#[inline]
pub fn probability(l: f32) -> f32 {
    1.0 / (1.0 + (-l).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    #[test]
    fn flat_ground_is_not_an_obstacle() {
        let s = p(0.0, 0.0, 2.15);
        let params = ObstacleTestParams::default();
        // Two beams at -20 and -18.67 deg hit the ground.
        let at = |deg: f64| 2.15 / (-deg.to_radians()).tan();
        let prob = obstacle_probability(
            &s,
            &p(at(-20.0), 0.0, 0.0),
            &p(at(-18.67), 0.0, 0.0),
            &params,
        )
        .unwrap();
        assert!(prob < 1e-9, "{prob}");
    }

    #[test]
    fn a_vertical_face_is_an_obstacle() {
        let s = p(0.0, 0.0, 2.15);
        let params = ObstacleTestParams::default();
        let prob = obstacle_probability(&s, &p(5.0, 0.0, 0.1), &p(5.0, 0.0, 0.2), &params).unwrap();
        assert!(prob > 0.999, "{prob}");
    }

    #[test]
    fn a_beam_over_an_obstacle_onto_far_ground_carries_no_information() {
        let s = p(0.0, 0.0, 2.15);
        let params = ObstacleTestParams::default();
        assert!(obstacle_probability(&s, &p(5.0, 0.0, 0.4), &p(20.0, 0.0, 0.0), &params).is_none());
    }

    #[test]
    fn unsafe_height_and_rising_beams_force_obstacles() {
        let s = p(0.0, 0.0, 2.15);
        let params = ObstacleTestParams::default();
        assert_eq!(
            obstacle_probability(&s, &p(30.0, 0.0, 0.0), &p(31.0, 0.0, 1.5), &params),
            Some(1.0)
        );
        let no_unsafe = ObstacleTestParams {
            unsafe_height_above_ground_m: None,
            ..params
        };
        assert_eq!(
            obstacle_probability(&s, &p(30.0, 0.0, 0.0), &p(31.0, 0.0, 2.5), &no_unsafe),
            Some(1.0)
        );
    }

    #[test]
    fn the_curve_is_half_near_half_evidence() {
        assert!(evidence_to_probability(0.0, 0.45).abs() < 1e-12);
        assert!((evidence_to_probability(1.0, 0.45) - 1.0).abs() < 1e-12);
        assert!((evidence_to_probability(0.485, 0.45) - 0.5).abs() < 0.01);
        assert_eq!(log_odds(1.0, 37.0), 37.0);
        assert_eq!(log_odds(0.0, 37.0), -37.0);
    }

    #[test]
    fn the_prepared_test_answers_as_the_probability_does() {
        let s = p(0.3, -0.2, 1.9);
        let range = |q: &Point3<f64>| (q.x - s.x).hypot(q.y - s.y);
        for params in [
            ObstacleTestParams::default(),
            ObstacleTestParams {
                sigma: 0.05,
                unsafe_height_above_ground_m: Some(1.0),
                ..Default::default()
            },
        ] {
            let test = ObstacleTest::new(params);
            let (mut yes, mut no) = (0, 0);
            // Lower hits on the ground or low, upper hits from ground-like to wall-like.
            for i in 0..60 {
                for j in 0..60 {
                    let lower = p(2.0 + 0.37 * i as f64, 0.5, 0.02 * (i % 7) as f64);
                    let upper = p(
                        lower.x + 0.013 * j as f64,
                        0.5 + 0.01 * j as f64,
                        lower.z + 0.025 * (j % 13) as f64,
                    );
                    let want = obstacle_probability(&s, &lower, &upper, &params)
                        .is_some_and(|pr| pr > 0.5);
                    let got = test.is_obstacle(&s, &lower, range(&lower), &upper, range(&upper));
                    assert_eq!(got, want, "{lower:?} {upper:?} {params:?}");
                    if want { yes += 1 } else { no += 1 }
                }
            }
            assert!(
                yes > 100 && no > 100,
                "both answers are exercised: {yes} / {no}"
            );
        }
    }
}
