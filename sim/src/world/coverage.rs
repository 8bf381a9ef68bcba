//! What a vehicle's LiDAR cannot see (`taxi-sim model coverage`): for each height level, the
//! ground around the airframe where an object of that level's height would get no return from
//! any beam - the blind zone - from the sensor's beam table and the vehicle's own parts (each ray
//! stopped where the airframe stops it, as the simulated sensor casts it).
//!
//! An object of height `h` standing at a ground point is hit when some ray passes through the
//! vertical segment from 0 to `h` above it before the airframe stops the ray. Level 0's object is
//! `low_object_m` tall (the smallest the simulator's map holds, 0.1 m); level i's is the level's
//! height of interest (the shortest of its objects, the hardest to see). The ground under the
//! level's parts (level 0: those reaching below its object's top; above: those reaching above
//! the level's height) is the vehicle's own - an object there already touches it - and is not
//! counted.

use std::path::Path;

use nalgebra::{Isometry2, Point2};
use serde::Serialize;

use super::{Lidar, LidarConfig, Scene, World};
use crate::error::{Error, Result};

/// How the blind zone is computed.
#[derive(Clone, Copy, Debug)]
pub struct CoverageOptions {
    /// Ground cell side, metres.
    pub cell_m: f64,
    /// How far around the vehicle's parts the ground is examined, metres.
    pub margin_m: f64,
    /// Height of level 0's object, metres (when above the level's own height).
    pub low_object_m: f64,
}

impl Default for CoverageOptions {
    fn default() -> Self {
        CoverageOptions {
            cell_m: 0.1,
            margin_m: 20.0,
            low_object_m: 0.1,
        }
    }
}

/// The ground grid examined, in the vehicle frame.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct GroundGrid {
    /// Lower corner (x, y), metres.
    pub min_m: [f64; 2],
    /// Cell side, metres.
    pub cell_m: f64,
    /// Cells along x and along y.
    pub cells: [usize; 2],
}

impl GroundGrid {
    /// The cell holding (x, y), if inside.
    fn cell(&self, x: f64, y: f64) -> Option<usize> {
        let i = ((x - self.min_m[0]) / self.cell_m).floor();
        let j = ((y - self.min_m[1]) / self.cell_m).floor();
        let inside =
            i >= 0.0 && j >= 0.0 && (i as usize) < self.cells[0] && (j as usize) < self.cells[1];
        inside.then(|| j as usize * self.cells[0] + i as usize)
    }

    /// The centre of cell `k`.
    pub fn centre(&self, k: usize) -> (f64, f64) {
        let (i, j) = (k % self.cells[0], k / self.cells[0]);
        (
            self.min_m[0] + (i as f64 + 0.5) * self.cell_m,
            self.min_m[1] + (j as f64 + 0.5) * self.cell_m,
        )
    }
}

/// The nearest blind ground from one point of the vehicle.
#[derive(Clone, Debug, Serialize)]
pub struct NearestBlind {
    /// What it is measured from (`ahead of nose_gear`, `beside the left wing tip`).
    pub from: String,
    /// Distance to the nearest blind cell's centre, metres (`None`: none in the grid).
    pub distance_m: Option<f64>,
}

/// One level's blind zone.
#[derive(Clone, Debug, Serialize)]
pub struct LevelCoverage {
    /// The level, from 0.
    pub level: usize,
    /// The object height examined, metres.
    pub object_height_m: f64,
    /// Blind ground in the grid, square metres.
    pub blind_area_m2: f64,
    /// How far the vehicle must travel straight ahead before all the ground its level's parts
    /// sweep has been seen, metres (0: the ground right ahead of them is seen).
    pub blind_ahead_m: f64,
    /// The nearest blind ground ahead of each gear and beside each wing tip.
    pub nearest: Vec<NearestBlind>,
    /// Per cell: blind.
    #[serde(skip)]
    pub blind: Vec<bool>,
    /// Per cell: under one of the level's parts (the vehicle's own).
    #[serde(skip)]
    pub own: Vec<bool>,
}

