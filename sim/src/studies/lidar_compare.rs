//! The synthetic HDL-32E against a real one (`taxi-sim compare-lidar`): the same figures from a
//! real capture's full revolutions and from the simulator's sensor at the same height over
//! flat, empty ground.
//!
//! Ground returns: those of the lasers aimed 8 degrees or more down, 4-30 m away horizontally,
//! within 0.25 m of the ground's most common height; a plane fitted to them by least squares,
//! refitted to those within 0.15 m of the first fit. From it: the sensor's height, pitch and
//! roll, and the spread of the returns about it (the range noise seen vertically). Per beam: the
//! fraction of firings without a return, the ground ring's radius (the median horizontal range
//! of its ground returns; a level sensor at height h puts it at h / tan|elevation|). The
//! intensity of ground returns (0-255, the sensor's raw scale; the simulator's 0-1 times 255).
//! And what the mapper's beam-pair obstacle test, with the run configuration's settings, makes
//! of the ground: obstacle returns among ground returns per revolution - with the sensor taken
//! as level (as `map --pcap` takes it), and with the fitted tilt removed.

use mapper::occupancy::ObstacleTest;
use mapper::{ObstacleTestParams, Scan};
use nalgebra::{Isometry2, Isometry3, Point3};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::pcap::{Ground, Recording};
use crate::world::{Lidar, LidarConfig, Scene, SweepPoses, World};

/// The figures of one sensor.
#[derive(Clone, Debug, Serialize)]
pub struct Figures {
    /// Which sensor.
    pub label: String,
    /// Revolutions measured.
    pub revolutions: usize,
    /// Firings (columns) a revolution, mean.
    pub firings_per_revolution: f64,
    /// Firings a second (the real sensor's from its firing times; the synthetic's columns times
    /// its rotation rate).
    pub firings_per_second: f64,
    /// Returns a revolution, mean.
    pub returns_per_revolution: f64,
    /// Each beam's elevation, degrees, lowest first.
    pub elevations_deg: Vec<f64>,
    /// Each beam's fraction of firings without a return.
    pub no_return: Vec<f64>,
    /// The lasers aimed 8 degrees or more down: their fraction of firings without a return in
    /// each 30-degree sector of azimuth (sector k from 30k degrees, counter-clockwise from
    /// ahead; a firing's azimuth is its first return's).
    pub no_return_low_by_sector: Vec<f64>,
    /// Ground returns used, a revolution.
    pub ground_returns_per_revolution: f64,
    /// The fitted ground: the sensor's height above it, metres.
    pub height_m: f64,
    /// The sensor's pitch (nose up positive) and roll (right side down positive), degrees.
    pub pitch_roll_deg: [f64; 2],
    /// Standard deviation of the ground returns about the plane, metres (range noise seen
    /// vertically, and the ground's own shape).
    pub ground_spread_m: f64,
    /// Range noise along the beam, metres: the spread of the range difference between one
    /// laser's ground returns in consecutive firings (1.4826 x its median absolute deviation,
    /// over the square root of 2) - blind to the ground's shape, which changes little in 0.2
    /// degree.
    pub range_noise_m: f64,
    /// Each beam's ground ring radius, metres (`None`: too few ground returns).
    pub ring_radius_m: Vec<Option<f64>>,
    /// Deciles (10-90 %) of the ground returns' intensity, 0-255.
    pub ground_intensity_deciles: Vec<f64>,
    /// Ground returns the obstacle test calls obstacles, a revolution: the sensor taken as
    /// level; with the fitted tilt removed; and with the tilt removed and no unsafe height (the
    /// beam-pair test alone, as CARMEN's default of 1 m nearly is).
    pub false_obstacles_per_revolution: [f64; 3],
}

/// A revolution's returns in the frame of a level sensor at the origin: `[beam]` per column,
/// the point and its intensity 0-255.
type Columns = Vec<Vec<Option<(Point3<f64>, f64)>>>;

fn columns_of(scan: &Scan, world_from_sensor: &Isometry3<f64>, scale: f64) -> Columns {
    let to_sensor = world_from_sensor.inverse();
    scan.returns()
        .chunks(scan.beams())
        .map(|c| {
            c.iter()
                .map(|r| r.map(|r| (to_sensor * r.point_in_world, f64::from(r.intensity) * scale)))
                .collect()
        })
        .collect()
}

