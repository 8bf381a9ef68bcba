//! The vehicle's collision model: circles tagged with a height level, checked against the ODMs.
//!
//! Each circle `(x, y, radius, level)` is in the vehicle frame (origin at the rear axle centre,
//! x forward, y left). A pose collides when, for some circle, the distance map of the circle's
//! level at the circle's centre is below `radius + safety` (FACTS.md; CARMEN
//! `obstacle_avoider_multi_height`). In banded mode a part is checked against every band from
//! its own level up. The check reports the *margin* `d - (r + safety)`: negative means collision.
//!
//! Far from everything a pose costs one lookup: if the bounding circle lies inside the map and
//! the distance at its centre exceeds its radius plus the safety distance plus one cell diagonal
//! (the slack of the cell lookup), no circle can be closer than its own radius plus the safety
//! distance (the distance map is 1-Lipschitz).

use nalgebra::{Isometry2, Point2};
use serde::{Deserialize, Serialize};

use crate::error::{MapError, Result};
use crate::odm::DistanceMaps;

/// One circle of a collision model, in the vehicle frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Circle {
    /// Centre, metres forward of the rear axle centre.
    pub x_m: f64,
    /// Centre, metres left of the vehicle's axis.
    pub y_m: f64,
    /// Radius in metres.
    pub radius_m: f64,
    /// Height level of the part this circle covers: the map it is checked against.
    pub level: usize,
}

/// A circle enclosing every circle of a model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingCircle {
    /// Centre in the vehicle frame.
    pub center: Point2<f64>,
    /// Radius in metres.
    pub radius_m: f64,
}

/// A vehicle as height-tagged circles, with the heights of interest of its levels.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionModel {
    circles: Vec<Circle>,
    level_heights_m: Vec<f64>,
    bounding: BoundingCircle,
}

impl CollisionModel {
    /// A model from its circles and the height of interest of each level (`level_heights_m[k]` =
    /// h_k, strictly increasing from h_0 >= 0). Every circle's level must exist.
    pub fn new(circles: Vec<Circle>, level_heights_m: Vec<f64>) -> Result<Self> {
        crate::levels::Levels::cumulative(level_heights_m.clone())?;
        if circles.is_empty() {
            return Err(MapError::invalid("collision model", "no circles"));
        }
        for (i, c) in circles.iter().enumerate() {
            if !(c.x_m.is_finite() && c.y_m.is_finite()) {
                return Err(MapError::invalid(
                    "circle centre",
                    format!("circle {i}: ({}, {}) is not finite", c.x_m, c.y_m),
                ));
            }
            if !(c.radius_m.is_finite() && c.radius_m > 0.0) {
                return Err(MapError::invalid(
                    "circle radius",
                    format!("circle {i}: radius {} must be > 0", c.radius_m),
                ));
            }
            if c.level >= level_heights_m.len() {
                return Err(MapError::invalid(
                    "circle level",
                    format!(
                        "circle {i}: level {} but the model has {} level(s)",
                        c.level,
                        level_heights_m.len()
                    ),
                ));
            }
        }
        let bounding = bounding_circle(&circles);
        Ok(CollisionModel {
            circles,
            level_heights_m,
            bounding,
        })
    }

    /// The circles.
    pub fn circles(&self) -> &[Circle] {
        &self.circles
    }
    /// Height of interest of each level, metres above the ground.
    pub fn level_heights_m(&self) -> &[f64] {
        &self.level_heights_m
    }
    /// Number of levels.
    pub fn level_count(&self) -> usize {
        self.level_heights_m.len()
    }
    /// A circle enclosing all circles (centred on their bounding box; not always the smallest).
    pub fn bounding_circle(&self) -> BoundingCircle {
        self.bounding
    }

    /// True when a point (vehicle frame, `height_m` above the ground) lies within `margin_m` of a
    /// circle whose part could have produced it: the LiDAR self-hit test. A part at level k has
    /// its underside at or above h_k, so points below h_k are never its own.
    pub fn is_self_hit(
        &self,
        point_in_vehicle: &Point2<f64>,
        height_m: f64,
        margin_m: f64,
    ) -> bool {
        let b = &self.bounding;
        if (point_in_vehicle - b.center).norm_squared() > (b.radius_m + margin_m).powi(2) {
            return false;
        }
        self.circles.iter().any(|c| {
            height_m >= self.level_heights_m[c.level]
                && (point_in_vehicle.x - c.x_m).powi(2) + (point_in_vehicle.y - c.y_m).powi(2)
                    <= (c.radius_m + margin_m).powi(2)
        })
    }

