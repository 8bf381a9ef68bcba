//! `taxi-sim scan`: one LiDAR revolution of a scenario's world from a point of its route, or one
//! revolution of a real Velodyne capture, as PLY; a scenario's revolutions as a Velodyne capture
//! (`--out FILE.pcap`), what VeloView and the ROS driver read.

use std::path::PathBuf;

use anyhow::Context as _;
use nalgebra::{Isometry2, Vector2};
use sim::scenario::RunConfig;
use sim::scenario::Scenario;
use sim::world::World;
use sim::world::{Lidar, SweepPoses};

/// Arguments of `taxi-sim scan`.
#[derive(Debug, Clone, clap::Args)]
pub struct ScanArgs {
    /// The scenario file (not with `--pcap`).
    #[arg(required_unless_present = "pcap", conflicts_with = "pcap")]
    pub scenario: Option<PathBuf>,
    /// A Velodyne capture (pcap or pcapng; HDL-32E, VLP-16) to take the revolution from.
    #[arg(long, value_name = "FILE")]
    pub pcap: Option<PathBuf>,
    /// The sensor's VeloView calibration file (XML; default: its built-in table).
    #[arg(long, value_name = "FILE", requires = "pcap")]
    pub calibration: Option<PathBuf>,
    /// The capture's revolution (VeloView's frame numbering: 0 is the partial first).
    #[arg(long, default_value_t = 1, requires = "pcap")]
    pub revolution: usize,
    /// Where the capture's sensor stands, `x,y,yaw` (metres, metres, degrees), for `--frame
    /// world`.
    #[arg(
        long,
        value_name = "X,Y,YAW",
        default_value = "0,0,0",
        requires = "pcap"
    )]
    pub pose: String,
    /// The capture's sensor height above the ground, metres, for `--frame world` (default:
    /// the ground fitted to its returns).
    #[arg(long, value_name = "M", requires = "pcap")]
    pub sensor_height: Option<f64>,
    /// Where on the route, metres along it from its first point (0 = the start pose).
    #[arg(long, default_value_t = 0.0)]
    pub at: f64,
    /// Output file: PLY, or - ending in `.pcap`, for a scenario - a Velodyne capture of the
    /// sensor's packets (HDL-32E or VLP-16, as `--lidar-model` or `[lidar]` say).
    #[arg(long)]
    pub out: PathBuf,
    /// Revolutions to write to a `.pcap`, the sensor standing (default 1).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub revolutions: usize,
    /// The sensor model instead of `[lidar]`'s beams: `hdl-32e` or `vlp-16`.
    #[arg(long, value_name = "MODEL", conflicts_with = "pcap")]
    pub lidar_model: Option<String>,
    /// Frame of the points.
    #[arg(long, value_enum, default_value_t = Frame::World)]
    pub frame: Frame,
    /// Leave out the run-time obstacles (the world of the mapping drive).
    #[arg(long)]
    pub static_only: bool,
    /// Run configuration (TOML) whose `[lidar]` settings to use (default: the defaults).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
}

/// Which frame the points are written in (`sim::world::ply::Frame` on the command line).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Frame {
    /// The world frame (x east, y north, z up).
    World,
    /// The sensor frame (x forward, z up), as the sensor reports it.
    Sensor,
}

impl From<Frame> for sim::world::ply::Frame {
    fn from(frame: Frame) -> Self {
        match frame {
            Frame::World => Self::World,
            Frame::Sensor => Self::Sensor,
        }
    }
}

