//! `taxi-sim check <scenario>`: validates a scenario file and prints a summary of it.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use sim::scenario::Scenario;

/// Arguments of `taxi-sim check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// The scenario file (TOML).
    pub scenario: PathBuf,
}

/// Runs `taxi-sim check`: an invalid file is an error (exit code 2), a valid one a summary.
pub fn run(args: &CheckArgs) -> anyhow::Result<()> {
    let scenario = Scenario::from_file(&args.scenario)?;
    crate::emit(&summary(&scenario)?)
}

/// The summary printed for a valid scenario.
fn summary(s: &Scenario) -> Result<String, std::fmt::Error> {
    let mut t = String::new();
    writeln!(t, "{}: valid", s.path.display())?;
    writeln!(t, "name       {}", s.name)?;
    if let Some(d) = &s.description {
        writeln!(t, "about      {}", d.trim())?;
    }
    let v = &s.vehicle;
    let levels: Vec<String> = v
        .vehicle
        .spec
        .heights_of_interest_m
        .iter()
        .map(|h| format!("{h:.2}"))
        .collect();
    let start = v.world_from_start.translation.vector;
    let from = if v.description == v.vehicle.spec.name {
        String::new()
    } else {
        format!(" (from {})", v.description)
    };
    writeln!(
        t,
        "vehicle    {}{from}, levels at {} m, ceiling {:.2} m (top {:.2} m), {} collision parts",
        v.vehicle.spec.name,
        levels.join(", "),
        v.vehicle.ceiling_m(),
        v.vehicle.top_m(),
        v.vehicle.parts.len()
    )?;
    writeln!(
        t,
        "start      ({:.2}, {:.2}) m, yaw {:.3} rad",
        start.x,
        start.y,
        v.world_from_start.rotation.angle()
    )?;
    let r = &s.route;
    writeln!(
        t,
        "route      {:.1} m, {} points, {}, {:.2} m/s",
        r.length_m(),
        r.waypoints_m.len(),
        if r.closed { "closed" } else { "open" },
        r.speed_m_s
    )?;
    writeln!(t, "laps       {}", s.laps)?;
    writeln!(t, "seed       {}", s.seed)?;
    writeln!(
        t,
        "world      [{}, {}] .. [{}, {}] m, ground remission {:.2}",
        s.world.min_m[0],
        s.world.min_m[1],
        s.world.max_m[0],
        s.world.max_m[1],
        s.world.ground_remission
    )?;
    let mut kinds: BTreeMap<&str, usize> = BTreeMap::new();
    for o in &s.objects {
        *kinds.entry(o.kind.name()).or_default() += 1;
    }
    let counts: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} {k}")).collect();
    writeln!(
        t,
        "objects    {}{}",
        s.objects.len(),
        if counts.is_empty() {
            String::new()
        } else {
            format!(" ({})", counts.join(", "))
        }
    )?;
    writeln!(t, "patches    {}", s.patches.len())?;
    writeln!(t, "obstacles  {}", s.obstacles.len())?;
    let id_width = s
        .obstacles
        .iter()
        .map(|o| o.solid.id.len())
        .max()
        .unwrap_or(0);
    for o in &s.obstacles {
        let mut when = String::new();
        if o.appears_s > 0.0 {
            write!(when, ", appears at {} s", o.appears_s)?;
        }
        if let Some(d) = o.disappears_s {
            write!(when, ", disappears at {d} s")?;
        }
        if let Some(m) = &o.motion {
            let len: f64 = m.path_m.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
            write!(when, ", moves {len:.1} m at {:.2} m/s", m.speed_m_s)?;
        }
        writeln!(
            t,
            "  {:<id_width$}  {:<10} at ({:.2}, {:.2}) m, {:.2} m tall: expect {}{when}",
            o.solid.id,
            o.solid.kind.name(),
            o.solid.x_m,
            o.solid.y_m,
            o.solid.z_min_m + o.solid.shape.height_m(),
            o.expect.as_str()
        )?;
    }
    Ok(t)
}
