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
            avx2: avx2_usable(maps.geometry()),
        })
    }
}

/// Whether the AVX2 path can serve maps of geometry `g` on this CPU.
fn avx2_usable(g: &crate::grid::GridGeometry) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        avx2::usable(g.width(), g.height())
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = g;
        false
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
    /// Whether [`CollisionChecker::clearance`] takes the AVX2 path.
    avx2: bool,
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

/// A pose in the distance maps' cell units, and the maps' size.
#[derive(Clone, Copy, Debug)]
struct Frame {
    /// cos and sin of the heading.
    c: f32,
    s: f32,
    /// The pose's origin, cells from the maps' origin.
    ox: f32,
    oy: f32,
    /// Width and height in cells, as floats and the width as an integer.
    w: f32,
    h: f32,
    width: usize,
}

/// The smallest `d - r` over one group's circles (centres in cells, vehicle frame) and its index
/// in the group (the first on ties), reading the distance of cell index `i` with `distance(i)`;
/// a centre outside the maps reads 0.
#[inline]
fn group_min(
    xs: &[f32],
    ys: &[f32],
    radii: &[f32],
    f: &Frame,
    distance: impl Fn(usize) -> f32,
) -> (f32, usize) {
    let mut best = (f32::INFINITY, 0usize);
    for (k, ((&x, &y), &r)) in xs.iter().zip(ys).zip(radii).enumerate() {
        let u = f.ox + f.c * x - f.s * y;
        let v = f.oy + f.s * x + f.c * y;
        // NaN fails every comparison and reads as outside, i.e. distance 0.
        let d = if u >= 0.0 && v >= 0.0 && u < f.w && v < f.h {
            distance(v as usize * f.width + u as usize)
        } else {
            0.0
        };
        let m = d - r;
        if m < best.0 {
            best = (m, k);
        }
    }
    best
}

