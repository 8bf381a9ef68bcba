//! `taxi-sim airport show`: an airport file summarised (runways, pavement, lines, the taxi network,
//! taxiways, stands, signs), drawn (`--picture`), and a taxi route found and drawn on it.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;

/// Airport files (X-Plane apt.dat).
#[derive(Debug, clap::Subcommand)]
pub enum AirportCommand {
    /// Summarise an apt.dat airport; draw it (--picture); find a taxi route on it (--from, --to).
    Show(ShowArgs),
}

/// Arguments of `taxi-sim airport show`.
#[derive(Debug, Clone, clap::Args)]
pub struct ShowArgs {
    /// The apt.dat file (X-Plane versions 1000 through 1200).
    pub file: PathBuf,
    /// The airport's code, when the file holds several.
    #[arg(long)]
    pub airport: Option<String>,
    /// Draw the airport (and the route) here: a .png or .svg file.
    #[arg(long)]
    pub picture: Option<PathBuf>,
    /// Route start: a stand's name, `node <id>` or `runway <number>` (vacating it).
    #[arg(long, requires = "to")]
    pub from: Option<String>,
    /// Route end: `runway <number>` (its hold point), a stand's name or `node <id>`.
    #[arg(long, requires = "from")]
    pub to: Option<String>,
    /// Taxiways to follow in order, comma separated (`B,A`).
    #[arg(long, value_delimiter = ',')]
    pub via: Vec<String>,
    /// The aircraft: a shipped vehicle or a sidecar path (its wingspan gives the code letter, its
    /// steering the tightest turn).
    #[arg(long, default_value = "praetor600")]
    pub vehicle: String,
    /// The radius of a turn where the legs leave room, metres.
    #[arg(long, default_value_t = sim::airports::DEFAULT_TURN_RADIUS_M)]
    pub turn_radius_m: f64,
    /// Taxi speed on straights, m/s.
    #[arg(long, default_value_t = sim::airports::DEFAULT_TAXI_SPEED_M_S)]
    pub speed_m_s: f64,
}

/// Runs `taxi-sim airport ...`.
pub fn run(command: &AirportCommand) -> anyhow::Result<()> {
    match command {
        AirportCommand::Show(args) => show(args),
    }
}

fn show(args: &ShowArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let airport = airport::Airport::read(&args.file, args.airport.as_deref())?;
    let read_s = started.elapsed().as_secs_f64();
    let mut text = sim::airports::summary(&airport);
    text.push_str(&format!("read and placed in {:.0} ms\n", read_s * 1000.0));
    let mut overlay = None;
    if let (Some(from), Some(to)) = (&args.from, &args.to) {
        let vehicle = aircraft::Vehicle::load(&args.vehicle)
            .with_context(|| format!("loading vehicle `{}`", args.vehicle))?;
        let planned = sim::airports::plan_taxi(
            &airport,
            &vehicle,
            from,
            to,
            &args.via,
            args.turn_radius_m,
            args.speed_m_s,
        )?;
        text.push_str(&planned.describe());
        overlay = Some(sim::airports::RouteOverlay {
            points: planned.path.points.clone(),
            pushback: planned
                .pushback
                .iter()
                .flat_map(|t| t.poses.iter().map(|p| p.0))
                .collect(),
            label: planned.title(),
        });
    }
    crate::emit(&text)?;
    if let Some(path) = &args.picture {
        sim::airports::draw_airport(&airport, overlay.as_ref(), path)?;
        crate::emit(&format!("wrote {}\n", path.display()))?;
    }
    Ok(())
}
