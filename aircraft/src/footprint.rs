//! Plane geometry of footprints (projections onto the ground, vehicle frame x forward, y left):
//! convex polygons and discs, with the few exact operations the circle fitter needs.

use nalgebra::{Point2, Vector2};

/// Tolerance of the geometric predicates, metres.
pub const EPS_M: f64 = 1e-9;

/// A disc in the plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    /// Centre, vehicle frame.
    pub center: Point2<f64>,
    /// Radius, metres.
    pub radius_m: f64,
}

impl Disc {
    /// True when `p` is inside or on the disc (within `EPS_M`).
    pub fn contains(&self, p: &Point2<f64>) -> bool {
        (p - self.center).norm() <= self.radius_m + EPS_M
    }
}

/// A convex polygon, vertices counter-clockwise, no repeated vertices, at least 3.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexPolygon {
    vertices: Vec<Point2<f64>>,
}

/// An oriented rectangle: centre, unit long axis, half extents along the long and short axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrientedRect {
    /// Centre.
    pub center: Point2<f64>,
    /// Unit vector along the long side.
    pub long_axis: Vector2<f64>,
    /// Half the long side, metres.
    pub half_length_m: f64,
    /// Half the short side, metres.
    pub half_width_m: f64,
}

fn cross(a: &Vector2<f64>, b: &Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The convex hull of `points`, counter-clockwise, exactly collinear and coincident (within
/// `EPS_M`) points dropped (Andrew's monotone chain).
pub fn convex_hull(points: &[Point2<f64>]) -> Vec<Point2<f64>> {
    let mut pts: Vec<Point2<f64>> = points
        .iter()
        .copied()
        .filter(|p| p.x.is_finite() && p.y.is_finite())
        .collect();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup_by(|a, b| (*a - *b).norm() <= EPS_M);
    if pts.len() < 3 {
        return pts;
    }
    let mut hull: Vec<Point2<f64>> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Point2<f64>>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2 {
                let a = hull[hull.len() - 2];
                let b = hull[hull.len() - 1];
                // Exact turn test: a tolerance here would let a nearly-degenerate point set
                // (a lying cylinder's flattened rims) lose hull points.
                if cross(&(b - a), &(p - a)) <= 0.0 {
                    hull.pop();
                } else {
                    break;
                }
            }
            hull.push(*p);
        }
        hull.pop();
    }
    hull
}

impl ConvexPolygon {
    /// The convex hull of `points`; `None` when it has no area (fewer than 3 non-collinear points).
    pub fn hull(points: &[Point2<f64>]) -> Option<Self> {
        let vertices = convex_hull(points);
        (vertices.len() >= 3).then_some(ConvexPolygon { vertices })
    }

    /// The vertices, counter-clockwise.
    pub fn vertices(&self) -> &[Point2<f64>] {
        &self.vertices
    }

