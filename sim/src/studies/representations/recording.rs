//! A real recording through the representations: each one's memory, insertion and distance
//! update on a real HDL-32E's revolutions (no ground truth there, so no answers are judged).

use std::path::Path;

use nalgebra::{Isometry2, Point2};

use super::drive::{Cloud, InsertTimes, Representations};
use super::{Options, SceneResult};
use crate::error::{Error, Result};
use crate::scenario::{RunConfig, Scenario};

/// Compares the representations on the full revolutions of the capture at `pcap`, the sensor
/// standing at the origin, levelled on the ground fitted under it, for `scenario`'s vehicle
/// (its levels and ceiling). Pose checks are not timed or judged: the rows' answers are empty.
pub fn compare_recording(
    pcap: &Path,
    scenario: &Scenario,
    config: &RunConfig,
    options: &Options,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<SceneResult> {
    let recording = crate::pcap::read(pcap, None)?;
    let full = recording.full();
    let ground = recording.ground(full).ok_or_else(|| {
        Error::Invalid(format!(
            "{}: no full revolution with ground under the sensor to level it on",
            pcap.display()
        ))
    })?;
    let vehicle_from_sensor = ground.sensor_above_level_ground();
    let pose = Isometry2::identity();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| Error::Invalid(format!("a one-thread pool: {e}")))?;
    let mut reps = Representations::new(scenario, config, Point2::origin(), false)?;
    let (mut times, mut clouds) = (InsertTimes::default(), Vec::new());
    for (k, frame) in full.iter().enumerate() {
        let scan = recording.scan(frame, &pose, &vehicle_from_sensor)?.scan;
        one.install(|| reps.insert(&scan, &mut times))?;
        if options.octomap.is_some() {
            clouds.push(Cloud::of(&scan)?);
        }
        progress("recording", k + 1, full.len());
    }
    let vehicle = &scenario.vehicle.vehicle;
    let model = config.collision_model(vehicle)?;
    let circles = super::spans::span_circles(&model, vehicle);
    let vehicle_model = (&model, circles.as_slice());
    let mut result =
        one.install(|| super::judge_all(scenario, vehicle_model, &mut reps, &[], &times))?;
    result.scenario = format!(
        "real HDL-32E recording {}",
        pcap.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    );
    result.path = pcap.display().to_string();
    result.revolutions = full.len();
    // A standing sensor's "route" is its window.
    result.route_blocks = 9;
    result.notes.push(format!(
        "a standing sensor {:.2} m up, levelled on the fitted ground; no ground truth: memory and time only",
        ground.height_m()
    ));
    if let Some(o) = &options.octomap {
        progress("OctoMap", 0, 1);
        let ctx = (scenario, &reps, circles.as_slice());
        super::octomap_rows(ctx, &[], &clouds, o, &mut result)?;
    }
    super::scale_route_memory(&mut result);
    Ok(result)
}
