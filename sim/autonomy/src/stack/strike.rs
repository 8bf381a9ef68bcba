//! The strike rule: an airframe that felt a strike - a tug, a van or a cart running into it, or
//! it into something - stands, and calls for a pilot once it stands. What struck it may stand
//! against it where no sensor sees (a tug against the nose, under the LiDAR's lowest beam), and
//! a struck aircraft is inspected before it moves: it does not move off on its own again.
//!
//! The strike is a sensor's: the simulator tells the stack the time of a contact the airframe
//! feels (an accelerometer's jolt, a crew's word), never where or with what.

use super::Driver;
use super::status::DriverStatus;

/// The vehicle stands when odometry reads slower than this, m/s.
const STANDING_M_S: f64 = 0.05;

impl Driver {
    /// The airframe felt a strike at `t_s`: from now on the vehicle is commanded to stand
    /// ([`DriverStatus::Struck`]); once it stands, [`Driver::calls_for_pilot`] calls for a
    /// pilot. A later strike changes nothing; nor does any with `stand_when_struck` off.
    pub fn on_strike(&mut self, t_s: f64) {
        if self.struck_at_s.is_none() && self.config.stand_when_struck {
            self.struck_at_s = Some(t_s);
            self.speed_command_m_s = 0.0;
            self.status = DriverStatus::Struck { at_s: t_s };
        }
    }

    /// When the airframe felt its first strike, seconds (`None`: never).
    pub fn struck_at_s(&self) -> Option<f64> {
        self.struck_at_s
    }

    /// Whether odometry says the vehicle stands (no odometry yet: it has not moved).
    pub(super) fn standing(&self) -> bool {
        self.last_odometry
            .is_none_or(|o| o.speed_m_s.abs() < STANDING_M_S)
    }
}
