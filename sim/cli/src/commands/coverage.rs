//! `taxi-sim model coverage`: what a vehicle's LiDAR cannot see, per height level - the blind
//! ground around the airframe, its area, the nearest blind ground ahead of each gear and beside
//! each wing tip, how far the first blind stretch reaches ahead - as a table or JSON, and a
//! picture (SVG and PNG).

use std::path::PathBuf;

use anyhow::Context as _;
use sim::world::coverage::{CoverageOptions, draw};

/// Arguments of `taxi-sim model coverage`.
#[derive(Debug, Clone, clap::Args)]
pub struct ModelCoverageArgs {
    /// A shipped vehicle (praetor600, a320, iara_car, iara_car_fake_wing) or a sidecar TOML path.
    pub description: String,
    /// Ground cell side, metres.
    #[arg(long, default_value_t = CoverageOptions::default().cell_m)]
    pub cell_m: f64,
    /// How far around the vehicle the ground is examined, metres.
    #[arg(long, default_value_t = CoverageOptions::default().margin_m)]
    pub margin_m: f64,
    /// Level 0's object height, metres (the smallest the simulator maps).
    #[arg(long, default_value_t = CoverageOptions::default().low_object_m)]
    pub low_object_m: f64,
    /// Draw the blind zones into DIR/coverage-<vehicle>.svg and .png.
    #[arg(long, value_name = "DIR")]
    pub picture: Option<PathBuf>,
    /// One JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Another LiDAR on the vehicle, beside the sidecar's: `MODEL@X,Y,Z` (model `hdl-32e` or
    /// `vlp-16`, mounted level at X, Y, Z metres in the vehicle frame); repeatable. Ground any of
    /// them sees is seen; each one's own blind area is reported too.
    #[arg(long, value_name = "MODEL@X,Y,Z")]
    pub sensor: Vec<String>,
}

/// A `--sensor MODEL@X,Y,Z` parsed.
fn mounted(spec: &str) -> anyhow::Result<sim::world::coverage::Mounted> {
    let bad = |why: &str| {
        anyhow::anyhow!("--sensor {spec:?}: {why} (expected MODEL@X,Y,Z, e.g. vlp-16@9.5,0,0.6)")
    };
    let (model, at) = spec.split_once('@').ok_or_else(|| bad("no `@`"))?;
    let config = sim::world::LidarConfig::model(model)
        .ok_or_else(|| bad(&format!("unknown model `{model}` (hdl-32e, vlp-16)")))?;
    let xyz: Vec<f64> = at
        .split(',')
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .map_err(|_| bad(&format!("`{v}` is not a number")))
        })
        .collect::<anyhow::Result<_>>()?;
    let [x, y, z] = xyz[..] else {
        return Err(bad(&format!("{} numbers, not 3", xyz.len())));
    };
    anyhow::ensure!(
        [x, y, z].iter().all(|v| v.is_finite()),
        bad("a coordinate is not finite")
    );
    Ok(sim::world::coverage::Mounted {
        name: spec.to_string(),
        config,
        vehicle_from_sensor: nalgebra::Isometry3::translation(x, y, z),
    })
}

/// Runs `taxi-sim model coverage`.
pub fn run(args: &ModelCoverageArgs) -> anyhow::Result<()> {
    let vehicle = aircraft::Vehicle::load(&args.description)
        .with_context(|| format!("loading vehicle `{}`", args.description))?;
    let options = CoverageOptions {
        cell_m: args.cell_m,
        margin_m: args.margin_m,
        low_object_m: args.low_object_m,
    };
    let mut sensors =
        sim::world::coverage::vehicle_lidars(&vehicle, &sim::scenario::RunConfig::default().lidar)?;
    for spec in &args.sensor {
        sensors.push(mounted(spec)?);
    }
    let c = sim::world::coverage::coverage_of(&vehicle, &sensors, &options)?;
    if let Some(dir) = &args.picture {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let stem = format!("coverage-{}", vehicle.spec.name);
        draw(&c, dir, &stem)?;
        eprintln!("wrote {}/{stem}.svg and .png", dir.display());
    }
    if args.json {
        return crate::emit(&format!("{}\n", serde_json::to_string(&c)?));
    }
    let mut out = String::new();
    for s in &c.sensors {
        let p = s.position_m;
        let alone: Vec<String> = s
            .alone_blind_area_m2
            .iter()
            .map(|a| format!("{a:.1}"))
            .collect();
        out += &format!(
            "LiDAR {} at ({:.2}, {:.2}, {:.2}) m: blind alone {} m2 by level\n",
            s.name,
            p[0],
            p[1],
            p[2],
            alone.join(" / ")
        );
    }
    out += &format!(
        "{}, all sensors together; ground examined {:.0} x {:.0} m in {} m cells\n",
        c.vehicle,
        c.grid.cells[0] as f64 * c.grid.cell_m,
        c.grid.cells[1] as f64 * c.grid.cell_m,
        c.grid.cell_m
    );
    out += &format!(
        "{:<6} {:>9} {:>13} {:>14}  nearest blind ground\n",
        "level", "object_m", "blind_area_m2", "blind_ahead_m"
    );
    for l in &c.levels {
        let nearest: Vec<String> = l
            .nearest
            .iter()
            .map(|n| match n.distance_m {
                Some(d) => format!("{} {d:.1} m", n.from),
                None => format!("{} none", n.from),
            })
            .collect();
        out += &format!(
            "{:<6} {:>9.2} {:>13.1} {:>14.1}  {}\n",
            l.level,
            l.object_height_m,
            l.blind_area_m2,
            l.blind_ahead_m,
            nearest.join(", ")
        );
    }
    crate::emit(&out)
}
