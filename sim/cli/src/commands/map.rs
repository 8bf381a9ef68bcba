//! `taxi-sim map`: the mapping drive that builds a scenario's offline multi-height map (optionally
//! recorded as a ROS 2 bag), or the same map built from a bag's point clouds and poses or from a
//! real Velodyne capture, with a progress bar.

use std::path::PathBuf;

use anyhow::Context as _;
use sim::offline_map::{
    default_map_dir, levels_of_vehicle, map_config, map_drive, self_filter_model,
};
use sim::rosbag::{BagMapOptions, DriveBag, PoseSource, map_from_bag};
use sim::scenario::{RunConfig, Scenario};

/// Where `--from-bag` takes poses from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PoseFrom {
    /// The transform tree (`/tf`, `/tf_static`).
    Tf,
    /// An odometry topic (`--odom-topic`), the sensor's mount from `/tf_static`.
    Odom,
}

/// Arguments of `taxi-sim map`.
#[derive(Debug, Clone, clap::Args)]
pub struct MapArgs {
    /// The scenario file: its vehicle's levels and self-hit filter (and, without `--from-bag` or
    /// `--pcap`, the route driven). `--from-bag` and `--pcap` may take `--vehicle` instead.
    #[arg(required_unless_present = "vehicle")]
    pub scenario: Option<PathBuf>,
    /// `--from-bag` or `--pcap` without a scenario: the vehicle whose levels and self-hit filter
    /// the map is built for (a shipped name or a sidecar path); the map covers what the data
    /// covers.
    #[arg(long, value_name = "NAME|SIDECAR", conflicts_with = "scenario")]
    pub vehicle: Option<String>,
    /// Output directory (default: out/maps/<scenario file name>, or out/maps/<bag name>-bag).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run configuration (TOML) whose LiDAR and mapping settings the map is built with.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Record the mapping drive as a ROS 2 bag (.mcap, `metadata.yaml` beside it): /tf_static,
    /// /tf, /velodyne_points, /clock.
    #[arg(long, value_name = "FILE.mcap", conflicts_with = "from_bag")]
    pub record: Option<PathBuf>,
    /// Build the map from this bag's point clouds (an .mcap file or a rosbag2 directory) instead
    /// of driving the route.
    #[arg(long, value_name = "BAG")]
    pub from_bag: Option<PathBuf>,
    /// The bag's point cloud topic (sensor_msgs/msg/PointCloud2 with x, y, z, intensity 0-255,
    /// ring).
    #[arg(long, default_value = "/velodyne_points", requires = "from_bag")]
    pub cloud_topic: String,
    /// Where each cloud's pose comes from.
    #[arg(long, value_enum, default_value = "tf", requires = "from_bag")]
    pub pose_source: PoseFrom,
    /// The odometry topic of `--pose-source odom` (nav_msgs/msg/Odometry).
    #[arg(long, default_value = "/odom", requires = "from_bag")]
    pub odom_topic: String,
    /// The map's frame in the transform tree.
    #[arg(long, default_value = "map", requires = "from_bag")]
    pub fixed_frame: String,
    /// The vehicle's frame (its origin the vehicle file's: the rear axle).
    #[arg(long, default_value = "base_link", requires = "from_bag")]
    pub base_frame: String,
    /// Firings a revolution (default: found in each cloud from its azimuths).
    #[arg(long, requires = "from_bag")]
    pub columns: Option<usize>,
    /// Build the map from this Velodyne capture (pcap or pcapng; HDL-32E, VLP-16): its full
    /// revolutions, the sensor standing at `--pose` or moving along `--poses`.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["from_bag", "record"])]
    pub pcap: Option<PathBuf>,
    /// The sensor's VeloView calibration file (XML; default: its built-in table).
    #[arg(long, value_name = "FILE", requires = "pcap")]
    pub calibration: Option<PathBuf>,
    /// Where the sensor stands, `x,y,yaw` (metres, metres, degrees; azimuth 0 along the yaw).
    #[arg(
        long,
        value_name = "X,Y,YAW",
        default_value = "0,0,0",
        requires = "pcap"
    )]
    pub pose: String,
    /// A moving sensor: its poses, CSV `time_s,x_m,y_m,yaw_deg` (time in seconds on the sensor's
    /// clock - its packets' timestamps, seconds past the hour); each revolution is placed at the
    /// pose interpolated at its middle firing.
    #[arg(long, value_name = "FILE", requires = "pcap", conflicts_with = "pose")]
    pub poses: Option<PathBuf>,
    /// The sensor's height above the ground, metres (default: the ground fitted to its returns).
    #[arg(long, value_name = "M", requires = "pcap")]
    pub sensor_height: Option<f64>,
    /// Remove the sensor's tilt fitted to the ground (its mount's pitch and roll; `taxi-sim
    /// compare-lidar` shows it); without it the sensor is taken as level.
    #[arg(long, requires = "pcap")]
    pub level: bool,
}