/// A LiDAR on the vehicle: its model and where it is mounted.
#[derive(Clone, Debug)]
pub struct Mounted {
    /// What it is called (`sidecar`, `vlp-16 under the nose`).
    pub name: String,
    /// Its beams.
    pub config: LidarConfig,
    /// Its mount on the vehicle.
    pub vehicle_from_sensor: nalgebra::Isometry3<f64>,
}

/// One sensor of several: where it is, and what each level would leave blind with it alone.
#[derive(Clone, Debug, Serialize)]
pub struct SensorCoverage {
    /// [`Mounted::name`].
    pub name: String,
    /// Its position in the vehicle frame, metres.
    pub position_m: [f64; 3],
    /// Per level: the blind ground with this sensor alone, square metres.
    pub alone_blind_area_m2: Vec<f64>,
}

/// A vehicle's blind zones, level by level.
#[derive(Clone, Debug, Serialize)]
pub struct Coverage {
    /// The vehicle's name.
    pub vehicle: String,
    /// The sensors, each with what it would leave blind alone (the levels below are all of
    /// them together).
    pub sensors: Vec<SensorCoverage>,
    /// The ground examined.
    pub grid: GroundGrid,
    /// Level by level.
    pub levels: Vec<LevelCoverage>,
}

/// The heights (from, to) along a ray's parameter `t` (unit direction `d`, origin height `z0`)
/// where it is between the ground and `h`: the `t` interval, if any, clipped to `[0, stop]`.
pub fn low_interval(z0: f64, dz: f64, h: f64, stop: f64) -> Option<(f64, f64)> {
    let (from, to) = if dz < 0.0 {
        (((z0 - h) / -dz).max(0.0), z0 / -dz)
    } else if dz > 0.0 {
        (0.0, if z0 <= h { (h - z0) / dz } else { -1.0 })
    } else if (0.0..=h).contains(&z0) {
        (0.0, f64::INFINITY)
    } else {
        return None;
    };
    let to = to.min(stop);
    (z0 >= 0.0 && to >= from).then_some((from, to))
}

/// The LiDARs `vehicle` carries: its main one (`[lidar]` in the sidecar, frame `velodyne`) as
/// `main` describes it, then each of the sidecar's `extra_lidars`, `main`'s settings with its
/// model's beam table, its own sensor unit (range biases).
pub fn vehicle_lidars(vehicle: &aircraft::Vehicle, main: &LidarConfig) -> Result<Vec<Mounted>> {
    let mut all = vec![Mounted {
        name: "velodyne".into(),
        config: main.clone(),
        vehicle_from_sensor: vehicle.vehicle_from_lidar(),
    }];
    for (k, extra) in vehicle.spec.extra_lidars.iter().enumerate() {
        let mut config = main.with_model(&extra.model).ok_or_else(|| {
            Error::Invalid(format!(
                "vehicle {}: extra_lidars[{k}].model {:?} is not a model the simulator has \
                 (hdl-32e, vlp-16)",
                vehicle.spec.name, extra.model
            ))
        })?;
        config.range_bias_unit = main.range_bias_unit.wrapping_add(k as u64 + 1);
        all.push(Mounted {
            name: extra.name.clone(),
            config,
            vehicle_from_sensor: extra.vehicle_from_lidar(),
        });
    }
    Ok(all)
}

/// The blind zones of `vehicle` with its sidecar's LiDARs ([`vehicle_lidars`]), the main one
/// under `lidar` (noise and drop-outs are irrelevant here: only the beams' geometry counts).
pub fn coverage(
    vehicle: &aircraft::Vehicle,
    lidar: &LidarConfig,
    options: &CoverageOptions,
) -> Result<Coverage> {
    coverage_of(vehicle, &vehicle_lidars(vehicle, lidar)?, options)
}

