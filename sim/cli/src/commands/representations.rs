//! `taxi-sim bench representations`: the thesis' multi-height grids against a dense 3D voxel
//! grid, OctoMap and a 2.5D map on the same revolutions, per scene: tables on stdout, and with
//! `--out DIR` the JSON, the tables and a picture per scene.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use indicatif::{ProgressBar, ProgressStyle};
use sim::studies::representations::{
    self as study, OctoMapOptions, Options, SceneResult, drive::Stretch, truth::PoseDraw,
};

use crate::emit;

/// The scenes compared when none is given.
const DEFAULT_SCENES: [&str; 5] = [
    "scenarios/parking_lot.toml",
    "scenarios/aerodrome.toml",
    "scenarios/low_bridge_jet.toml",
    "scenarios/footbridge_jet.toml",
    "scenarios/airliner_wing_over_parked_jet.toml",
];

/// Options of `bench representations`.
#[derive(Debug, Clone, clap::Args)]
pub struct RepresentationArgs {
    /// Poses judged per scene, drawn near the objects the drive passed.
    #[arg(long, default_value_t = 10_000)]
    pub poses: usize,
    /// Seed of the poses' draw.
    #[arg(long, default_value_t = 1)]
    pub pose_seed: u64,
    /// Route driven per scene, metres, centred on `--at-m` (default: the route's middle).
    #[arg(long, default_value_t = 200.0)]
    pub stretch_m: f64,
    /// Where along the route the window is centred, metres.
    #[arg(long)]
    pub at_m: Option<f64>,
    /// Distance between revolutions, metres (default 1; 0: one every 0.1 s at the route's
    /// speed, as the mapping drive casts them).
    #[arg(long, default_value_t = 1.0)]
    pub spacing_m: f64,
    /// The Python with the `octomap-python` binding (`pip install octomap-python==1.10.0.0`);
    /// without it OctoMap is left out and the report says so.
    #[arg(long, value_name = "PYTHON")]
    pub octomap_python: Option<PathBuf>,
    /// OctoMap's leaf sizes, metres.
    #[arg(long, value_delimiter = ',', default_value = "0.2,0.1")]
    pub octomap_resolutions: Vec<f64>,
    /// Poses checked through the binding itself (timed, and compared with our answers on its
    /// voxels).
    #[arg(long, default_value_t = 200)]
    pub octomap_timed_poses: usize,
    /// Also the dense 3D grid without free-space carving: which of its misses come from beams
    /// carving away what they grazed (a diagnostic row).
    #[arg(long)]
    pub carving_diagnostic: bool,
    /// Read OctoMap's figures and voxels from an earlier run's `--out DIR/octomap/` instead of
    /// inserting again (the same options give the same revolutions and poses).
    #[arg(long)]
    pub octomap_reuse: bool,
    /// A real Velodyne capture (pcap) as one more scene (alone when no `--scenario` is given):
    /// memory and time only (no ground truth), the sensor standing, levelled on the ground
    /// fitted under it.
    #[arg(long, value_name = "FILE")]
    pub pcap: Option<PathBuf>,
    /// The scenario whose vehicle (levels, ceiling) the capture is mapped for.
    #[arg(long, default_value = "scenarios/straight_cone_under_wing.toml")]
    pub pcap_scenario: PathBuf,
    /// Draw the pictures and write the tables again from `DIR/representations.json` (a run's
    /// `--out`), measuring nothing.
    #[arg(long, value_name = "DIR")]
    pub redraw: Option<PathBuf>,
}

fn options(args: &RepresentationArgs, out: Option<&Path>) -> anyhow::Result<Options> {
    anyhow::ensure!(args.poses > 0, "--poses: must be at least 1");
    anyhow::ensure!(
        args.stretch_m.is_finite() && args.stretch_m > 0.0,
        "--stretch-m: {} is not a positive length",
        args.stretch_m
    );
    anyhow::ensure!(
        args.spacing_m.is_finite() && args.spacing_m >= 0.0,
        "--spacing-m: {} is not a length",
        args.spacing_m
    );
    for r in &args.octomap_resolutions {
        anyhow::ensure!(
            r.is_finite() && *r >= 0.05,
            "--octomap-resolutions: {r} (at least 0.05 m)"
        );
    }
    let scratch = out.map_or_else(
        || std::env::temp_dir().join("taxi-sim-octomap"),
        |d| d.join("octomap"),
    );
    Ok(Options {
        stretch: Stretch {
            at_m: args.at_m,
            length_m: args.stretch_m,
            spacing_m: (args.spacing_m > 0.0).then_some(args.spacing_m),
        },
        draw: PoseDraw {
            count: args.poses,
            seed: args.pose_seed,
            near_m: 2.0,
            max_depth_m: 0.3,
            seen_m: 40.0,
        },
        octomap: args.octomap_python.clone().map(|python| OctoMapOptions {
            python,
            resolutions_m: args.octomap_resolutions.clone(),
            dir: scratch,
            timed_poses: args.octomap_timed_poses,
            reuse: args.octomap_reuse,
        }),
        carving_diagnostic: args.carving_diagnostic,
    })
}

