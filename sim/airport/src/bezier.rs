//! Node chains with Bezier control points (`111`-`116`) as polylines in the local frame.
//!
//! A node's control point is where the curve leaving it heads; the curve arrives at a node from
//! the control point's mirror image through the node. A segment is always a cubic Bezier (as
//! X-Plane and WorldEditor draw it): a plain node's handle is the node itself; between two plain
//! nodes the segment is straight.

use nalgebra::Vector2;

/// A chain node in metres.
#[derive(Debug, Clone, Copy)]
pub struct LocalNode {
    /// The node.
    pub at: Vector2<f64>,
    /// Its control point, if curved.
    pub control: Option<Vector2<f64>>,
}

/// Longest chord of a curve's polyline (m).
pub const MAX_CHORD_M: f64 = 1.0;
/// Most pieces a curved segment is cut into (curves whose handles reach beyond 85 m get longer chords).
const MAX_PIECES: usize = 256;

/// The points of the segment from `a` to `b`, `a` included, `b` left out (the next segment's
/// first point).
#[must_use]
pub fn segment(a: LocalNode, b: LocalNode) -> Vec<Vector2<f64>> {
    let arrive = b.control.map(|c| 2.0 * b.at - c);
    // Between two nodes at one place (WorldEditor writes a split node so) X-Plane draws nothing,
    // unless both have handles (a loop).
    let together = (b.at - a.at).norm() < 1e-6 && (a.control.is_none() || b.control.is_none());
    if together || (a.control.is_none() && arrive.is_none()) {
        return vec![a.at];
    }
    let controls = [
        a.at,
        a.control.unwrap_or(a.at),
        arrive.unwrap_or(b.at),
        b.at,
    ];
    // A cubic's speed never exceeds 3x its longest control leg: so many pieces keep every chord
    // within MAX_CHORD_M.
    let leg = controls
        .windows(2)
        .map(|w| (w[1] - w[0]).norm())
        .fold(0.0, f64::max);
    let pieces = ((3.0 * leg / MAX_CHORD_M).ceil() as usize).clamp(2, MAX_PIECES);
    (0..pieces)
        .map(|i| de_casteljau(&controls, i as f64 / pieces as f64))
        .collect()
}

/// A chain as a polyline: closed chains do not repeat their first point.
#[must_use]
pub fn polyline(nodes: &[LocalNode], closed: bool) -> Vec<Vector2<f64>> {
    let mut points = Vec::new();
    let count = nodes.len();
    let segments = if closed {
        count
    } else {
        count.saturating_sub(1)
    };
    for i in 0..segments {
        points.extend(segment(nodes[i], nodes[(i + 1) % count]));
    }
    if !closed && let Some(last) = nodes.last() {
        points.push(last.at);
    }
    points.dedup_by(|a, b| (*a - *b).norm() < 1e-6);
    points
}

fn de_casteljau(controls: &[Vector2<f64>], t: f64) -> Vector2<f64> {
    let mut points = controls.to_vec();
    while points.len() > 1 {
        points = points
            .windows(2)
            .map(|w| w[0] + (w[1] - w[0]) * t)
            .collect();
    }
    points[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(x: f64, y: f64, control: Option<(f64, f64)>) -> LocalNode {
        LocalNode {
            at: Vector2::new(x, y),
            control: control.map(|(cx, cy)| Vector2::new(cx, cy)),
        }
    }

    #[test]
    fn plain_nodes_give_the_nodes() {
        let line = polyline(
            &[
                node(0.0, 0.0, None),
                node(10.0, 0.0, None),
                node(10.0, 10.0, None),
            ],
            false,
        );
        assert_eq!(
            line,
            vec![
                Vector2::new(0.0, 0.0),
                Vector2::new(10.0, 0.0),
                Vector2::new(10.0, 10.0)
            ]
        );
    }

    #[test]
    fn a_corner_with_one_handle_is_a_cubic_cut_finely() {
        // From (0,0) heading to the control (10,0), arriving at (10,10): a rounded corner.
        let line = polyline(
            &[node(0.0, 0.0, Some((10.0, 0.0))), node(10.0, 10.0, None)],
            false,
        );
        assert!(line.len() > 15, "{}", line.len());
        for w in line.windows(2) {
            assert!((w[1] - w[0]).norm() <= MAX_CHORD_M + 1e-9);
        }
        // Cubic (P0, C, P3, P3): its midpoint is 0.125 P0 + 0.375 C + 0.5 P3 = (8.75, 5.0)
        // (a quadratic's would be (7.5, 2.5)).
        let mid = line
            .iter()
            .map(|p| (p - Vector2::new(8.75, 5.0)).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(mid < 0.5, "{mid}");
    }

    #[test]
    fn the_curve_arrives_from_the_mirror_of_the_end_nodes_control() {
        // End node (10,0) with control (10,-5): the curve arrives from (10,5), i.e. heading south.
        let line = polyline(
            &[node(0.0, 0.0, None), node(10.0, 0.0, Some((10.0, -5.0)))],
            false,
        );
        let before_end = line[line.len() - 2];
        assert!(before_end.y > 0.0 && before_end.x < 10.0, "{before_end}");
    }
}
