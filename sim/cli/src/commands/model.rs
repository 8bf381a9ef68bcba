//! `taxi-sim model fit`: fits a vehicle's circle collision model and prints the per-level table
//! (`model levels`: the parts' undersides and the heights of interest they suggest);
//! optionally writes an SVG picture and a CARMEN collision file (atomically).

use std::path::PathBuf;

use anyhow::Context as _;

/// Arguments of `taxi-sim model fit`.
#[derive(Debug, Clone, clap::Args)]
pub struct ModelFitArgs {
    /// A shipped vehicle (praetor600, a320, iara_car, iara_car_fake_wing) or a sidecar TOML path.
    pub description: String,
    /// Heights of interest in metres, comma separated, starting at 0 (default: the sidecar's).
    #[arg(long, value_delimiter = ',', num_args = 1..)]
    pub levels: Option<Vec<f64>>,
    /// Most circles in the whole model (default: the sidecar's, else no limit).
    #[arg(long)]
    pub max_circles: Option<usize>,
    /// Largest distance a circle may reach beyond its part, metres (default: the sidecar's, else
    /// 0.15 m unless --max-circles is given).
    #[arg(long)]
    pub max_overshoot: Option<f64>,
    /// Fit for banded maps: keep parts that lie over a lower level's parts.
    #[arg(long)]
    pub banded: bool,
    /// Write an SVG picture of the footprints and circles here.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Write the model in CARMEN's collision file format here.
    #[arg(long)]
    pub carmen: Option<PathBuf>,
}

/// Runs `taxi-sim model fit`.
pub fn run(args: &ModelFitArgs) -> anyhow::Result<()> {
    let vehicle = aircraft::Vehicle::load(&args.description)
        .with_context(|| format!("loading vehicle `{}`", args.description))?;
    let heights = args
        .levels
        .clone()
        .unwrap_or_else(|| vehicle.spec.heights_of_interest_m.clone());
    let mut options = vehicle.spec.fit.clone();
    if args.max_circles.is_some() || args.max_overshoot.is_some() {
        // Command-line bounds replace the sidecar's.
        options.max_circles = args.max_circles;
        options.max_overshoot_m = args.max_overshoot;
    }
    options.banded_maps |= args.banded;
    let fit = vehicle
        .fit_with(&heights, &options)
        .with_context(|| format!("fitting `{}`", vehicle.spec.name))?;
    let reports = aircraft::evaluate(&fit, aircraft::report::DEFAULT_SAMPLES_PER_AXIS);
    crate::emit(&aircraft::report::table(&vehicle.spec.name, &fit, &reports))?;
    if let Some(path) = &args.svg {
        let svg = aircraft::svg::to_svg(&fit, &vehicle.spec.name);
        aircraft::io::write_atomic(path, svg.as_bytes())
            .with_context(|| format!("writing the SVG {}", path.display()))?;
        crate::emit(&format!("wrote {}\n", path.display()))?;
    }
    if let Some(path) = &args.carmen {
        aircraft::carmen::write_carmen_file(path, &fit.model)
            .with_context(|| format!("writing the CARMEN file {}", path.display()))?;
        crate::emit(&format!("wrote {}\n", path.display()))?;
    }
    Ok(())
}

/// Arguments of `taxi-sim model levels`.
#[derive(Debug, Clone, clap::Args)]
pub struct ModelLevelsArgs {
    /// A shipped vehicle (praetor600, a320, iara_car, iara_car_fake_wing) or a sidecar TOML path.
    pub description: String,
    /// How far under a part's underside its level goes, metres.
    #[arg(long, default_value_t = 0.1)]
    pub margin: f64,
    /// Parts lower than this are on the ground level, metres.
    #[arg(long, default_value_t = 0.15)]
    pub min: f64,
}

/// Runs `taxi-sim model levels`: every part's underside and top, and the candidate heights of
/// interest they give (for a tuning campaign's `mapping.heights_of_interest_m`).
pub fn levels(args: &ModelLevelsArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.margin.is_finite() && args.margin >= 0.0 && args.min.is_finite(),
        "--margin {} and --min {}: finite, margin >= 0",
        args.margin,
        args.min
    );
    let vehicle = aircraft::Vehicle::load(&args.description)
        .with_context(|| format!("loading vehicle `{}`", args.description))?;
    let mut parts: Vec<&aircraft::Part> = vehicle.parts.iter().collect();
    parts.sort_by(|a, b| a.underside_m().total_cmp(&b.underside_m()));
    let mut s = format!(
        "{}: heights of interest in the sidecar {:?}\n{:<28} {:>11} {:>8}\n",
        vehicle.spec.name, vehicle.spec.heights_of_interest_m, "part", "underside_m", "top_m"
    );
    for p in parts {
        s += &format!(
            "{:<28} {:>11.3} {:>8.3}\n",
            format!("{}#{}", p.link, p.collision_index),
            p.underside_m(),
            p.top_m()
        );
    }
    let proposed = aircraft::fit::proposed_heights(&vehicle.parts, args.min, args.margin);
    s += &format!(
        "candidate heights (undersides above {} m, less {} m): {proposed:?}\n",
        args.min, args.margin
    );
    crate::emit(&s)
}
