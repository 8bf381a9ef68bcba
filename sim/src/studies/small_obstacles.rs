//! The small-obstacle sweep: a box of each height in the path of a vehicle's left wheels on a
//! straight road, driven at each speed in closed loop; for each pair, the range at which the
//! stack first mapped it (level 0) and what the vehicle did. It finds the smallest object the
//! obstacle test sees in time at each speed, for the README's table.

use std::path::Path;

use nalgebra::Point2;
use rayon::prelude::*;
use serde::Serialize;

use crate::engine::{Observer, RevolutionFrame};
use crate::engine::{RunHandles, RunSetup, run_with};
use crate::error::{Error, Result};
use crate::scenario::RunConfig;
use crate::scenario::Scenario;

/// Where the obstacle stands along the road, metres from the start.
const OBSTACLE_X_M: f64 = 90.0;
/// Its footprint, metres (a brick, a chock, a piece of a fairing).
const FOOTPRINT_M: f64 = 0.3;

/// What to sweep.
#[derive(Clone, Debug)]
pub struct SweepSpec {
    /// A shipped vehicle name or a sidecar path.
    pub vehicle: String,
    /// Obstacle heights, metres.
    pub heights_m: Vec<f64>,
    /// Route speeds, m/s.
    pub speeds_m_s: Vec<f64>,
    /// Runs per pair, the obstacle moved by a fraction of the distance driven per revolution
    /// each time (whether a beam lands on a short face depends on where the revolutions fall).
    pub phases: usize,
    /// The runs' seed.
    pub seed: u64,
    /// The run configuration.
    pub config: RunConfig,
}

/// One (height, speed) pair.
#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    /// Obstacle height, metres.
    pub height_m: f64,
    /// Route speed, m/s.
    pub speed_m_s: f64,
    /// Which phase (the obstacle `phase / phases` of a revolution's travel further on).
    pub phase: usize,
    /// Horizontal range from the sensor to the obstacle when a level-0 cell of its footprint
    /// first became an obstacle, metres (`None`: never mapped).
    pub first_mapped_m: Option<f64>,
    /// What the vehicle did: `passed`, `deviated`, `stopped` or `collided`.
    pub outcome: String,
    /// Contacts with the obstacle.
    pub contacts: usize,
    /// Smallest ground-truth clearance of the level-0 parts to it, metres.
    pub min_clearance_m: f64,
}

impl SweepRow {
    /// Whether the vehicle kept off it (went round or stopped short, no contact).
    pub fn avoided(&self) -> bool {
        self.contacts == 0 && (self.outcome == "deviated" || self.outcome == "stopped")
    }
}

/// The scenario of one run, as a file's text: a 200 m straight road, the obstacle in the left
/// wheels' path (`wheel_y_m` from the centreline) at `x_m`.
pub fn scenario_text(
    vehicle: &str,
    (height_m, speed_m_s): (f64, f64),
    (x_m, wheel_y_m): (f64, f64),
    seed: u64,
) -> String {
    // Taken away 40 s after the vehicle would have reached it: a vehicle that stops and waits
    // for it (an aircraft) then drives on and the pass closes.
    let gone_s = (x_m / speed_m_s + 40.0).round();
    format!(
        r#"name = "small obstacle {height_m} m at {speed_m_s} m/s"
seed = {seed}

[world]
min_m = [-20.0, -40.0]
max_m = [220.0, 40.0]
ground_remission = 0.2

[vehicle]
description = "{vehicle}"

[route]
waypoints_m = [[0.0, 0.0], [200.0, 0.0]]
speed_m_s = {speed_m_s}

[[objects]]
id = "lamp"
kind = "lamp_post"
x_m = 40.0
y_m = 30.0

[[patches]]
id = "centreline"
x_m = 100.0
y_m = 0.0
length_m = 200.0
width_m = 0.15

[[obstacles]]
id = "small_obstacle"
kind = "debris"
x_m = {x_m}
y_m = {wheel_y_m}
size_m = [{FOOTPRINT_M}, {FOOTPRINT_M}, {height_m}]
expect = "no_contact"
disappears_s = {gone_s}
"#
    )
}

/// Watches the level-0 map for the obstacle's footprint.
struct FirstMapped {
    center: Point2<f64>,
    sensor_x_m: f64,
    first_m: Option<f64>,
}

impl Observer for FirstMapped {
    fn revolution(&mut self, frame: &RevolutionFrame<'_>) -> Result<()> {
        if self.first_m.is_some() {
            return Ok(());
        }
        let r = frame.map.config().resolution_m;
        let half = 0.5 * FOOTPRINT_M;
        let cells = frame
            .map
            .obstacles_within(0, &self.center, half * std::f64::consts::SQRT_2);
        let inside = cells.iter().any(|&c| {
            let p = frame.map.world_cell_center(c);
            (p.x - self.center.x).abs() <= half + r && (p.y - self.center.y).abs() <= half + r
        });
        if inside {
            let sensor = frame.truth * Point2::new(self.sensor_x_m, 0.0);
            let near = Point2::new(self.center.x - half, self.center.y);
            self.first_m = Some((near - sensor).norm());
        }
        Ok(())
    }
}

