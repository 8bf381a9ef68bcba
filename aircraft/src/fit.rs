//! Fitting the height-tagged circle model: parts are sorted into levels by their undersides, and
//! each level's footprint is covered with circles. Pure and deterministic.
//!
//! A part belongs to the highest level whose height of interest is at or below its underside.
//! Per level, footprints lying inside another footprint are dropped (a wheel under the body), and
//! so, for cumulative maps, are those lying inside a lower level's footprint (the cabin on the body).
//! Every remaining footprint (a *piece*) is covered on its own: a disc by itself; a convex polygon
//! is cut along the long and short axes of its smallest enclosing rectangle into `k x m` cells,
//! each covered by the smallest circle enclosing the cell. Every point of a cell is inside that
//! circle (a disc is convex and contains the cell's vertices), so coverage is total by
//! construction. Which split each piece gets is chosen either per piece (fewest circles whose
//! overshoot stays within `max_overshoot_m`) or over the whole model (least area outside the
//! pieces within `max_circles`, an exact multiple-choice knapsack).

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::footprint::{ConvexPolygon, Disc, EPS_M, Footprint, min_enclosing_disc};
use crate::shapes::Part;

/// Overshoot target used when neither option is given, metres.
pub const DEFAULT_MAX_OVERSHOOT_M: f64 = 0.15;
/// Most circles tried on one piece.
const MAX_CIRCLES_PER_PIECE: usize = 48;
/// Most cuts across a piece's short axis.
const MAX_ACROSS: usize = 3;
/// Points sampled on a circle's boundary to estimate its overshoot.
const OVERSHOOT_SAMPLES: usize = 64;

/// How hard to fit. Either bound may be given; with both, the overshoot target is tried first
/// and the circle budget wins if the target needs more circles.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitOptions {
    /// Most circles in the whole model, all levels together. Default: no limit.
    #[serde(default)]
    pub max_circles: Option<usize>,
    /// Largest distance, metres, that a circle may reach beyond the footprint of the part it
    /// covers. Default: [`DEFAULT_MAX_OVERSHOOT_M`] (0.15 m) when `max_circles` is not given,
    /// none when it is (the budget is then spent to minimise the over-approximated area).
    #[serde(default)]
    pub max_overshoot_m: Option<f64>,
    /// Whether the model will be checked against *banded* maps. Default false (cumulative maps,
    /// the thesis' choice): a part whose footprint lies inside a lower level's part is then not
    /// covered, because the lower level's map already holds every obstacle that could reach it.
    #[serde(default)]
    pub banded_maps: bool,
}

/// The parts of one level and their footprints.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelFootprint {
    /// Height of interest h_k of the level, metres.
    pub height_m: f64,
    /// Footprints of every part of the level (their union is the level's footprint).
    pub footprints: Vec<Footprint>,
    /// `link#collision` label of each footprint.
    pub labels: Vec<String>,
    /// Indices into `footprints` of the pieces that were covered (the others lie inside them).
    pub covered: Vec<usize>,
    /// Indices into `footprints` of the parts left to a lower level's circles (cumulative maps:
    /// their footprint lies inside a lower level's part). The others are this level's own.
    pub below: Vec<usize>,
}

/// A fitted model with the footprints it was fitted to.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedModel {
    /// The circles and heights, ready for the mapper's collision checks.
    pub model: mapper::CollisionModel,
    /// Per level, its footprints.
    pub levels: Vec<LevelFootprint>,
    /// The overshoot target in force, metres (`None` in pure budget mode).
    pub overshoot_target_m: Option<f64>,
    /// False when the target could not be met (more circles needed than allowed or tried).
    pub overshoot_target_met: bool,
}

/// The level of a part whose lowest point is `underside_m` above the ground: the highest level
/// whose height is at or below it (level 0 for parts touching or below the ground).
pub fn level_of(underside_m: f64, heights_m: &[f64]) -> usize {
    heights_m
        .iter()
        .rposition(|h| *h <= underside_m + EPS_M)
        .unwrap_or(0)
}

/// Candidate heights of interest from a vehicle's geometry: the undersides of its parts off the
/// ground (above `min_m`), each lowered by `margin_m` (a level must sit just under the parts it
/// lets pass over an obstacle, as the thesis' 1.1 m under the Praetor's 1.2 m wing root) and
/// rounded down to 5 cm; undersides that give the same candidate count once. Sorted, without 0.
pub fn proposed_heights(parts: &[Part], min_m: f64, margin_m: f64) -> Vec<f64> {
    let mut out: Vec<f64> = parts
        .iter()
        .map(Part::underside_m)
        .filter(|u| *u > min_m)
        .map(|u| ((u - margin_m) * 20.0 + 1e-9).floor() / 20.0)
        .filter(|h| *h > 0.0)
        .collect();
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    out
}

