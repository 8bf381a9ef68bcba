//! How far the stack's pose estimate was from the truth: every published estimate against the
//! true pose of the same step, in the truth's frame (along track, across track, heading), with
//! the estimate's own cross-track standard deviation; summarised per lap (RMSE, 95th percentile,
//! maximum) for the report.

use nalgebra::{Isometry2, Vector2};
use serde::Serialize;

/// The error of one published estimate.
#[derive(Clone, Copy, Debug)]
struct Sample {
    lap: u32,
    along_m: f64,
    cross_m: f64,
    heading_rad: f64,
    sigma_cross_m: f64,
}

/// Absolute errors along one axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Root mean square.
    pub rmse: f64,
    /// 95th percentile of the absolute error.
    pub p95: f64,
    /// Largest absolute error.
    pub max: f64,
}

impl ErrorStats {
    fn of(mut v: Vec<f64>) -> Self {
        if v.is_empty() {
            return ErrorStats::default();
        }
        let rmse = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
        v.iter_mut().for_each(|x| *x = x.abs());
        v.sort_by(f64::total_cmp);
        let p95 = v[((v.len() - 1) as f64 * 0.95).round() as usize];
        ErrorStats {
            rmse,
            p95,
            max: v[v.len() - 1],
        }
    }
}

/// The localization error over one lap (or the whole run).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LocalizationErrors {
    /// The lap, from 1 (`None`: the whole run).
    pub lap: Option<u32>,
    /// Estimates compared.
    pub estimates: usize,
    /// Along the true heading, metres.
    pub along_m: ErrorStats,
    /// Across it (left positive), metres.
    pub cross_m: ErrorStats,
    /// Heading, radians.
    pub heading_rad: ErrorStats,
    /// Mean of the estimate's own cross-track standard deviation, metres.
    pub mean_sigma_cross_m: f64,
    /// Its largest value, metres.
    pub max_sigma_cross_m: f64,
}

impl LocalizationErrors {
    fn of(lap: Option<u32>, samples: &[&Sample]) -> Self {
        let axis = |f: fn(&Sample) -> f64| ErrorStats::of(samples.iter().map(|s| f(s)).collect());
        let sigmas = samples.iter().map(|s| s.sigma_cross_m);
        LocalizationErrors {
            lap,
            estimates: samples.len(),
            along_m: axis(|s| s.along_m),
            cross_m: axis(|s| s.cross_m),
            heading_rad: axis(|s| s.heading_rad),
            mean_sigma_cross_m: sigmas.clone().sum::<f64>() / samples.len().max(1) as f64,
            max_sigma_cross_m: sigmas.fold(0.0, f64::max),
        }
    }
}

/// The report's localization section: the whole run, then lap by lap.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LocalizationReport {
    /// The whole run.
    pub run: LocalizationErrors,
    /// Each lap driven (the last may be partial).
    pub laps: Vec<LocalizationErrors>,
}

/// Collects the errors as the run goes.
#[derive(Clone, Debug, Default)]
pub struct ErrorLog {
    samples: Vec<Sample>,
}

impl ErrorLog {
    /// Records the estimate published during lap `lap` (from 1) against the truth.
    pub fn record(&mut self, lap: u32, truth: &Isometry2<f64>, estimate: &autonomy::PoseEstimate) {
        let d = estimate.world_from_vehicle.translation.vector - truth.translation.vector;
        let forward = truth.rotation * Vector2::x();
        let left = truth.rotation * Vector2::y();
        self.samples.push(Sample {
            lap,
            along_m: d.dot(&forward),
            cross_m: d.dot(&left),
            heading_rad: autonomy::wrap_angle(
                estimate.world_from_vehicle.rotation.angle() - truth.rotation.angle(),
            ),
            sigma_cross_m: estimate.cross_track_sigma_m(),
        });
    }

    /// The summaries.
    pub fn report(&self) -> LocalizationReport {
        let all: Vec<&Sample> = self.samples.iter().collect();
        let last = self.samples.iter().map(|s| s.lap).max().unwrap_or(0);
        LocalizationReport {
            run: LocalizationErrors::of(None, &all),
            laps: (1..=last)
                .map(|lap| {
                    let of_lap: Vec<&Sample> =
                        all.iter().copied().filter(|s| s.lap == lap).collect();
                    LocalizationErrors::of(Some(lap), &of_lap)
                })
                .collect(),
        }
    }
}

/// What the run's localization missed of the scenario's `[expectations]`
/// (`max_cross_track_rmse_m`, `max_heading_rmse_rad`) over the whole run, one line each with the
/// numbers; nothing when the run had no estimate to compare (the true pose).
pub fn localization_misses(
    scenario: &crate::scenario::Scenario,
    report: Option<&LocalizationReport>,
) -> Vec<String> {
    let Some(run) = report.map(|r| &r.run) else {
        return Vec::new();
    };
    // Within the bound, or a miss (a NaN error is one too).
    let within = |x: f64, max: f64| x.partial_cmp(&max).is_some_and(|o| o.is_le());
    let mut misses = Vec::new();
    if let Some(max) = scenario
        .max_cross_track_rmse_m
        .filter(|&m| !within(run.cross_m.rmse, m))
    {
        misses.push(format!(
            "cross-track RMSE {:.3} m, at most {max} m expected",
            run.cross_m.rmse
        ));
    }
    if let Some(max) = scenario
        .max_heading_rmse_rad
        .filter(|&m| !within(run.heading_rad.rmse, m))
    {
        misses.push(format!(
            "heading RMSE {:.4} rad, at most {max} rad expected",
            run.heading_rad.rmse
        ));
    }
    misses
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_are_in_the_truths_frame_and_summarised_per_lap() {
        let mut log = ErrorLog::default();
        // Heading north: 0.1 m east of the truth is 0.1 m to its right (cross -0.1).
        let truth = Isometry2::new(Vector2::new(10.0, 5.0), std::f64::consts::FRAC_PI_2);
        let est = autonomy::PoseEstimate::exact(
            0.0,
            Isometry2::new(Vector2::new(10.1, 5.2), std::f64::consts::FRAC_PI_2 + 0.01),
        );
        log.record(1, &truth, &est);
        log.record(2, &truth, &autonomy::PoseEstimate::exact(0.0, truth));
        let r = log.report();
        assert_eq!(r.laps.len(), 2);
        let l1 = &r.laps[0];
        assert!((l1.cross_m.max - 0.1).abs() < 1e-9 && (l1.along_m.max - 0.2).abs() < 1e-9);
        assert!((l1.heading_rad.rmse - 0.01).abs() < 1e-9);
        assert_eq!(r.laps[1].cross_m.max, 0.0);
        assert!((r.run.cross_m.rmse - (0.01f64 / 2.0).sqrt()).abs() < 1e-9);
    }

    #[test]
    fn the_95th_percentile_ignores_the_worst_twentieth() {
        let s = ErrorStats::of((1..=100).map(|k| k as f64 / 100.0).collect());
        assert!((s.p95 - 0.95).abs() < 0.011 && s.max == 1.0, "{s:?}");
    }
}
