//! `taxi-sim run`: the closed loop (its offline map built first when missing or stale), with
//! progress bars, the report table and the JSON report.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context as _;
use sim::engine::{Hold, RunReport};
use sim::engine::{NoObserver, Observer, Observers};
use sim::engine::{RunHandles, RunSetup};
use sim::offline_map::default_map_dir;
use sim::replay::{Replay, ReplayOptions};
use sim::scenario::Scenario;
use sim::scenario::{NoisyTruthConfig, PoseSourceConfig, RunConfig, Schedule};

/// The pose sources `--pose-source` can pick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PoseSourceKind {
    /// The true pose.
    Truth,
    /// The particle filter over the offline map.
    ParticleFilter,
}

/// Arguments of `taxi-sim run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// The scenario file.
    pub scenario: PathBuf,
    /// Laps (default: the scenario's; at least 1).
    #[arg(long)]
    pub laps: Option<u32>,
    /// End the run at this simulated time, seconds, when its own limit (60 s plus four times
    /// the route's length over its speed) is later; the mapping drive is not cut.
    #[arg(long, value_name = "S")]
    pub time_limit_s: Option<f64>,
    /// Run configuration (TOML; `taxi-sim config` prints the defaults). Flags below override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Seed (default: the scenario's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write the JSON report here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// The offline map (default: out/maps/<scenario file name>; built there when missing or stale).
    #[arg(long, conflicts_with = "maps_dir")]
    pub map_dir: Option<PathBuf>,
    /// A map cache shared with `regress` and campaigns (`regress --maps-dir`): the scenario's map
    /// is the one under DIR for its static world, built there on first use.
    #[arg(long, value_name = "DIR")]
    pub maps_dir: Option<PathBuf>,
    /// Where the stack's pose comes from: `truth`, or `particle-filter` (the configuration's
    /// settings, or the defaults). Default: the configuration's.
    #[arg(long, value_enum)]
    pub pose_source: Option<PoseSourceKind>,
    /// Pose source `noisy_truth` with this white noise in position, metres (standard deviation,
    /// each axis, at the source's rate); the configuration's other noisy-truth settings are kept.
    #[arg(long)]
    pub pose_noise_m: Option<f64>,
    /// Pose source `noisy_truth` with this white noise in heading, radians (standard deviation).
    #[arg(long)]
    pub pose_noise_rad: Option<f64>,
    /// Map and plan each revolution the instant it is taken (no latency; slower), instead of
    /// while the LiDAR takes the next one.
    #[arg(long)]
    pub sequential_sensing: bool,
    /// Record the run here: a Rerun recording (.rrd; open it with `rerun FILE`, viewer 0.36)
    /// or a ROS 2 bag (.mcap, with `metadata.yaml` beside it: `ros2 bag play DIR`, Foxglove,
    /// rosbags); may be given twice, once each.
    #[arg(long, value_name = "FILE")]
    pub record: Vec<PathBuf>,
    /// Start a Rerun viewer (`rerun` on the PATH) and stream the run to it.
    #[arg(long)]
    pub spawn: bool,
    /// Stream the run to a running Rerun viewer (default 127.0.0.1:9876).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:9876")]
    pub connect: Option<String>,
    /// Replay: LiDAR points and planner candidates every N revolutions (10 per second).
    #[arg(long, value_name = "N", default_value_t = ReplayOptions::default().scan_every)]
    pub replay_scan_every: u32,
    /// Replay: keep every K-th column of a logged revolution (all 32 beams).
    #[arg(long, value_name = "K", default_value_t = ReplayOptions::default().point_stride)]
    pub replay_point_stride: usize,
    /// Replay: occupancy and distance maps per second of simulated time (0: none).
    #[arg(long, value_name = "HZ", default_value_t = ReplayOptions::default().maps_hz)]
    pub replay_maps_hz: f64,
    /// Replay: half side of the square of map logged around the vehicle, metres.
    #[arg(long, value_name = "M", default_value_t = ReplayOptions::default().map_half_m)]
    pub replay_map_half_m: f64,
    /// Replay: vehicle pose and time series per second of simulated time.
    #[arg(long, value_name = "HZ", default_value_t = ReplayOptions::default().steps_hz)]
    pub replay_steps_hz: f64,
    /// Which stack drives the vehicle, and how an external one is waited for.
    #[command(flatten)]
    pub stack: super::stack::StackArgs,
}

