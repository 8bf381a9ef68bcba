//! Latitude and longitude to a local metric frame at the airport's datum: the azimuthal
//! equidistant projection, made of WGS 84 geodesics (GeographicLib, georust's port).
//!
//! A point's east and north are its geodesic distance from the datum times the sine and cosine of
//! the geodesic's azimuth at the datum: distances and directions from the datum are exact, and the
//! distance between two points 5 km out differs from their geodesic distance by under a
//! millimetre (`distances_5_km_out_are_geodesic_within_a_millimetre`).

use geographiclib_rs::{DirectGeodesic, Geodesic, InverseGeodesic};
use nalgebra::Vector2;

/// A latitude and longitude in degrees (WGS 84).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatLon {
    /// Degrees north, -90..=90.
    pub lat: f64,
    /// Degrees east, -180..=180.
    pub lon: f64,
}

/// The local frame: x east, y north (m), origin at the datum.
#[derive(Debug, Clone)]
pub struct LocalFrame {
    datum: LatLon,
    geodesic: Geodesic,
}

impl LocalFrame {
    /// The frame at `datum`.
    #[must_use]
    pub fn new(datum: LatLon) -> Self {
        Self {
            datum,
            geodesic: Geodesic::wgs84(),
        }
    }

    /// Its datum.
    #[must_use]
    pub fn datum(&self) -> LatLon {
        self.datum
    }

    /// East and north of `p` (m).
    #[must_use]
    pub fn to_local(&self, p: LatLon) -> Vector2<f64> {
        let (s12, azi1, _azi2, _a12): (f64, f64, f64, f64) =
            self.geodesic
                .inverse(self.datum.lat, self.datum.lon, p.lat, p.lon);
        let azimuth = azi1.to_radians();
        Vector2::new(s12 * azimuth.sin(), s12 * azimuth.cos())
    }

    /// The latitude and longitude of a local point (the inverse of [`Self::to_local`]).
    #[must_use]
    pub fn to_lat_lon(&self, local: Vector2<f64>) -> LatLon {
        let s12 = local.norm();
        let azimuth = local.x.atan2(local.y).to_degrees();
        let (lat, lon): (f64, f64) =
            self.geodesic
                .direct(self.datum.lat, self.datum.lon, azimuth, s12);
        LatLon { lat, lon }
    }

    /// A heading in degrees true (clockwise from north) as an angle in the local frame
    /// (radians counter-clockwise from east). The projection keeps directions from the datum;
    /// elsewhere grid north turns from true north by the meridians' convergence, under 0.002 rad
    /// within 5 km at mid latitudes - corrected here by the azimuth of the local north at `at`.
    #[must_use]
    pub fn heading_to_yaw(&self, heading_deg: f64, at: LatLon) -> f64 {
        let north = self.to_local(self.geodesic_step(at, 0.0));
        let here = self.to_local(at);
        let grid_north = (north - here).y.atan2((north - here).x);
        grid_north - heading_deg.to_radians()
    }

    fn geodesic_step(&self, from: LatLon, azimuth_deg: f64) -> LatLon {
        let (lat, lon): (f64, f64) = self.geodesic.direct(from.lat, from.lon, azimuth_deg, 10.0);
        LatLon { lat, lon }
    }

    /// The geodesic distance between two points (m).
    #[must_use]
    pub fn geodesic_distance_m(&self, a: LatLon, b: LatLon) -> f64 {
        let s12: f64 = self.geodesic.inverse(a.lat, a.lon, b.lat, b.lon);
        s12
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_5_km_out_are_geodesic_within_a_millimetre() {
        let frame = LocalFrame::new(LatLon {
            lat: 43.111194444,
            lon: -76.106305556,
        });
        let mut worst: f64 = 0.0;
        for i in 0..36 {
            let angle = f64::from(i) * 10.0_f64.to_radians();
            let at = |angle: f64| {
                frame.to_lat_lon(Vector2::new(5000.0 * angle.cos(), 5000.0 * angle.sin()))
            };
            let (a, b) = (at(angle), at(angle + 60.0_f64.to_radians()));
            let local = (frame.to_local(b) - frame.to_local(a)).norm();
            worst = worst.max((local - frame.geodesic_distance_m(a, b)).abs());
        }
        assert!(worst < 1e-3, "worst {worst} m");
        assert!(worst > 0.0);
    }

    #[test]
    fn local_and_lat_lon_round_trip_within_a_micrometre() {
        let frame = LocalFrame::new(LatLon {
            lat: 43.0,
            lon: -76.0,
        });
        for p in [
            Vector2::new(1234.5, -987.0),
            Vector2::new(-4000.0, 3000.0),
            Vector2::new(0.0, 0.0),
        ] {
            let back = frame.to_local(frame.to_lat_lon(p));
            assert!((back - p).norm() < 1e-6, "{p} -> {back}");
        }
    }

    #[test]
    fn a_heading_due_east_is_yaw_zero_and_north_is_a_quarter_turn() {
        let datum = LatLon {
            lat: 43.0,
            lon: -76.0,
        };
        let frame = LocalFrame::new(datum);
        assert!((frame.heading_to_yaw(90.0, datum)).abs() < 1e-6);
        assert!((frame.heading_to_yaw(0.0, datum) - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
    }
}