/// Checks heights of interest: h_0 = 0, strictly increasing, finite.
pub fn check_heights(heights_m: &[f64]) -> std::result::Result<(), String> {
    match heights_m.first() {
        None => return Err("at least one height of interest (h_0 = 0) is needed".into()),
        Some(h0) if *h0 != 0.0 => return Err(format!("h_0 must be 0, got {h0}")),
        _ => {}
    }
    for (k, w) in heights_m.windows(2).enumerate() {
        if !(w[1].is_finite() && w[1] > w[0]) {
            return Err(format!(
                "h_{} = {} must be finite and above h_{k} = {}",
                k + 1,
                w[1],
                w[0]
            ));
        }
    }
    Ok(())
}

/// One way of covering a piece.
#[derive(Clone, Debug)]
struct Cover {
    circles: Vec<Disc>,
    /// Sum over circles of the circle's area outside the piece, m^2.
    outside_m2: f64,
    /// Largest distance of a circle point from the piece, metres (sampled).
    overshoot_m: f64,
}

/// Largest distance from the piece of a point of the disc (sampled on its boundary; the distance
/// to a convex set is convex, so its maximum over a disc is on the boundary).
fn disc_overshoot(disc: &Disc, piece: &ConvexPolygon) -> f64 {
    (0..OVERSHOOT_SAMPLES)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / OVERSHOOT_SAMPLES as f64;
            let p = disc.center + Vector2::new(t.cos(), t.sin()) * disc.radius_m;
            piece.distance(&p)
        })
        .fold(0.0, f64::max)
}

/// The ways of covering a convex polygon with at most `cap` circles, fewest circles first.
fn polygon_covers(poly: &ConvexPolygon, cap: usize) -> Vec<Cover> {
    let rect = poly.min_area_rect();
    let u = rect.long_axis;
    let v = Vector2::new(-u.y, u.x);
    let (cu, cv) = (u.dot(&rect.center.coords), v.dot(&rect.center.coords));
    let (u0, len) = (cu - rect.half_length_m, 2.0 * rect.half_length_m);
    let (v0, wid) = (cv - rect.half_width_m, 2.0 * rect.half_width_m);
    let mut covers = Vec::new();
    for m in 1..=MAX_ACROSS.min(cap) {
        for k in 1..=cap / m {
            let mut circles = Vec::with_capacity(k * m);
            for i in 0..k {
                let (a, b) = (
                    u0 + len * i as f64 / k as f64,
                    u0 + len * (i + 1) as f64 / k as f64,
                );
                let Some(slab) = (if k == 1 {
                    Some(poly.clone())
                } else {
                    poly.clip(&u, b).and_then(|p| p.clip(&-u, -a))
                }) else {
                    continue;
                };
                for j in 0..m {
                    let (c, d) = (
                        v0 + wid * j as f64 / m as f64,
                        v0 + wid * (j + 1) as f64 / m as f64,
                    );
                    let cell = if m == 1 {
                        Some(slab.clone())
                    } else {
                        slab.clip(&v, d).and_then(|p| p.clip(&-v, -c))
                    };
                    if let Some(cell) = cell {
                        circles.push(min_enclosing_disc(cell.vertices()));
                    }
                }
            }
            let outside_m2 = circles
                .iter()
                .map(|c| {
                    std::f64::consts::PI * c.radius_m * c.radius_m
                        - poly.disc_intersection_area_m2(c)
                })
                .sum();
            let overshoot_m = circles
                .iter()
                .map(|c| disc_overshoot(c, poly))
                .fold(0.0, f64::max);
            covers.push(Cover {
                circles,
                outside_m2,
                overshoot_m,
            });
        }
    }
    covers.sort_by(|a, b| {
        a.circles
            .len()
            .cmp(&b.circles.len())
            .then(a.outside_m2.total_cmp(&b.outside_m2))
    });
    covers
}

fn piece_covers(piece: &Footprint, cap: usize) -> Vec<Cover> {
    match piece {
        Footprint::Disc(d) => vec![Cover {
            circles: vec![Disc {
                center: d.center,
                radius_m: d.radius_m + EPS_M,
            }],
            outside_m2: 0.0,
            overshoot_m: 0.0,
        }],
        Footprint::Polygon(p) => polygon_covers(p, cap),
    }
}

