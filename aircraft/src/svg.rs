//! A picture of a fitted model: each level's footprint (filled) and circles (outlined), coloured
//! by level, seen from above with x (forward) to the right and y (left) up.

use std::fmt::Write as _;

use nalgebra::Point2;

use crate::fit::FittedModel;
use crate::footprint::Footprint;

/// Level colours, cycled.
const COLOURS: [&str; 5] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"];
/// Picture width in pixels (the height follows the model's aspect).
const WIDTH_PX: f64 = 1000.0;
/// Margin around the drawing, pixels.
const MARGIN_PX: f64 = 40.0;

/// The SVG text of the fitted model.
pub fn to_svg(fit: &FittedModel, title: &str) -> String {
    let (mut lo, mut hi) = (
        Point2::new(f64::INFINITY, f64::INFINITY),
        Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for level in &fit.levels {
        for f in &level.footprints {
            let (a, b) = f.bounds();
            lo = lo.inf(&a);
            hi = hi.sup(&b);
        }
    }
    for c in fit.model.circles() {
        lo = lo.inf(&Point2::new(c.x_m - c.radius_m, c.y_m - c.radius_m));
        hi = hi.sup(&Point2::new(c.x_m + c.radius_m, c.y_m + c.radius_m));
    }
    lo = lo.inf(&Point2::origin());
    hi = hi.sup(&Point2::origin());
    let scale = (WIDTH_PX - 2.0 * MARGIN_PX) / (hi.x - lo.x).max(1e-6);
    let height_px = (hi.y - lo.y) * scale + 2.0 * MARGIN_PX + 20.0 * fit.levels.len() as f64;
    let px = |x: f64| (x - lo.x) * scale + MARGIN_PX;
    let py = |y: f64| (hi.y - y) * scale + MARGIN_PX;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH_PX:.0}" height="{height_px:.0}" viewBox="0 0 {WIDTH_PX:.0} {height_px:.0}">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{MARGIN_PX}" y="24" font-family="sans-serif" font-size="16">{} ({} circles; x forward, y left; 1 m = {scale:.1} px)</text>"#,
        escape(title),
        fit.model.circles().len()
    );
    for (k, level) in fit.levels.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let _ = writeln!(s, r#"<g id="level-{k}">"#);
        for f in &level.footprints {
            match f {
                Footprint::Polygon(p) => {
                    let pts: Vec<String> = p
                        .vertices()
                        .iter()
                        .map(|v| format!("{:.2},{:.2}", px(v.x), py(v.y)))
                        .collect();
                    let _ = writeln!(
                        s,
                        r#"<polygon points="{}" fill="{colour}" fill-opacity="0.3" stroke="{colour}" stroke-width="0.5"/>"#,
                        pts.join(" ")
                    );
                }
                Footprint::Disc(d) => {
                    let _ = writeln!(
                        s,
                        r#"<circle cx="{:.2}" cy="{:.2}" r="{:.2}" fill="{colour}" fill-opacity="0.3" stroke="{colour}" stroke-width="0.5"/>"#,
                        px(d.center.x),
                        py(d.center.y),
                        d.radius_m * scale
                    );
                }
            }
        }
        for c in fit.model.circles().iter().filter(|c| c.level == k) {
            let _ = writeln!(
                s,
                r#"<circle cx="{:.2}" cy="{:.2}" r="{:.2}" fill="none" stroke="{colour}" stroke-width="1.5"/>"#,
                px(c.x_m),
                py(c.y_m),
                c.radius_m * scale
            );
        }
        let _ = writeln!(s, "</g>");
        let n = fit.model.circles().iter().filter(|c| c.level == k).count();
        let _ = writeln!(
            s,
            r#"<text x="{MARGIN_PX}" y="{:.0}" font-family="sans-serif" font-size="14" fill="{colour}">level {k}: h = {:.2} m, {} part(s), {n} circle(s)</text>"#,
            height_px - 10.0 - 20.0 * (fit.levels.len() - 1 - k) as f64,
            level.height_m,
            level.footprints.len()
        );
    }
    // The vehicle frame's origin and axes (1 m).
    let (ox, oy) = (px(0.0), py(0.0));
    let _ = writeln!(
        s,
        r#"<line x1="{ox:.2}" y1="{oy:.2}" x2="{:.2}" y2="{oy:.2}" stroke="black" stroke-width="1"/><line x1="{ox:.2}" y1="{oy:.2}" x2="{ox:.2}" y2="{:.2}" stroke="black" stroke-width="1"/>"#,
        ox + scale,
        oy - scale
    );
    let _ = writeln!(s, "</svg>");
    s
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