/// Runs `taxi-sim bench representations`.
pub fn run(
    scenes: &[PathBuf],
    out: Option<&Path>,
    args: &RepresentationArgs,
    json: bool,
) -> anyhow::Result<()> {
    // With --json stdout holds the JSON alone: the tables go to --out only.
    let emit = |text: &str| if json { Ok(()) } else { emit(text) };
    if let Some(dir) = &args.redraw {
        return redraw(dir, json);
    }
    let options = options(args, out)?;
    let scenes: Vec<PathBuf> = if scenes.is_empty() && args.pcap.is_none() {
        DEFAULT_SCENES.iter().map(PathBuf::from).collect()
    } else {
        scenes.to_vec()
    };
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut results: Vec<SceneResult> = Vec::new();
    for path in &scenes {
        let scenario = sim::scenario::Scenario::from_file(path)?;
        let config = sim::scenario::RunConfig::for_scenario(&scenario, None)?;
        let bar = ProgressBar::new(1).with_style(
            ProgressStyle::with_template("{msg:>28} [{bar:30}] {pos}/{len} {elapsed}")?
                .progress_chars("=> "),
        );
        let name = path.display().to_string();
        let result =
            study::compare_scene(&scenario, &config, &options, &mut |stage, done, total| {
                bar.set_message(format!("{name}: {stage}"));
                bar.set_length(total as u64);
                bar.set_position(done as u64);
            })
            .with_context(|| format!("{}: the comparison", path.display()))?;
        bar.finish_and_clear();
        if let Some(dir) = out {
            let stem = path
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            study::chart::draw(&result, dir, &stem)?;
        }
        emit(&study::table::scene_table(&result))?;
        emit("\n")?;
        results.push(result);
    }
    if let Some(pcap) = &args.pcap {
        let scenario = sim::scenario::Scenario::from_file(&args.pcap_scenario)?;
        let config = sim::scenario::RunConfig::for_scenario(&scenario, None)?;
        let bar = ProgressBar::new(1);
        let result = study::recording::compare_recording(
            pcap,
            &scenario,
            &config,
            &options,
            &mut |stage, done, total| {
                bar.set_message(stage.to_string());
                bar.set_length(total as u64);
                bar.set_position(done as u64);
            },
        )
        .with_context(|| format!("{}: the comparison", pcap.display()))?;
        bar.finish_and_clear();
        emit(&study::table::scene_table(&result))?;
        emit("\n")?;
        results.push(result);
    }
    write_all(&results, out, json)
}

/// The headline on stdout (`json`: the results as JSON lines instead, one scene's object a
/// line); with `out`, the tables and the JSON (one array, `representations.json`) in it.
fn write_all(results: &[SceneResult], out: Option<&Path>, json: bool) -> anyhow::Result<()> {
    let mut text =
        String::from("Against the thesis' representation (multi-height, cumulative):\n\n");
    text.push_str(&study::table::headline(results));
    if json {
        let mut lines = String::new();
        for r in results {
            writeln!(lines, "{}", serde_json::to_string(r)?)?;
        }
        emit(&lines)?;
    } else {
        emit(&text)?;
    }
    if let Some(dir) = out {
        let mut md = String::new();
        for r in results {
            writeln!(md, "{}", study::table::scene_table(r))?;
            for n in &r.notes {
                writeln!(md, "- {n}")?;
            }
            writeln!(md)?;
        }
        md.push_str(&text);
        mapper::write_atomically(&dir.join("representations.md"), md.as_bytes())?;
        mapper::write_atomically(
            &dir.join("representations.json"),
            serde_json::to_string_pretty(results)?.as_bytes(),
        )?;
    }
    Ok(())
}

/// Pictures and tables again from a run's JSON.
fn redraw(dir: &Path, json: bool) -> anyhow::Result<()> {
    let emit = |text: &str| if json { Ok(()) } else { emit(text) };
    let path = dir.join("representations.json");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let results: Vec<SceneResult> = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a comparison's results", path.display()))?;
    for r in &results {
        let stem = Path::new(&r.path)
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        if r.poses.0 > 0 {
            study::chart::draw(r, dir, &stem)?;
        }
        emit(&study::table::scene_table(r))?;
        emit("\n")?;
    }
    write_all(&results, Some(dir), json)
}
