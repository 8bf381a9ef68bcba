//! The Rerun replay of a closed-loop run: an [`Observer`] that writes a `.rrd` recording and/or
//! streams to a live viewer. The only module that knows Rerun.
//!
//! Everything is logged on the `sim_time` timeline (seconds of simulated time). Entity paths:
//!
//! | path | what | when |
//! | --- | --- | --- |
//! | `world/ground`, `world/patches` | the ground slab, painted markings | once (static) |
//! | `world/objects/<id>` | static objects: boxes, cylinders, cones (meshes) | once (static) |
//! | `world/route` | the route | once (static) |
//! | `world/obstacles/<id>` | run-time obstacles in their own frame, cleared while inactive | on change |
//! | `world/vehicle` | the vehicle's true pose (`Transform3D`) | `steps_hz` |
//! | `world/vehicle/parts/<link>/<k>` | the URDF collision primitives | once (static) |
//! | `world/vehicle/circles/level_<k>` | the circle model, at the level's height, coloured by level | once (static) |
//! | `world/lidar` | a revolution's returns, classed ground / level k / vehicle / unmapped | every `scan_every` revolutions |
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

use std::path::{Path, PathBuf};

use mapper::{Levels, MultiHeightMap};
use nalgebra::{Isometry2, Isometry3, Point2, UnitQuaternion, Vector3};
use rerun::RecordingStream;
use rerun::blueprint::{
    Blueprint, ContainerLike, Grid, Horizontal, Spatial2DView, Spatial3DView, TextLogView,
    TimePanel, TimeSeriesView, Vertical,
};
use rerun::components::{Colormap, FillMode, TextLogLevel};
use rerun::datatypes::{ChannelDatatype, ColorModel, Quaternion, Rgba32};
use rerun::sink::{FileSink, GrpcSink, LogSink};

use crate::error::Error;
use crate::observer::{Event, Observer, RunStart, ScanFrame, StepFrame};
use crate::report::RunReport;

type Result<T, E = Error> = std::result::Result<T, E>;

/// A bad option: the message names the flag.
macro_rules! invalid {
    ($($arg:tt)*) => { Error::Invalid(format!($($arg)*)) };
}

/// Returns a bad-option error unless `cond` holds.
macro_rules! ensure {
    ($cond:expr, $($arg:tt)*) => {
        if !$cond {
            return Err(invalid!($($arg)*));
        }
    };
}

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
use crate::scene::{ObjectKind, Solid, SolidShape};
use crate::world::Owner;

/// The timeline every entity is logged on.
pub const TIMELINE: &str = "sim_time";

/// The Rerun version this module is built against (the viewer should match it).
pub const RERUN_VERSION: &str = "0.36";

/// Where the replay goes and how much of the run it shows.
#[derive(Clone, Debug)]
pub struct ReplayOptions {
    /// Write a recording here (`.rrd`), atomically at the end of the run.
    pub record: Option<PathBuf>,
    /// Start a viewer (`rerun` from the PATH, or the one already listening on port 9876) and
    /// stream to it.
    pub spawn: bool,
    /// Stream to the viewer at this address (`rerun+http://host:port/proxy` or `host:port`).
    pub connect: Option<String>,
    /// LiDAR points and planner candidates every this many revolutions (the chosen path and the
    /// speed scale every revolution). Default 10 (1 Hz with the 10 Hz LiDAR).
    pub scan_every: u32,
    /// Keep every this many columns of a logged revolution (all 32 beams of each). Default 4.
    pub point_stride: usize,
    /// Occupancy and distance maps per second of simulated time (0: none). Default 1.
    pub maps_hz: f64,
    /// Half side of the square of the maps logged around the vehicle, metres. Default 30.
    pub map_half_m: f64,
    /// Vehicle pose and time series per second of simulated time (at most the physics rate).
    /// Default 20.
    pub steps_hz: f64,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            record: None,
            spawn: false,
            connect: None,
            scan_every: 10,
            point_stride: 4,
            maps_hz: 1.0,
            map_half_m: 30.0,
            steps_hz: 20.0,
        }
    }
}

impl ReplayOptions {
    /// True when the replay has somewhere to go.
    pub fn enabled(&self) -> bool {
        self.record.is_some() || self.spawn || self.connect.is_some()
    }

    /// Checks the options; errors name the command-line flag.
    pub fn validate(&self) -> Result<()> {
        ensure!(
            self.scan_every >= 1,
            "--replay-scan-every {}: must be at least 1",
            self.scan_every
        );
        ensure!(
            self.point_stride >= 1,
            "--replay-point-stride {}: must be at least 1",
            self.point_stride
        );
        ensure!(
            self.maps_hz.is_finite() && self.maps_hz >= 0.0,
            "--replay-maps-hz {}: must be >= 0 (0: no maps)",
            self.maps_hz
        );
        ensure!(
            self.map_half_m.is_finite() && self.map_half_m > 0.0 && self.map_half_m <= 500.0,
            "--replay-map-half-m {}: must be in (0, 500] metres",
            self.map_half_m
        );
        ensure!(
            self.steps_hz.is_finite() && self.steps_hz > 0.0,
            "--replay-steps-hz {}: must be > 0",
            self.steps_hz
        );
        if let Some(path) = &self.record {
            ensure!(
                path.file_name().is_some(),
                "--record {}: not a file name",
                path.display()
            );
        }
        if let Some(addr) = &self.connect {
            proxy_url(addr)?;
        }
        Ok(())
    }
}