    fn edges(&self) -> impl Iterator<Item = (Point2<f64>, Point2<f64>)> + '_ {
        let n = self.vertices.len();
        (0..n).map(move |i| (self.vertices[i], self.vertices[(i + 1) % n]))
    }

    /// Area, square metres.
    pub fn area_m2(&self) -> f64 {
        0.5 * self
            .edges()
            .map(|(a, b)| a.x * b.y - a.y * b.x)
            .sum::<f64>()
    }

    /// True when `p` is inside or on the boundary (within `EPS_M`).
    pub fn contains(&self, p: &Point2<f64>) -> bool {
        self.edges().all(|(a, b)| {
            let e = b - a;
            cross(&e, &(p - a)) >= -EPS_M * e.norm()
        })
    }

    /// Distance from `p` to the polygon, 0 inside.
    pub fn distance(&self, p: &Point2<f64>) -> f64 {
        if self.contains(p) {
            return 0.0;
        }
        self.edges()
            .map(|(a, b)| segment_distance(p, &a, &b))
            .fold(f64::INFINITY, f64::min)
    }

    /// The part of the polygon where `normal . p <= offset`; `None` when nothing with area is left.
    pub fn clip(&self, normal: &Vector2<f64>, offset: f64) -> Option<ConvexPolygon> {
        let mut out = Vec::with_capacity(self.vertices.len() + 1);
        for (a, b) in self.edges() {
            let da = normal.dot(&a.coords) - offset;
            let db = normal.dot(&b.coords) - offset;
            if da <= 0.0 {
                out.push(a);
            }
            if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
                let t = da / (da - db);
                out.push(a + (b - a) * t);
            }
        }
        ConvexPolygon::hull(&out)
    }

    /// The smallest-area enclosing rectangle (one side lies on a hull edge); ties keep the first edge.
    pub fn min_area_rect(&self) -> OrientedRect {
        let mut best: Option<(f64, OrientedRect)> = None;
        for (a, b) in self.edges() {
            let u = (b - a).normalize();
            let v = Vector2::new(-u.y, u.x);
            let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
            for p in &self.vertices {
                let (pu, pv) = (u.dot(&p.coords), v.dot(&p.coords));
                u0 = u0.min(pu);
                u1 = u1.max(pu);
                v0 = v0.min(pv);
                v1 = v1.max(pv);
            }
            let area = (u1 - u0) * (v1 - v0);
            if best.as_ref().is_none_or(|(a, _)| area < *a - 1e-12) {
                let center = Point2::from(u * (0.5 * (u0 + u1)) + v * (0.5 * (v0 + v1)));
                let (hu, hv) = (0.5 * (u1 - u0), 0.5 * (v1 - v0));
                let rect = if hu >= hv {
                    OrientedRect {
                        center,
                        long_axis: u,
                        half_length_m: hu,
                        half_width_m: hv,
                    }
                } else {
                    OrientedRect {
                        center,
                        long_axis: v,
                        half_length_m: hv,
                        half_width_m: hu,
                    }
                };
                best = Some((area, rect));
            }
        }
        // A polygon has >= 3 edges, so `best` is set; the fallback is never used.
        best.map_or(
            OrientedRect {
                center: self.vertices[0],
                long_axis: Vector2::x(),
                half_length_m: 0.0,
                half_width_m: 0.0,
            },
            |(_, r)| r,
        )
    }

    /// Area of the intersection with a disc, square metres (exact).
    pub fn disc_intersection_area_m2(&self, disc: &Disc) -> f64 {
        let c = disc.center;
        self.edges()
            .map(|(a, b)| disc_triangle_area(&(a - c), &(b - c), disc.radius_m))
            .sum::<f64>()
            .abs()
    }
}

/// Distance from `p` to the segment `a`-`b`.
pub fn segment_distance(p: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Distance between the segments `a`-`b` and `c`-`d` (0 when they cross).
pub fn segments_distance(
    a: &Point2<f64>,
    b: &Point2<f64>,
    c: &Point2<f64>,
    d: &Point2<f64>,
) -> f64 {
    let (ab, cd) = (b - a, d - c);
    let (d1, d2) = (cross(&ab, &(c - a)), cross(&ab, &(d - a)));
    let (d3, d4) = (cross(&cd, &(a - c)), cross(&cd, &(b - c)));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return 0.0;
    }
    segment_distance(a, c, d)
        .min(segment_distance(b, c, d))
        .min(segment_distance(c, a, b))
        .min(segment_distance(d, a, b))
}

/// Signed area of the intersection of the disc (origin, r) with the triangle (origin, a, b).
fn disc_triangle_area(a: &Vector2<f64>, b: &Vector2<f64>, r: f64) -> f64 {
    let sector = |u: &Vector2<f64>, v: &Vector2<f64>| 0.5 * r * r * cross(u, v).atan2(u.dot(v));
    let d = b - a;
    let qa = d.norm_squared();
    if qa <= 1e-300 {
        return 0.0;
    }
    let qb = a.dot(&d);
    let qc = a.norm_squared() - r * r;
    let disc = qb * qb - qa * qc;
    if disc <= 0.0 {
        return sector(a, b);
    }
    let s = disc.sqrt();
    let t1 = ((-qb - s) / qa).max(0.0);
    let t2 = ((-qb + s) / qa).min(1.0);
    if t1 >= t2 {
        return sector(a, b);
    }
    let p1 = a + d * t1;
    let p2 = a + d * t2;
    sector(a, &p1) + 0.5 * cross(&p1, &p2) + sector(&p2, b)
}

