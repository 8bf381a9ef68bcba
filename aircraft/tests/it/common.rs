//! Test helpers shared by the integration tests: dense-sampling coverage checks.

use aircraft::FittedModel;
use aircraft::footprint::Footprint;
use nalgebra::Point2;

/// Points of a footprint: a `n x n` grid over its bounds kept where inside, plus its vertices
/// (or, for a disc, points on its rim).
pub fn footprint_samples(f: &Footprint, n: usize) -> Vec<Point2<f64>> {
    let (lo, hi) = f.bounds();
    let mut pts = Vec::new();
    for iy in 0..=n {
        for ix in 0..=n {
            let p = Point2::new(
                lo.x + (hi.x - lo.x) * ix as f64 / n as f64,
                lo.y + (hi.y - lo.y) * iy as f64 / n as f64,
            );
            if f.contains(&p) {
                pts.push(p);
            }
        }
    }
    match f {
        Footprint::Polygon(p) => pts.extend_from_slice(p.vertices()),
        Footprint::Disc(d) => {
            for k in 0..64 {
                let t = std::f64::consts::TAU * k as f64 / 64.0;
                pts.push(d.center + nalgebra::Vector2::new(t.cos(), t.sin()) * d.radius_m);
            }
        }
    }
    pts
}

/// The first point of a level-k footprint that no circle of level <= k contains, if any.
pub fn uncovered_point(fit: &FittedModel, n: usize) -> Option<(usize, Point2<f64>)> {
    for (k, level) in fit.levels.iter().enumerate() {
        for f in &level.footprints {
            for p in footprint_samples(f, n) {
                let covered = fit.model.circles().iter().any(|c| {
                    c.level <= k
                        && ((p.x - c.x_m).powi(2) + (p.y - c.y_m).powi(2)).sqrt()
                            <= c.radius_m + 1e-9
                });
                if !covered {
                    return Some((k, p));
                }
            }
        }
    }
    None
}