/// The gRPC proxy URL of a `--connect` address.
fn proxy_url(addr: &str) -> Result<String> {
    let url = if addr.contains("://") {
        addr.to_string()
    } else {
        format!("rerun+http://{addr}/proxy")
    };
    url.parse::<rerun::external::re_uri::ProxyUri>()
        .map_err(|e| invalid!("--connect {addr}: not a viewer address ({e}); expected host:port or rerun+http://host:port/proxy"))?;
    Ok(url)
}

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

/// Class ids of the LiDAR points (see the annotation context at `world/lidar`).
const CLASS_GROUND: u16 = 0;
const CLASS_VEHICLE: u16 = 1;
const CLASS_UNMAPPED: u16 = 2;
const CLASS_ABOVE: u16 = 3;
const CLASS_LEVEL0: u16 = 10;

/// The colour of level k (circles, points, plots).
fn level_color(k: usize) -> Rgba32 {
    const COLORS: [(u8, u8, u8); 6] = [
        (255, 140, 0),
        (0, 190, 255),
        (230, 60, 230),
        (120, 220, 60),
        (255, 220, 0),
        (255, 90, 90),
    ];
    let (r, g, b) = COLORS[k % COLORS.len()];
    Rgba32::from_rgb(r, g, b)
}

fn kind_color(kind: ObjectKind) -> Rgba32 {
    match kind {
        ObjectKind::Cone => Rgba32::from_rgb(255, 110, 20),
        ObjectKind::Container => Rgba32::from_rgb(60, 110, 200),
        ObjectKind::Marker => Rgba32::from_rgb(240, 220, 40),
        ObjectKind::Building => Rgba32::from_rgb(150, 150, 160),
        ObjectKind::LampPost => Rgba32::from_rgb(110, 110, 110),
        ObjectKind::ParkedCar => Rgba32::from_rgb(170, 60, 60),
        ObjectKind::Vehicle => Rgba32::from_rgb(220, 40, 40),
        ObjectKind::Debris => Rgba32::from_rgb(200, 0, 160),
        ObjectKind::Box | ObjectKind::Cylinder => Rgba32::from_rgb(140, 120, 90),
    }
}

/// An entity path part from a name (ids and link names may hold any character).
fn path_part(name: &str) -> String {
    let cleaned: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if cleaned.is_empty() {
        "_".into()
    } else {
        cleaned
    }
}

fn quat(q: &UnitQuaternion<f64>) -> Quaternion {
    Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
}

fn yaw_quat(yaw_rad: f64) -> Quaternion {
    let h = 0.5 * yaw_rad;
    Quaternion::from_xyzw([0.0, 0.0, h.sin() as f32, h.cos() as f32])
}