    /// Binds the model to a set of distance maps, checking once that their levels fit.
    pub fn checker<'a>(&'a self, maps: &'a DistanceMaps) -> Result<CollisionChecker<'a>> {
        if maps.level_count() < self.level_count() {
            return Err(MapError::LevelMismatch {
                model: self.level_count(),
                map: maps.level_count(),
            });
        }
        // Circles sorted by level so each group reads one distance map.
        let inv = 1.0 / maps.geometry().resolution_m();
        let mut order: Vec<usize> = (0..self.circles.len()).collect();
        order.sort_by_key(|&i| self.circles[i].level);
        let mut groups: Vec<CircleGroup<'a>> = Vec::new();
        for (k, &i) in order.iter().enumerate() {
            let level = self.circles[i].level;
            match groups.last_mut() {
                Some(g) if g.level == level => g.range.end = k + 1,
                _ => groups.push(CircleGroup {
                    level,
                    range: k..k + 1,
                    data: match maps.mode() {
                        crate::levels::LevelMode::Cumulative => {
                            LevelData::One(maps.levels()[level].grid().data())
                        }
                        crate::levels::LevelMode::Banded => {
                            LevelData::Bands(&maps.levels()[level..])
                        }
                    },
                }),
            }
        }
        Ok(CollisionChecker {
            model: self,
            maps,
            xs: order
                .iter()
                .map(|&i| (self.circles[i].x_m * inv) as f32)
                .collect(),
            ys: order
                .iter()
                .map(|&i| (self.circles[i].y_m * inv) as f32)
                .collect(),
            radii: order
                .iter()
                .map(|&i| self.circles[i].radius_m as f32)
                .collect(),
            order,
            groups,
        })
    }
}

fn bounding_circle(circles: &[Circle]) -> BoundingCircle {
    let (mut lo, mut hi) = (
        Point2::new(f64::INFINITY, f64::INFINITY),
        Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for c in circles {
        lo.x = lo.x.min(c.x_m - c.radius_m);
        lo.y = lo.y.min(c.y_m - c.radius_m);
        hi.x = hi.x.max(c.x_m + c.radius_m);
        hi.y = hi.y.max(c.y_m + c.radius_m);
    }
    let center = nalgebra::center(&lo, &hi);
    let radius_m = circles
        .iter()
        .map(|c| (Point2::new(c.x_m, c.y_m) - center).norm() + c.radius_m)
        .fold(0.0, f64::max);
    BoundingCircle { center, radius_m }
}

/// The result of checking one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseCheck {
    /// Smallest `d - (r + safety)` over the circles, metres; negative = collision. When
    /// `nearest_circle` is `None` the bounding-circle early out answered and this is a lower bound.
    pub margin_m: f32,
    /// The circle with the smallest margin, `None` when the early out answered.
    pub nearest_circle: Option<usize>,
    /// True when some circle is closer to an obstacle than its radius plus the safety distance.
    pub colliding: bool,
}

/// The result of checking a trajectory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrajectoryCheck {
    /// Index of the first colliding pose, if any.
    pub first_collision: Option<usize>,
    /// The smallest margin over all poses (a lower bound where the early out answered).
    pub min_margin_m: f32,
    /// The pose with the smallest margin.
    pub min_margin_pose: usize,
}

/// A collision model bound to distance maps whose levels fit it. Queries are infallible.
#[derive(Debug)]
pub struct CollisionChecker<'a> {
    model: &'a CollisionModel,
    maps: &'a DistanceMaps,
    /// Circle centres in cells (vehicle frame), sorted by level.
    xs: Vec<f32>,
    ys: Vec<f32>,
    radii: Vec<f32>,
    /// `order[k]` = index in the model of the k-th sorted circle.
    order: Vec<usize>,
    groups: Vec<CircleGroup<'a>>,
}

/// Consecutive sorted circles of one level and the distances they read.
#[derive(Debug)]
struct CircleGroup<'a> {
    level: usize,
    range: std::ops::Range<usize>,
    data: LevelData<'a>,
}

