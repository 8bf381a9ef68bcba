//! Route geometry: a polyline with arc length, points and headings along it, and the Frenet
//! projection (arc length, signed lateral offset) of a point, searched near a hint.

use nalgebra::Point2;

/// A route as a polyline with arc length.
#[derive(Clone, Debug)]
pub struct RoutePath {
    points: Vec<Point2<f64>>,
    /// Arc length at each point (and at the closing point for a closed route).
    s: Vec<f64>,
    closed: bool,
    /// A speed limit at each point (m/s), if the route has them.
    speed_limits: Option<Vec<f64>>,
}

impl RoutePath {
    /// A path through `points` (at least 2, consecutive points distinct), closed or not.
    pub fn new(points: &[Point2<f64>], closed: bool) -> Self {
        let mut pts = points.to_vec();
        if closed && let Some(first) = pts.first().copied() {
            pts.push(first);
        }
        let mut s = vec![0.0];
        for w in pts.windows(2) {
            let last = s[s.len() - 1];
            s.push(last + (w[1] - w[0]).norm());
        }
        RoutePath {
            points: pts,
            s,
            closed,
            speed_limits: None,
        }
    }

    /// The route with a speed limit at each of its points (m/s; a taxi route's turns, braked
    /// into). `None`, or a list of another length than the points, leaves it without.
    #[must_use]
    pub fn with_speed_limits(mut self, limits: Option<Vec<f64>>) -> Self {
        let count = self.points.len() - usize::from(self.closed);
        self.speed_limits = limits.filter(|l| l.len() == count && !self.closed);
        self
    }

    /// The speed limit at arc length `s`, interpolated between points (infinite without limits).
    pub fn speed_limit_at(&self, s: f64) -> f64 {
        let Some(limits) = &self.speed_limits else {
            return f64::INFINITY;
        };
        let s = self.wrap(s);
        let i = self.segment(s);
        let span = (self.s[i + 1] - self.s[i]).max(1e-12);
        let t = ((s - self.s[i]) / span).clamp(0.0, 1.0);
        limits[i] + (limits[i + 1] - limits[i]) * t
    }
    /// Total length, metres.
    pub fn length_m(&self) -> f64 {
        self.s[self.s.len() - 1]
    }
    /// True for a closed circuit.
    pub fn closed(&self) -> bool {
        self.closed
    }
    fn wrap(&self, s: f64) -> f64 {
        if self.closed {
            s.rem_euclid(self.length_m())
        } else {
            s.clamp(0.0, self.length_m())
        }
    }
    fn segment(&self, s: f64) -> usize {
        let i = self.s.partition_point(|&x| x <= s);
        i.saturating_sub(1).min(self.points.len() - 2)
    }
    /// Point and heading at arc length `s` (wrapped on a closed route, clamped on an open one).
    pub fn at(&self, s: f64) -> (Point2<f64>, f64) {
        let s = self.wrap(s);
        let i = self.segment(s);
        let d = self.points[i + 1] - self.points[i];
        let len = d.norm().max(1e-12);
        (self.points[i] + d * ((s - self.s[i]) / len), d.y.atan2(d.x))
    }
    /// Arc length and signed lateral offset (left positive) of a point, searched within
    /// `window_m` of `s_hint` (so a circuit that passes near itself is followed in order).
    /// Only the segments whose arc-length span meets the window are visited (found by bisection),
    /// in index order, so the result is that of testing every segment.
    pub fn project(&self, p: &Point2<f64>, s_hint: f64, window_m: f64) -> (f64, f64) {
        let length = self.length_m();
        let last = self.points.len() - 2;
        // Index ranges of the segments to visit, ascending.
        let mut spans = [(0, last), (1, 0)];
        if window_m.is_finite() && window_m < 0.5 * length {
            let (lo, hi) = if self.closed {
                let h = s_hint.rem_euclid(length);
                (h - window_m, h + window_m)
            } else {
                (s_hint - window_m, s_hint + window_m)
            };
            spans = if self.closed && lo < 0.0 {
                [(0, self.segment(hi)), (self.segment(lo + length), last)]
            } else if self.closed && hi > length {
                [(0, self.segment(hi - length)), (self.segment(lo), last)]
            } else {
                [(self.segment(lo), self.segment(hi)), (1, 0)]
            };
        }
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for i in spans.iter().flat_map(|&(a, b)| a..=b) {
            let (a, b) = (self.points[i], self.points[i + 1]);
            let ab = b - a;
            let len2 = ab.norm_squared().max(1e-12);
            let t = ((p - a).dot(&ab) / len2).clamp(0.0, 1.0);
            let q = a + ab * t;
            let s = self.s[i] + t * len2.sqrt();
            let along = if self.closed {
                let d = (s - s_hint).rem_euclid(length);
                d.min(length - d)
            } else {
                (s - s_hint).abs()
            };
            if along > window_m {
                continue;
            }
            let dist = (p - q).norm();
            if dist < best.0 {
                let side = ab.x * (p.y - a.y) - ab.y * (p.x - a.x);
                best = (dist, s, if side >= 0.0 { dist } else { -dist });
            }
        }
        if best.0.is_infinite() {
            self.project(p, s_hint, f64::INFINITY)
        } else {
            (best.1, best.2)
        }
    }
}