/// The blind zones of `vehicle` carrying `sensors`: ground is seen when any of them sees it
/// (each cast against the airframe, as the LiDAR casts it); each sensor's own figures beside.
pub fn coverage_of(
    vehicle: &aircraft::Vehicle,
    sensors: &[Mounted],
    options: &CoverageOptions,
) -> Result<Coverage> {
    if !(options.cell_m > 0.0 && options.margin_m >= 0.0 && options.low_object_m > 0.0) {
        return Err(Error::Invalid(format!(
            "coverage: cell {} m, margin {} m, low object {} m: the cell and the object must be > 0, the margin >= 0",
            options.cell_m, options.margin_m, options.low_object_m
        )));
    }
    if sensors.is_empty() {
        return Err(Error::Invalid("coverage: no sensor".into()));
    }
    // The vehicle's origin inside too.
    let origin = Point2::new(0.0, 0.0);
    let (lo, hi) = bounds(vehicle.parts.iter(), (origin, origin));
    let grid = GroundGrid {
        min_m: [lo.x - options.margin_m, lo.y - options.margin_m],
        cell_m: options.cell_m,
        cells: [
            ((hi.x - lo.x + 2.0 * options.margin_m) / options.cell_m).ceil() as usize,
            ((hi.y - lo.y + 2.0 * options.margin_m) / options.cell_m).ceil() as usize,
        ],
    };
    let scene = Scene {
        min_m: [grid.min_m[0] - 1.0, grid.min_m[1] - 1.0],
        max_m: [hi.x + options.margin_m + 1.0, hi.y + options.margin_m + 1.0],
        ground_remission: 0.2,
        ..Scene::default()
    };
    let world = World::with_obstacles(&scene, vehicle, &Isometry2::identity());
    let heights = &vehicle.spec.heights_of_interest_m;
    let objects: Vec<f64> = heights
        .iter()
        .enumerate()
        .map(|(level, &h)| {
            if level == 0 {
                h.max(options.low_object_m)
            } else {
                h
            }
        })
        .collect();
    // Per sensor, per level: the cells it sees.
    let mut seen_by: Vec<Vec<Vec<bool>>> = Vec::new();
    let mut out = Vec::new();
    for m in sensors {
        let sensor = Lidar::new(m.config.clone(), m.vehicle_from_sensor)
            .map_err(|e| Error::Invalid(format!("sensor `{}`: {e}", m.name)))?;
        let at = sensor.vehicle_from_sensor().translation.vector;
        let rays = sensor.rays_in_vehicle(&world);
        let seen: Vec<Vec<bool>> = objects
            .iter()
            .map(|&object| seen_cells(&grid, [at.x, at.y, at.z], &rays, object, m.config.range_m))
            .collect();
        let alone = objects
            .iter()
            .enumerate()
            .map(|(level, &object)| {
                level_coverage(vehicle, &grid, level, object, &seen[level]).blind_area_m2
            })
            .collect();
        out.push(SensorCoverage {
            name: m.name.clone(),
            position_m: [at.x, at.y, at.z],
            alone_blind_area_m2: alone,
        });
        seen_by.push(seen);
    }
    let levels = objects
        .iter()
        .enumerate()
        .map(|(level, &object)| {
            let seen: Vec<bool> = (0..grid.cells[0] * grid.cells[1])
                .map(|k| seen_by.iter().any(|s| s[level][k]))
                .collect();
            level_coverage(vehicle, &grid, level, object, &seen)
        })
        .collect();
    Ok(Coverage {
        vehicle: vehicle.spec.name.clone(),
        sensors: out,
        grid,
        levels,
    })
}

/// The parts' footprints' bounds, grown from `start` (a box around a point).
fn bounds<'a>(
    parts: impl Iterator<Item = &'a aircraft::Part>,
    start: (Point2<f64>, Point2<f64>),
) -> (Point2<f64>, Point2<f64>) {
    parts
        .map(|p| p.footprint().bounds())
        .fold(start, |(lo, hi), (a, b)| {
            (
                Point2::new(lo.x.min(a.x), lo.y.min(a.y)),
                Point2::new(hi.x.max(b.x), hi.y.max(b.y)),
            )
        })
}