/// Per piece, the cover with the fewest circles within `target_m` (ties: least area outside);
/// where none is within, the one with the least overshoot. Returns the choice and whether all met it.
fn choose_by_overshoot(covers: &[Vec<Cover>], target_m: f64) -> (Vec<usize>, bool) {
    let mut met = true;
    let choice = covers
        .iter()
        .map(
            |cs| match cs.iter().position(|c| c.overshoot_m <= target_m) {
                Some(i) => i,
                None => {
                    met = false;
                    let mut best = 0;
                    for (i, c) in cs.iter().enumerate() {
                        if c.overshoot_m < cs[best].overshoot_m {
                            best = i;
                        }
                    }
                    best
                }
            },
        )
        .collect();
    (choice, met)
}

/// The choice of one cover per piece with at most `budget` circles in all that minimises the
/// summed area outside the pieces (dynamic programming over the budget).
fn choose_by_budget(covers: &[Vec<Cover>], budget: usize) -> Result<Vec<usize>> {
    let needed: usize = covers
        .iter()
        .map(|cs| cs.iter().map(|c| c.circles.len()).min().unwrap_or(0))
        .sum();
    if needed > budget {
        return Err(Error::Fit(format!(
            "max_circles = {budget} is below the {needed} circles needed to cover every separate part once"
        )));
    }
    // best[p][b]: least cost of pieces 0..p with at most b circles; pick[p][b]: cover of piece p-1.
    let n = covers.len();
    let mut best = vec![vec![0.0f64; budget + 1]; n + 1];
    let mut pick = vec![vec![usize::MAX; budget + 1]; n + 1];
    for p in 0..n {
        for b in 0..=budget {
            let mut cost = f64::INFINITY;
            for (i, c) in covers[p].iter().enumerate() {
                let used = c.circles.len();
                if used <= b {
                    let total = best[p][b - used] + c.outside_m2;
                    if total < cost - 1e-12 {
                        cost = total;
                        pick[p + 1][b] = i;
                    }
                }
            }
            best[p + 1][b] = cost;
        }
    }
    let mut choice = vec![0; n];
    let mut b = budget;
    for p in (0..n).rev() {
        let i = pick[p + 1][b];
        let used = covers[p]
            .get(i)
            .map(|c| c.circles.len())
            .ok_or_else(|| Error::Fit("no feasible cover within the budget".into()))?;
        choice[p] = i;
        b -= used;
    }
    Ok(choice)
}

