//! A track's motion: a constant-velocity Kalman filter on the centre of its hits.

use nalgebra::{Matrix2, Matrix4, Point2, Vector2, Vector4};

/// A constant-velocity Kalman filter on the centre of a track's hits: state `[x, y, vx, vy]`.
#[derive(Clone, Debug)]
pub(super) struct Motion {
    /// The state `[x, y, vx, vy]`.
    pub(super) x: Vector4<f64>,
    /// The state's covariance.
    pub(super) p: Matrix4<f64>,
}

impl Motion {
    /// At `at`, standing, its velocity unknown up to `speed_sigma` m/s.
    pub(super) fn new(
        at: Point2<f64>,
        velocity: Vector2<f64>,
        position_sigma: f64,
        speed_sigma: f64,
    ) -> Self {
        let (ps, vs) = (position_sigma * position_sigma, speed_sigma * speed_sigma);
        Motion {
            x: Vector4::new(at.x, at.y, velocity.x, velocity.y),
            p: Matrix4::from_diagonal(&Vector4::new(ps, ps, vs, vs)),
        }
    }

    /// Carried `dt` seconds forward, with white-noise acceleration of `sigma_a`.
    pub(super) fn predict(&mut self, dt: f64, sigma_a: f64) {
        let mut f = Matrix4::identity();
        f[(0, 2)] = dt;
        f[(1, 3)] = dt;
        self.x = f * self.x;
        let q = sigma_a * sigma_a;
        let (a, b, c) = (q * dt.powi(4) / 4.0, q * dt.powi(3) / 2.0, q * dt * dt);
        let mut noise = Matrix4::zeros();
        for i in 0..2 {
            noise[(i, i)] = a;
            noise[(i, i + 2)] = b;
            noise[(i + 2, i)] = b;
            noise[(i + 2, i + 2)] = c;
        }
        self.p = f * self.p * f.transpose() + noise;
    }

    /// Corrected by a measured centre with standard deviation `sigma`.
    pub(super) fn correct(&mut self, at: Point2<f64>, sigma: f64) {
        let h = nalgebra::Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let s = h * self.p * h.transpose() + Matrix2::identity() * (sigma * sigma);
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let k = self.p * h.transpose() * s_inv;
        let innovation = at.coords - h * self.x;
        self.x += k * innovation;
        self.p = (Matrix4::identity() - k * h) * self.p;
        // Kept symmetric against rounding.
        self.p = 0.5 * (self.p + self.p.transpose());
    }

    /// Its velocity, m/s.
    pub(super) fn velocity(&self) -> Vector2<f64> {
        Vector2::new(self.x[2], self.x[3])
    }
}
