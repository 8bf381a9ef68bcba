//! A taxi route for a vehicle: its code letter from its wingspan, its tightest turn from its
//! steering, the route found on the network and rounded into a drivable path.

use std::fmt::Write as _;

use aircraft::Vehicle;
use airport::{Airport, NetworkRoute, PathOptions, Place, RouteRequest, SizeClass, TaxiPath, Tow};

use crate::error::{Error, Result};

/// Radius of a turn where the legs leave room (m). Airliners at Zurich turn on a median radius of
/// about 39 m (FACTS.md); junctions here are often tighter, so 30 m.
pub const DEFAULT_TURN_RADIUS_M: f64 = 30.0;
/// How far inside a junction's corner a turn may pass (m): about a taxiway's half width less the
/// main gear's margin for code B and C (Annex 14: 10.5 m and 15 m wide, 2.25 m and 3 m margins).
pub const MAX_CORNER_CUT_M: f64 = 2.5;
/// Taxi speed on straights (m/s): Zurich's median ground speed is 6.0 m/s (FACTS.md).
pub const DEFAULT_TAXI_SPEED_M_S: f64 = 6.0;

/// A planned taxi: what was asked, the network route and the path driven.
#[derive(Debug, Clone)]
pub struct PlannedTaxi {
    /// The vehicle's name.
    pub vehicle: String,
    /// Its code letter.
    pub code: SizeClass,
    /// The route: on the network, moved onto the painted centreline where the network strays.
    pub route: NetworkRoute,
    /// The path driven, with its speed limits.
    pub path: TaxiPath,
    /// From a stand the aircraft faces away from its taxilane: the push-back before the path
    /// (which then starts at its release point).
    pub pushback: Option<Tow>,
}

impl PlannedTaxi {
    /// `Gate 4 -> runway 28 via F, T, B (praetor600, code B)`.
    #[must_use]
    pub fn title(&self) -> String {
        format!(
            "{} -> {} via {} ({}, code {})",
            self.route.from,
            self.route.to,
            self.route.taxiways.join(", "),
            self.vehicle,
            self.code
        )
    }

    /// A few lines for a terminal.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "route {}", self.title());
        let slowest = self
            .path
            .speed_m_s
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let _ = writeln!(
            out,
            "  {:.0} m along the taxiways, {:.0} m driven; {} corner points; tightest turn {:.1} m; speed {:.1} m/s on straights, down to {:.1} in turns{}",
            self.route.length_m,
            self.path.length_m,
            self.route.points.len(),
            self.path.tightest_radius_m,
            self.path.speed_m_s.iter().copied().fold(0.0, f64::max),
            slowest,
            if self.route.crossings.is_empty() {
                String::new()
            } else {
                format!("; crosses runway zones {}", self.route.crossings.join(", "))
            }
        );
        if let Some(tow) = &self.pushback {
            let _ = writeln!(
                out,
                "  pushed back {:.0} m tail first from the stand (the tug's tightest turn {:.1} m), released on the taxilane facing the route",
                tow.length_m, tow.radius_m
            );
        }
        out
    }
}

/// How a route is rounded for `vehicle` at `turn_radius_m` (no tighter than it turns) and
/// `speed_m_s` on straights (no faster than it goes).
pub fn path_options(vehicle: &Vehicle, turn_radius_m: f64, speed_m_s: f64) -> PathOptions {
    let motion = &vehicle.spec.motion;
    PathOptions {
        turn_radius_m: turn_radius_m.max(vehicle.min_turn_radius_m()),
        max_corner_cut_m: MAX_CORNER_CUT_M,
        min_turn_radius_m: vehicle.min_turn_radius_m(),
        straight_speed_m_s: speed_m_s.min(motion.max_speed_m_s),
        lateral_acceleration_m_s2: motion.max_centripetal_acceleration_m_s2,
        deceleration_m_s2: 0.5 * motion.max_deceleration_m_s2,
    }
}

/// Plans a taxi of `vehicle` on `airport` from `from` to `to` along `via`.
///
/// # Errors
/// The vehicle is too wide for any code letter, or the route cannot be made (why).
pub fn plan_taxi(
    airport: &Airport,
    vehicle: &Vehicle,
    from: &str,
    to: &str,
    via: &[String],
    turn_radius_m: f64,
    speed_m_s: f64,
) -> Result<PlannedTaxi> {
    let span = vehicle.wingspan_m();
    let code = SizeClass::for_wingspan(span).ok_or_else(|| {
        Error::Invalid(format!(
            "{}: a wingspan of {span:.1} m has no ICAO code letter (80 m and over)",
            vehicle.spec.name
        ))
    })?;
    let request = RouteRequest {
        from: Place::parse(from),
        to: Place::parse(to),
        via: via.to_vec(),
        code,
    };
    // From a stand: on the stand as the file places the aircraft, pushed back where it faces
    // away from its taxilane (the tug turns it as tight as the aircraft itself can turn).
    let stand = match &request.from {
        Place::Stand(name) => Some(airport.find_stand(name).map_err(Error::Invalid)?),
        _ => None,
    };
    let from_stand = |route: NetworkRoute| -> Result<(NetworkRoute, Option<Tow>)> {
        match stand {
            Some(stand) => airport::leave_stand(stand, &route, vehicle.min_turn_radius_m())
                .map_err(|e| Error::Invalid(e.to_string())),
            None => Ok((route, None)),
        }
    };
    let err = |e: airport::AirportError| Error::Invalid(e.to_string());
    let (route, pushback) = from_stand(airport::find(airport, &request).map_err(err)?)?;
    let options = path_options(vehicle, turn_radius_m, speed_m_s);
    // On the paint where the network strays; should the paint's line not round for this
    // aircraft (its turn radius) where the network's does, the network's own line.
    let (route, path, pushback) = match airport::smooth(&route, &options) {
        Ok(path) => (route, path, pushback),
        Err(on_paint) => {
            let (network, pushback) =
                from_stand(airport::find_on_network(airport, &request).map_err(err)?)?;
            match airport::smooth(&network, &options) {
                Ok(path) => (network, path, pushback),
                Err(_) => return Err(Error::Invalid(on_paint.to_string())),
            }
        }
    };
    Ok(PlannedTaxi {
        vehicle: vehicle.spec.name.clone(),
        code,
        route,
        path,
        pushback,
    })
}
