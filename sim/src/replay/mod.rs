//! The Rerun replay of a closed-loop run: an [`Observer`] that writes a `.rrd` recording and/or
//! streams to a live viewer. The only module that knows Rerun.
//!
//! Everything is logged on the `sim_time` timeline (seconds of simulated time). Entity paths:
//!
//! | path | what | when |
//! | --- | --- | --- |
//! | `world/ground`, `world/patches`, `world/areas` | the ground slab, painted markings, paved areas' outlines | once (static) |
//! | `world/objects/<id>` | static objects: boxes, cylinders, cones (meshes) | once (static) |
//! | `world/route` | the route | once (static) |
//! | `world/obstacles/<id>` | run-time obstacles in their own frame, cleared while inactive | on change |
//! | `world/vehicle` | the vehicle's true pose (`Transform3D`) | `steps_hz` |
//! | `world/vehicle/parts/<link>/<k>` | the URDF collision primitives | once (static) |
//! | `world/vehicle/circles/level_<k>` | the circle model, at the level's height, coloured by level | once (static) |
//! | `world/lidar` | a revolution's returns, classed ground / level k / vehicle / unmapped | every `scan_every` revolutions |
//! | `world/lidar/<name>` | the same for each of the vehicle's other LiDARs (`extra_lidars`) | with `world/lidar` |
//! | `world/maps/level_<k>/occupancy` | the level's merged occupancy (`GridMap`, ROS values) at its height | `maps_hz` |
//! | `maps/level_<k>/distance` | the level's obstacle distance map (`DepthImage`, metres) | `maps_hz` |
//! | `world/planner/candidates` | the planner's candidates (red: colliding) | every `scan_every` revolutions |
//! | `world/planner/chosen` | the chosen path | every revolution |
//! | `plots/speed_m_s`, `plots/steering_rad`, `plots/real_time_factor` | time series | `steps_hz` |
//! | `plots/clearance_m/level_<k>` | ground-truth clearance per level (when something is within about 15 m) | `steps_hz` |
//! | `plots/speed_scale` | the avoider's speed over the wanted speed | every revolution |
//! | `events` | stop, resume, deviate, back on route, contact, lap, pass (`TextLog`) | as they happen |
//!
//! The recording is written to a temporary file next to its destination and renamed over it
//! when the run finishes, so a crash or an error leaves no partial `.rrd` behind.

use std::path::PathBuf;

use mapper::Levels;
use nalgebra::Point2;
use rerun::RecordingStream;
use rerun::components::TextLogLevel;

use crate::engine::{
    Event, Observer, RevolutionFrame, RunReport, RunStart, SensedFrame, StepFrame,
};
use crate::error::Error;
use style::{path_part, yaw_quat};

type Result<T, E = Error> = std::result::Result<T, E>;

/// A bad option: the message names the flag.
macro_rules! invalid {
    ($($arg:tt)*) => { $crate::error::Error::Invalid(format!($($arg)*)) };
}

/// Returns a bad-option error unless `cond` holds.
macro_rules! ensure {
    ($cond:expr, $($arg:tt)*) => {
        if !$cond {
            return Err(invalid!($($arg)*));
        }
    };
}

mod blueprint;
mod events;
mod frames;
mod maps;
mod options;
mod shapes;
mod static_world;
mod style;

pub use options::ReplayOptions;

/// A failure of Rerun or of the recording's file, with what was being done.
trait Context<T> {
    fn ctx<S: std::fmt::Display>(self, what: impl FnOnce() -> S) -> Result<T>;
}

impl<T, E: std::fmt::Display> Context<T> for std::result::Result<T, E> {
    fn ctx<S: std::fmt::Display>(self, what: impl FnOnce() -> S) -> Result<T> {
        self.map_err(|e| Error::Replay(format!("{}: {e}", what())))
    }
}

impl From<rerun::RecordingStreamError> for Error {
    fn from(e: rerun::RecordingStreamError) -> Self {
        Error::Replay(e.to_string())
    }
}

impl From<rerun::sink::SinkFlushError> for Error {
    fn from(e: rerun::sink::SinkFlushError) -> Self {
        Error::Replay(format!("flushing the recording: {e}"))
    }
}

/// The timeline every entity is logged on.
pub const TIMELINE: &str = "sim_time";

/// The ground the start-up rule found out of the LiDAR's sight at the start (orange squares on
/// the ground), cleared by the walk-around.
pub const START_UNSEEN: &str = "world/start/unseen";