fn v3(v: &Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// A cone (apex up) as a mesh, from [`cone_vertices`].
fn cone_mesh(vertices: Vec<[f32; 3]>, color: Rgba32) -> rerun::Mesh3D {
    let sides = vertices.len() as u32 - 2;
    let mut triangles = Vec::new();
    for k in 0..sides {
        let (a, b) = (2 + k, 2 + (k + 1) % sides);
        triangles.push([0, a, b]);
        triangles.push([1, b, a]);
    }
    rerun::Mesh3D::new(vertices)
        .with_triangle_indices(triangles)
        .with_albedo_factor(color)
}

/// Logs a solid's shape: in its own frame (`local`), or placed in the world.
fn log_solid(
    rec: &RecordingStream,
    path: &str,
    solid: &Solid,
    local: bool,
    is_static: bool,
) -> Result<()> {
    let color = kind_color(solid.kind);
    let (x, y, z0, yaw) = if local {
        (0.0, 0.0, solid.z_min_m, 0.0)
    } else {
        (solid.x_m, solid.y_m, solid.z_min_m, solid.yaw_rad)
    };
    let h = solid.shape.height_m();
    let center = [x as f32, y as f32, (z0 + 0.5 * h) as f32];
    let log = |what: &dyn rerun::AsComponents| -> Result<()> {
        if is_static {
            rec.log_static(path, what)?;
        } else {
            rec.log(path, what)?;
        }
        Ok(())
    };
    match solid.shape {
        SolidShape::Box { size_m } => log(&rerun::Boxes3D::from_centers_and_half_sizes(
            [center],
            [[
                0.5 * size_m[0] as f32,
                0.5 * size_m[1] as f32,
                0.5 * size_m[2] as f32,
            ]],
        )
        .with_quaternions([yaw_quat(yaw)])
        .with_fill_mode(FillMode::Solid)
        .with_colors([color])),
        SolidShape::Cylinder { radius_m, height_m } => log(
            &rerun::Cylinders3D::from_lengths_and_radii([height_m as f32], [radius_m as f32])
                .with_centers([center])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
        ),
        SolidShape::Cone { radius_m, height_m } => {
            // A mesh has no pose of its own: a static object's is baked into its vertices.
            log(&cone_mesh(
                cone_vertices(radius_m, height_m, x, y, z0),
                color,
            ))
        }
    }
}

/// A cone of `radius` and `height` standing at (x, y, z0): apex, base centre, base rim.
fn cone_vertices(radius_m: f64, height_m: f64, x: f64, y: f64, z0: f64) -> Vec<[f32; 3]> {
    const SIDES: u32 = 16;
    let mut positions = vec![
        [x as f32, y as f32, (z0 + height_m) as f32],
        [x as f32, y as f32, z0 as f32],
    ];
    for k in 0..SIDES {
        let a = std::f64::consts::TAU * k as f64 / SIDES as f64;
        positions.push([
            (x + radius_m * a.cos()) as f32,
            (y + radius_m * a.sin()) as f32,
            z0 as f32,
        ]);
    }
    positions
}

/// A vehicle part (URDF collision primitive) in the vehicle frame.
fn log_part(rec: &RecordingStream, path: &str, part: &aircraft::Part, color: Rgba32) -> Result<()> {
    let pose: &Isometry3<f64> = &part.vehicle_from_part;
    let center = v3(&pose.translation.vector);
    let q = quat(&pose.rotation);
    let color = Rgba32::from_unmultiplied_rgba(
        color.to_array()[0],
        color.to_array()[1],
        color.to_array()[2],
        200,
    );
    match part.shape {
        aircraft::Shape::Box { half_extents_m } => rec.log_static(
            path,
            &rerun::Boxes3D::from_centers_and_half_sizes([center], [v3(&half_extents_m)])
                .with_quaternions([q])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
        )?,
        aircraft::Shape::Cylinder {
            radius_m,
            half_length_m,
        } => rec.log_static(
            path,
            &rerun::Cylinders3D::from_lengths_and_radii(
                [2.0 * half_length_m as f32],
                [radius_m as f32],
            )
            .with_centers([center])
            .with_quaternions([q])
            .with_fill_mode(FillMode::Solid)
            .with_colors([color]),
        )?,
        aircraft::Shape::Capsule {
            radius_m,
            half_length_m,
        } => {
            // Rerun's capsule runs from its origin along +z.
            let start = pose * nalgebra::Point3::new(0.0, 0.0, -half_length_m);
            rec.log_static(
                path,
                &rerun::Capsules3D::from_lengths_and_radii(
                    [2.0 * half_length_m as f32],
                    [radius_m as f32],
                )
                .with_translations([v3(&start.coords)])
                .with_quaternions([q])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
            )?
        }
        aircraft::Shape::Sphere { radius_m } => rec.log_static(
            path,
            &rerun::Ellipsoids3D::from_centers_and_radii([center], [radius_m as f32])
                .with_fill_mode(FillMode::Solid)
                .with_colors([color]),
        )?,
    }
    Ok(())
}

/// The ground slab and the painted patches (grey by remission).
fn log_ground(rec: &RecordingStream, scene: &crate::scene::Scene) -> Result<()> {
    let (min, max) = (scene.min_m, scene.max_m);
    rec.log_static(
        "world/ground",
        &rerun::Boxes3D::from_centers_and_half_sizes(
            [[
                (0.5 * (min[0] + max[0])) as f32,
                (0.5 * (min[1] + max[1])) as f32,
                -0.03,
            ]],
            [[
                (0.5 * (max[0] - min[0])) as f32,
                (0.5 * (max[1] - min[1])) as f32,
                0.02,
            ]],
        )
        .with_fill_mode(FillMode::Solid)
        .with_colors([Rgba32::from_rgb(70, 72, 78)]),
    )?;
    if !scene.patches.is_empty() {
        let grey = |r: f32| {
            let v = (90.0 + 160.0 * r.clamp(0.0, 1.0)) as u8;
            Rgba32::from_rgb(v, v, v)
        };
        rec.log_static(
            "world/patches",
            &rerun::Boxes3D::from_centers_and_half_sizes(
                scene
                    .patches
                    .iter()
                    .map(|p| [p.x_m as f32, p.y_m as f32, -0.005]),
                scene
                    .patches
                    .iter()
                    .map(|p| [0.5 * p.length_m as f32, 0.5 * p.width_m as f32, 0.004]),
            )
            .with_quaternions(scene.patches.iter().map(|p| yaw_quat(p.yaw_rad)))
            .with_fill_mode(FillMode::Solid)
            .with_colors(scene.patches.iter().map(|p| grey(p.remission))),
        )?;
    }
    Ok(())
}

/// The route as a line strip just above the ground, closed back to its first point when the
/// route is closed.
fn log_route(rec: &RecordingStream, scenario: &crate::scenario::Scenario) -> Result<()> {
    let mut route: Vec<[f32; 3]> = scenario
        .route
        .waypoints_m
        .iter()
        .map(|p| [p.x as f32, p.y as f32, 0.02])
        .collect();
    if scenario.route.closed
        && let Some(first) = route.first().copied()
    {
        route.push(first);
    }
    rec.log_static(
        "world/route",
        &rerun::LineStrips3D::new([route])
            .with_radii([0.08])
            .with_colors([Rgba32::from_rgb(250, 250, 250)]),
    )?;
    Ok(())
}

/// A circle of the plane z = `z` as a closed line strip.
fn circle_strip(x: f64, y: f64, r: f64, z: f64) -> Vec<[f32; 3]> {
    const SIDES: usize = 32;
    (0..=SIDES)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / SIDES as f64;
            [(x + r * a.cos()) as f32, (y + r * a.sin()) as f32, z as f32]
        })
        .collect()
}

/// The cells of a grid within a square around a point.
struct Crop {
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
    /// The grid's width (row stride).
    stride: usize,
    resolution_m: f64,
    /// Lower-left corner of the crop, metres.
    corner: Point2<f64>,
}