#[derive(Debug, Clone, Copy)]
enum LevelData<'a> {
    /// Cumulative: the level's own map.
    One(&'a [f32]),
    /// Banded: every band from the part's level up.
    Bands(&'a [crate::odm::DistanceMap]),
}

impl CollisionChecker<'_> {
    /// Checks one pose, with the bounding-circle early out.
    #[inline]
    pub fn check_pose(&self, world_from_vehicle: &Isometry2<f64>, safety_m: f32) -> PoseCheck {
        let b = self.model.bounding;
        let centre = world_from_vehicle * b.center;
        let slack = (self.maps.geometry().resolution_m() * std::f64::consts::SQRT_2) as f32;
        let bound = (b.radius_m as f32) + safety_m + slack;
        let d = match self.maps.mode() {
            crate::levels::LevelMode::Cumulative => self.maps.levels()[0].distance_at(&centre),
            crate::levels::LevelMode::Banded => self
                .maps
                .levels()
                .iter()
                .map(|m| m.distance_at(&centre))
                .fold(f32::INFINITY, f32::min),
        };
        // Outside the map reads 0, so the bound only holds when the bounding circle is inside it.
        let g = self.maps.geometry();
        let reach = b.radius_m + g.resolution_m();
        let (lo, hi) = (
            g.origin_m(),
            g.origin_m()
                + nalgebra::Vector2::new(g.width() as f64, g.height() as f64) * g.resolution_m(),
        );
        let inside = centre.x - reach >= lo.x
            && centre.x + reach < hi.x
            && centre.y - reach >= lo.y
            && centre.y + reach < hi.y;
        if inside && d > bound {
            return PoseCheck {
                margin_m: d - bound,
                nearest_circle: None,
                colliding: false,
            };
        }
        self.clearance(world_from_vehicle, safety_m)
    }

    /// Checks one pose circle by circle (no early out): the exact smallest margin and its circle.
    pub fn clearance(&self, world_from_vehicle: &Isometry2<f64>, safety_m: f32) -> PoseCheck {
        let g = self.maps.geometry();
        let inv = 1.0 / g.resolution_m();
        let (c, s) = (
            world_from_vehicle.rotation.re as f32,
            world_from_vehicle.rotation.im as f32,
        );
        // The pose's origin in cell units; circle offsets are pre-scaled to cells. f32 is exact to
        // 1e-4 cells over a 1050-cell window.
        let ox = ((world_from_vehicle.translation.x - g.origin_m().x) * inv) as f32;
        let oy = ((world_from_vehicle.translation.y - g.origin_m().y) * inv) as f32;
        let (w, h, width) = (g.width() as f32, g.height() as f32, g.width());
        let mut best = (f32::INFINITY, 0usize);
        // In chunks: first every cell index (branch-free arithmetic the compiler vectorises;
        // f32 -> i32 is one instruction, f32 -> usize is not), then the lookups, then the minimum.
        const CHUNK: usize = 16;
        let mut idx = [0i32; CHUNK];
        let mut margins = [0f32; CHUNK];
        for group in &self.groups {
            let mut start = group.range.start;
            while start < group.range.end {
                let n = CHUNK.min(group.range.end - start);
                let (xs, ys) = (&self.xs[start..start + n], &self.ys[start..start + n]);
                for k in 0..n {
                    let u = ox + c * xs[k] - s * ys[k];
                    let v = oy + s * xs[k] + c * ys[k];
                    // NaN fails every comparison and reads as outside, i.e. distance 0.
                    let inside = u >= 0.0 && v >= 0.0 && u < w && v < h;
                    idx[k] = if inside {
                        v as i32 * width as i32 + u as i32
                    } else {
                        -1
                    };
                }
                match group.data {
                    LevelData::One(data) => {
                        for k in 0..n {
                            margins[k] = if idx[k] < 0 {
                                0.0
                            } else {
                                data.get(idx[k] as usize).copied().unwrap_or(0.0)
                            };
                        }
                    }
                    LevelData::Bands(maps) => {
                        for k in 0..n {
                            margins[k] = if idx[k] < 0 {
                                0.0
                            } else {
                                maps.iter()
                                    .map(|m| m.grid().data()[idx[k] as usize])
                                    .fold(f32::INFINITY, f32::min)
                            };
                        }
                    }
                }
                for (m, r) in margins[..n].iter_mut().zip(&self.radii[start..start + n]) {
                    *m -= r;
                }
                let (k, m) =
                    margins[..n]
                        .iter()
                        .enumerate()
                        .fold(
                            (0, f32::INFINITY),
                            |a, (k, &m)| if m < a.1 { (k, m) } else { a },
                        );
                if m < best.0 {
                    best = (m, start + k);
                }
                start += n;
            }
        }
        let margin_m = best.0 - safety_m;
        PoseCheck {
            margin_m,
            nearest_circle: Some(self.order[best.1]),
            colliding: margin_m < 0.0,
        }
    }

    /// Checks every pose of a trajectory (with the early out), reporting the first collision and
    /// the smallest margin.
    pub fn check_trajectory(
        &self,
        world_from_vehicle: &[Isometry2<f64>],
        safety_m: f32,
    ) -> TrajectoryCheck {
        let mut out = TrajectoryCheck {
            first_collision: None,
            min_margin_m: f32::INFINITY,
            min_margin_pose: 0,
        };
        for (k, pose) in world_from_vehicle.iter().enumerate() {
            let check = self.check_pose(pose, safety_m);
            if check.colliding && out.first_collision.is_none() {
                out.first_collision = Some(k);
            }
            if check.margin_m < out.min_margin_m {
                out.min_margin_m = check.margin_m;
                out.min_margin_pose = k;
            }
        }
        out
    }

    /// The model.
    pub fn model(&self) -> &CollisionModel {
        self.model
    }
}