/// Runs every (height, speed, phase), in parallel, over one offline map built in
/// `out_dir/map` (the road without the obstacle is the same for all); each run's scenario is
/// written to `out_dir/scenarios/h<height>_v<speed>_p<phase>.toml`. `progress` is told each run
/// done.
pub fn run_sweep(
    spec: &SweepSpec,
    out_dir: &Path,
    progress: &(dyn Fn(&SweepRow) + Sync),
) -> Result<Vec<SweepRow>> {
    let vehicle = aircraft::Vehicle::load(&spec.vehicle)
        .map_err(|e| Error::Invalid(format!("vehicle {}: {e}", spec.vehicle)))?;
    // The left wheels (a car's `wheel_*_left`, an aircraft's `main_gear_left`).
    let left = |word: &str| {
        vehicle
            .parts
            .iter()
            .filter(|p| p.link.contains(word) && p.link.contains("left"))
            .map(|p| p.vehicle_from_part.translation.y)
            .next()
    };
    let wheel_y_m = left("wheel")
        .or_else(|| left("gear"))
        .ok_or_else(|| Error::Invalid(format!("{}: no left wheel or gear link", spec.vehicle)))?;
    let sensor_x_m = vehicle.vehicle_from_lidar().translation.x;
    // Each pair as a plain scenario file beside the results: any row can be run again alone.
    let files = out_dir.join("scenarios");
    std::fs::create_dir_all(&files).map_err(|source| Error::Io {
        what: "creating the sweep's scenario directory",
        path: files.clone(),
        source,
    })?;
    let scan_period_s = 1.0 / spec.config.scan_hz;
    let x_of = |v: f64, phase: usize| {
        OBSTACLE_X_M + v * scan_period_s * phase as f64 / spec.phases.max(1) as f64
    };
    let parse = |h: f64, v: f64, phase: usize| -> Result<Scenario> {
        let vehicle = if Path::new(&spec.vehicle).exists() {
            std::path::absolute(&spec.vehicle)
                .map_or(spec.vehicle.clone(), |p| p.display().to_string())
        } else {
            spec.vehicle.clone()
        };
        let text = scenario_text(&vehicle, (h, v), (x_of(v, phase), wheel_y_m), spec.seed);
        let path = files.join(format!("h{h}_v{v}_p{phase}.toml"));
        mapper::write_atomically(&path, text.as_bytes())?;
        Ok(Scenario::from_file(&path)?)
    };
    let first = parse(spec.heights_m[0], spec.speeds_m_s[0], 0)?;
    let map_dir = out_dir.join("map");
    crate::offline_map::map_drive(&first, &spec.config, &map_dir, &mut |_, _| {})?;
    let phases = spec.phases.max(1);
    let runs: Vec<(f64, f64, usize)> = spec
        .heights_m
        .iter()
        .flat_map(|&h| {
            spec.speeds_m_s
                .iter()
                .flat_map(move |&v| (0..phases).map(move |p| (h, v, p)))
        })
        .collect();
    runs.par_iter()
        .map(|&(h, v, phase)| {
            let s = parse(h, v, phase)?;
            let setup = RunSetup {
                config: spec.config.clone(),
                ..RunSetup::new(map_dir.clone())
            };
            let mut watch = FirstMapped {
                center: Point2::new(x_of(v, phase), wheel_y_m),
                sensor_x_m,
                first_m: None,
            };
            let report = run_with(
                &s,
                &setup,
                RunHandles {
                    stop: None,
                    progress: &mut |_| {},
                    observer: &mut watch,
                },
            )?;
            let o = &report.obstacles[0];
            let pass = o.passes.first();
            // A vehicle that stops and waits (an aircraft) never passes an obstacle that stays:
            // a stop without contact is its outcome.
            let waited = pass.is_none() && report.contacts.is_empty() && !report.stops.is_empty();
            let row = SweepRow {
                height_m: h,
                speed_m_s: v,
                phase,
                first_mapped_m: watch.first_m,
                outcome: match pass {
                    Some(p) => p.outcome.as_str().into(),
                    None if waited => "stopped".into(),
                    None => "not passed".into(),
                },
                contacts: report.contacts.len(),
                min_clearance_m: pass.map_or(f64::NAN, |p| p.min_clearance_m[0]),
            };
            progress(&row);
            Ok(row)
        })
        .collect()
}