impl RunArgs {
    fn replay_options(&self) -> ReplayOptions {
        ReplayOptions {
            record: self
                .record
                .iter()
                .find(|p| p.extension().is_some_and(|e| e == "rrd"))
                .cloned(),
            spawn: self.spawn,
            connect: self.connect.clone(),
            scan_every: self.replay_scan_every,
            point_stride: self.replay_point_stride,
            maps_hz: self.replay_maps_hz,
            map_half_m: self.replay_map_half_m,
            steps_hz: self.replay_steps_hz,
        }
    }
}

/// The scenario of `args` and what to run it with (its offline map built when missing).
pub fn setup(args: &RunArgs) -> anyhow::Result<(Scenario, RunSetup)> {
    let scenario = Scenario::from_file(&args.scenario)?;
    let config = run_config(args, &scenario)?;
    let dir = offline_map_dir(args, &scenario, &config)?;
    let setup = RunSetup {
        laps: args.laps,
        seed: args.seed,
        config,
        time_limit_s: args.time_limit_s,
        ..RunSetup::new(dir)
    };
    Ok((scenario, setup))
}

/// Runs `taxi-sim run`; returns whether every expectation held.
pub fn run(args: &RunArgs) -> anyhow::Result<bool> {
    anyhow::ensure!(
        args.laps != Some(0),
        "--laps 0: a run drives at least one lap"
    );
    if let Some(t) = args.time_limit_s {
        anyhow::ensure!(
            t.is_finite() && t > 0.0,
            "--time-limit-s {t}: a positive number of seconds"
        );
    }
    let replay_options = args.replay_options();
    replay_options.validate()?;
    let bag_path = bag_file(&args.record)?;
    let (scenario, setup) = setup(args)?;
    let stop = Arc::new(AtomicBool::new(false));
    let stop_flag = stop.clone();
    // A second Ctrl-C falls through to the default handler only if this one could not be set.
    let _ = ctrlc::set_handler(move || stop_flag.store(true, Ordering::Relaxed));
    let mut replay = if replay_options.enabled() {
        Some(Replay::new(&replay_options, &scenario.name)?)
    } else {
        None
    };
    let mut bag = bag_path
        .map(|f| sim::rosbag::RosBag::create(&f))
        .transpose()?;
    let mut no_observer = NoObserver;
    let mut observers: Vec<&mut (dyn Observer + Send)> = Vec::new();
    if let Some(r) = replay.as_mut() {
        observers.push(r);
    }
    if let Some(b) = bag.as_mut() {
        observers.push(b);
    }
    let mut both;
    let observer: &mut (dyn Observer + Send) = match observers.len() {
        0 => &mut no_observer,
        _ => {
            both = Observers(observers);
            &mut both
        }
    };
    let progress = crate::bar(1000, "running");
    let report = super::stack::drive(
        &args.stack,
        &scenario,
        &setup,
        RunHandles {
            stop: Some(&stop),
            progress: &mut |p| {
                progress.set_position((p.fraction * 1000.0) as u64);
                progress.set_message(format!(
                    "lap {} t={:.0}s",
                    p.laps_completed + 1,
                    p.sim_time_s
                ));
            },
            observer,
        },
    )?;
    progress.finish_and_clear();
    if let Some(replay) = &replay {
        let summary = replay.summary();
        for w in &summary.warnings {
            eprintln!("replay: {w}");
        }
        if let Some((path, bytes)) = &summary.recorded {
            eprintln!(
                "replay: wrote {} ({:.1} MB, {:.0} kB per simulated second)",
                path.display(),
                *bytes as f64 / 1e6,
                *bytes as f64 / 1e3 / report.sim_time_s.max(1e-9)
            );
        }
        if let Some(url) = &summary.streamed_to {
            eprintln!("replay: streamed to {url}");
        }
    }
    if let Some(summary) = bag.as_ref().and_then(|b| b.summary()) {
        let messages: u64 = summary.topics.iter().map(|t| t.1).sum();
        eprintln!(
            "ROS 2 bag: wrote {} ({:.1} MB, {messages} messages on {} topics) and metadata.yaml beside it",
            summary.file.display(),
            summary.bytes as f64 / 1e6,
            summary.topics.len()
        );
    }
    if let Some(path) = &args.report {
        mapper::write_atomically(path, serde_json::to_string_pretty(&report)?.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    crate::emit(&table(&report))?;
    Ok(report.expectations_met)
}

/// The offline map the run drives on: from the shared cache (`--maps-dir`), or the map directory
/// (`--map-dir`, default `out/maps/<name>`) made sure of by [`sim::offline_map::ensure`].
fn offline_map_dir(
    args: &RunArgs,
    scenario: &Scenario,
    config: &RunConfig,
) -> anyhow::Result<PathBuf> {
    Ok(match &args.maps_dir {
        // The cache's key is what the map depends on: an entry is never stale.
        Some(cache) => {
            std::fs::create_dir_all(cache)
                .with_context(|| format!("creating the map cache {}", cache.display()))?;
            let bar = crate::bar(0, "mapping");
            let dir = sim::campaign::MapCache::new(cache.clone()).get_for_file_showing(
                scenario,
                config,
                &|done, total| {
                    bar.set_length(total as u64);
                    bar.set_position(done as u64);
                },
            )?;
            bar.finish_and_clear();
            dir
        }
        None => {
            let dir = args
                .map_dir
                .clone()
                .unwrap_or_else(|| default_map_dir(scenario, config));
            let bar = crate::bar(0, "mapping");
            sim::offline_map::ensure(
                scenario,
                config,
                &dir,
                &mut || {
                    eprintln!(
                        "offline map {} is missing or stale: building it (mapping drive)",
                        dir.display()
                    );
                },
                &mut |done, total| {
                    bar.set_length(total as u64);
                    bar.set_position(done as u64);
                },
            )?;
            bar.finish_and_clear();
            dir
        }
    })
}

/// The `.mcap` of `--record`, if one is asked for; every file must be `.rrd` or `.mcap`, each
/// kind at most once.
fn bag_file(record: &[PathBuf]) -> anyhow::Result<Option<PathBuf>> {
    let ext = |p: &PathBuf| p.extension().map(|e| e.to_string_lossy().into_owned());
    for p in record {
        anyhow::ensure!(
            matches!(ext(p).as_deref(), Some("rrd" | "mcap")),
            "--record {}: a Rerun recording (.rrd) or a ROS 2 bag (.mcap)",
            p.display()
        );
    }
    for kind in ["rrd", "mcap"] {
        anyhow::ensure!(
            record
                .iter()
                .filter(|p| ext(p).as_deref() == Some(kind))
                .count()
                <= 1,
            "--record: one .{kind} file at most"
        );
    }
    Ok(record
        .iter()
        .find(|p| ext(p).as_deref() == Some("mcap"))
        .cloned())
}

/// The run's configuration: the file's (or the defaults), with the flags' overrides.
fn run_config(args: &RunArgs, scenario: &Scenario) -> anyhow::Result<RunConfig> {
    let mut config = RunConfig::for_scenario(scenario, args.config.as_deref())?;
    if args.sequential_sensing {
        config.schedule = Schedule::Sequential;
    }
    match args.pose_source {
        Some(PoseSourceKind::Truth) => config.pose_source = PoseSourceConfig::Truth,
        Some(PoseSourceKind::ParticleFilter)
            if !matches!(config.pose_source, PoseSourceConfig::ParticleFilter(_)) =>
        {
            config.pose_source = PoseSourceConfig::ParticleFilter(Default::default());
        }
        _ => {}
    }
    if args.pose_noise_m.is_some() || args.pose_noise_rad.is_some() {
        let mut noisy = match &config.pose_source {
            PoseSourceConfig::NoisyTruth(n) => n.clone(),
            PoseSourceConfig::Truth | PoseSourceConfig::ParticleFilter(_) => {
                NoisyTruthConfig::default()
            }
        };
        if let Some(m) = args.pose_noise_m {
            noisy.white_sigma_m = m;
        }
        if let Some(rad) = args.pose_noise_rad {
            noisy.white_sigma_rad = rad;
        }
        config.pose_source = PoseSourceConfig::NoisyTruth(noisy);
    }
    config
        .validate()
        .map_err(|m| anyhow::anyhow!("run configuration (with the flags): {m}"))?;
    Ok(config)
}

/// The human summary of a run.
/// The line saying the stack lowered the route's speed, when it did.
fn speed_lowered_line(t: &mut String, r: &RunReport) {
    use std::fmt::Write as _;
    let Some(l) = &r.speed_lowered else { return };
    let why = match l.limit {
        sim::autonomy::planner::SpeedLimit::Horizon => "autonomy.max_horizon_m",
        sim::autonomy::planner::SpeedLimit::DetectionRange => "autonomy.detection_range_m",
    };
    let _ = writeln!(
        t,
        "route speed {:.1} m/s lowered to {:.1} m/s: faster, the vehicle could not stop within {why}",
        l.route_m_s, l.cap_m_s
    );
}

/// The table's lines on the start-up rule and on an external stack, when the run had them.
fn start_and_stack(t: &mut String, r: &RunReport) {
    use std::fmt::Write as _;
    if let Some(s) = &r.stack {
        let _ = writeln!(t, "{}", super::stack::summary(s));
    }
    if let Some(a) = r.start_unseen_m2 {
        let _ = writeln!(
            t,
            "start-up rule: {a:.1} m2 of the ground the first plan sweeps is out of the LiDAR's sight from the start{}",
            if a > 0.0 {
                " (held until a walk-around)"
            } else {
                ""
            }
        );
    }
}

pub fn table(r: &RunReport) -> String {
    use std::fmt::Write as _;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{} (seed {}): {}",
        r.scenario,
        r.seed,
        if r.expectations_met {
            "every expectation held"
        } else {
            "EXPECTATIONS NOT MET"
        }
    );
    let _ = writeln!(
        t,
        "laps {}/{}  lap times {:?} s  stops {}  contacts {}{}{}",
        r.laps_completed,
        r.laps,
        r.lap_times_s
            .iter()
            .map(|x| (x * 10.0).round() / 10.0)
            .collect::<Vec<_>>(),
        r.stops.len(),
        r.contacts.len(),
        if r.contacts.is_empty() {
            String::new()
        } else {
            format!(
                " ({} at fault, {} struck)",
                r.contacts_at_fault, r.contacts_struck
            )
        },
        r.end.note().map(|n| format!("  ({n})")).unwrap_or_default(),
    );
    start_and_stack(&mut t, r);
    let f = &r.faults;
    if *f != sim::world::FaultCounts::default() {
        let _ = writeln!(
            t,
            "faults: {} revolutions lost, {} delivered late, {} returns dropped, {} spurious returns; the watchdog held the vehicle {} times",
            f.lost_revolutions,
            f.delayed_revolutions,
            f.dropped_returns,
            f.spurious_returns,
            f.watchdog_stops
        );
    }
    if let Some(l) = &r.localization {
        // The laps one by one when there is more than one.
        let laps = if l.laps.len() > 1 { &l.laps[..] } else { &[] };
        for e in std::iter::once(&l.run).chain(laps) {
            let _ = writeln!(
                t,
                "localization {}: cross-track RMSE {:.3} m (p95 {:.3}, max {:.3}), along {:.3} m, heading {:.4} rad; its sigma {:.3} m mean, {:.3} max",
                e.lap.map_or("(run)".to_string(), |k| format!("lap {k}")),
                e.cross_m.rmse,
                e.cross_m.p95,
                e.cross_m.max,
                e.along_m.rmse,
                e.heading_rad.rmse,
                e.mean_sigma_cross_m,
                e.max_sigma_cross_m
            );
        }
    }
    speed_lowered_line(&mut t, r);
    if let Some(w) = &r.waiting_for {
        let _ = writeln!(
            t,
            "waiting since {:.1} s for an obstacle at ({:.1}, {:.1}) m the sensor last hit {}",
            w.since_s,
            w.x_m,
            w.y_m,
            w.last_seen_s
                .map_or("never (offline map)".to_string(), |s| format!(
                    "at {s:.1} s"
                ))
        );
    }
    pushback_line(&mut t, r);
    pilot_call_line(&mut t, r);
    obstacle_rows(&mut t, r);
    closest_static_row(&mut t, r);
    for j in &r.contacts_judged {
        let c = &j.contact;
        let fault = if j.at_fault {
            format!(" (at fault: moving at {:.2} m/s)", j.vehicle_speed_m_s)
        } else if j.struck_while_moving {
            format!(
                " (struck while moving at {:.2} m/s: it came into room the vehicle held)",
                j.vehicle_speed_m_s
            )
        } else {
            " (struck while standing)".to_string()
        };
        let _ = writeln!(
            t,
            "contact at {:.2} s: {} ({:?}) touched by {}{fault}",
            c.time_s, c.object, c.kind, c.part
        );
    }
    let s = &r.time_split_s;
    let _ = writeln!(
        t,
        "sim {:.1} s in {:.1} s wall: {:.1}x real time (lidar {:.1} s, mapping {:.1} s, distance maps {:.1} s, planning {:.1} s, physics {:.1} s, localization {:.1} s)",
        r.sim_time_s,
        r.wall_time_s,
        r.real_time_factor,
        s.lidar,
        s.mapping,
        s.distance_maps,
        s.planning,
        s.physics,
        s.localization
    );
    t
}

/// The static objects the vehicle came nearest (ground truth), a line.
fn closest_static_row(t: &mut String, r: &RunReport) {
    if !r.closest_static.is_empty() {
        let near: Vec<String> = r
            .closest_static
            .iter()
            .take(5)
            .map(|c| format!("{} ({}) {:.2} m", c.id, c.kind.name(), c.min_clearance_m))
            .collect();
        t.push_str(&format!("closest static objects: {}\n", near.join(", ")));
    }
}

/// The obstacle table of a run's summary: one row per pass (or `not passed`).
fn obstacle_rows(t: &mut String, r: &RunReport) {
    use std::fmt::Write as _;
    let _ = writeln!(
        t,
        "{:<22} {:<10} {:<11} {:>4} {:<9} {:>10} {:>22}",
        "obstacle", "kind", "expected", "lap", "outcome", "offset_m", "min clearance per level"
    );
    for o in &r.obstacles {
        if o.passes.is_empty() {
            let _ = writeln!(
                t,
                "{:<22} {:<10} {:<11} {:>4} {:<9}",
                o.id, o.kind, o.expected, "-", "not passed"
            );
        }
        if o.min_ttc_s.is_some() || o.pet_s.is_some() {
            let first = match o.pet_mover_first {
                Some(true) => " (mover first)",
                Some(false) => " (vehicle first)",
                None => "",
            };
            let s = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.1} s"));
            let _ = writeln!(
                t,
                "{:<22} traffic: min time to collision {}, post-encroachment time {}{first}",
                o.id,
                s(o.min_ttc_s),
                s(o.pet_s)
            );
        }
        for p in &o.passes {
            let clear: Vec<String> = p
                .min_clearance_m
                .iter()
                .map(|c| {
                    if c.is_finite() {
                        format!("{c:.2}")
                    } else {
                        "-".into()
                    }
                })
                .collect();
            let _ = writeln!(
                t,
                "{:<22} {:<10} {:<11} {:>4} {:<9} {:>10.2} {:>22}{}",
                o.id,
                o.kind,
                o.expected,
                p.lap,
                p.outcome,
                p.max_offset_m,
                clear.join(" / "),
                if p.met { "" } else { "  <- not as expected" }
            );
        }
    }
}