/// The Rerun version this module is built against (the viewer should match it).
pub const RERUN_VERSION: &str = "0.36";

/// What the replay did, for the command line to print.
#[derive(Clone, Debug, Default)]
pub struct ReplaySummary {
    /// The recording written, and its size in bytes.
    pub recorded: Option<(PathBuf, u64)>,
    /// Where it streamed live.
    pub streamed_to: Option<String>,
    /// LiDAR revolutions, map frames and steps logged.
    pub scans_logged: u64,
    /// Map frames logged.
    pub maps_logged: u64,
    /// Steps logged.
    pub steps_logged: u64,
    /// Things that went wrong without ending the run (a viewer that went away).
    pub warnings: Vec<String>,
}

/// Where a run's replay goes: implements [`Observer`].
pub struct Replay {
    options: ReplayOptions,
    rec: RecordingStream,
    /// The temporary recording and its destination.
    file: Option<(tempfile::TempPath, PathBuf)>,
    summary: ReplaySummary,
    levels: Option<Levels>,
    level_heights_m: Vec<f64>,
    /// The run's obstacle test (to class the LiDAR's points as the mapper does).
    obstacle_test: mapper::ObstacleTestParams,
    first_obstacle: usize,
    /// Last logged (active, x, y, yaw) of each run-time obstacle.
    obstacles: Vec<Option<(f64, f64, f64)>>,
    obstacle_paths: Vec<String>,
    /// `world/lidar/<name>`: where each of the vehicle's other LiDARs' points go.
    more_lidar_paths: Vec<String>,
    scans_seen: u64,
    next_step_t: f64,
    next_map_t: f64,
    finished: bool,
}

impl Replay {
    /// Opens the recording file and/or the live viewer. Errors name the flag at fault.
    pub fn new(options: &ReplayOptions, name: &str) -> Result<Self> {
        options.validate()?;
        let options::Sinks {
            sinks,
            file,
            streamed_to,
        } = options.open_sinks()?;
        let rec = rerun::RecordingStreamBuilder::new("taxi-sim")
            .recording_name(name)
            .enabled(true)
            .batcher_config(options.batcher_config())
            .set_sinks(sinks)
            .ctx(|| "starting the Rerun recording")?;
        Ok(Replay {
            options: options.clone(),
            rec,
            file,
            summary: ReplaySummary {
                streamed_to,
                ..Default::default()
            },
            levels: None,
            level_heights_m: Vec::new(),
            obstacle_test: mapper::ObstacleTestParams::default(),
            first_obstacle: 0,
            obstacles: Vec::new(),
            obstacle_paths: Vec::new(),
            more_lidar_paths: Vec::new(),
            scans_seen: 0,
            next_step_t: 0.0,
            next_map_t: 0.0,
            finished: false,
        })
    }

    /// What the replay did (complete after the run finished).
    pub fn summary(&self) -> &ReplaySummary {
        &self.summary
    }

    fn time(&self, t_s: f64) {
        self.rec.set_duration_secs(TIMELINE, t_s);
    }

    /// Writes the footer of the recording, renames it into place and flushes the live viewer.
    fn close(&mut self) -> Result<()> {
        self.rec.finalize_deferred_sinks();
        if self.summary.streamed_to.is_some()
            && let Err(e) = self
                .rec
                .flush_with_timeout(std::time::Duration::from_secs(10))
        {
            self.summary
                .warnings
                .push(format!("the live viewer did not take everything: {e}"));
        }
        if let Some((tmp, dest)) = self.file.take() {
            self.summary.recorded = Some(options::persist(tmp, dest)?);
        }
        Ok(())
    }
}

impl Observer for Replay {
    fn start(&mut self, run: &RunStart<'_>) -> Result<()> {
        let levels = crate::offline_map::levels_of(run.scenario, run.config)?;
        self.level_heights_m = levels.heights_m().to_vec();
        self.levels = Some(levels);
        self.obstacle_test = run.config.mapping.map.obstacle_test;
        self.first_obstacle = run.first_obstacle;
        let obstacles = run.scene.solids.len().saturating_sub(run.first_obstacle);
        self.obstacles = vec![None; obstacles];
        self.more_lidar_paths = run
            .more_lidars
            .iter()
            .map(|l| format!("world/lidar/{}", path_part(&l.name)))
            .collect();
        self.obstacle_paths = run.scene.solids[run.first_obstacle..]
            .iter()
            .map(|s| format!("world/obstacles/{}", path_part(&s.id)))
            .collect();
        self.send_blueprint(
            self.level_heights_m.len(),
            &run.scenario.vehicle.world_from_start,
        )?;
        self.log_static_world(run)?;
        self.time(0.0);
        self.rec.log(
            "events",
            &rerun::TextLog::new(format!(
                "start: {} (seed {}, {} lap{})",
                run.scenario.name,
                run.seed,
                run.laps,
                if run.laps == 1 { "" } else { "s" }
            ))
            .with_level(TextLogLevel::INFO),
        )?;
        Ok(())
    }