/// `--pose x,y,yaw_deg` read.
pub(crate) fn parse_pose(text: &str) -> anyhow::Result<nalgebra::Isometry2<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|w| w.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| {
            anyhow::anyhow!("--pose {text}: {e} (want x,y,yaw: metres, metres, degrees)")
        })?;
    anyhow::ensure!(
        v.len() == 3 && v.iter().all(|x| x.is_finite()),
        "--pose {text}: want three finite numbers x,y,yaw (metres, metres, degrees)"
    );
    Ok(nalgebra::Isometry2::new(
        nalgebra::Vector2::new(v[0], v[1]),
        v[2].to_radians(),
    ))
}

/// `--pcap`.
fn from_pcap(
    args: &MapArgs,
    pcap: &std::path::Path,
    vehicle: &aircraft::Vehicle,
    config: &RunConfig,
) -> anyhow::Result<()> {
    let pose = parse_pose(&args.pose)?;
    if let Some(h) = args.sensor_height {
        anyhow::ensure!(
            h.is_finite() && h > 0.0,
            "--sensor-height {h}: a height above the ground, metres"
        );
    }
    let dir = args.out.clone().unwrap_or_else(|| {
        let stem = pcap
            .file_stem()
            .map_or_else(|| "pcap".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("out")
            .join("maps")
            .join(format!("{stem}-pcap"))
    });
    let levels = levels_of_vehicle(vehicle, config)?;
    let progress = crate::bar(0, "mapping the capture");
    let poses = match &args.poses {
        Some(file) => sim::pcap::read_poses_csv(file)?,
        None => Vec::new(),
    };
    let placement = sim::pcap::Placement {
        pose,
        poses,
        height_m: args.sensor_height,
        level: args.level,
    };
    let report = sim::pcap::map_from_pcap(
        pcap,
        args.calibration.as_deref(),
        &placement,
        &levels,
        map_config(config),
        &dir,
        &mut |done, total| {
            progress.set_length(total);
            progress.set_position(done);
        },
    )
    .with_context(|| format!("taxi-sim map --pcap {}", pcap.display()))?;
    progress.finish_and_clear();
    if let Some(line) = &report.skipped {
        eprintln!("{line}");
    }
    let m = &report.manifest;
    let [pitch, roll] = report.ground.pitch_roll_deg();
    let h = report.vehicle_from_sensor.translation.vector.z;
    crate::emit(&format!(
        "{}: mapped {} revolutions, the sensor {h:.2} m above the ground ({}), the ground's tilt {pitch:.2} deg pitch, {roll:.2} deg roll ({}), into {} blocks; occupied cells per level {:?} (levels at {:?} m)\nwrote {}\n",
        pcap.display(),
        report.revolutions,
        if args.sensor_height.is_some() {
            "as given"
        } else {
            "fitted to the ground"
        },
        if args.level {
            "removed"
        } else {
            "kept: the sensor taken as level"
        },
        m.blocks,
        m.occupied_cells,
        m.level_heights_m,
        dir.display()
    ))
}

pub(crate) fn build_map(
    scenario: &Scenario,
    config: &RunConfig,
    dir: &std::path::Path,
) -> anyhow::Result<sim::offline_map::MapManifest> {
    let progress = crate::bar(0, "mapping");
    let manifest = map_drive(scenario, config, dir, &mut |done, total| {
        progress.set_length(total as u64);
        progress.set_position(done as u64);
    })?;
    progress.finish_and_clear();
    Ok(manifest)
}

/// The mapping drive, recorded into `bag`.
fn build_and_record(
    scenario: &Scenario,
    config: &RunConfig,
    dir: &std::path::Path,
    bag: &std::path::Path,
) -> anyhow::Result<sim::offline_map::MapManifest> {
    anyhow::ensure!(
        bag.extension().is_some_and(|e| e == "mcap"),
        "--record {}: a ROS 2 bag is an .mcap file",
        bag.display()
    );
    let mount = scenario.vehicle.vehicle.vehicle_from_lidar();
    let mut writer = DriveBag::create(bag, &mount)?;
    let progress = crate::bar(0, "mapping");
    let manifest = sim::offline_map::map_drive_with(
        scenario,
        config,
        dir,
        &mut |done, total| {
            progress.set_length(total as u64);
            progress.set_position(done as u64);
        },
        &mut |(t, pose, scan)| writer.revolution(t, pose, scan),
    )?;
    progress.finish_and_clear();
    let summary = writer.finish()?;
    crate::emit(&format!(
        "recorded {} ({} messages)\n",
        bag.display(),
        summary.topics.iter().map(|(_, n)| n).sum::<u64>()
    ))?;
    Ok(manifest)
}

/// `--from-bag`.
fn from_bag(
    args: &MapArgs,
    bag: &std::path::Path,
    vehicle: &aircraft::Vehicle,
    config: &RunConfig,
) -> anyhow::Result<()> {
    let options = BagMapOptions {
        cloud_topic: args.cloud_topic.clone(),
        pose_source: match args.pose_source {
            PoseFrom::Tf => PoseSource::Tf,
            PoseFrom::Odom => PoseSource::Odom(args.odom_topic.clone()),
        },
        fixed_frame: args.fixed_frame.clone(),
        base_frame: args.base_frame.clone(),
        columns: args.columns,
    };
    let dir = args.out.clone().unwrap_or_else(|| {
        let stem = bag
            .file_stem()
            .map_or_else(|| "bag".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("out")
            .join("maps")
            .join(format!("{stem}-bag"))
    });
    let levels = levels_of_vehicle(vehicle, config)?;
    let filter = self_filter_model(vehicle)?;
    let progress = crate::bar(0, "mapping from the bag");
    let report = map_from_bag(
        bag,
        &options,
        &levels,
        map_config(config),
        Some(&filter),
        &dir,
        &mut |done, total| {
            progress.set_length(total);
            progress.set_position(done);
        },
    )
    .with_context(|| format!("taxi-sim map --from-bag {}", bag.display()))?;
    progress.finish_and_clear();
    let m = &report.manifest;
    let skipped = match &report.first_skipped {
        Some(why) => format!("; {} clouds skipped (the first: {why})", report.skipped),
        None => String::new(),
    };
    let layout = report.layout.map_or(String::new(), |l| {
        format!(", {} firings a revolution", l.columns)
    });
    crate::emit(&format!(
        "{}: mapped {:.0} m with {} of {} clouds{layout} into {} blocks; occupied cells per level {:?} (levels at {:?} m){skipped}\nwrote {}\n",
        bag.display(),
        m.route_m,
        m.scans,
        report.clouds,
        m.blocks,
        m.occupied_cells,
        m.level_heights_m,
        dir.display()
    ))
}

/// Runs `taxi-sim map`.
pub fn run(args: &MapArgs) -> anyhow::Result<()> {
    let Some(path) = &args.scenario else {
        // Only with --vehicle (clap requires one of the two).
        let name = args.vehicle.as_deref().unwrap_or_default();
        let vehicle = aircraft::Vehicle::load(name)
            .with_context(|| format!("--vehicle {name}: loading the vehicle"))?;
        let config = match &args.config {
            Some(file) => RunConfig::from_file(file)?,
            None => RunConfig::default(),
        };
        return match (&args.from_bag, &args.pcap) {
            (Some(bag), _) => from_bag(args, bag, &vehicle, &config),
            (None, Some(pcap)) => from_pcap(args, pcap, &vehicle, &config),
            (None, None) => anyhow::bail!(
                "--vehicle {name} without a scenario: a map from data needs --from-bag BAG or \
                 --pcap FILE; a mapping drive needs the scenario file whose route it drives"
            ),
        };
    };
    let scenario = Scenario::from_file(path)?;
    let config = RunConfig::for_scenario(&scenario, args.config.as_deref())?;
    let vehicle = &scenario.vehicle.vehicle;
    if let Some(bag) = &args.from_bag {
        return from_bag(args, bag, vehicle, &config);
    }
    if let Some(pcap) = &args.pcap {
        return from_pcap(args, pcap, vehicle, &config);
    }
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_map_dir(&scenario, &config));
    let m = match &args.record {
        Some(bag) => build_and_record(&scenario, &config, &dir, bag)?,
        None => build_map(&scenario, &config, &dir)?,
    };
    crate::emit(&format!(
        "{}: mapped {:.0} m with {} revolutions into {} blocks; occupied cells per level {:?} (levels at {:?} m)\nwrote {}\n",
        scenario.name,
        m.route_m,
        m.scans,
        m.blocks,
        m.occupied_cells,
        m.level_heights_m,
        dir.display()
    ))
}
