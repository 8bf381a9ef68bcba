//! A sensor's self mask: for each of its rays, how far the beam goes before the vehicle itself
//! stops it. A return that comes from that far along its ray (less a tolerance) is the vehicle's
//! own; one nearer is something between the sensor and the airframe - a cone under the nose seen
//! by a sensor among the gears - and is kept.
//!
//! The circles' self-hit test ([`crate::SelfHitFilter`]) drops every return within a margin of
//! the vehicle's circles, whatever it is: right for a sensor above the airframe, which sees little
//! of it, but a sensor mounted low sees the gears and the fuselage's underside on many rays and
//! the ground right beside them, where the margin would hide what matters most. The mask is what
//! a real installation calibrates once (the rays that meet the airframe, at the range they do),
//! and it follows the sensor, not the vehicle's pose: no pose error moves it.

use crate::error::{MapError, Result};
use crate::scan::Scan;

/// Per ray of one sensor, `column * beams + beam`: the range at which it meets the vehicle
/// (metres; infinite where it does not).
#[derive(Clone, Debug, PartialEq)]
pub struct SelfMask {
    beams: usize,
    ranges_m: Vec<f32>,
    tolerance_m: f32,
}

impl SelfMask {
    /// The mask of a sensor of `beams` beams per column from each ray's range to the vehicle
    /// (`None`: it does not meet it); a return within `tolerance_m` of that range, or beyond it,
    /// is a self-hit. Refuses a ray count that is not whole columns, a range that is not finite
    /// and positive, or a tolerance that is not finite and >= 0.
    pub fn new(beams: usize, ranges_m: &[Option<f64>], tolerance_m: f64) -> Result<Self> {
        if beams == 0 || !ranges_m.len().is_multiple_of(beams) {
            return Err(MapError::invalid(
                "self mask",
                format!(
                    "{} rays are not whole columns of {beams} beams",
                    ranges_m.len()
                ),
            ));
        }
        if !(tolerance_m.is_finite() && tolerance_m >= 0.0) {
            return Err(MapError::invalid(
                "self mask",
                format!("tolerance {tolerance_m} m must be finite and >= 0"),
            ));
        }
        let mut out = Vec::with_capacity(ranges_m.len());
        for (i, r) in ranges_m.iter().enumerate() {
            match r {
                None => out.push(f32::INFINITY),
                Some(r) if r.is_finite() && *r > 0.0 => out.push(*r as f32),
                Some(r) => {
                    return Err(MapError::invalid(
                        "self mask",
                        format!("ray {i}: range {r} m must be finite and > 0"),
                    ));
                }
            }
        }
        Ok(SelfMask {
            beams,
            ranges_m: out,
            tolerance_m: tolerance_m as f32,
        })
    }

    /// Whether it fits `scan`: the same beams and columns.
    pub fn fits(&self, scan: &Scan) -> Result<()> {
        if scan.beams() != self.beams || scan.returns().len() != self.ranges_m.len() {
            return Err(MapError::invalid(
                "self mask",
                format!(
                    "made for {} columns x {} beams, given a scan of {} x {}",
                    self.ranges_m.len() / self.beams,
                    self.beams,
                    scan.columns().len(),
                    scan.beams()
                ),
            ));
        }
        Ok(())
    }

    /// Whether a return of ray `column * beams + beam` at `range_m` from its sensor is the
    /// vehicle's own.
    #[inline]
    pub fn is_self_hit(&self, column: usize, beam: usize, range_m: f64) -> bool {
        self.ranges_m
            .get(column * self.beams + beam)
            .is_some_and(|&r| range_m as f32 >= r - self.tolerance_m)
    }

    /// How many rays meet the vehicle.
    pub fn rays_on_the_vehicle(&self) -> usize {
        self.ranges_m.iter().filter(|r| r.is_finite()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_return_short_of_the_airframe_is_kept_and_one_on_it_is_not() {
        // Two columns of two beams: ray 1 meets the vehicle at 3 m, ray 2 at 1.5 m.
        let mask = SelfMask::new(2, &[None, Some(3.0), Some(1.5), None], 0.1).unwrap();
        assert_eq!(mask.rays_on_the_vehicle(), 2);
        assert!(
            !mask.is_self_hit(0, 0, 50.0),
            "a ray that misses the vehicle"
        );
        assert!(mask.is_self_hit(0, 1, 3.0));
        assert!(mask.is_self_hit(0, 1, 2.95), "within the tolerance");
        assert!(
            !mask.is_self_hit(0, 1, 2.85),
            "a cone 0.15 m short of the airframe"
        );
        assert!(mask.is_self_hit(1, 0, 1.6), "beyond it (noise)");
        assert!(!mask.is_self_hit(1, 0, 0.9));
        assert!(!mask.is_self_hit(5, 0, 1.0), "a ray it does not know");
    }

    #[test]
    fn bad_masks_are_refused_naming_what_is_wrong() {
        let e = SelfMask::new(2, &[None, None, None], 0.1).unwrap_err();
        assert!(e.to_string().contains("3 rays"), "{e}");
        let e = SelfMask::new(1, &[Some(-1.0)], 0.1).unwrap_err();
        assert!(e.to_string().contains("ray 0"), "{e}");
        let e = SelfMask::new(1, &[None], f64::NAN).unwrap_err();
        assert!(e.to_string().contains("tolerance"), "{e}");
        let mask = SelfMask::new(2, &[None; 4], 0.1).unwrap();
        let scan = Scan::new(1, Vec::new(), Vec::new()).unwrap();
        let e = mask.fits(&scan).unwrap_err();
        assert!(e.to_string().contains("2 columns x 2 beams"), "{e}");
    }
}