impl Crop {
    fn around(g: &mapper::GridGeometry, center: Point2<f64>, half_m: f64) -> Option<Crop> {
        let res = g.resolution_m();
        let half = (half_m / res).round() as i64;
        let (cx, cy) = g.cell_coords(&center);
        let x0 = (cx - half).clamp(0, g.width() as i64) as usize;
        let x1 = (cx + half).clamp(0, g.width() as i64) as usize;
        let y0 = (cy - half).clamp(0, g.height() as i64) as usize;
        let y1 = (cy + half).clamp(0, g.height() as i64) as usize;
        (x1 > x0 && y1 > y0).then(|| Crop {
            x0,
            y0,
            w: x1 - x0,
            h: y1 - y0,
            stride: g.width(),
            resolution_m: res,
            corner: g.origin_m() + nalgebra::Vector2::new(x0 as f64 * res, y0 as f64 * res),
        })
    }

    /// Row `y` of the crop in `data` (a grid of this geometry).
    fn row<'a, T>(&self, data: &'a [T], y: usize) -> &'a [T] {
        let start = y * self.stride + self.x0;
        &data[start..start + self.w]
    }
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
    scans_seen: u64,
    next_step_t: f64,
    next_map_t: f64,
    finished: bool,
}

impl Replay {
    /// Opens the recording file and/or the live viewer. Errors name the flag at fault.
    pub fn new(options: &ReplayOptions, name: &str) -> Result<Self> {
        options.validate()?;
        let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
        let mut file = None;
        if let Some(path) = &options.record {
            let dir = match path.parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => PathBuf::from("."),
            };
            std::fs::create_dir_all(&dir)
                .ctx(|| format!("--record {}: creating {}", path.display(), dir.display()))?;
            let tmp = tempfile::Builder::new()
                .prefix(".taxi-sim-replay-")
                .suffix(".rrd.part")
                .tempfile_in(&dir)
                .ctx(|| {
                    format!(
                        "--record {}: creating a file in {}",
                        path.display(),
                        dir.display()
                    )
                })?
                .into_temp_path();
            let sink = FileSink::new(tmp.to_path_buf())
                .ctx(|| format!("--record {}: opening the recording", path.display()))?;
            sinks.push(Box::new(sink));
            file = Some((tmp, path.clone()));
        }
        let mut streamed_to = None;
        if options.spawn {
            let spawn = rerun::SpawnOptions::default();
            let info = rerun::spawn(&spawn).map_err(|e| {
                invalid!(
                    "--spawn: could not start the Rerun viewer ({e}); install it with `pip install rerun-sdk=={}.*` (the viewer must match Rerun {RERUN_VERSION}) or use --record",
                    RERUN_VERSION
                )
            })?;
            let url = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
            sinks.push(Box::new(grpc_sink(&url)?));
            streamed_to = Some(url);
        }
        if let Some(addr) = &options.connect {
            let url = proxy_url(addr)?;
            sinks.push(Box::new(grpc_sink(&url)?));
            streamed_to = Some(url);
        }
        ensure!(
            !sinks.is_empty(),
            "the replay needs --record, --spawn or --connect"
        );
        let live = options.spawn || options.connect.is_some();
        // A recording only: large chunks (fewer, smaller on disk). Live: the default 200 ms.
        let batcher = if live {
            rerun::log::ChunkBatcherConfig::DEFAULT
        } else {
            rerun::log::ChunkBatcherConfig {
                flush_tick: std::time::Duration::from_secs(2),
                flush_num_bytes: 8 * 1024 * 1024,
                ..rerun::log::ChunkBatcherConfig::DEFAULT
            }
        };
        let rec = rerun::RecordingStreamBuilder::new("taxi-sim")
            .recording_name(name)
            .enabled(true)
            .batcher_config(batcher)
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

    /// The layout: the 3D world large on the left; the distance maps, the time series and the
    /// events on the right. Sent as the active blueprint (a user's own layout is one click away:
    /// "reset to default blueprint" brings this one back).
    fn blueprint(levels: usize) -> (Blueprint, Option<String>) {
        let maps: Vec<rerun::blueprint::ContainerLike> = (0..levels)
            .map(|k| {
                Spatial2DView::new(format!("level {k} distance map (m)"))
                    .with_origin(format!("/maps/level_{k}"))
                    .into()
            })
            .collect();
        let series = |name: &str, origin: &str, contents: &[&str]| -> ContainerLike {
            TimeSeriesView::new(name)
                .with_origin(origin)
                .with_contents(contents.iter().map(|c| c.to_string()))
                .into()
        };
        let plots = Grid::new([
            series(
                "speed (m/s), avoider scale",
                "/plots",
                &["/plots/speed_m_s", "/plots/speed_scale"],
            ),
            series("steering (rad)", "/plots", &["/plots/steering_rad"]),
            series(
                "clearance per level (m)",
                "/plots/clearance_m",
                &["/plots/clearance_m/**"],
            ),
            series("real-time factor", "/plots", &["/plots/real_time_factor"]),
        ])
        .with_grid_columns(2);
        let world: ContainerLike = Spatial3DView::new("world").with_origin("/world").into();
        let world_path = match &world {
            ContainerLike::View(v) => Some(v.blueprint_path().to_string()),
            _ => None,
        };
        let blueprint = Blueprint::new(
            Horizontal::new([
                world,
                Vertical::new([
                    Horizontal::new(maps).into(),
                    plots.into(),
                    TextLogView::new("events").with_origin("/events").into(),
                ])
                .with_row_shares([1.0, 1.4, 0.7])
                .into(),
            ])
            .with_column_shares([1.8, 1.0]),
        )
        .with_time_panel(TimePanel::new().with_timeline(TIMELINE));
        (blueprint, world_path)
    }

