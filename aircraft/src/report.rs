//! Measuring a fitted model by dense sampling: per level, coverage of the footprint, the
//! over-approximated area ratio and the largest overshoot, and the table the CLI prints.

use std::fmt::Write as _;

use nalgebra::{Point2, Vector2};

use crate::fit::FittedModel;
use crate::footprint::Footprint;

/// Default number of sample points along the longer side of a level's bounds.
pub const DEFAULT_SAMPLES_PER_AXIS: usize = 500;
/// Points sampled on each circle's boundary (and on three inner rings) for the overshoot.
const OVERSHOOT_ANGLES: usize = 96;

/// The quality of one level of a fitted model.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelReport {
    /// Level index.
    pub level: usize,
    /// Height of interest h_k, metres.
    pub height_m: f64,
    /// Parts (collision elements) at this level.
    pub parts: usize,
    /// Circles at this level.
    pub circles: usize,
    /// Smallest and largest circle radius, metres (0 when no circles).
    pub radius_range_m: (f64, f64),
    /// Fraction of the sampled points of the level's parts inside a circle of this level or a
    /// lower one (1.0 = total; 1.0 also for a level with no parts).
    pub coverage: f64,
    /// Area of the union of the level's circles over the area of the level's own parts (those
    /// not left to a lower level), sampled; NaN when the level has no own parts.
    pub area_ratio: f64,
    /// Largest distance of a circle point from the level's footprint, metres (sampled).
    pub max_overshoot_m: f64,
}

fn bounds_of(
    items: impl Iterator<Item = (Point2<f64>, Point2<f64>)>,
) -> Option<(Point2<f64>, Point2<f64>)> {
    items.fold(None, |acc, (lo, hi)| match acc {
        None => Some((lo, hi)),
        Some((a, b)) => Some((a.inf(&lo), b.sup(&hi))),
    })
}