/// Per cell: some ray passes between the ground and `h` above it before anything stops it.
fn seen_cells(
    grid: &GroundGrid,
    origin: [f64; 3],
    rays: &[([f64; 3], Option<f64>)],
    h: f64,
    range_m: f64,
) -> Vec<bool> {
    let mut seen = vec![false; grid.cells[0] * grid.cells[1]];
    let reach = grid.cells[0].max(grid.cells[1]) as f64 * grid.cell_m * 1.5;
    for (d, stop) in rays {
        let stop = stop.unwrap_or(range_m).min(range_m);
        let Some((from, to)) = low_interval(origin[2], d[2], h, stop) else {
            continue;
        };
        let horizontal = d[0].hypot(d[1]);
        let to = to.min(if horizontal > 0.0 {
            reach / horizontal
        } else {
            from
        });
        let step = if horizontal > 0.0 {
            0.5 * grid.cell_m / horizontal
        } else {
            f64::INFINITY
        };
        let mut t = from;
        loop {
            if let Some(k) = grid.cell(origin[0] + t * d[0], origin[1] + t * d[1]) {
                seen[k] = true;
            }
            if t >= to {
                break;
            }
            t = (t + step).min(to);
        }
    }
    seen
}

/// One level's figures from its seen cells.
fn level_coverage(
    vehicle: &aircraft::Vehicle,
    grid: &GroundGrid,
    level: usize,
    object: f64,
    seen: &[bool],
) -> LevelCoverage {
    // The level's parts - what its objects can touch - and the ground under them: on level 0
    // the parts reaching below its object's top, above it the parts reaching above the level's
    // height (its objects are that tall or taller).
    let low: Vec<&aircraft::Part> = vehicle
        .parts
        .iter()
        .filter(|p| {
            if level == 0 {
                p.underside_m() < object
            } else {
                p.top_m() > object
            }
        })
        .collect();
    let footprints: Vec<_> = low.iter().map(|p| p.footprint()).collect();
    let own: Vec<bool> = (0..seen.len())
        .map(|k| {
            let (x, y) = grid.centre(k);
            footprints.iter().any(|f| f.contains(&Point2::new(x, y)))
        })
        .collect();
    let blind: Vec<bool> = seen.iter().zip(&own).map(|(s, o)| !s && !o).collect();
    let blind_area_m2 = blind.iter().filter(|b| **b).count() as f64 * grid.cell_m * grid.cell_m;
    let nearest = nearest_blind(grid, &blind, &low, level);
    LevelCoverage {
        level,
        object_height_m: object,
        blind_area_m2,
        blind_ahead_m: blind_ahead(grid, &blind, &own),
        nearest,
        blind,
        own,
    }
}

/// The nearest blind cell ahead of each gear (along its own width; level 0, where the wheels
/// roll) and beside each wing tip (the levels above, where the wings are).
fn nearest_blind(
    grid: &GroundGrid,
    blind: &[bool],
    low: &[&aircraft::Part],
    level: usize,
) -> Vec<NearestBlind> {
    let cells: Vec<(f64, f64)> = (0..blind.len())
        .filter(|&k| blind[k])
        .map(|k| grid.centre(k))
        .collect();
    let mut out = Vec::new();
    let mut gears: Vec<&str> = low
        .iter()
        .map(|p| p.link.as_str())
        .filter(|l| level == 0 && l.contains("gear"))
        .collect();
    gears.dedup();
    for gear in gears {
        let empty = (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        let (lo, hi) = bounds(low.iter().copied().filter(|p| p.link == gear), empty);
        let distance_m = cells
            .iter()
            .filter(|(x, y)| *x > hi.x && (lo.y..=hi.y).contains(y))
            .map(|(x, _)| x - hi.x)
            .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.min(d))));
        out.push(NearestBlind {
            from: format!("ahead of {gear}"),
            distance_m,
        });
    }
    // The wing tips: the farthest any part of the level reaches to each side.
    for (side, sign) in [("left", 1.0), ("right", -1.0)] {
        let Some(tip) = low
            .iter()
            .filter(|p| level > 0 && p.link.contains("wing"))
            .map(|p| {
                let (a, b) = p.footprint().bounds();
                let y = if sign > 0.0 { b.y } else { a.y };
                (0.5 * (a.x + b.x), y)
            })
            .max_by(|a, b| (sign * a.1).total_cmp(&(sign * b.1)))
        else {
            continue;
        };
        let distance_m = cells
            .iter()
            .map(|(x, y)| (x - tip.0).hypot(y - tip.1))
            .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.min(d))));
        out.push(NearestBlind {
            from: format!("beside the {side} wing tip"),
            distance_m,
        });
    }
    out
}