    /// Sends the layout as the active blueprint, with the 3D view's camera behind the vehicle
    /// and following it. The Rust blueprint API cannot set a view's camera yet, so its messages
    /// are rendered into memory first and the camera is added to the same blueprint store.
    fn send_blueprint(&self, levels: usize, start: &Isometry2<f64>) -> Result<()> {
        use rerun::external::re_sdk_types::blueprint::archetypes::EyeControls3D;
        let (blueprint, world_path) = Self::blueprint(levels);
        let activation = rerun::blueprint::BlueprintActivation {
            make_active: true,
            make_default: true,
        };
        let (memory, storage) = rerun::RecordingStreamBuilder::new("taxi-sim").memory()?;
        blueprint.send(&memory, activation)?;
        memory.flush_blocking()?;
        let mut messages = storage.take();
        let Some(command) = messages.iter().find_map(|m| match m {
            rerun::log::LogMsg::BlueprintActivationCommand(c) => Some(c.clone()),
            _ => None,
        }) else {
            // Nothing to add the camera to: send the layout as it is.
            return Ok(blueprint.send(&self.rec, activation)?);
        };
        messages.retain(|m| {
            m.store_id() == &command.blueprint_id
                && !matches!(m, rerun::log::LogMsg::BlueprintActivationCommand(_))
        });
        if let Some(world_path) = world_path {
            let (eye, eye_storage) =
                rerun::RecordingStreamBuilder::from_store_id(&command.blueprint_id).memory()?;
            eye.set_time_sequence("blueprint", 0);
            let at = |x: f64, y: f64, z: f64| -> [f32; 3] {
                let p = start * Point2::new(x, y);
                [p.x as f32, p.y as f32, z as f32]
            };
            eye.log(
                format!("{world_path}/EyeControls3D"),
                &EyeControls3D::new()
                    .with_position(at(-18.0, 12.0, 14.0))
                    .with_look_target(at(6.0, 0.0, 0.0))
                    .with_eye_up([0.0, 0.0, 1.0])
                    .with_tracking_entity("/world/vehicle"),
            )?;
            eye.flush_blocking()?;
            messages.extend(
                eye_storage
                    .take()
                    .into_iter()
                    .filter(|m| matches!(m, rerun::log::LogMsg::ArrowMsg(..))),
            );
        }
        self.rec.send_blueprint(messages, command);
        Ok(())
    }

    /// Logs what stays the same all run (static): the axes' convention, the ground and its
    /// patches, the static objects, the route, the vehicle, the LiDAR's classes and the names
    /// and colours of the time series, in that order.
    fn log_static_world(&mut self, run: &RunStart<'_>) -> Result<()> {
        let rec = &self.rec;
        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        let scene = run.scene;
        log_ground(rec, scene)?;
        for solid in &scene.solids[..run.first_obstacle] {
            log_solid(
                rec,
                &format!("world/objects/{}", path_part(&solid.id)),
                solid,
                false,
                true,
            )?;
        }
        log_route(rec, run.scenario)?;
        self.log_vehicle(run)?;
        self.log_lidar_classes()?;
        self.log_series_names()?;
        Ok(())
    }

    /// The vehicle: its parts, coloured by level, and its circles at each level's height.
    fn log_vehicle(&self, run: &RunStart<'_>) -> Result<()> {
        let rec = &self.rec;
        let vehicle = &run.scenario.vehicle.vehicle;
        for (i, part) in vehicle.parts.iter().enumerate() {
            let level = run.part_levels.get(i).copied().unwrap_or(0);
            log_part(
                rec,
                &format!(
                    "world/vehicle/parts/{}/{}",
                    path_part(&part.link),
                    part.collision_index
                ),
                part,
                level_color(level),
            )?;
        }
        for (k, h) in self.level_heights_m.iter().enumerate() {
            let strips: Vec<Vec<[f32; 3]>> = run
                .model
                .circles()
                .iter()
                .filter(|c| c.level == k)
                .map(|c| circle_strip(c.x_m, c.y_m, c.radius_m, h.max(0.05)))
                .collect();
            rec.log_static(
                format!("world/vehicle/circles/level_{k}"),
                &rerun::LineStrips3D::new(strips)
                    .with_radii([0.03])
                    .with_colors([level_color(k)]),
            )?;
        }
        Ok(())
    }