/// Measures every level of `fit`, sampling `samples_per_axis` points along the longer side of
/// each level's bounds (plus every footprint vertex for the coverage).
///
/// A point of a level-k part counts as covered when it lies in a circle of level k or below: a
/// lower level's map holds every obstacle a higher level's map does (cumulative), and in banded
/// mode a level-j circle is checked against every band from j up.
pub fn evaluate(fit: &FittedModel, samples_per_axis: usize) -> Vec<LevelReport> {
    let n = samples_per_axis.max(8);
    let all = fit.model.circles();
    fit.levels
        .iter()
        .enumerate()
        .map(|(k, level)| {
            let own: Vec<&Footprint> = (0..level.footprints.len())
                .filter(|i| !level.below.contains(i))
                .map(|i| &level.footprints[i])
                .collect();
            let circles: Vec<_> = all.iter().filter(|c| c.level == k).collect();
            let reaching: Vec<_> = all.iter().filter(|c| c.level <= k).collect();
            let inside = |cs: &[&mapper::Circle], p: &Point2<f64>| {
                cs.iter().any(|c| {
                    (p.x - c.x_m).powi(2) + (p.y - c.y_m).powi(2) <= c.radius_m * c.radius_m
                })
            };
            let radius_range_m = if circles.is_empty() {
                (0.0, 0.0)
            } else {
                circles.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), c| {
                    (lo.min(c.radius_m), hi.max(c.radius_m))
                })
            };
            let footprint_bounds = bounds_of(level.footprints.iter().map(Footprint::bounds));
            let circle_bounds = bounds_of(circles.iter().map(|c| {
                let r = Vector2::new(c.radius_m, c.radius_m);
                let p = Point2::new(c.x_m, c.y_m);
                (p - r, p + r)
            }));
            // Samples: in any part of the level / covered by a reaching circle / in an own part /
            // in a circle of the level.
            let (mut in_parts, mut covered, mut in_own, mut in_circles) = (0usize, 0, 0, 0);
            if let Some((lo, hi)) = bounds_of(footprint_bounds.into_iter().chain(circle_bounds)) {
                let step = (hi.x - lo.x).max(hi.y - lo.y) / n as f64;
                let (nx, ny) = (
                    ((hi.x - lo.x) / step).ceil() as usize,
                    ((hi.y - lo.y) / step).ceil() as usize,
                );
                for iy in 0..ny {
                    for ix in 0..nx {
                        let p = Point2::new(
                            lo.x + (ix as f64 + 0.5) * step,
                            lo.y + (iy as f64 + 0.5) * step,
                        );
                        if level.footprints.iter().any(|f| f.contains(&p)) {
                            in_parts += 1;
                            covered += inside(&reaching, &p) as usize;
                        }
                        in_own += own.iter().any(|f| f.contains(&p)) as usize;
                        in_circles += inside(&circles, &p) as usize;
                    }
                }
            }
            // Footprint boundary points: the vertices, where coverage is tightest.
            for f in &level.footprints {
                if let Footprint::Polygon(p) = f {
                    for v in p.vertices() {
                        in_parts += 1;
                        covered += inside(&reaching, v) as usize;
                    }
                }
            }
            let max_overshoot_m = circles
                .iter()
                .flat_map(|c| {
                    (0..OVERSHOOT_ANGLES).flat_map(move |i| {
                        let t = std::f64::consts::TAU * i as f64 / OVERSHOOT_ANGLES as f64;
                        [1.0, 0.75, 0.5, 0.25].map(move |s| {
                            Point2::new(
                                c.x_m + s * c.radius_m * t.cos(),
                                c.y_m + s * c.radius_m * t.sin(),
                            )
                        })
                    })
                })
                .map(|p| {
                    level
                        .footprints
                        .iter()
                        .map(|f| f.distance(&p))
                        .fold(f64::INFINITY, f64::min)
                })
                .filter(|d| d.is_finite())
                .fold(0.0, f64::max);
            LevelReport {
                level: k,
                height_m: level.height_m,
                parts: level.footprints.len(),
                circles: circles.len(),
                radius_range_m,
                coverage: if in_parts == 0 {
                    1.0
                } else {
                    covered as f64 / in_parts as f64
                },
                area_ratio: if in_own == 0 {
                    f64::NAN
                } else {
                    in_circles as f64 / in_own as f64
                },
                max_overshoot_m,
            }
        })
        .collect()
}

/// The per-level table printed by `taxi-sim model fit`.
pub fn table(name: &str, fit: &FittedModel, reports: &[LevelReport]) -> String {
    let mut s = String::new();
    let total: usize = reports.iter().map(|r| r.circles).sum();
    let _ = writeln!(s, "{name}: {total} circles");
    let _ = writeln!(
        s,
        "{:>5} {:>7} {:>5} {:>7} {:>13} {:>9} {:>10} {:>13}",
        "level", "h_m", "parts", "circles", "radius_m", "coverage", "area_ratio", "overshoot_m"
    );
    for r in reports {
        let _ = writeln!(
            s,
            "{:>5} {:>7.2} {:>5} {:>7} {:>13} {:>8.2}% {:>10} {:>13.3}",
            r.level,
            r.height_m,
            r.parts,
            r.circles,
            format!("{:.3}-{:.3}", r.radius_range_m.0, r.radius_range_m.1),
            100.0 * r.coverage,
            if r.area_ratio.is_nan() {
                "-".to_string()
            } else {
                format!("{:.3}", r.area_ratio)
            },
            r.max_overshoot_m,
        );
    }
    match (fit.overshoot_target_m, fit.overshoot_target_met) {
        (Some(t), true) => {
            let _ = writeln!(s, "overshoot target {t:.3} m: met by every part");
        }
        (Some(t), false) => {
            let _ = writeln!(
                s,
                "overshoot target {t:.3} m: NOT met (circle budget or per-part limit reached)"
            );
        }
        (None, _) => {
            let _ = writeln!(s, "circle budget mode: least over-approximated area");
        }
    }
    s
}