/// Runs `taxi-sim scan`.
pub fn run(args: &ScanArgs) -> anyhow::Result<()> {
    if let Some(pcap) = &args.pcap {
        return from_pcap(args, pcap);
    }
    let Some(path) = &args.scenario else {
        anyhow::bail!("a scenario file or --pcap FILE");
    };
    let scenario = Scenario::from_file(path)?;
    anyhow::ensure!(
        args.at.is_finite() && args.at >= 0.0,
        "--at {}: must be a distance >= 0 along the route",
        args.at
    );
    let pose = if args.at == 0.0 {
        scenario.vehicle.world_from_start
    } else {
        pose_along(&scenario, args.at)?
    };
    let vehicle = &scenario.vehicle.vehicle;
    let world = if args.static_only {
        World::static_only(&scenario.static_scene(), vehicle, &pose)
    } else {
        World::with_obstacles(&scenario.full_scene(), vehicle, &pose)
    };
    let config = match &args.config {
        Some(path) => RunConfig::from_file(path)?,
        None => RunConfig::default(),
    };
    let lidar_config = match &args.lidar_model {
        Some(name) => config.lidar.with_model(name).ok_or_else(|| {
            anyhow::anyhow!("--lidar-model {name}: not a model (hdl-32e, vlp-16)")
        })?,
        None => config.lidar,
    };
    let hz = lidar_config.rotation_frequency_hz;
    let lidar =
        Lidar::new(lidar_config, vehicle.vehicle_from_lidar()).map_err(anyhow::Error::msg)?;
    if args.out.extension().is_some_and(|e| e == "pcap") {
        anyhow::ensure!(args.revolutions >= 1, "--revolutions: at least 1");
        let scans: Vec<_> = (0..args.revolutions as u64)
            .map(|r| lidar.scan(&world, &SweepPoses::still(pose), r, scenario.seed))
            .collect();
        let packets = sim::pcap::write_capture(&scans, hz, 0.0, &args.out)?;
        let n: usize = scans
            .iter()
            .map(|s| s.scan.returns().iter().flatten().count())
            .sum();
        return crate::emit(&format!(
            "{}: {} revolution(s), {n} returns in {packets} data packets; wrote {}\n",
            scenario.name,
            scans.len(),
            args.out.display()
        ));
    }
    let scan = lidar.scan(&world, &SweepPoses::still(pose), 0, scenario.seed);
    sim::world::ply::write(&scan, args.frame.into(), &args.out)
        .with_context(|| format!("writing {}", args.out.display()))?;
    let n = scan.scan.returns().iter().flatten().count();
    crate::emit(&format!(
        "{}: {n} of {} rays returned, vehicle at ({:.2}, {:.2}) heading {:.1} deg; wrote {}\n",
        scenario.name,
        lidar.rays(),
        pose.translation.x,
        pose.translation.y,
        pose.rotation.angle().to_degrees(),
        args.out.display()
    ))
}

/// The pose `s` metres along the route's polyline, heading along its segment.
fn pose_along(scenario: &Scenario, s: f64) -> anyhow::Result<Isometry2<f64>> {
    let route = &scenario.route;
    let mut points = route.waypoints_m.clone();
    if route.closed
        && let Some(first) = points.first().copied()
    {
        points.push(first);
    }
    let mut left = s;
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let len = d.norm();
        if left <= len && len > 0.0 {
            let p = w[0] + d * (left / len);
            return Ok(Isometry2::new(Vector2::new(p.x, p.y), d.y.atan2(d.x)));
        }
        left -= len;
    }
    anyhow::bail!("--at {s}: the route is only {:.1} m long", route.length_m())
}

/// `--pcap`: one revolution of a capture.
fn from_pcap(args: &ScanArgs, pcap: &std::path::Path) -> anyhow::Result<()> {
    let recording = sim::pcap::read(pcap, args.calibration.as_deref())?;
    if let Some(line) = recording.skipped_line(pcap) {
        eprintln!("{line}");
    }
    let n = recording.frames.len();
    let frame = recording.frames.get(args.revolution).ok_or_else(|| {
        anyhow::anyhow!(
            "--revolution {}: {} has {n} (0 to {})",
            args.revolution,
            pcap.display(),
            n.saturating_sub(1)
        )
    })?;
    let pose = crate::commands::map::parse_pose(&args.pose)?;
    let (height, how) = match args.sensor_height {
        Some(h) => (h, "as given"),
        None => (
            recording
                .ground(std::slice::from_ref(frame))
                .ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}: revolution {}: too few ground returns to fit the ground; give \
                         --sensor-height",
                        pcap.display(),
                        args.revolution
                    )
                })?
                .height_m(),
            "fitted to the ground",
        ),
    };
    let mount = nalgebra::Isometry3::translation(0.0, 0.0, height);
    let scan = recording.scan(frame, &pose, &mount)?;
    sim::world::ply::write(&scan, args.frame.into(), &args.out)
        .with_context(|| format!("writing {}", args.out.display()))?;
    let partial = if args.revolution == 0 || args.revolution + 1 == n {
        " (partial: the capture starts or ends inside it)"
    } else {
        ""
    };
    crate::emit(&format!(
        "{}: revolution {} of {n}{partial}: {} returns in {} firings of {} lasers, the sensor {height:.2} m above the ground ({how}); wrote {}\n",
        pcap.display(),
        args.revolution,
        frame.points.len(),
        scan.scan.columns().len(),
        scan.scan.beams(),
        args.out.display()
    ))
}
