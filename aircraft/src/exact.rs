//! The exact reference for a circle model: the vehicle's own part footprints, each at its level,
//! against the obstacle cells of the same distance maps.
//!
//! The circle check (`mapper::CollisionChecker`) says a pose collides when, for some circle,
//! the distance map of its level, read at the cell under the circle's centre, is below `radius +
//! safety`. The reference asks the question the circles approximate: is some part's footprint
//! closer than `safety` to the centre of an obstacle cell (a cell at distance 0 in the map its
//! level is checked against: its own level on cumulative maps, every band from its own up on
//! banded ones)? Only cells of the map are searched: compare poses whose vehicle lies inside it
//! (the circle check reads outside the map as an obstacle; the distance map does not see beyond it).
//!
//! Circles over-approximate the footprints, so the circles say "collision" where the parts would
//! pass (a *false alarm*). A model that covers every part (every fitted model: coverage is total
//! by construction) misses nothing except by the cell lookup: the circle check reads the
//! distance at the centre of the cell holding a circle's centre, up to half a cell diagonal
//! away, so its margin is at most the exact margin plus half a cell diagonal
//! ([`lookup_slack_m`]). A *miss* (the parts collide, the circles do not) can only lie within
//! that band: the property the tests check. The reference visits every obstacle cell within
//! reach of every part: slow (tens of microseconds to milliseconds), and meant to be.

use nalgebra::{Isometry2, Point2};

use crate::fit::FittedModel;
use crate::footprint::Footprint;
use mapper::{DistanceMaps, LevelMode};

/// One part's footprint at its level.
#[derive(Clone, Debug)]
struct ExactPart {
    level: usize,
    footprint: Footprint,
    lo: Point2<f64>,
    hi: Point2<f64>,
}

/// The vehicle's part footprints by level: the reference a circle model is measured against.
#[derive(Clone, Debug)]
pub struct ExactModel {
    parts: Vec<ExactPart>,
    labels: Vec<String>,
}

/// The exact check of one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactCheck {
    /// Smallest distance from a part's footprint to an obstacle cell centre of its maps, minus
    /// the safety distance, metres; negative = collision. Distances beyond the search reach are
    /// not looked for: the margin is then `reach - safety` (a lower bound).
    pub margin_m: f64,
    /// The part with the smallest margin (`None` when nothing was within reach).
    pub nearest_part: Option<usize>,
}

impl ExactCheck {
    /// True when a part is closer than the safety distance to an obstacle.
    pub fn colliding(&self) -> bool {
        self.margin_m < 0.0
    }
}

/// The largest amount by which the circle check's margin can exceed the exact margin for a model
/// that covers every part: half the diagonal of a cell.
pub fn lookup_slack_m(resolution_m: f64) -> f64 {
    resolution_m * std::f64::consts::FRAC_1_SQRT_2
}

impl ExactModel {
    /// Every part of a fitted model at its own level (including the parts its circles leave to a
    /// lower level's circles: they are still there, and still checked against their own level).
    pub fn from_fit(fit: &FittedModel) -> Self {
        let mut parts = Vec::new();
        let mut labels = Vec::new();
        for (level, l) in fit.levels.iter().enumerate() {
            for (f, label) in l.footprints.iter().zip(&l.labels) {
                let (lo, hi) = f.bounds();
                parts.push(ExactPart {
                    level,
                    footprint: f.clone(),
                    lo,
                    hi,
                });
                labels.push(label.clone());
            }
        }
        ExactModel { parts, labels }
    }

    /// Number of parts.
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    /// True when there are no parts.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// The `link#collision` label of part `i`.
    pub fn label(&self, i: usize) -> &str {
        &self.labels[i]
    }

