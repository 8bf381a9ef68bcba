//! The LiDAR self-hit test for a whole revolution: [`CollisionModel::is_self_hit`] with the
//! circles binned on a grid over the vehicle, so a return tests only the circles whose widened
//! disc reaches its cell instead of every circle of the model.
//!
//! A jet's bounding circle (11-12 m with the margin) holds the ground returns of a third of the
//! beams, and its model has 62 circles: the straightforward test is about 1.3 million circle
//! tests a revolution. The binned test gives the same answer for every point (it tests the same
//! inequality on a subset that holds every circle that could pass it).

use nalgebra::Point2;

use crate::collision::CollisionModel;

/// Side of a bin, metres: a few circles per bin on the airframes of this project.
const BIN_M: f64 = 0.5;

/// A [`CollisionModel`]'s self-hit test at one margin, binned.
#[derive(Clone, Debug, PartialEq)]
pub struct SelfHitFilter {
    model: CollisionModel,
    margin_m: f64,
    origin: Point2<f64>,
    size: [usize; 2],
    /// Bin b holds `circles[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    /// Per circle in bin order: centre x, y, squared widened radius, height of its level.
    circles: Vec<[f64; 4]>,
}

impl SelfHitFilter {
    /// The filter of `model` widened by `margin_m` (>= 0).
    pub fn new(model: &CollisionModel, margin_m: f64) -> Self {
        let margin = margin_m.max(0.0);
        let heights = model.level_heights_m();
        let widened = |c: &crate::collision::Circle| c.radius_m + margin;
        let (mut lo, mut hi) = (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for c in model.circles() {
            lo.x = lo.x.min(c.x_m - widened(c));
            lo.y = lo.y.min(c.y_m - widened(c));
            hi.x = hi.x.max(c.x_m + widened(c));
            hi.y = hi.y.max(c.y_m + widened(c));
        }
        let size = [
            ((hi.x - lo.x) / BIN_M).ceil().max(1.0) as usize,
            ((hi.y - lo.y) / BIN_M).ceil().max(1.0) as usize,
        ];
        let mut start = Vec::with_capacity(size[0] * size[1] + 1);
        let mut circles = Vec::new();
        start.push(0);
        for by in 0..size[1] {
            for bx in 0..size[0] {
                let (x0, y0) = (lo.x + bx as f64 * BIN_M, lo.y + by as f64 * BIN_M);
                for c in model.circles() {
                    // Distance from the centre to the bin's square (0 inside it).
                    let dx = (x0 - c.x_m).max(c.x_m - (x0 + BIN_M)).max(0.0);
                    let dy = (y0 - c.y_m).max(c.y_m - (y0 + BIN_M)).max(0.0);
                    let r = widened(c);
                    // A hair of slack: a point on the bin's edge may round into it.
                    if dx * dx + dy * dy <= r * r + 1e-9 {
                        circles.push([c.x_m, c.y_m, r * r, heights[c.level]]);
                    }
                }
                start.push(circles.len() as u32);
            }
        }
        SelfHitFilter {
            model: model.clone(),
            margin_m: margin,
            origin: lo,
            size,
            start,
            circles,
        }
    }

    /// Whether it is the filter of `model` at `margin_m`.
    pub fn is_for(&self, model: &CollisionModel, margin_m: f64) -> bool {
        self.margin_m == margin_m.max(0.0) && self.model == *model
    }

    /// [`CollisionModel::is_self_hit`] at the filter's margin: the same answer.
    #[inline]
    pub fn is_self_hit(&self, p: &Point2<f64>, height_m: f64) -> bool {
        let (bx, by) = ((p.x - self.origin.x) / BIN_M, (p.y - self.origin.y) / BIN_M);
        // Off the grid (NaN included) no widened disc reaches the point. On it `as` truncates,
        // which is the floor there.
        if !(bx >= 0.0 && by >= 0.0 && bx < self.size[0] as f64 && by < self.size[1] as f64) {
            return false;
        }
        let b = by as usize * self.size[0] + bx as usize;
        self.circles[self.start[b] as usize..self.start[b + 1] as usize]
            .iter()
            .any(|&[x, y, r2, h]| height_m >= h && (p.x - x).powi(2) + (p.y - y).powi(2) <= r2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::Circle;
    use rand::{RngExt, SeedableRng};

    fn jet_like() -> CollisionModel {
        let mut circles = Vec::new();
        // A fuselage of 20 overlapping circles, wings of 2 x 15, engines, a tail.
        for i in 0..20 {
            circles.push(Circle {
                x_m: -4.0 + i as f64,
                y_m: 0.0,
                radius_m: 1.1,
                level: 0,
            });
        }
        for side in [-1.0, 1.0] {
            for i in 0..15 {
                circles.push(Circle {
                    x_m: 3.0 - 0.2 * i as f64,
                    y_m: side * (1.5 + 0.65 * i as f64),
                    radius_m: 0.55 - 0.02 * i as f64,
                    level: 1,
                });
            }
            circles.push(Circle {
                x_m: -3.0,
                y_m: side * 1.9,
                radius_m: 0.7,
                level: 1,
            });
        }
        CollisionModel::new(circles, vec![0.0, 1.1]).unwrap()
    }

    /// Every point of a dense random cloud around the jet (and a few on bin edges) gets the
    /// straightforward test's answer, at several margins and heights; and the cloud has both
    /// answers in numbers (a test of a filter that always says no would fail).
    #[test]
    fn the_binned_test_answers_as_the_straightforward_one() {
        let model = jet_like();
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(5);
        for margin in [0.0, 0.3, 0.8, 2.0] {
            let filter = SelfHitFilter::new(&model, margin);
            assert!(filter.is_for(&model, margin));
            assert!(!filter.is_for(&model, margin + 0.1));
            let (mut yes, mut no) = (0, 0);
            for k in 0..200_000 {
                let p = if k % 10 == 0 {
                    // On a bin edge.
                    Point2::new(
                        filter.origin.x + BIN_M * rng.random_range(0..60) as f64,
                        rng.random_range(-16.0..16.0),
                    )
                } else {
                    Point2::new(rng.random_range(-10.0..20.0), rng.random_range(-16.0..16.0))
                };
                let h = [-0.1, 0.0, 0.5, 1.1, 3.0][k % 5];
                let expected = model.is_self_hit(&p, h, margin);
                assert_eq!(
                    filter.is_self_hit(&p, h),
                    expected,
                    "margin {margin} at {p:?}, height {h}"
                );
                if expected { yes += 1 } else { no += 1 }
            }
            assert!(
                yes > 5_000 && no > 5_000,
                "margin {margin}: {yes} self-hits, {no} not"
            );
        }
        let filter = SelfHitFilter::new(&model, 0.8);
        assert!(!filter.is_self_hit(&Point2::new(f64::NAN, 0.0), 1.0));
    }
}