/// The smallest disc containing every point (Welzl's algorithm, iterative, deterministic).
/// Its radius is inflated by `EPS_M` so that the points are strictly covered.
pub fn min_enclosing_disc(points: &[Point2<f64>]) -> Disc {
    let inside = |d: &Disc, p: &Point2<f64>| (p - d.center).norm() <= d.radius_m + 1e-12;
    let mut disc = Disc {
        center: points.first().copied().unwrap_or_else(Point2::origin),
        radius_m: 0.0,
    };
    for i in 0..points.len() {
        if inside(&disc, &points[i]) {
            continue;
        }
        disc = Disc {
            center: points[i],
            radius_m: 0.0,
        };
        for j in 0..i {
            if inside(&disc, &points[j]) {
                continue;
            }
            disc = disc_of_two(&points[i], &points[j]);
            for k in 0..j {
                if !inside(&disc, &points[k]) {
                    disc = disc_of_three(&points[i], &points[j], &points[k]);
                }
            }
        }
    }
    Disc {
        center: disc.center,
        radius_m: disc.radius_m + EPS_M,
    }
}

fn disc_of_two(a: &Point2<f64>, b: &Point2<f64>) -> Disc {
    Disc {
        center: nalgebra::center(a, b),
        radius_m: 0.5 * (a - b).norm(),
    }
}

fn disc_of_three(a: &Point2<f64>, b: &Point2<f64>, c: &Point2<f64>) -> Disc {
    let (ab, ac) = (b - a, c - a);
    let d = 2.0 * cross(&ab, &ac);
    if d.abs() < 1e-14 {
        // Collinear: the disc on the farthest pair.
        let pairs = [disc_of_two(a, b), disc_of_two(a, c), disc_of_two(b, c)];
        return pairs
            .into_iter()
            .fold(pairs[0], |m, p| if p.radius_m > m.radius_m { p } else { m });
    }
    let (b2, c2) = (ab.norm_squared(), ac.norm_squared());
    let ux = (ac.y * b2 - ab.y * c2) / d;
    let uy = (ab.x * c2 - ac.x * b2) / d;
    let off = Vector2::new(ux, uy);
    let center = a + off;
    let radius_m = off.norm().max((b - center).norm()).max((c - center).norm());
    Disc { center, radius_m }
}

/// A part's projection onto the ground plane.
#[derive(Clone, Debug, PartialEq)]
pub enum Footprint {
    /// Boxes, tilted or lying cylinders and capsules.
    Polygon(ConvexPolygon),
    /// Spheres, upright cylinders and capsules.
    Disc(Disc),
}

impl Footprint {
    /// Area, square metres.
    pub fn area_m2(&self) -> f64 {
        match self {
            Footprint::Polygon(p) => p.area_m2(),
            Footprint::Disc(d) => std::f64::consts::PI * d.radius_m * d.radius_m,
        }
    }

    /// True when `p` is inside or on the boundary.
    pub fn contains(&self, p: &Point2<f64>) -> bool {
        match self {
            Footprint::Polygon(poly) => poly.contains(p),
            Footprint::Disc(d) => d.contains(p),
        }
    }

    /// Distance from `p` to the footprint, 0 inside.
    pub fn distance(&self, p: &Point2<f64>) -> f64 {
        match self {
            Footprint::Polygon(poly) => poly.distance(p),
            Footprint::Disc(d) => ((p - d.center).norm() - d.radius_m).max(0.0),
        }
    }