/// How far the vehicle must travel straight ahead before every ground cell its level's parts
/// sweep has been seen: per row of cells its parts cover, the run of blind cells that starts
/// right ahead of their front in that row (the blind zone moves with the vehicle, so only ground
/// blind from every position up to reaching it is never seen), the longest of them, metres.
fn blind_ahead(grid: &GroundGrid, blind: &[bool], own: &[bool]) -> f64 {
    let nx = grid.cells[0];
    let longest = (0..grid.cells[1])
        .filter_map(|j| {
            let row = j * nx;
            let front = (0..nx).rev().find(|&i| own[row + i])?;
            Some((front + 1..nx).take_while(|&i| blind[row + i]).count())
        })
        .max()
        .unwrap_or(0);
    longest as f64 * grid.cell_m
}

/// The picture: a panel per level, the blind ground red, the vehicle's own grey, the sensor a
/// blue dot; SVG and PNG as `<dir>/<stem>.svg` and `.png`.
pub fn draw(coverage: &Coverage, dir: &Path, stem: &str) -> Result<()> {
    let panels = coverage.levels.len().max(1) as u32;
    let g = coverage.grid;
    let aspect = g.cells[1] as f64 / g.cells[0] as f64;
    let (w, h) = (560u32, (560.0 * aspect) as u32 + 40);
    crate::chart::both(
        dir,
        stem,
        (w * panels, h),
        |root| draw_on(&root, coverage),
        |root| draw_on(&root, coverage),
    )
}

fn draw_on<DB: plotters::prelude::DrawingBackend>(
    root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    coverage: &Coverage,
) -> crate::chart::DrawResult {
    use plotters::prelude::*;
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let panels = root.split_evenly((1, coverage.levels.len().max(1)));
    let g = coverage.grid;
    let (x0, y0) = (g.min_m[0], g.min_m[1]);
    let (x1, y1) = (
        x0 + g.cells[0] as f64 * g.cell_m,
        y0 + g.cells[1] as f64 * g.cell_m,
    );
    for (panel, level) in panels.iter().zip(&coverage.levels) {
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!(
                    "{} level {}: a {:.2} m object, blind {:.1} m2",
                    coverage.vehicle, level.level, level.object_height_m, level.blind_area_m2
                ),
                ("sans-serif", 14),
            )
            .margin(6)
            .x_label_area_size(24)
            .y_label_area_size(30)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .disable_mesh()
            .draw()
            .map_err(|e| e.to_string())?;
        for (mask, colour) in [
            (&level.own, RGBColor(170, 170, 170)),
            (&level.blind, RGBColor(220, 40, 40)),
        ] {
            let rects = runs(&g, mask)
                .into_iter()
                .map(|(a, b, y)| Rectangle::new([(a, y), (b, y + g.cell_m)], colour.filled()));
            chart.draw_series(rects).map_err(|e| e.to_string())?;
        }
        for s in &coverage.sensors {
            let p = s.position_m;
            chart
                .draw_series(std::iter::once(Circle::new((p[0], p[1]), 3, BLUE.filled())))
                .map_err(|e| e.to_string())?;
        }
    }
    root.present().map_err(|e| e.to_string())
}