    /// The exact margin of `world_from_vehicle`: obstacle cells are searched within `reach_m` of
    /// each part's footprint bounds.
    pub fn check(
        &self,
        maps: &DistanceMaps,
        world_from_vehicle: &Isometry2<f64>,
        safety_m: f64,
        reach_m: f64,
    ) -> ExactCheck {
        let g = maps.geometry();
        let res = g.resolution_m();
        let vehicle_from_world = world_from_vehicle.inverse();
        let mut best = (reach_m, None);
        for (i, part) in self.parts.iter().enumerate() {
            let levels = match maps.mode() {
                LevelMode::Cumulative => part.level..part.level + 1,
                LevelMode::Banded => part.level..maps.level_count(),
            };
            let (lo, hi) = world_bounds(world_from_vehicle, part.lo, part.hi, best.0);
            let (x0, y0) = g.cell_coords(&lo);
            let (x1, y1) = g.cell_coords(&hi);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let obstacle = match g.cell_at(x, y) {
                        None => false,
                        Some(cell) => {
                            let k = g.index(cell);
                            levels
                                .clone()
                                .any(|l| maps.levels()[l].grid().data()[k] <= 0.0)
                        }
                    };
                    if !obstacle {
                        continue;
                    }
                    let centre = g.origin_m()
                        + nalgebra::Vector2::new((x as f64 + 0.5) * res, (y as f64 + 0.5) * res);
                    let d = part.footprint.distance(&(vehicle_from_world * centre));
                    if d < best.0 {
                        best = (d, Some(i));
                    }
                }
            }
        }
        ExactCheck {
            margin_m: best.0 - safety_m,
            nearest_part: best.1,
        }
    }
}

/// World-frame axis-aligned bounds of the vehicle-frame box `lo..hi` grown by `grow_m`.
fn world_bounds(
    world_from_vehicle: &Isometry2<f64>,
    lo: Point2<f64>,
    hi: Point2<f64>,
    grow_m: f64,
) -> (Point2<f64>, Point2<f64>) {
    let corners = [
        Point2::new(lo.x, lo.y),
        Point2::new(lo.x, hi.y),
        Point2::new(hi.x, lo.y),
        Point2::new(hi.x, hi.y),
    ];
    let mut a = Point2::new(f64::INFINITY, f64::INFINITY);
    let mut b = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for c in corners {
        let w = world_from_vehicle * c;
        a = a.inf(&w);
        b = b.sup(&w);
    }
    let g = nalgebra::Vector2::new(grow_m, grow_m);
    (a - g, b + g)
}

/// How a circle model compares with the exact reference over a set of poses.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Poses checked.
    pub poses: usize,
    /// Poses the exact reference says collide.
    pub exact_collisions: usize,
    /// Poses the circles say collide.
    pub circle_collisions: usize,
    /// The circles say collision, the exact parts do not.
    pub false_alarms: usize,
    /// The exact parts collide, the circles do not.
    pub misses: usize,
    /// Misses whose exact margin is below minus the lookup slack (none for a covering model).
    pub misses_beyond_lookup: usize,
    /// Largest (circle margin - exact margin) over the poses where both were searched, metres.
    pub max_excess_m: f64,
}

impl Comparison {
    /// Adds one pose: the circle check's margin and the exact check.
    pub fn add(&mut self, circle_margin_m: f64, exact: &ExactCheck, slack_m: f64, reach_m: f64) {
        self.poses += 1;
        let (c, e) = (circle_margin_m < 0.0, exact.colliding());
        self.exact_collisions += e as usize;
        self.circle_collisions += c as usize;
        self.false_alarms += (c && !e) as usize;
        self.misses += (e && !c) as usize;
        self.misses_beyond_lookup += (e && !c && exact.margin_m < -slack_m) as usize;
        if exact.nearest_part.is_some() && exact.margin_m < reach_m {
            let excess = circle_margin_m - exact.margin_m;
            if self.poses == 1 || excess > self.max_excess_m {
                self.max_excess_m = excess;
            }
        }
    }

    /// Adds the counts of `other` (poses checked elsewhere) to these.
    pub fn absorb(&mut self, other: &Comparison) {
        let first = self.poses == 0;
        self.poses += other.poses;
        self.exact_collisions += other.exact_collisions;
        self.circle_collisions += other.circle_collisions;
        self.false_alarms += other.false_alarms;
        self.misses += other.misses;
        self.misses_beyond_lookup += other.misses_beyond_lookup;
        self.max_excess_m = if first {
            other.max_excess_m
        } else {
            self.max_excess_m.max(other.max_excess_m)
        };
    }