    fn revolution(&mut self, frame: &RevolutionFrame<'_>) -> Result<()> {
        let full = self.log_revolution_points(
            frame.t_s,
            frame.revolution,
            frame.owners,
            frame.more_owners,
        )?;
        self.log_localization(frame, full)?;
        self.log_plan(frame, full)?;
        self.log_traffic(frame)?;
        self.rec.log(
            "plots/speed_scale",
            &rerun::Scalars::single(frame.speed_scale),
        )?;
        if self.options.maps_hz > 0.0 && frame.t_s + 1e-9 >= self.next_map_t {
            self.next_map_t = frame.t_s + 1.0 / self.options.maps_hz;
            self.log_maps(frame.map, Point2::from(frame.estimate.translation.vector))?;
        }
        Ok(())
    }

    fn sensed(&mut self, frame: &SensedFrame<'_>) -> Result<()> {
        self.log_revolution_points(frame.t_s, frame.revolution, frame.owners, frame.more_owners)?;
        Ok(())
    }

    fn step(&mut self, frame: &StepFrame<'_>) -> Result<()> {
        if frame.t_s + 1e-9 < self.next_step_t {
            return Ok(());
        }
        self.next_step_t = frame.t_s + 1.0 / self.options.steps_hz;
        self.time(frame.t_s);
        let s = frame.state;
        self.rec.log(
            "world/vehicle",
            &rerun::Transform3D::from_translation_rotation(
                [s.x_m as f32, s.y_m as f32, 0.0],
                yaw_quat(s.yaw_rad),
            ),
        )?;
        self.log_obstacles(frame.world)?;
        self.rec
            .log("plots/speed_m_s", &rerun::Scalars::single(s.speed_m_s))?;
        self.rec.log(
            "plots/steering_rad",
            &rerun::Scalars::single(s.steering_rad),
        )?;
        self.rec.log(
            "plots/real_time_factor",
            &rerun::Scalars::single(frame.real_time_factor),
        )?;
        for (k, d) in frame.clearance_m.iter().enumerate() {
            if d.is_finite() {
                self.rec.log(
                    format!("plots/clearance_m/level_{k}"),
                    &rerun::Scalars::single(*d),
                )?;
            }
        }
        self.summary.steps_logged += 1;
        Ok(())
    }

    fn event(&mut self, t_s: f64, event: &Event) -> Result<()> {
        self.time(t_s);
        let (text, level) = events::event_line(event);
        self.rec
            .log("events", &rerun::TextLog::new(text).with_level(level))?;
        match event {
            Event::StartUnseen {
                cell_m, cells_m, ..
            } if !cells_m.is_empty() => {
                let h = (*cell_m / 2.0) as f32;
                self.rec.log(
                    START_UNSEEN,
                    &rerun::Boxes3D::from_centers_and_half_sizes(
                        cells_m.iter().map(|c| [c[0] as f32, c[1] as f32, 0.02]),
                        cells_m.iter().map(|_| [h, h, 0.01]),
                    )
                    .with_colors([rerun::Color::from_unmultiplied_rgba(255, 140, 0, 160)])
                    .with_fill_mode(rerun::FillMode::Solid),
                )?;
            }
            Event::WalkAround => self.rec.log(START_UNSEEN, &rerun::Clear::flat())?,
            _ => {}
        }
        Ok(())
    }

    fn finish(&mut self, report: &RunReport) -> Result<()> {
        self.time(report.sim_time_s);
        let (text, level) = events::end_line(report);
        self.rec
            .log("events", &rerun::TextLog::new(text).with_level(level))?;
        self.finished = true;
        self.close()
    }
}

impl Drop for Replay {
    fn drop(&mut self) {
        if !self.finished {
            // A run that failed: stop writing; the temporary file is removed with `file`.
            self.rec.finalize_deferred_sinks();
        }
    }
}