    /// The LiDAR's classes (ground, vehicle, unmapped, above every level, one per level) as the
    /// annotation context of `world/lidar`.
    fn log_lidar_classes(&self) -> Result<()> {
        let mut classes: Vec<(u16, String, Rgba32)> = vec![
            (
                CLASS_GROUND,
                "ground (free)".into(),
                Rgba32::from_rgb(150, 150, 150),
            ),
            (
                CLASS_VEHICLE,
                "vehicle (self)".into(),
                Rgba32::from_rgb(90, 60, 120),
            ),
            (
                CLASS_UNMAPPED,
                "beyond mapping range".into(),
                Rgba32::from_rgb(80, 80, 80),
            ),
            (
                CLASS_ABOVE,
                "above every level".into(),
                Rgba32::from_rgb(200, 200, 255),
            ),
        ];
        for k in 0..self.level_heights_m.len() {
            classes.push((
                CLASS_LEVEL0 + k as u16,
                format!("obstacle, level {k}"),
                level_color(k),
            ));
        }
        self.rec.log_static(
            "world/lidar",
            &rerun::AnnotationContext::new(
                classes
                    .iter()
                    .map(|(id, label, color)| (*id, label.as_str(), *color)),
            ),
        )?;
        Ok(())
    }

    /// Names and colours of the time series.
    fn log_series_names(&self) -> Result<()> {
        let rec = &self.rec;
        for (k, _) in self.level_heights_m.iter().enumerate() {
            rec.log_static(
                format!("plots/clearance_m/level_{k}"),
                &rerun::SeriesLines::new()
                    .with_names([format!("clearance level {k} (m)")])
                    .with_colors([level_color(k)]),
            )?;
        }
        for (path, name) in [
            ("plots/speed_m_s", "speed (m/s)"),
            ("plots/steering_rad", "steering (rad)"),
            ("plots/real_time_factor", "real-time factor"),
            ("plots/speed_scale", "avoider speed scale"),
        ] {
            rec.log_static(path, &rerun::SeriesLines::new().with_names([name]))?;
        }
        Ok(())
    }

    fn log_obstacles(&mut self, world: &crate::world::World) -> Result<()> {
        for (k, last) in self.obstacles.iter_mut().enumerate() {
            let i = self.first_obstacle + k;
            let path = &self.obstacle_paths[k];
            let active = world.object_active(i);
            let Some(solid) = world.scene().solids.get(i) else {
                continue;
            };
            match (active, *last) {
                (false, None) => {}
                (false, Some(_)) => {
                    self.rec.log(path.as_str(), &rerun::Clear::flat())?;
                    *last = None;
                }
                (true, prev) => {
                    let now = (solid.x_m, solid.y_m, solid.yaw_rad);
                    if prev.is_none() {
                        log_solid(&self.rec, path, solid, true, false)?;
                    }
                    if prev != Some(now) {
                        self.rec.log(
                            path.as_str(),
                            &rerun::Transform3D::from_translation_rotation(
                                [now.0 as f32, now.1 as f32, 0.0],
                                yaw_quat(now.2),
                            ),
                        )?;
                    }
                    *last = Some(now);
                }
            }
        }
        Ok(())
    }

    fn log_lidar(&mut self, frame: &ScanFrame<'_>) -> Result<()> {
        let Some(levels) = &self.levels else {
            return Ok(());
        };
        let scan = &frame.revolution.scan;
        let beams = scan.beams();
        let params = self.obstacle_test;
        let (mut positions, mut classes) = (Vec::new(), Vec::new());
        for (c, column) in scan
            .columns()
            .iter()
            .enumerate()
            .step_by(self.options.point_stride)
        {
            let sensor = nalgebra::Point3::from(column.world_from_sensor.translation.vector);
            let returns = &scan.returns()[c * beams..(c + 1) * beams];
            for (b, r) in returns.iter().enumerate() {
                let Some(r) = r else { continue };
                let p = r.point_in_world;
                positions.push([p.x as f32, p.y as f32, p.z as f32]);
                let owner = frame.owners.get(c * beams + b).copied().flatten();
                let range_xy = (p.x - sensor.x).hypot(p.y - sensor.y);
                let class = if matches!(owner, Some(Owner::VehiclePart(_))) {
                    CLASS_VEHICLE
                } else if range_xy > params.max_range_m {
                    CLASS_UNMAPPED
                } else {
                    // The mapper's obstacle test: this return against the one below it.
                    let height = p.z - params.ground_height_m;
                    let obstacle = match b.checked_sub(1).and_then(|lb| returns[lb]) {
                        Some(lower) => mapper::occupancy::obstacle_probability(
                            &sensor,
                            &lower.point_in_world,
                            &p,
                            &params,
                        )
                        .is_some_and(|pr| pr > 0.5),
                        None => params
                            .unsafe_height_above_ground_m
                            .is_some_and(|h| height >= h),
                    };
                    if !obstacle {
                        CLASS_GROUND
                    } else {
                        (0..levels.count())
                            .rev()
                            .find(|&k| levels.classify(k, height) == mapper::HeightClass::Inside)
                            .map_or(CLASS_ABOVE, |k| CLASS_LEVEL0 + k as u16)
                    }
                };
                classes.push(class);
            }
        }
        self.rec.log(
            "world/lidar",
            &rerun::Points3D::new(positions)
                .with_class_ids(classes)
                .with_radii([0.04]),
        )?;
        Ok(())
    }

