//! The push-back: a tug moves the aircraft, tail first, along the route's tow path
//! (`airport::Tow`) from its stand to the release point at [`TOW_SPEED_M_S`], a kinematic motion
//! the stack does not command (it senses, maps and localizes meanwhile; its commands are
//! ignored and no pilot is called) and the judge watches as any other: contacts, and the
//! clearance to what stands round the stand - the neighbours' wing tips - in the report.

use nalgebra::Vector2;
use serde::Serialize;

use crate::world::{VehicleState, World, wrap_angle};

/// A tug's push-back speed, m/s (walking pace, as a wing walker keeps up with).
pub const TOW_SPEED_M_S: f64 = 1.0;

/// What the push-back did.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PushbackReport {
    /// Its length, metres.
    pub length_m: f64,
    /// The tug's tightest turn, metres.
    pub radius_m: f64,
    /// When the tug let go, seconds.
    pub released_s: f64,
    /// The smallest ground-truth clearance to any object during it, metres.
    pub min_clearance_m: f64,
    /// The object it came nearest (an object's id; a parked aircraft's parts share its prefix).
    pub nearest_object: Option<String>,
}

/// The tow under way.
pub(super) struct Towing {
    poses: Vec<(Vector2<f64>, f64)>,
    /// Distance along the poses to each, metres.
    along_m: Vec<f64>,
    radius_m: f64,
    s_m: f64,
    wheelbase_m: f64,
    min_clearance_m: f64,
    nearest: Option<String>,
}

impl Towing {
    /// The tow of `tow` for a vehicle of `wheelbase_m` (its odometry's steering).
    pub(super) fn new(tow: &airport::Tow, wheelbase_m: f64) -> Self {
        let mut along_m = vec![0.0];
        for w in tow.poses.windows(2) {
            along_m.push(along_m[along_m.len() - 1] + (w[1].0 - w[0].0).norm());
        }
        Towing {
            poses: tow.poses.clone(),
            along_m,
            radius_m: tow.radius_m,
            s_m: 0.0,
            wheelbase_m,
            min_clearance_m: f64::INFINITY,
            nearest: None,
        }
    }

    /// The pose `s` metres along the tow.
    fn pose_at(&self, s: f64) -> (Vector2<f64>, f64) {
        let i = self
            .along_m
            .partition_point(|&a| a <= s)
            .clamp(1, self.poses.len() - 1);
        let (a, b) = (self.poses[i - 1], self.poses[i]);
        let span = (self.along_m[i] - self.along_m[i - 1]).max(1e-9);
        let f = ((s - self.along_m[i - 1]) / span).clamp(0.0, 1.0);
        (a.0 + (b.0 - a.0) * f, a.1 + wrap_angle(b.1 - a.1) * f)
    }

    /// Moves `state` one step of `dt_s` along the tow, reversing at the tug's speed, its steering
    /// the bicycle's for the turn (what the odometry reads); true once released (the vehicle
    /// then stands, its steering straight).
    pub(super) fn step(&mut self, state: &mut VehicleState, dt_s: f64) -> bool {
        let length = self.along_m[self.along_m.len() - 1];
        self.s_m = (self.s_m + TOW_SPEED_M_S * dt_s).min(length);
        let (at, yaw) = self.pose_at(self.s_m);
        let yaw_rate = wrap_angle(yaw - state.yaw_rad) / dt_s;
        let released = self.s_m >= length;
        *state = VehicleState {
            x_m: at.x,
            y_m: at.y,
            yaw_rad: wrap_angle(yaw),
            speed_m_s: if released { 0.0 } else { -TOW_SPEED_M_S },
            // yaw_rate = v tan(steering) / wheelbase, v = -TOW_SPEED_M_S.
            steering_rad: if released {
                0.0
            } else {
                (-yaw_rate * self.wheelbase_m / TOW_SPEED_M_S).atan()
            },
        };
        released
    }

    /// Notes the clearance at the vehicle's pose now.
    pub(super) fn note(&mut self, world: &World) {
        if let Some((i, d)) = world.nearest_object_now()
            && d < self.min_clearance_m
        {
            self.min_clearance_m = d;
            self.nearest = world.scene().solids.get(i).map(|s| s.id.clone());
        }
    }

    /// The report, released at `t_s`.
    pub(super) fn report(&self, t_s: f64) -> PushbackReport {
        PushbackReport {
            length_m: self.along_m[self.along_m.len() - 1],
            radius_m: self.radius_m,
            released_s: t_s,
            min_clearance_m: self.min_clearance_m,
            nearest_object: self.nearest.clone(),
        }
    }
}