/// The ground under the sensor ([`Ground::fit`]) from the low lasers' returns of `revs`.
fn fit_ground(label: &str, low: &[bool], revs: &[Columns]) -> Result<Ground> {
    let points: Vec<Point3<f64>> = revs
        .iter()
        .flatten()
        .flat_map(|col| col.iter().enumerate())
        .filter_map(|(b, r)| r.filter(|_| low[b]).map(|(p, _)| p))
        .collect();
    Ground::fit(&points).ok_or_else(|| Error::Invalid(format!("{label}: too few ground returns")))
}

/// The figures of revolutions `revs` (in the sensor frame, beams lowest first).
fn figures(
    label: &str,
    elevations_deg: &[f64],
    revs: &[Columns],
    firings_per_second: f64,
    test: ObstacleTestParams,
) -> Result<Figures> {
    let beams = elevations_deg.len();
    let low: Vec<bool> = elevations_deg.iter().map(|&w| w <= -8.0).collect();
    let ground_fit = fit_ground(label, &low, revs)?;
    let (plane, spread) = (ground_fit, ground_fit.spread_m);
    let is_ground = |p: &Point3<f64>| {
        (4.0..30.0).contains(&p.coords.xy().norm()) && (p.z - plane.z_at(p)).abs() < 0.15
    };
    let height_m = plane.height_m();
    // Per beam: no returns, ring radii; ground intensities; false obstacles.
    let mut firings = 0usize;
    let mut missing = vec![0usize; beams];
    let mut ring: Vec<Vec<f64>> = vec![Vec::new(); beams];
    let mut intensities = Vec::new();
    let mut returns = 0usize;
    let mut ground = 0usize;
    let mut false_obstacles = [0usize; 3];
    let mut steps: Vec<f64> = Vec::new();
    let mut by_sector = [(0usize, 0usize); SECTORS];
    let level = Isometry3::translation(0.0, 0.0, height_m);
    let untilted = plane.sensor_above_level_ground();
    let tests = [
        (
            &ObstacleTest::new(ObstacleTestParams {
                ground_height_m: 0.0,
                ..test
            }),
            test.unsafe_height_above_ground_m,
        ),
        (
            &ObstacleTest::new(ObstacleTestParams {
                ground_height_m: 0.0,
                unsafe_height_above_ground_m: None,
                ..test
            }),
            None,
        ),
    ];
    for rev in revs {
        for pair in rev.windows(2) {
            for (a, b) in pair[0]
                .iter()
                .zip(&pair[1])
                .zip(&low)
                .filter(|(_, l)| **l)
                .map(|(x, _)| x)
            {
                if let (Some((a, _)), Some((b, _))) = (a, b)
                    && is_ground(a)
                    && is_ground(b)
                {
                    steps.push(b.coords.norm() - a.coords.norm());
                }
            }
        }
        for col in rev {
            firings += 1;
            count_low_by_sector(col, &low, &mut by_sector);
            for (b, r) in col.iter().enumerate() {
                match r {
                    None => missing[b] += 1,
                    Some((p, i)) => {
                        returns += 1;
                        if low[b] && is_ground(p) {
                            ground += 1;
                            ring[b].push(p.coords.xy().norm());
                            intensities.push(*i);
                        }
                    }
                }
            }
            for (k, (frame, test)) in [(level, 0), (untilted, 0), (untilted, 1)]
                .iter()
                .enumerate()
            {
                let low_ground = |b: usize, p: &Point3<f64>| low[b] && is_ground(p);
                false_obstacles[k] += ground_obstacles(col, frame, tests[*test], &low_ground);
            }
        }
    }
    let n = revs.len().max(1) as f64;
    intensities.sort_by(f64::total_cmp);
    let decile = |q: f64| {
        intensities
            .get(((intensities.len() as f64 - 1.0) * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    Ok(Figures {
        label: label.to_string(),
        revolutions: revs.len(),
        firings_per_revolution: firings as f64 / n,
        firings_per_second,
        returns_per_revolution: returns as f64 / n,
        elevations_deg: elevations_deg.to_vec(),
        no_return: missing
            .iter()
            .map(|&m| m as f64 / firings.max(1) as f64)
            .collect(),
        no_return_low_by_sector: by_sector
            .iter()
            .map(|&(missing, fired)| missing as f64 / fired.max(1) as f64)
            .collect(),
        ground_returns_per_revolution: ground as f64 / n,
        height_m,
        pitch_roll_deg: plane.pitch_roll_deg(),
        ground_spread_m: spread,
        range_noise_m: robust_std(&mut steps) / 2f64.sqrt(),
        ring_radius_m: ring
            .into_iter()
            .map(|mut v| {
                (v.len() >= 20).then(|| {
                    v.sort_by(f64::total_cmp);
                    v[v.len() / 2]
                })
            })
            .collect(),
        ground_intensity_deciles: (1..10).map(|k| decile(k as f64 / 10.0)).collect(),
        false_obstacles_per_revolution: false_obstacles.map(|f| f as f64 / n),
    })
}

/// Sectors of azimuth for the missing returns (30 degrees each).
const SECTORS: usize = 12;

/// Adds a column's low beams to its azimuth sector's `(missing, fired)` (the sector of its
/// first return; a column with no return at all is left out: its azimuth is unknown).
fn count_low_by_sector(
    col: &[Option<(Point3<f64>, f64)>],
    low: &[bool],
    by_sector: &mut [(usize, usize); SECTORS],
) {
    let Some((p, _)) = col.iter().flatten().next() else {
        return;
    };
    let azimuth = p.y.atan2(p.x).to_degrees().rem_euclid(360.0);
    let sector = ((azimuth / (360.0 / SECTORS as f64)) as usize).min(SECTORS - 1);
    for (r, _) in col.iter().zip(low).filter(|(_, l)| **l) {
        by_sector[sector].1 += 1;
        if r.is_none() {
            by_sector[sector].0 += 1;
        }
    }
}

/// How many of a column's ground returns (`is_ground(beam, point)`) the obstacle test with its
/// unsafe height calls obstacles, its points moved by `world_from_sensor` - the beam below each
/// one as the mapper pairs them: the previous beam with a return, none after a beam without (the
/// vehicle's ceiling, which also breaks pairs, is left out: no ground return lies above one).
fn ground_obstacles(
    col: &[Option<(Point3<f64>, f64)>],
    world_from_sensor: &Isometry3<f64>,
    (test, unsafe_height): (&ObstacleTest, Option<f64>),
    is_ground: &dyn Fn(usize, &Point3<f64>) -> bool,
) -> usize {
    let sensor = Point3::from(world_from_sensor.translation.vector);
    let mut below: Option<(Point3<f64>, f64)> = None;
    let mut n = 0;
    for (b, r) in col.iter().enumerate() {
        let Some((p, _)) = r else {
            below = None;
            continue;
        };
        let w = world_from_sensor * p;
        let range = (w.coords.xy() - sensor.coords.xy()).norm();
        // As the mapper pairs them (`mapper::map::insert`): with no beam below, only the unsafe
        // height decides.
        let obstacle = match below {
            Some((lower, lower_range)) => test.is_obstacle(&sensor, &lower, lower_range, &w, range),
            None => unsafe_height.is_some_and(|h| w.z >= h),
        };
        if obstacle && is_ground(b, p) {
            n += 1;
        }
        below = Some((w, range));
    }
    n
}

/// 1.4826 times the median absolute deviation of `v` (the standard deviation of a normal
/// spread, unmoved by a few outliers); 0 for an empty `v`.
fn robust_std(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let median = v[v.len() / 2];
    let mut dev: Vec<f64> = v.iter().map(|x| (x - median).abs()).collect();
    dev.sort_by(f64::total_cmp);
    1.4826 * dev[dev.len() / 2]
}

/// The real sensor's figures from `recording`'s full revolutions.
pub fn real(recording: &Recording, label: &str, test: ObstacleTestParams) -> Result<Figures> {
    let order = velodyne::scan::beams(&recording.calibration);
    let mut elevations = vec![0.0; order.len()];
    for (laser, &beam) in order.iter().enumerate() {
        elevations[beam] = recording.calibration.vertical_deg[laser];
    }
    let revs = recording
        .full()
        .iter()
        .map(|f| {
            let s = recording.scan(f, &Isometry2::identity(), &Isometry3::identity())?;
            Ok(columns_of(&s.scan, &Isometry3::identity(), 255.0))
        })
        .collect::<Result<Vec<_>>>()?;
    figures(
        label,
        &elevations,
        &revs,
        firing_rate(recording.full()),
        test,
    )
}

/// The simulator's sensor (`config`) `height_m` above flat, empty ground of `remission`: the
/// figures of `revolutions` revolutions.
pub fn synthetic(
    config: &LidarConfig,
    height_m: f64,
    remission: f32,
    revolutions: usize,
    seed: u64,
    test: ObstacleTestParams,
) -> Result<Figures> {
    let vehicle =
        aircraft::Vehicle::shipped("iara_car").map_err(|e| Error::Invalid(e.to_string()))?;
    let scene = Scene {
        min_m: [-150.0, -150.0],
        max_m: [150.0, 150.0],
        ground_remission: remission,
        pavement_texture: 0.0,
        solids: Vec::new(),
        patches: Vec::new(),
        areas: Vec::new(),
    };
    let pose = Isometry2::identity();
    let world = World::static_only(&scene, &vehicle, &pose);
    let mount = Isometry3::translation(0.0, 0.0, height_m);
    let lidar = Lidar::new(config.clone(), mount).map_err(Error::Invalid)?;
    let revs: Vec<Columns> = (0..revolutions as u64)
        .map(|i| {
            let s = lidar.scan(&world, &SweepPoses::still(pose), i, seed);
            columns_of(&s.scan, &mount, 255.0)
        })
        .collect();
    let n = config.channels;
    let elevations: Vec<f64> = (0..n)
        .map(|b| {
            config.lower_fov_deg
                + b as f64 / (n - 1).max(1) as f64 * (config.upper_fov_deg - config.lower_fov_deg)
        })
        .collect();
    let rate = config.columns as f64 * config.rotation_frequency_hz;
    figures("synthetic HDL-32E", &elevations, &revs, rate, test)
}

/// Firings a second over `frames`: firing sequences counted against the time from the first
/// firing to the last (NaN with fewer than two).
fn firing_rate(frames: &[velodyne::Frame]) -> f64 {
    let mut firings = std::collections::BTreeSet::new();
    let (mut first, mut last) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in frames.iter().flat_map(|f| &f.points) {
        firings.insert(p.firing);
        first = first.min(p.time_us);
        last = last.max(p.time_us);
    }
    match (firings.first(), firings.last()) {
        (Some(a), Some(b)) if b > a && last > first => {
            // Firings between the first and the last, over the time between them.
            f64::from(b - a) / ((last - first) * 1e-6)
        }
        _ => f64::NAN,
    }
}

/// Low beams' sectors that miss more than this fraction are the mount's shadow (the vehicle the
/// sensor stands on, its housing) or what stands close by: not the sensor's own misses.
pub const SHADOW_MISS_FRACTION: f64 = 0.1;

/// What the comparison says of one figure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Verdict {
    /// A property of the sensor, calibrated: the synthetic's figure is within `tolerance` of
    /// the real one (`holds`), by the setting `knob`.
    Calibrated {
        /// The tolerance, as said.
        tolerance: String,
        /// Whether the synthetic figure is within it.
        holds: bool,
        /// The setting that moves it.
        knob: &'static str,
    },
    /// Not a property of the sensor alone (the scene's, the mount's) or not calibratable from
    /// the capture: why.
    Not(&'static str),
}

/// One row of the comparison.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The figure.
    pub figure: &'static str,
    /// The real sensor's value.
    pub real: String,
    /// The synthetic sensor's value.
    pub synthetic: String,
    /// What the calibration claims of it.
    pub verdict: Verdict,
}

/// Mean of the low beams' no-return fractions where `keep(elevation)`.
fn no_return_mean(f: &Figures, keep: impl Fn(f64) -> bool) -> f64 {
    let v: Vec<f64> = f
        .elevations_deg
        .iter()
        .zip(&f.no_return)
        .filter(|(w, _)| keep(**w))
        .map(|(_, n)| *n)
        .collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The sectors where the low beams miss more than [`SHADOW_MISS_FRACTION`].
pub fn shadow_sectors(f: &Figures) -> Vec<bool> {
    f.no_return_low_by_sector
        .iter()
        .map(|&m| m > SHADOW_MISS_FRACTION)
        .collect()
}

/// The low beams' no-return fraction outside `shadow` (mean over the sectors).
pub fn no_return_outside(f: &Figures, shadow: &[bool]) -> f64 {
    let v: Vec<f64> = f
        .no_return_low_by_sector
        .iter()
        .zip(shadow)
        .filter(|(_, s)| !**s)
        .map(|(m, _)| *m)
        .collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Median relative error of the ground rings' radii against `h / tan(elevation)`, percent, and
/// how many rings.
fn ring_error(f: &Figures) -> Option<(f64, usize)> {
    let mut e: Vec<f64> = f
        .elevations_deg
        .iter()
        .zip(&f.ring_radius_m)
        .filter_map(|(w, r)| {
            let expected = f.height_m / (-w.to_radians()).tan();
            r.map(|r| 100.0 * (r - expected) / expected)
        })
        .collect();
    e.sort_by(f64::total_cmp);
    e.get(e.len() / 2).map(|m| (*m, e.len()))
}

/// Whether `synthetic` is within `fraction` of `real`, relative.
fn within(real: f64, synthetic: f64, fraction: f64) -> bool {
    (synthetic - real).abs() <= fraction * real.abs()
}

/// The comparison, figure by figure, with what the calibration claims of each.
pub fn rows(real: &Figures, synthetic: &Figures) -> Vec<Row> {
    let mut rows = returns_rows(real, synthetic);
    rows.extend(ground_rows(real, synthetic));
    rows
}

/// The rows being written, with both sensors' figures at hand.
struct Rows<'a> {
    real: &'a Figures,
    synthetic: &'a Figures,
    rows: Vec<Row>,
}

impl<'a> Rows<'a> {
    fn new(real: &'a Figures, synthetic: &'a Figures) -> Self {
        Rows {
            real,
            synthetic,
            rows: Vec::new(),
        }
    }

    /// A figure of each sensor.
    fn both(&self, f: &dyn Fn(&Figures) -> String) -> (String, String) {
        (f(self.real), f(self.synthetic))
    }

    fn push(
        &mut self,
        figure: &'static str,
        (real, synthetic): (String, String),
        verdict: Verdict,
    ) {
        self.rows.push(Row {
            figure,
            real,
            synthetic,
            verdict,
        });
    }
}

/// The rows of the firings and their returns.
fn returns_rows(real: &Figures, synthetic: &Figures) -> Vec<Row> {
    use Verdict::{Calibrated, Not};
    let mut t = Rows::new(real, synthetic);
    let (fr, fs) = (real.firings_per_second, synthetic.firings_per_second);
    t.push(
        "firings a second",
        t.both(&|f| format!("{:.0}", f.firings_per_second)),
        Calibrated {
            tolerance: "1 %".into(),
            holds: within(fr, fs, 0.01),
            knob: "columns x rotation_frequency_hz",
        },
    );
    t.push(
        "firings a revolution",
        t.both(&|f| format!("{:.0}", f.firings_per_revolution)),
        Not("the rotation rate set on the unit: firings a second over revolutions a second"),
    );
    t.push(
        "returns a revolution",
        t.both(&|f| format!("{:.0}", f.returns_per_revolution)),
        Not("the scene's: the real one has cars, trees and sky, the synthetic flat empty ground"),
    );
    let shadow = shadow_sectors(real);
    let sectors = |f: &Figures| {
        let s: Vec<String> = shadow_sectors(f)
            .iter()
            .enumerate()
            .filter(|(_, s)| **s)
            .map(|(k, _)| format!("{}-{}", 30 * k, 30 * (k + 1)))
            .collect();
        if s.is_empty() {
            "none".into()
        } else {
            s.join(", ") + " deg"
        }
    };
    t.push(
        "sectors where the beams 8 deg or more down miss > 10 %",
        t.both(&sectors),
        Not(
            "the mount's shadow or what stands close by (a capture cannot tell which); the \
             simulator casts its own vehicle",
        ),
    );
    let (or, os) = (
        no_return_outside(real, &shadow),
        no_return_outside(synthetic, &shadow),
    );
    t.push(
        "no return, beams 8 deg or more down, outside those sectors",
        (
            format!("{:.2} %", 100.0 * or),
            format!("{:.2} %", 100.0 * os),
        ),
        Calibrated {
            tolerance: "0.5 percentage point".into(),
            holds: (os - or).abs() <= 0.005,
            knob: "dropoff_general_rate",
        },
    );
    t.push(
        "no return, beams above 8 deg down (mean)",
        t.both(&|f| format!("{:.1} %", 100.0 * no_return_mean(f, |w| w > -8.0))),
        Not("the scene's: sky and far objects"),
    );
    t.push(
        "ground returns a revolution",
        t.both(&|f| format!("{:.0}", f.ground_returns_per_revolution)),
        Not("the scene's: what stands on the ground hides it"),
    );
    t.push(
        "height above the fitted ground; pitch, roll",
        t.both(&|f| {
            let [p, r] = f.pitch_roll_deg;
            format!("{:.3} m; {p:.2}, {r:.2} deg", f.height_m)
        }),
        Not("the mount's: the synthetic sensor is put at the fitted height, level"),
    );
    t.push(
        "ground spread about the plane (std)",
        t.both(&|f| format!("{:.1} mm", 1000.0 * f.ground_spread_m)),
        Not("the road's shape (crown, camber) against a flat plane"),
    );
    t.rows
}

/// The rows of the ground: its noise, rings, intensity and false obstacles.
fn ground_rows(real: &Figures, synthetic: &Figures) -> Vec<Row> {
    use Verdict::{Calibrated, Not};
    let mut t = Rows::new(real, synthetic);
    let (nr, ns) = (real.range_noise_m, synthetic.range_noise_m);
    t.push(
        "range noise along the beam (consecutive firings on the ground)",
        t.both(&|f| format!("{:.1} mm", 1000.0 * f.range_noise_m)),
        Calibrated {
            tolerance: "15 %".into(),
            holds: within(nr, ns, 0.15),
            knob: "noise_stddev_m",
        },
    );
    let (er, es) = (ring_error(real), ring_error(synthetic));
    t.push(
        "ground rings against h / tan(elevation) (median error)",
        t.both(&|f| ring_error(f).map_or("-".into(), |(m, n)| format!("{m:+.1} % ({n} rings)"))),
        Calibrated {
            tolerance: "2 percentage points".into(),
            holds: matches!((er, es), (Some((a, _)), Some((b, _))) if (a - b).abs() <= 2.0),
            knob: "lower_fov_deg, upper_fov_deg (the beams' elevations)",
        },
    );
    t.push(
        "ground intensity 10 / 50 / 90 % (0-255)",
        t.both(&|f| {
            let d = &f.ground_intensity_deciles;
            format!("{:.0} / {:.0} / {:.0}", d[0], d[4], d[8])
        }),
        Not(
            "raw against calibrated: the mapper takes remission, which CARMEN makes from raw \
             values with a per-laser table; the capture has no surface of known remission to \
             make one",
        ),
    );
    t.push(
        "ground returns taken for obstacles a revolution: level; tilt removed; and no unsafe height",
        t.both(&|f| {
            let [a, b, c] = f.false_obstacles_per_revolution;
            format!("{a:.0}; {b:.0}; {c:.0}")
        }),
        Not("the mount's tilt and the road's shape (docs/velodyne.md)"),
    );
    t.rows
}

/// The comparison as a Markdown table.
pub fn table(real: &Figures, synthetic: &Figures) -> String {
    use std::fmt::Write as _;
    let mut t = format!(
        "| figure | {} | {} | calibrated? |\n| --- | --- | --- | --- |\n",
        real.label, synthetic.label
    );
    for row in rows(real, synthetic) {
        let verdict = match &row.verdict {
            Verdict::Calibrated {
                tolerance,
                holds,
                knob,
            } => format!(
                "{} within {tolerance} (`{knob}`)",
                if *holds { "yes:" } else { "NO: not" }
            ),
            Verdict::Not(why) => format!("not the sensor's: {why}"),
        };
        let _ = writeln!(
            t,
            "| {} | {} | {} | {verdict} |",
            row.figure, row.real, row.synthetic
        );
    }
    t
}