/// The push-back from the stand: how long, and how near it came to what stands round the stand.
fn pushback_line(t: &mut String, r: &RunReport) {
    use std::fmt::Write as _;
    let Some(p) = &r.pushback else {
        return;
    };
    let nearest = match &p.nearest_object {
        Some(id) => format!("nearest {id} at {:.2} m", p.min_clearance_m),
        None => "nothing within range".to_string(),
    };
    let _ = writeln!(
        t,
        "push-back: {:.1} m tail first, turned at {:.1} m radius, released at {:.1} s; {nearest}",
        p.length_m, p.radius_m, p.released_s
    );
}

/// Why the pilot was called, and whether anything was really there.
fn pilot_call_line(t: &mut String, r: &RunReport) {
    use std::fmt::Write as _;
    let Some(c) = &r.pilot_call else {
        return;
    };
    let held = match (&c.hold, c.at_m) {
        (Some(Hold::Struck { at_s }), _) => format!("a strike it felt at {at_s:.1} s"),
        (Some(h), Some([x, y])) => format!("{} at ({x:.1}, {y:.1}) m", h.name().replace('_', " ")),
        (Some(h), None) => h.name().replace('_', " "),
        (None, _) => "nothing it named".to_string(),
    };
    let truth = match &c.nearest_object {
        Some((id, d)) if c.call == "struck" => format!("struck by {id}, now {d:.2} m off"),
        Some((id, d)) => format!("nearest object {id} {d:.2} m"),
        None => "no object".to_string(),
    };
    let _ = writeln!(
        t,
        "pilot call at {:.1} s ({}): held by {held}; ground truth: {truth} - {}",
        c.t_s,
        c.call.replace('_', " "),
        if c.needless {
            "needless"
        } else {
            "something was there"
        }
    );
}
