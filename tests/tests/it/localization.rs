//! The particle filter in the closed loop (issue #24): the degradations - the markings gone (a
//! featureless field, the remission map its only input) and the odometry's bias doubled - make
//! the estimate's covariance grow and the vehicle slow or stop; nothing is ever touched. The parking lot
//! localized within its target (0.10 m, 0.01 rad) is the scenario's own expectation
//! (`[expectations] max_cross_track_rmse_m`, `max_heading_rmse_rad`), judged by `taxi-sim
//! regress`.

use crate::common::{run_with, scenario};
use autonomy::localizer::{LocalizerConfig, MeasurementModel};
use sim::engine::{EndReason, RunReport};
use sim::scenario::{PoseSourceConfig, RunConfig};

fn particle_filter(measurement: MeasurementModel) -> RunConfig {
    RunConfig {
        pose_source: PoseSourceConfig::ParticleFilter(LocalizerConfig {
            measurement,
            ..Default::default()
        }),
        ..RunConfig::default()
    }
}

fn one_lap(s: &mut sim::scenario::Scenario) {
    s.laps = 1;
}

fn localization(r: &RunReport) -> &sim::engine::LocalizationReport {
    r.localization
        .as_ref()
        .expect("a particle-filter run reports its localization")
}

/// The markings and the pavement's texture gone and the remission map the filter's only input:
/// nothing to match, so the covariance must grow and the vehicle slow or stop - never drive on
/// with a confident wrong estimate into anything.
#[test]
fn on_a_featureless_lot_the_covariance_grows_and_the_vehicle_slows_or_stops() {
    let mut s = scenario("parking_lot");
    one_lap(&mut s);
    s.patches.clear();
    s.world.pavement_texture = 0.0;
    let r = run_with(&s, particle_filter(MeasurementModel::Remission));
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    let l = &localization(&r).run;
    let slow_m = RunConfig::default().autonomy.uncertainty_slow_m;
    assert!(
        l.max_sigma_cross_m > slow_m,
        "the sigma never passed {slow_m} m: {l:?}"
    );
    // Slower than the lap with markings (90.9 s; 98.5 s seen), or stopped for good (timed out,
    // or - since the prediction of movers, issue 36 - stopped and calling a pilot).
    let lap_s = r.lap_times_s.first().copied();
    assert!(
        matches!(
            r.end,
            EndReason::TimedOut | EndReason::WaitingForHiddenObstacle
        ) || lap_s.is_some_and(|t| t > 95.0),
        "end {:?}, lap {lap_s:?}",
        r.end
    );
}

/// The odometry's bias doubled (2 % on the speed, 0.004 rad on the steering): the filter still
/// localizes on the lot's markings and obstacles, the vehicle meets every expectation and
/// touches nothing.
#[test]
fn with_the_odometry_bias_doubled_nothing_is_touched() {
    let mut s = scenario("parking_lot");
    one_lap(&mut s);
    let base = particle_filter(MeasurementModel::Both);
    let doubled = RunConfig {
        odometry: sim::world::OdometryConfig {
            speed_scale_bias: 2.0 * base.odometry.speed_scale_bias,
            steering_bias_rad: 2.0 * base.odometry.steering_bias_rad,
            ..base.odometry.clone()
        },
        ..base
    };
    let r = run_with(&s, doubled);
    assert!(r.contacts.is_empty(), "{:?}", r.contacts);
    assert!(r.expectations_met, "{:?}", r.obstacles);
    let l = &localization(&r).run;
    assert!(
        l.cross_m.rmse <= 0.10,
        "cross-track RMSE {}",
        l.cross_m.rmse
    );
}
