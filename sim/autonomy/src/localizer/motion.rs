//! The motion update: the odometry's arc integrated into the nominal pose (and its trail, for
//! revolutions taken earlier), each particle moved by it with its own errors.

use nalgebra::{Isometry2, Vector2};

use super::ParticleFilter;
use crate::messages::Odometry;
use crate::route::wrap_angle;

/// How long the odometry trail is kept, seconds (a revolution later than this is not used).
const TRAIL_S: f64 = 2.0;

impl ParticleFilter {
    /// The odometry's reading since the last: the nominal pose is integrated along its arc (the
    /// particles follow it at the next update or estimate - a hundred readings a second, ten
    /// updates).
    pub fn on_odometry(&mut self, odometry: &Odometry) {
        if let Some(last) = self.last_odometry {
            let dt = odometry.t_s - last.t_s;
            if dt > 0.0 {
                let (v, delta, l) = (last.speed_m_s, last.steering_rad, self.wheelbase_m);
                self.travelled_m += (v * dt).abs();
                let ds = v * dt;
                let dtheta = ds * delta.tan() / l;
                let step = Isometry2::new(
                    Vector2::new(ds * (0.5 * dtheta).cos(), ds * (0.5 * dtheta).sin()),
                    dtheta,
                );
                self.odometry_pose *= step;
            }
        }
        self.last_odometry = Some(*odometry);
        self.trail.push_back((odometry.t_s, self.odometry_pose));
        while self
            .trail
            .front()
            .is_some_and(|(t, _)| *t < odometry.t_s - TRAIL_S)
        {
            self.trail.pop_front();
        }
    }

    /// Motion update: every particle moves by the odometry's displacement since the last
    /// propagation, read with its own errors - its distance times `1 + speed_scale`, its turn
    /// plus the distance times `tan(steering error) / wheelbase`.
    pub(super) fn propagate(&mut self) {
        let delta = self.propagated_at.inverse() * self.odometry_pose;
        if delta == Isometry2::identity() {
            return;
        }
        let (t, turn) = (delta.translation.vector, delta.rotation.angle());
        let d = t.norm().copysign(t.x);
        for p in &mut self.particles {
            let (s, c) = p.theta.sin_cos();
            let k = 1.0 + p.speed_scale;
            let (dx, dy) = (k * t.x, k * t.y);
            p.x += c * dx - s * dy;
            p.y += s * dx + c * dy;
            p.theta = wrap_angle(p.theta + turn + d * p.steering_rad.tan() / self.wheelbase_m);
        }
        self.propagated_at = self.odometry_pose;
        self.refresh();
    }

    /// Where the vehicle was at `t_s` in its frame now, by the odometry (`None`: before the
    /// trail, or no odometry yet).
    pub fn now_from_then(&self, t_s: f64) -> Option<Isometry2<f64>> {
        let (t_last, now) = *self.trail.back()?;
        if t_s >= t_last {
            return Some(Isometry2::identity());
        }
        let k = self.trail.partition_point(|(t, _)| *t <= t_s + 1e-9);
        let (_, then) = if k == 0 {
            // Older than the trail: only at the start, when the trail is shorter than its span.
            (t_last - self.trail.front()?.0 < TRAIL_S - 0.05).then(|| self.trail.front())??
        } else {
            self.trail.get(k - 1)?
        };
        Some(now.inverse() * then)
    }
}