/// Fits circles to vehicle-frame parts for the given heights of interest (h_0 = 0 < h_1 < ...).
pub fn fit_parts(parts: &[Part], heights_m: &[f64], options: &FitOptions) -> Result<FittedModel> {
    check_heights(heights_m).map_err(Error::Fit)?;
    if options.max_circles == Some(0) {
        return Err(Error::Fit("max_circles must be at least 1".into()));
    }
    if let Some(t) = options.max_overshoot_m
        && !(t.is_finite() && t > 0.0)
    {
        return Err(Error::Fit(format!("max_overshoot_m = {t} must be > 0")));
    }
    if parts.is_empty() {
        return Err(Error::Fit("no parts to fit".into()));
    }
    let mut levels: Vec<LevelFootprint> = heights_m
        .iter()
        .map(|h| LevelFootprint {
            height_m: *h,
            footprints: Vec::new(),
            labels: Vec::new(),
            covered: Vec::new(),
            below: Vec::new(),
        })
        .collect();
    for part in parts {
        let level = &mut levels[level_of(part.underside_m(), heights_m)];
        level.footprints.push(part.footprint());
        level
            .labels
            .push(format!("{}#{}", part.link, part.collision_index));
    }
    for k in 0..levels.len() {
        let (lower, rest) = levels.split_at_mut(k);
        let level = &mut rest[0];
        let f = &level.footprints;
        level.below = (0..f.len())
            .filter(|&i| {
                !options.banded_maps
                    && lower
                        .iter()
                        .flat_map(|l| &l.footprints)
                        .any(|g| g.contains_footprint(&f[i]))
            })
            .collect();
        level.covered = (0..f.len())
            .filter(|&i| {
                let inside_same = (0..f.len()).any(|j| {
                    j != i
                        && f[j].contains_footprint(&f[i])
                        && (j < i || !f[i].contains_footprint(&f[j]))
                });
                !(inside_same || level.below.contains(&i))
            })
            .collect();
    }
    let pieces: Vec<(usize, &Footprint)> = levels
        .iter()
        .enumerate()
        .flat_map(|(k, l)| l.covered.iter().map(move |&i| (k, &l.footprints[i])))
        .collect();
    let cap = options
        .max_circles
        .unwrap_or(MAX_CIRCLES_PER_PIECE)
        .min(MAX_CIRCLES_PER_PIECE);
    let covers: Vec<Vec<Cover>> = pieces.iter().map(|(_, f)| piece_covers(f, cap)).collect();
    let target = match (options.max_circles, options.max_overshoot_m) {
        (_, Some(t)) => Some(t),
        (None, None) => Some(DEFAULT_MAX_OVERSHOOT_M),
        (Some(_), None) => None,
    };
    let (choice, met) = match (target, options.max_circles) {
        (Some(t), budget) => {
            let (choice, met) = choose_by_overshoot(&covers, t);
            let total: usize = choice
                .iter()
                .zip(&covers)
                .map(|(&i, cs)| cs[i].circles.len())
                .sum();
            match budget {
                Some(b) if total > b => (choose_by_budget(&covers, b)?, false),
                _ => (choice, met),
            }
        }
        (None, Some(b)) => (choose_by_budget(&covers, b)?, true),
        (None, None) => (
            choose_by_overshoot(&covers, DEFAULT_MAX_OVERSHOOT_M).0,
            true,
        ),
    };
    let mut circles = Vec::new();
    for ((level, _), (cs, &i)) in pieces.iter().zip(covers.iter().zip(&choice)) {
        for d in &cs[i].circles {
            circles.push(mapper::Circle {
                x_m: d.center.x,
                y_m: d.center.y,
                radius_m: d.radius_m,
                level: *level,
            });
        }
    }
    let model =
        mapper::CollisionModel::new(circles, heights_m.to_vec()).map_err(|error| Error::Model {
            context: "fitted model".into(),
            error,
        })?;
    Ok(FittedModel {
        model,
        levels,
        overshoot_target_m: target,
        overshoot_target_met: met,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;

    fn point(x: f64, y: f64) -> Point2<f64> {
        Point2::new(x, y)
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> ConvexPolygon {
        ConvexPolygon::hull(&[point(x0, y0), point(x1, y0), point(x1, y1), point(x0, y1)])
            .expect("rect")
    }

    #[test]
    fn levels_follow_undersides() {
        let h = [0.0, 0.7];
        assert_eq!(level_of(0.0, &h), 0);
        assert_eq!(level_of(0.69, &h), 0);
        assert_eq!(level_of(0.7, &h), 1);
        assert_eq!(level_of(5.0, &h), 1);
        assert_eq!(level_of(-0.1, &h), 0);
    }

    #[test]
    fn heights_are_checked() {
        assert!(check_heights(&[0.0, 0.7]).is_ok());
        assert!(check_heights(&[]).is_err());
        assert!(check_heights(&[0.1]).is_err());
        assert!(check_heights(&[0.0, 0.7, 0.7]).is_err());
        assert!(check_heights(&[0.0, f64::NAN]).is_err());
    }

    #[test]
    fn car_body_with_five_circles_is_the_circumscribed_split() {
        let body = rect(-0.96, -0.903, 3.475, 0.903);
        let covers = polygon_covers(&body, 10);
        let five = covers
            .iter()
            .find(|c| c.circles.len() == 5)
            .expect("a 5-circle cover");
        let s = 4.435 / 5.0;
        let r = (s * s + 1.806f64.powi(2)).sqrt() / 2.0;
        assert!(five.circles.iter().all(|c| (c.radius_m - r).abs() < 1e-6));
        // The end circles reach furthest past the body: r - s/2 beyond its ends.
        assert!((five.overshoot_m - (r - s / 2.0)).abs() < 1e-3);
    }

    #[test]
    fn budget_choice_is_optimal_on_two_pieces() {
        let covers = vec![
            polygon_covers(&rect(0.0, 0.0, 10.0, 1.0), 10),
            polygon_covers(&rect(0.0, 5.0, 2.0, 6.0), 10),
        ];
        let choice = choose_by_budget(&covers, 6).expect("feasible");
        let used: usize = choice
            .iter()
            .zip(&covers)
            .map(|(&i, c)| c[i].circles.len())
            .sum();
        assert!(used <= 6);
        // The long piece gets most of the budget.
        assert!(covers[0][choice[0]].circles.len() >= 4);
        assert!(choose_by_budget(&covers, 1).is_err());
    }
}