/// A mask's cells as horizontal runs (x from, x to, y): what a picture draws, a rectangle each.
fn runs(g: &GroundGrid, mask: &[bool]) -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    for j in 0..g.cells[1] {
        let y = g.min_m[1] + j as f64 * g.cell_m;
        let mut i = 0;
        while i < g.cells[0] {
            if mask[j * g.cells[0] + i] {
                let start = i;
                while i < g.cells[0] && mask[j * g.cells[0] + i] {
                    i += 1;
                }
                let x = |i: usize| g.min_m[0] + i as f64 * g.cell_m;
                out.push((x(start), x(i), y));
            } else {
                i += 1;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_is_low_between_its_height_and_the_ground() {
        // From 1.55 m, 30 degrees down: at or under 0.7 m from t = 1.7 to the ground at t = 3.1.
        let dz = -(30f64.to_radians().sin());
        let (a, b) = low_interval(1.55, dz, 0.7, 100.0).unwrap();
        assert!(
            (a - 0.85 / 0.5).abs() < 1e-9 && (b - 1.55 / 0.5).abs() < 1e-9,
            "{a} {b}"
        );
        // Stopped by the airframe first: nothing; stopped inside: cut there.
        assert_eq!(low_interval(1.55, dz, 0.7, 1.0), None);
        assert_eq!(low_interval(1.55, dz, 0.7, 2.0), Some((a, 2.0)));
        // Upward from 1.55 m never passes under 0.7 m; from 0.5 m it does at first.
        assert_eq!(low_interval(1.55, 0.1, 0.7, 100.0), None);
        assert_eq!(
            low_interval(0.5, 0.1, 0.7, 100.0),
            Some((0.0, (0.7 - 0.5) / 0.1))
        );
        // Level: everything or nothing.
        assert_eq!(low_interval(0.5, 0.0, 0.7, 9.0), Some((0.0, 9.0)));
        assert_eq!(low_interval(1.5, 0.0, 0.7, 9.0), None);
    }

    #[test]
    fn the_praetors_nose_hides_a_cone_just_ahead_and_not_one_a_few_metres_on() {
        let jet = aircraft::Vehicle::load("praetor600").unwrap();
        let options = CoverageOptions {
            cell_m: 0.1,
            margin_m: 8.0,
            low_object_m: 0.7,
        };
        let c = coverage(&jet, &LidarConfig::default(), &options).unwrap();
        let level0 = &c.levels[0];
        assert!((level0.object_height_m - 0.7).abs() < 1e-12);
        let blind_at = |x: f64, y: f64| level0.blind[c.grid.cell(x, y).unwrap()];
        // tests/found/cone_left_under_the_nose_at_the_stand.toml's cone, 1.15 m ahead of the
        // sensor (its lowest beam 0.87 m up there), and 4 m ahead of it (beams 12-20 degrees
        // down pass under 0.7 m there).
        assert!(blind_at(13.0, 0.0));
        assert!(!blind_at(16.0, 0.0));
        // Under the fuselage is the jet's own ground, not blind.
        assert!(level0.own[c.grid.cell(2.0, 0.0).unwrap()]);
        assert!(!blind_at(2.0, 0.0));
        assert!(level0.blind_ahead_m > 0.0, "{}", level0.blind_ahead_m);
        let nose = level0
            .nearest
            .iter()
            .find(|n| n.from == "ahead of nose_gear")
            .unwrap();
        assert!(nose.distance_m.is_some_and(|d| d < 4.0), "{nose:?}");
        // Level 1 (1.1 m): the wings are its parts, the gears not.
        let froms: Vec<&str> = c.levels[1]
            .nearest
            .iter()
            .map(|n| n.from.as_str())
            .collect();
        assert_eq!(
            froms,
            ["beside the left wing tip", "beside the right wing tip"]
        );
    }

    #[test]
    fn a_low_vlp16_under_the_nose_pod_sees_the_cone_the_sidecar_cannot() {
        let jet = aircraft::Vehicle::load("praetor600").unwrap();
        let options = CoverageOptions {
            cell_m: 0.1,
            margin_m: 8.0,
            low_object_m: 0.7,
        };
        let one = coverage(&jet, &LidarConfig::default(), &options).unwrap();
        let sidecar = Mounted {
            name: "sidecar".into(),
            config: LidarConfig::default(),
            vehicle_from_sensor: jet.vehicle_from_lidar(),
        };
        let low = Mounted {
            name: "vlp-16".into(),
            config: LidarConfig::vlp16(),
            vehicle_from_sensor: nalgebra::Isometry3::translation(11.85, 0.0, 0.5),
        };
        let two = coverage_of(&jet, &[sidecar, low], &options).unwrap();
        // The sidecar's own figures are the one-sensor run's.
        let alone: Vec<f64> = one.levels.iter().map(|l| l.blind_area_m2).collect();
        assert_eq!(two.sensors[0].alone_blind_area_m2, alone);
        assert_eq!(two.sensors[1].position_m, [11.85, 0.0, 0.5]);
        // Together: blind only where both are, so no more than either alone on every level.
        for (k, l) in two.levels.iter().enumerate() {
            let least = two
                .sensors
                .iter()
                .map(|s| s.alone_blind_area_m2[k])
                .fold(f64::MAX, f64::min);
            assert!(l.blind_area_m2 <= least + 1e-9, "level {k}");
        }
        // The cone 1.15 m ahead of the sidecar, blind to it, is seen; nothing ahead of a gear
        // or of the parts is blind any more.
        let level0 = &two.levels[0];
        assert!(one.levels[0].blind[one.grid.cell(13.0, 0.0).unwrap()]);
        assert!(!level0.blind[two.grid.cell(13.0, 0.0).unwrap()]);
        assert_eq!(level0.blind_ahead_m, 0.0);
        assert!(
            level0.nearest.iter().all(|n| n.distance_m.is_none()),
            "{:?}",
            level0.nearest
        );
    }

    #[test]
    fn the_two_lidar_praetor_is_the_praetor_with_that_vlp16_and_a_bad_model_is_named() {
        let options = CoverageOptions {
            cell_m: 0.2,
            margin_m: 8.0,
            low_object_m: 0.7,
        };
        let jet = aircraft::Vehicle::load("praetor600").unwrap();
        let two = aircraft::Vehicle::load("praetor600_two_lidars").unwrap();
        let sensors = vehicle_lidars(&two, &LidarConfig::default()).unwrap();
        let names: Vec<&str> = sensors.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["velodyne", "nose_low"]);
        assert_eq!(sensors[1].config.channels, 16);
        // Its own unit: the two sensors' range biases are drawn apart.
        assert_ne!(
            sensors[0].config.range_bias_unit,
            sensors[1].config.range_bias_unit
        );
        let low = Mounted {
            name: "vlp-16".into(),
            config: LidarConfig::vlp16(),
            vehicle_from_sensor: nalgebra::Isometry3::translation(11.85, 0.0, 0.5),
        };
        let by_hand = coverage_of(
            &jet,
            &[
                vehicle_lidars(&jet, &LidarConfig::default()).unwrap()[0].clone(),
                low,
            ],
            &options,
        )
        .unwrap();
        let shipped = coverage(&two, &LidarConfig::default(), &options).unwrap();
        for (a, b) in shipped.levels.iter().zip(&by_hand.levels) {
            assert_eq!(a.blind, b.blind);
        }
        let mut odd = two.clone();
        odd.spec.extra_lidars[0].model = "os1-64".into();
        let e = vehicle_lidars(&odd, &LidarConfig::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("extra_lidars[0].model") && e.contains("os1-64"),
            "{e}"
        );
    }
}