    /// Axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (Point2<f64>, Point2<f64>) {
        match self {
            Footprint::Polygon(p) => {
                let mut lo = Point2::new(f64::INFINITY, f64::INFINITY);
                let mut hi = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
                for v in p.vertices() {
                    lo = lo.inf(v);
                    hi = hi.sup(v);
                }
                (lo, hi)
            }
            Footprint::Disc(d) => {
                let r = Vector2::new(d.radius_m, d.radius_m);
                (d.center - r, d.center + r)
            }
        }
    }

    /// True when `other` lies entirely inside `self`.
    pub fn contains_footprint(&self, other: &Footprint) -> bool {
        match (self, other) {
            (Footprint::Polygon(a), Footprint::Polygon(b)) => {
                b.vertices().iter().all(|v| a.contains(v))
            }
            (Footprint::Polygon(a), Footprint::Disc(d)) => {
                a.contains(&d.center)
                    && a.edges().all(|(p, q)| {
                        let e = q - p;
                        cross(&e, &(d.center - p)) / e.norm() >= d.radius_m - EPS_M
                    })
            }
            (Footprint::Disc(d), Footprint::Polygon(b)) => {
                b.vertices().iter().all(|v| d.contains(v))
            }
            (Footprint::Disc(a), Footprint::Disc(b)) => {
                (a.center - b.center).norm() + b.radius_m <= a.radius_m + EPS_M
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(h: f64) -> ConvexPolygon {
        ConvexPolygon::hull(&[
            Point2::new(-h, -h),
            Point2::new(h, -h),
            Point2::new(h, h),
            Point2::new(-h, h),
            Point2::new(0.0, h), // collinear, dropped
        ])
        .expect("square")
    }

    #[test]
    fn hull_is_ccw_without_collinear_points() {
        let s = square(1.0);
        assert_eq!(s.vertices().len(), 4);
        assert!((s.area_m2() - 4.0).abs() < 1e-12);
    }

    #[test]
    fn disc_polygon_area_matches_known_cases() {
        let s = square(1.0);
        let inside = Disc {
            center: Point2::origin(),
            radius_m: 0.5,
        };
        assert!((s.disc_intersection_area_m2(&inside) - std::f64::consts::PI * 0.25).abs() < 1e-12);
        let around = Disc {
            center: Point2::origin(),
            radius_m: 2.0,
        };
        assert!((s.disc_intersection_area_m2(&around) - 4.0).abs() < 1e-12);
        // A disc centred on a corner covers a quarter of itself.
        let corner = Disc {
            center: Point2::new(1.0, 1.0),
            radius_m: 0.5,
        };
        assert!(
            (s.disc_intersection_area_m2(&corner) - std::f64::consts::PI * 0.25 / 4.0).abs()
                < 1e-12
        );
    }

    #[test]
    fn min_enclosing_disc_of_rectangle_is_circumscribed() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(4.0, 0.0),
            Point2::new(4.0, 3.0),
            Point2::new(0.0, 3.0),
        ];
        let d = min_enclosing_disc(&pts);
        assert!((d.radius_m - 2.5).abs() < 1e-6);
        assert!((d.center - Point2::new(2.0, 1.5)).norm() < 1e-9);
    }

    #[test]
    fn min_area_rect_of_rotated_rectangle() {
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let rot = |x: f64, y: f64| Point2::new(c * x - s * y, s * x + c * y);
        let p = ConvexPolygon::hull(&[
            rot(-3.0, -1.0),
            rot(3.0, -1.0),
            rot(3.0, 1.0),
            rot(-3.0, 1.0),
        ])
        .expect("rect");
        let r = p.min_area_rect();
        assert!((r.half_length_m - 3.0).abs() < 1e-9);
        assert!((r.half_width_m - 1.0).abs() < 1e-9);
        assert!((r.long_axis.x.abs() - c).abs() < 1e-9);
    }

    #[test]
    fn clip_keeps_the_lower_half() {
        let s = square(1.0);
        let half = s.clip(&Vector2::new(1.0, 0.0), 0.0).expect("half");
        assert!((half.area_m2() - 2.0).abs() < 1e-12);
        assert!(s.clip(&Vector2::new(1.0, 0.0), -2.0).is_none());
    }
}