    /// False alarms per pose the exact reference finds clear (0 when there is none).
    pub fn false_alarm_rate(&self) -> f64 {
        let clear = self.poses - self.exact_collisions;
        if clear == 0 {
            0.0
        } else {
            self.false_alarms as f64 / clear as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::{SHIPPED_VEHICLES, Vehicle};
    use crate::{FitOptions, fit::FittedModel};
    use mapper::edt::EdtScratch;
    use mapper::{DistanceMap, GridGeometry};
    use proptest::prelude::*;

    /// Maps of `levels` levels over a 100 m square at 0.2 m: obstacle cells where `hash(cell)`
    /// falls under `density`, each level's obstacles a subset of the level below (cumulative
    /// maps hold, on a lower level, everything a higher one does).
    fn maps(levels: usize, density: f64, seed: u64, mode: LevelMode) -> DistanceMaps {
        let g = GridGeometry::new(Point2::new(-50.0, -50.0), 0.2, 500, 500).unwrap();
        let mut s = EdtScratch::default();
        let hash = |i: usize, l: usize| {
            let mut z = (i as u64) ^ seed.rotate_left(17) ^ ((l as u64) << 40);
            z = z.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            z ^= z >> 31;
            z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            (z >> 11) as f64 / (1u64 << 53) as f64
        };
        let v = (0..levels)
            .map(|l| {
                DistanceMap::compute(g, 30.0, |i| (0..=l).all(|j| hash(i, j) < density), &mut s)
            })
            .collect();
        DistanceMaps::new(mode, v).unwrap()
    }

    /// The vehicle's fit with a circle budget; a budget below one circle per separate part
    /// (which the fitter refuses) is raised to the smallest it accepts.
    fn fitted(name: &str, budget: Option<usize>, banded: bool) -> FittedModel {
        let v = Vehicle::shipped(name).unwrap();
        let mut options = FitOptions {
            max_circles: budget,
            banded_maps: banded,
            ..v.spec.fit.clone()
        };
        loop {
            match v.fit_with(&v.spec.heights_of_interest_m, &options) {
                Ok(fit) => return fit,
                Err(e) => match options.max_circles {
                    Some(n) if n < 400 => options.max_circles = Some(n + 1),
                    _ => panic!("{name}: {e}"),
                },
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, .. ProptestConfig::default() })]

        /// A covering model's margin exceeds the exact margin by at most the lookup slack, so
        /// it misses nothing beyond it, for every shipped vehicle, budget, map mode and pose.
        #[test]
        fn a_covering_model_misses_nothing_beyond_the_cell_lookup(
            vehicle in 0..SHIPPED_VEHICLES.len(),
            budget in prop_oneof![Just(None), (1usize..80).prop_map(Some)],
            banded in any::<bool>(),
            density in 0.0005f64..0.02,
            seed in any::<u64>(),
            poses in proptest::collection::vec((-6.0f64..6.0, -6.0f64..6.0, -3.2f64..3.2), 8),
            safety in 0.0f64..0.8,
        ) {
            let fit = fitted(SHIPPED_VEHICLES[vehicle], budget, banded);
            let mode = if banded { LevelMode::Banded } else { LevelMode::Cumulative };
            let m = maps(fit.levels.len(), density, seed, mode);
            let exact = ExactModel::from_fit(&fit);
            let checker = fit.model.checker(&m).unwrap();
            let slack = lookup_slack_m(0.2);
            let reach = 3.0;
            let mut cmp = Comparison::default();
            for (x, y, yaw) in poses {
                let pose = Isometry2::new(nalgebra::Vector2::new(x, y), yaw);
                let circles = checker.clearance(&pose, safety as f32).margin_m as f64;
                let e = exact.check(&m, &pose, safety, reach);
                cmp.add(circles, &e, slack, reach);
                // The margin inequality (f32 lookups: 1e-4 m of rounding).
                if e.margin_m < reach - safety {
                    prop_assert!(circles <= e.margin_m + slack + 1e-4,
                        "circles {circles} exact {:?} at {pose:?}", e);
                }
            }
            prop_assert_eq!(cmp.misses_beyond_lookup, 0);
        }
    }

    #[test]
    fn a_model_that_leaves_a_part_uncovered_misses_it() {
        // A made-up model that stops short of the car's front: one circle at the rear axle. An
        // obstacle just ahead of the bumper is a miss for it and not for the fitted model.
        let fit = fitted("iara_car", Some(5), false);
        let short = mapper::CollisionModel::new(
            vec![mapper::Circle {
                x_m: 0.0,
                y_m: 0.0,
                radius_m: 1.0,
                level: 0,
            }],
            vec![0.0],
        )
        .unwrap();
        let g = GridGeometry::new(Point2::new(-20.0, -20.0), 0.2, 200, 200).unwrap();
        let mut s = EdtScratch::default();
        // One obstacle cell 0.1 m ahead of the car's front bumper.
        let front_x = fit.levels[0]
            .footprints
            .iter()
            .map(|f| f.bounds().1.x)
            .fold(f64::NEG_INFINITY, f64::max);
        let target = g.index_of(&Point2::new(front_x + 0.1, 0.0)).unwrap();
        let m = DistanceMaps::new(
            LevelMode::Cumulative,
            vec![DistanceMap::compute(g, 30.0, |i| i == target, &mut s)],
        )
        .unwrap();
        let exact = ExactModel::from_fit(&fit);
        let pose = Isometry2::identity();
        let e = exact.check(&m, &pose, 0.2, 3.0);
        assert!(e.colliding(), "{e:?}");
        let short_margin = short.checker(&m).unwrap().clearance(&pose, 0.2).margin_m;
        assert!(short_margin > 0.0, "{short_margin}");
        let fitted_margin = fit
            .model
            .checker(&m)
            .unwrap()
            .clearance(&pose, 0.2)
            .margin_m;
        assert!(fitted_margin < 0.0, "{fitted_margin}");
    }

    #[test]
    fn far_from_obstacles_the_margin_is_the_search_bound_and_near_one_it_is_exact() {
        let fit = fitted("praetor600", None, false);
        let g = GridGeometry::new(Point2::new(-40.0, -40.0), 0.2, 400, 400).unwrap();
        let mut s = EdtScratch::default();
        let empty = DistanceMaps::new(
            LevelMode::Cumulative,
            (0..fit.levels.len())
                .map(|_| DistanceMap::compute(g, 30.0, |_| false, &mut s))
                .collect(),
        )
        .unwrap();
        let exact = ExactModel::from_fit(&fit);
        let e = exact.check(&empty, &Isometry2::identity(), 0.3, 2.0);
        assert_eq!(e.nearest_part, None);
        assert!((e.margin_m - 1.7).abs() < 1e-12);
        // One level-0 obstacle cell straight behind the tail: its distance is the gap between
        // the rearmost level-0 footprint and the cell centre.
        let behind_x = fit.levels[0]
            .footprints
            .iter()
            .map(|f| f.bounds().0.x)
            .fold(f64::INFINITY, f64::min);
        let p = Point2::new(behind_x - 1.0, 0.1);
        let k = g.index_of(&p).unwrap();
        let c = g.center_of(g.cell_of_index(k).unwrap());
        let one = DistanceMaps::new(
            LevelMode::Cumulative,
            (0..fit.levels.len())
                .map(|l| DistanceMap::compute(g, 30.0, |i| l == 0 && i == k, &mut s))
                .collect(),
        )
        .unwrap();
        let e = exact.check(&one, &Isometry2::identity(), 0.0, 2.0);
        let want = fit.levels[0]
            .footprints
            .iter()
            .map(|f| f.distance(&c))
            .fold(f64::INFINITY, f64::min);
        assert!((e.margin_m - want).abs() < 1e-12, "{e:?} {want}");
    }
}