    /// The estimate's error against the truth of the same revolution and its own standard
    /// deviation (plots); with `particles`, a hundred of the particles and the 2-sigma ellipse
    /// of the estimate's position.
    fn log_localization(&mut self, frame: &ScanFrame<'_>, particles: bool) -> Result<()> {
        let Some(estimate) = frame.pose_estimate else {
            return Ok(());
        };
        let d = frame.estimate.translation.vector - frame.truth.translation.vector;
        let left = frame.truth.rotation * nalgebra::Vector2::y();
        self.rec.log(
            "plots/localization/cross_track_error_m",
            &rerun::Scalars::single(d.dot(&left)),
        )?;
        self.rec.log(
            "plots/localization/cross_track_sigma_m",
            &rerun::Scalars::single(estimate.cross_track_sigma_m()),
        )?;
        let Some(ps) = frame.particles.filter(|_| particles) else {
            return Ok(());
        };
        let every = ps.len().div_ceil(100).max(1);
        self.rec.log(
            "world/localization/particles",
            &rerun::Points3D::new(
                ps.iter()
                    .step_by(every)
                    .map(|p| [p.x as f32, p.y as f32, 0.08]),
            )
            .with_radii([0.05])
            .with_colors([Rgba32::from_rgb(255, 120, 0)]),
        )?;
        let c = estimate.covariance.fixed_view::<2, 2>(0, 0).into_owned();
        let eig = c.symmetric_eigen();
        let centre = estimate.world_from_vehicle.translation.vector;
        let ellipse: Vec<[f32; 3]> = (0..=32)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 32.0;
                let u = nalgebra::Vector2::new(
                    2.0 * eig.eigenvalues[0].max(0.0).sqrt() * a.cos(),
                    2.0 * eig.eigenvalues[1].max(0.0).sqrt() * a.sin(),
                );
                let p = centre + eig.eigenvectors * u;
                [p.x as f32, p.y as f32, 0.08]
            })
            .collect();
        self.rec.log(
            "world/localization/covariance_2sigma",
            &rerun::LineStrips3D::new([ellipse]).with_colors([Rgba32::from_rgb(255, 120, 0)]),
        )?;
        Ok(())
    }

    fn log_plan(&mut self, frame: &ScanFrame<'_>, candidates: bool) -> Result<()> {
        let strip = |poses: &[Isometry2<f64>], every: usize| -> Vec<[f32; 3]> {
            let mut out: Vec<[f32; 3]> = poses
                .iter()
                .step_by(every)
                .map(|p| [p.translation.x as f32, p.translation.y as f32, 0.06])
                .collect();
            if let Some(last) = poses.last()
                && poses.len() % every != 1 % every
            {
                out.push([last.translation.x as f32, last.translation.y as f32, 0.06]);
            }
            out
        };
        let plan = frame.plan;
        if candidates {
            let colors: Vec<Rgba32> = plan
                .candidates
                .iter()
                .map(|c| {
                    if c.collision_at_m.is_some() {
                        Rgba32::from_unmultiplied_rgba(255, 60, 60, 160)
                    } else {
                        Rgba32::from_unmultiplied_rgba(120, 230, 120, 120)
                    }
                })
                .collect();
            self.rec.log(
                "world/planner/candidates",
                &rerun::LineStrips3D::new(plan.candidates.iter().map(|c| strip(&c.poses, 4)))
                    .with_radii([0.025])
                    .with_colors(colors),
            )?;
        }
        let chosen = plan.chosen();
        let color = if plan.blocked {
            Rgba32::from_rgb(255, 40, 40)
        } else {
            Rgba32::from_rgb(40, 120, 255)
        };
        self.rec.log(
            "world/planner/chosen",
            &rerun::LineStrips3D::new([strip(&chosen.poses, 2)])
                .with_radii([0.07])
                .with_colors([color]),
        )?;
        Ok(())
    }

    fn log_maps(&mut self, map: &MultiHeightMap, center: Point2<f64>) -> Result<()> {
        let half_m = self.options.map_half_m;
        let merge = map.config().merge;
        for k in 0..map.levels().count() {
            let (Some(live), Some(prior)) = (map.live_log_odds(k), map.prior_log_odds(k)) else {
                continue;
            };
            // ROS OccupancyGrid values: 0..100 = probability in percent, 255 (-1) = unknown;
            // row 0 at the lowest y, like the grid.
            if let Some(crop) = Crop::around(live.geometry(), center, half_m) {
                let mut occupancy = Vec::with_capacity(crop.w * crop.h);
                for y in crop.y0..crop.y0 + crop.h {
                    let (l, p) = (crop.row(live.data(), y), crop.row(prior.data(), y));
                    occupancy.extend(l.iter().zip(p).map(|(l, p)| {
                        mapper::map::merge_log_odds(*l, *p, merge).map_or(255u8, |lo| {
                            (mapper::occupancy::probability(lo) * 100.0).round() as u8
                        })
                    }));
                }
                let z = self
                    .level_heights_m
                    .get(k)
                    .copied()
                    .unwrap_or(0.0)
                    .max(0.01);
                self.rec.log(
                    format!("world/maps/level_{k}/occupancy"),
                    &rerun::GridMap::new(
                        occupancy,
                        rerun::components::ImageFormat::from_color_model(
                            [crop.w as u32, crop.h as u32],
                            ColorModel::L,
                            ChannelDatatype::U8,
                        ),
                        crop.resolution_m as f32,
                    )
                    .with_translation([crop.corner.x as f32, crop.corner.y as f32, z as f32])
                    .with_colormap(Colormap::RvizMap)
                    .with_opacity(0.55),
                )?;
            }
            // The distance map (its own, smaller geometry) as an image, north up, 0.1 m a unit.
            if let Some(odm) = map.distance_maps().level(k)
                && let Some(crop) = Crop::around(odm.grid().geometry(), center, half_m)
            {
                let mut pixels = Vec::with_capacity(crop.w * crop.h);
                for y in (crop.y0..crop.y0 + crop.h).rev() {
                    pixels.extend(
                        crop.row(odm.grid().data(), y)
                            .iter()
                            .map(|v| (v * 10.0).round().clamp(0.0, 255.0) as u8),
                    );
                }
                self.rec.log(
                    format!("maps/level_{k}/distance"),
                    &rerun::DepthImage::new(
                        pixels,
                        rerun::components::ImageFormat::depth(
                            [crop.w as u32, crop.h as u32],
                            ChannelDatatype::U8,
                        ),
                    )
                    .with_meter(10.0)
                    .with_colormap(Colormap::Turbo)
                    // In the image's own units (0.1 m): the colours span 0-8 m, where the
                    // circles' radii plus the safety distance live; farther is all red.
                    .with_depth_range([0.0, 80.0]),
                )?;
            }
        }
        self.summary.maps_logged += 1;
        Ok(())
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
            let size = std::fs::metadata(&tmp)
                .ctx(|| format!("--record {}: the recording vanished", dest.display()))?
                .len();
            ensure!(
                size > 0,
                "--record {}: Rerun wrote nothing (see its messages above)",
                dest.display()
            );
            set_readable(&tmp);
            tmp.persist(&dest).ctx(|| {
                format!(
                    "--record {}: moving the recording into place",
                    dest.display()
                )
            })?;
            self.summary.recorded = Some((dest, size));
        }
        Ok(())
    }
}