/// [`group_min`] over one distance map, eight circles at a time with AVX2 gathers. The project's
/// only unsafe code: intrinsics behind a runtime feature check, and a gather whose every active
/// lane is an index the bounds checks above it proved inside `data`.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx2 {
    use super::Frame;
    use std::arch::x86_64::*;

    /// Whether this CPU runs [`group_min`] (AVX2), and `data` is a whole `w x h` map whose cell
    /// indices fit an i32 and whose sides f32 holds exactly.
    pub(super) fn usable(width: usize, height: usize) -> bool {
        is_x86_feature_detected!("avx2")
            && width < (1 << 24)
            && height < (1 << 24)
            && width
                .checked_mul(height)
                .is_some_and(|n| n < i32::MAX as usize)
    }

    /// As the scalar `group_min` over `data`, bit for bit.
    pub(super) fn group_min(
        xs: &[f32],
        ys: &[f32],
        radii: &[f32],
        data: &[f32],
        f: &Frame,
    ) -> (f32, usize) {
        let read = |i: usize| data.get(i).copied().unwrap_or(0.0);
        if data.len() != f.width * (f.h as usize) || !is_x86_feature_detected!("avx2") {
            return super::group_min(xs, ys, radii, f, read);
        }
        let full = xs.len().min(ys.len()).min(radii.len()) / 8 * 8;
        // SAFETY: AVX2 is present (checked just above); `eight` reads `full` elements of each
        // slice, within their lengths, and gathers only lanes inside the w x h map of `data`.
        let (m, k) = unsafe { eight(&xs[..full], &ys[..full], &radii[..full], data, f) };
        let (rm, rk) = super::group_min(&xs[full..], &ys[full..], &radii[full..], f, read);
        if rm < m { (rm, full + rk) } else { (m, k) }
    }

    /// The first `xs.len()` (a multiple of 8) circles, 8 lanes at a time; the same arithmetic
    /// in the same order as the scalar loop (no fused multiply-add), so the same cells.
    #[target_feature(enable = "avx2")]
    unsafe fn eight(
        xs: &[f32],
        ys: &[f32],
        radii: &[f32],
        data: &[f32],
        f: &Frame,
    ) -> (f32, usize) {
        let (c, s) = (_mm256_set1_ps(f.c), _mm256_set1_ps(f.s));
        let (ox, oy) = (_mm256_set1_ps(f.ox), _mm256_set1_ps(f.oy));
        let (w, h, zero) = (
            _mm256_set1_ps(f.w),
            _mm256_set1_ps(f.h),
            _mm256_setzero_ps(),
        );
        let width = _mm256_set1_epi32(f.width as i32);
        let mut best_m = _mm256_set1_ps(f32::INFINITY);
        let mut best_k = _mm256_setzero_si256();
        let mut lane_k = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        for k in (0..xs.len()).step_by(8) {
            // SAFETY: k + 8 <= len of each slice (the caller passes multiples of 8).
            let (x, y, r) = unsafe {
                (
                    _mm256_loadu_ps(xs.as_ptr().add(k)),
                    _mm256_loadu_ps(ys.as_ptr().add(k)),
                    _mm256_loadu_ps(radii.as_ptr().add(k)),
                )
            };
            let u = _mm256_sub_ps(_mm256_add_ps(ox, _mm256_mul_ps(c, x)), _mm256_mul_ps(s, y));
            let v = _mm256_add_ps(_mm256_add_ps(oy, _mm256_mul_ps(s, x)), _mm256_mul_ps(c, y));
            let inside = _mm256_and_ps(
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero),
                    _mm256_cmp_ps::<_CMP_GE_OQ>(v, zero),
                ),
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_LT_OQ>(u, w),
                    _mm256_cmp_ps::<_CMP_LT_OQ>(v, h),
                ),
            );
            let idx = _mm256_add_epi32(
                _mm256_mullo_epi32(_mm256_cvttps_epi32(v), width),
                _mm256_cvttps_epi32(u),
            );
            // SAFETY: an active lane has 0 <= u < w and 0 <= v < h, so its index is at most
            // (h - 1) * width + w - 1 < data.len(); inactive lanes read nothing and give 0.
            let d = unsafe { _mm256_mask_i32gather_ps::<4>(zero, data.as_ptr(), idx, inside) };
            let m = _mm256_sub_ps(d, r);
            let lower = _mm256_cmp_ps::<_CMP_LT_OQ>(m, best_m);
            best_m = _mm256_blendv_ps(best_m, m, lower);
            best_k = _mm256_blendv_epi8(best_k, lane_k, _mm256_castps_si256(lower));
            lane_k = _mm256_add_epi32(lane_k, _mm256_set1_epi32(8));
        }
        let (mut m, mut k) = ([0f32; 8], [0i32; 8]);
        // SAFETY: both arrays hold 8 lanes.
        unsafe {
            _mm256_storeu_ps(m.as_mut_ptr(), best_m);
            _mm256_storeu_si256(k.as_mut_ptr().cast(), best_k);
        }
        // The smallest margin; on ties the first circle, as the scalar loop.
        let mut best = (f32::INFINITY, 0usize);
        for (&m, &k) in m.iter().zip(&k) {
            let k = k as usize;
            if m < best.0 || (m == best.0 && k < best.1) {
                best = (m, k);
            }
        }
        best
    }
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
    /// On a CPU with AVX2, eight circles at a time (the same numbers as
    /// [`CollisionChecker::clearance_portable`], bit for bit: tested).
    pub fn clearance(&self, world_from_vehicle: &Isometry2<f64>, safety_m: f32) -> PoseCheck {
        self.clearance_with(world_from_vehicle, safety_m, self.avx2)
    }

    /// Whether [`CollisionChecker::clearance`] checks eight circles at a time (AVX2) here.
    pub fn vectorised(&self) -> bool {
        self.avx2
    }

    /// [`CollisionChecker::clearance`] one circle at a time, on any CPU: the straightforward way,
    /// for benchmarks and tests.
    pub fn clearance_portable(
        &self,
        world_from_vehicle: &Isometry2<f64>,
        safety_m: f32,
    ) -> PoseCheck {
        self.clearance_with(world_from_vehicle, safety_m, false)
    }

    fn clearance_with(
        &self,
        world_from_vehicle: &Isometry2<f64>,
        safety_m: f32,
        avx2: bool,
    ) -> PoseCheck {
        let g = self.maps.geometry();
        let inv = 1.0 / g.resolution_m();
        // The pose's origin in cell units; circle offsets are pre-scaled to cells. f32 is exact to
        // 1e-4 cells over a 1050-cell window.
        let frame = Frame {
            c: world_from_vehicle.rotation.re as f32,
            s: world_from_vehicle.rotation.im as f32,
            ox: ((world_from_vehicle.translation.x - g.origin_m().x) * inv) as f32,
            oy: ((world_from_vehicle.translation.y - g.origin_m().y) * inv) as f32,
            w: g.width() as f32,
            h: g.height() as f32,
            width: g.width(),
        };
        let mut best = (f32::INFINITY, 0usize);
        for group in &self.groups {
            let range = group.range.clone();
            let (xs, ys, radii) = (
                &self.xs[range.clone()],
                &self.ys[range.clone()],
                &self.radii[range.clone()],
            );
            let (m, k) = match group.data {
                #[cfg(target_arch = "x86_64")]
                LevelData::One(data) if avx2 => avx2::group_min(xs, ys, radii, data, &frame),
                LevelData::One(data) => group_min(xs, ys, radii, &frame, |i| {
                    data.get(i).copied().unwrap_or(0.0)
                }),
                LevelData::Bands(maps) => group_min(xs, ys, radii, &frame, |i| {
                    maps.iter()
                        .map(|m| m.grid().data().get(i).copied().unwrap_or(0.0))
                        .fold(f32::INFINITY, f32::min)
                }),
            };
            if m < best.0 {
                best = (m, range.start + k);
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