/// An angle wrapped to (-pi, pi].
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_and_points_agree_on_a_closed_square() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            Point2::new(10.0, 10.0),
            Point2::new(0.0, 10.0),
        ];
        let r = RoutePath::new(&pts, true);
        assert_eq!(r.length_m(), 40.0);
        let (p, h) = r.at(15.0);
        assert!(
            (p - Point2::new(10.0, 5.0)).norm() < 1e-12
                && (h - std::f64::consts::FRAC_PI_2).abs() < 1e-12
        );
        let (p, _) = r.at(41.0);
        assert!((p - Point2::new(1.0, 0.0)).norm() < 1e-12, "wraps");
        let (s, d) = r.project(&Point2::new(5.0, 1.0), 5.0, 10.0);
        assert!(
            (s - 5.0).abs() < 1e-12 && (d - 1.0).abs() < 1e-12,
            "left of the first side: {s} {d}"
        );
        let (_, d) = r.project(&Point2::new(5.0, -1.0), 5.0, 10.0);
        assert!((d + 1.0).abs() < 1e-12);
    }

    #[test]
    fn speed_limits_are_interpolated_along_the_route_and_only_where_given() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            Point2::new(10.0, 10.0),
        ];
        let r = RoutePath::new(&pts, false).with_speed_limits(Some(vec![6.0, 4.0, 6.0]));
        assert_eq!(r.speed_limit_at(0.0), 6.0);
        assert!((r.speed_limit_at(5.0) - 5.0).abs() < 1e-12);
        assert!((r.speed_limit_at(15.0) - 5.0).abs() < 1e-12);
        assert_eq!(r.speed_limit_at(30.0), 6.0, "clamped at the end");
        let unlimited = RoutePath::new(&pts, false);
        assert_eq!(unlimited.speed_limit_at(5.0), f64::INFINITY);
        let wrong_count = RoutePath::new(&pts, false).with_speed_limits(Some(vec![1.0]));
        assert_eq!(wrong_count.speed_limit_at(5.0), f64::INFINITY);
    }

    /// The windowed search (bisection on arc length) agrees with testing every segment.
    #[test]
    fn windowed_projection_matches_the_exhaustive_search() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        // A wobbly closed loop and an open one of many short segments.
        let pts: Vec<Point2<f64>> = (0..400)
            .map(|i| {
                let a = i as f64 / 400.0 * std::f64::consts::TAU;
                let r = 50.0 + 5.0 * (7.0 * a).sin();
                Point2::new(r * a.cos(), r * a.sin())
            })
            .collect();
        for closed in [true, false] {
            let r = RoutePath::new(&pts, closed);
            // The old search: every segment, and the whole route when none is in the window.
            let brute = |p: &Point2<f64>, hint: f64, w: f64| {
                let mut best = (f64::INFINITY, 0.0, 0.0);
                for w in [w, f64::INFINITY] {
                    for i in 0..r.points.len() - 1 {
                        let (a, b) = (r.points[i], r.points[i + 1]);
                        let ab = b - a;
                        let len2 = ab.norm_squared().max(1e-12);
                        let t = ((p - a).dot(&ab) / len2).clamp(0.0, 1.0);
                        let s = r.s[i] + t * len2.sqrt();
                        let along = if closed {
                            let d = (s - hint).rem_euclid(r.length_m());
                            d.min(r.length_m() - d)
                        } else {
                            (s - hint).abs()
                        };
                        let dist = (p - (a + ab * t)).norm();
                        if along <= w && dist < best.0 {
                            let side = ab.x * (p.y - a.y) - ab.y * (p.x - a.x);
                            best = (dist, s, if side >= 0.0 { dist } else { -dist });
                        }
                    }
                    if best.0.is_finite() {
                        break;
                    }
                }
                (best.1, best.2)
            };
            for _ in 0..2000 {
                let p = Point2::new(rng.random_range(-60.0..60.0), rng.random_range(-60.0..60.0));
                let hint = rng.random_range(-10.0..r.length_m() + 10.0);
                let w = [5.0, 30.0, 100.0][rng.random_range(0..3)];
                let fast = r.project(&p, hint, w);
                let slow = brute(&p, hint, w);
                assert_eq!(fast, slow, "closed {closed} p {p} hint {hint} window {w}");
            }
        }
    }
}