/// tempfile creates 0600 files; a recording is for others to read too.
fn set_readable(path: &Path) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        let _ = std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o644));
    }
    #[cfg(not(unix))]
    let _ = path;
}

fn grpc_sink(url: &str) -> Result<GrpcSink> {
    let uri = url
        .parse::<rerun::external::re_uri::ProxyUri>()
        .map_err(|e| invalid!("viewer address {url}: {e}"))?;
    Ok(GrpcSink::new(uri))
}

impl Observer for Replay {
    fn start(&mut self, run: &RunStart<'_>) -> Result<()> {
        let levels = crate::mapping::levels_of(run.scenario, run.config)?;
        self.level_heights_m = levels.heights_m().to_vec();
        self.levels = Some(levels);
        self.obstacle_test = run.config.mapping.map.obstacle_test;
        self.first_obstacle = run.first_obstacle;
        let obstacles = run.scene.solids.len().saturating_sub(run.first_obstacle);
        self.obstacles = vec![None; obstacles];
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

    fn scan(&mut self, frame: &ScanFrame<'_>) -> Result<()> {
        self.time(frame.t_s);
        let full = self
            .scans_seen
            .is_multiple_of(u64::from(self.options.scan_every));
        self.scans_seen += 1;
        if full {
            self.log_lidar(frame)?;
            self.summary.scans_logged += 1;
        }
        self.log_localization(frame, full)?;
        self.log_plan(frame, full)?;
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
        let (text, level) = match event {
            Event::Stop { route_s_m } => (
                format!("stop at {route_s_m:.1} m along the route"),
                TextLogLevel::WARN,
            ),
            Event::Resume { stopped_s } => {
                (format!("resume after {stopped_s:.1} s"), TextLogLevel::INFO)
            }
            Event::Deviate { offset_m } => (
                format!("deviate: offset {offset_m:+.2} m"),
                TextLogLevel::INFO,
            ),
            Event::BackOnRoute => ("back on the route".to_string(), TextLogLevel::INFO),
            Event::Watchdog { holding: true } => (
                "watchdog: no fresh LiDAR revolution, stopping".to_string(),
                TextLogLevel::WARN,
            ),
            Event::Watchdog { holding: false } => (
                "watchdog: revolutions are back".to_string(),
                TextLogLevel::INFO,
            ),
            Event::Contact(c) => (
                format!("contact: {} ({:?}) touched by {}", c.object, c.kind, c.part),
                TextLogLevel::ERROR,
            ),
            Event::Lap { lap, time_s } => {
                (format!("lap {lap} in {time_s:.1} s"), TextLogLevel::INFO)
            }
            Event::Pass { id, outcome, met } => (
                format!(
                    "pass {id}: {outcome}{}",
                    if *met { "" } else { " (not as expected)" }
                ),
                if *met {
                    TextLogLevel::INFO
                } else {
                    TextLogLevel::WARN
                },
            ),
        };
        self.rec
            .log("events", &rerun::TextLog::new(text).with_level(level))?;
        Ok(())
    }

    fn finish(&mut self, report: &RunReport) -> Result<()> {
        self.time(report.sim_time_s);
        self.rec.log(
            "events",
            &rerun::TextLog::new(format!(
                "end: {}/{} laps, {} contacts, {}{}",
                report.laps_completed,
                report.laps,
                report.contacts.len(),
                if report.expectations_met {
                    "every expectation held"
                } else {
                    "expectations not met"
                },
                match report.end {
                    crate::judge::EndReason::Completed => "",
                    crate::judge::EndReason::TimedOut => " (timed out)",
                    crate::judge::EndReason::Interrupted => " (interrupted)",
                    crate::judge::EndReason::WaitingForHiddenObstacle =>
                        " (waiting for a hidden obstacle: pilot called)",
                }
            ))
            .with_level(if report.expectations_met {
                TextLogLevel::INFO
            } else {
                TextLogLevel::WARN
            }),
        )?;
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
