//! The geometry the paint is followed in: a leg's frame (station along it, offset to its left)
//! and lines through the plane.

use super::{V2, finite};

/// A leg's frame: station `s` along it from its start, offset `d` to its left.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame {
    pub(super) origin: V2,
    pub(super) u: V2,
    pub(super) n: V2,
    pub(super) length: f64,
}

impl Frame {
    pub(super) fn of(a: V2, b: V2) -> Option<Self> {
        let length = (b - a).norm();
        (length.is_finite() && length > 1e-6).then(|| {
            let u = (b - a) / length;
            Self {
                origin: a,
                u,
                n: V2::new(-u.y, u.x),
                length,
            }
        })
    }

    /// `(s, d)` of a point.
    pub(super) fn sd(&self, p: V2) -> V2 {
        let r = p - self.origin;
        V2::new(r.dot(&self.u), r.dot(&self.n))
    }

    pub(super) fn world(&self, sd: V2) -> V2 {
        self.origin + self.u * sd.x + self.n * sd.y
    }

    pub(super) fn line(&self) -> Line {
        Line {
            at: self.origin,
            dir: self.u,
        }
    }
}

/// A line through `at` along the unit vector `dir`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Line {
    pub(super) at: V2,
    pub(super) dir: V2,
}

impl Line {
    pub(super) fn through(a: V2, b: V2) -> Option<Self> {
        let length = (b - a).norm();
        (length.is_finite() && length > 1e-9).then(|| Self {
            at: a,
            dir: (b - a) / length,
        })
    }

    /// The point of the line nearest `p`.
    pub(super) fn foot(&self, p: V2) -> V2 {
        self.at + self.dir * (p - self.at).dot(&self.dir)
    }

    /// |sin| of the angle between the lines.
    pub(super) fn sin_to(&self, other: &Self) -> f64 {
        self.dir.perp(&other.dir).abs()
    }

    pub(super) fn meet(&self, other: &Self) -> Option<V2> {
        let den = self.dir.perp(&other.dir);
        if den.abs() < 1e-9 {
            return None;
        }
        let t = (other.at - self.at).perp(&other.dir) / den;
        let p = self.at + self.dir * t;
        finite(p).then_some(p)
    }

    /// The line in `frame`'s `(s, d)` as `d = a + b s`; `None` if it crosses the leg at more than
    /// [`REFERENCE_DEG`].
    pub(super) fn in_frame(&self, frame: &Frame) -> Option<(f64, f64)> {
        let along = self.dir.dot(&frame.u);
        if along.abs() < super::REFERENCE_DEG.to_radians().cos() {
            return None;
        }
        let at = frame.sd(self.at);
        let slope = self.dir.dot(&frame.n) / along;
        Some((at.y - slope * at.x, slope))
    }
}
