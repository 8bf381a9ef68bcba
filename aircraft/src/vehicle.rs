//! A vehicle: its sidecar spec plus its collision parts in the vehicle frame; the shipped
//! vehicles, and loading one by name or by sidecar path.

use std::path::Path;

use crate::error::{Error, Result};
use crate::fit::{FitOptions, FittedModel, fit_parts};
use crate::shapes::Part;
use crate::spec::VehicleSpec;

/// Names of the vehicles shipped in `aircraft/vehicles/`.
pub const SHIPPED_VEHICLES: [&str; 5] = [
    "praetor600",
    "iara_car",
    "iara_car_fake_wing",
    "a320",
    "praetor600_two_lidars",
];

macro_rules! shipped {
    ($name:literal) => {
        shipped!($name, $name)
    };
    ($name:literal, $urdf:literal) => {
        (
            $name,
            concat!(env!("CARGO_MANIFEST_DIR"), "/vehicles/", $name, ".toml"),
            include_str!(concat!("../vehicles/", $name, ".toml")),
            concat!(env!("CARGO_MANIFEST_DIR"), "/vehicles/", $urdf, ".urdf"),
            include_str!(concat!("../vehicles/", $urdf, ".urdf")),
        )
    };
}

/// (name, sidecar path, sidecar text, URDF path, URDF text) of each shipped vehicle.
const SHIPPED: [(&str, &str, &str, &str, &str); 5] = [
    shipped!("praetor600"),
    shipped!("iara_car"),
    shipped!("iara_car_fake_wing"),
    shipped!("a320"),
    // The same airframe with a second, low LiDAR under the nose.
    shipped!("praetor600_two_lidars", "praetor600"),
];

/// A described vehicle.
#[derive(Clone, Debug, PartialEq)]
pub struct Vehicle {
    /// What the sidecar says.
    pub spec: VehicleSpec,
    /// Every collision primitive, in the vehicle frame.
    pub parts: Vec<Part>,
}

impl Vehicle {
    /// A vehicle from sidecar and URDF texts; the file names label errors.
    pub fn from_strs(
        spec_toml: &str,
        spec_file: &str,
        urdf: &str,
        urdf_file: &str,
    ) -> Result<Self> {
        let spec = VehicleSpec::from_str(spec_toml, spec_file)?;
        let parts = crate::urdf::parts_from_str(urdf, urdf_file)?;
        let vehicle = Vehicle { spec, parts };
        if let Some(wingspan) = vehicle.spec.wingspan_m
            && (wingspan - vehicle.span_m()).abs() > 1.0
        {
            return Err(Error::Field {
                file: spec_file.to_string(),
                field: "wingspan_m".to_string(),
                message: format!(
                    "{wingspan} m is more than 1 m from the span of the URDF's parts ({:.2} m)",
                    vehicle.span_m()
                ),
            });
        }
        Ok(vehicle)
    }

    /// Reads a sidecar file and the URDF it names (relative to the sidecar's directory).
    pub fn from_file(spec_path: &Path) -> Result<Self> {
        let read = |path: &Path| {
            std::fs::read_to_string(path).map_err(|error| Error::Io {
                path: path.to_path_buf(),
                error,
            })
        };
        let spec_text = read(spec_path)?;
        let spec_file = spec_path.display().to_string();
        let spec = VehicleSpec::from_str(&spec_text, &spec_file)?;
        let urdf_path = spec_path
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join(&spec.urdf);
        let urdf_text = read(&urdf_path)?;
        let parts = crate::urdf::parts_from_str(&urdf_text, &urdf_path.display().to_string())?;
        Ok(Vehicle { spec, parts })
    }

    /// A shipped vehicle by name (compiled in: works wherever the binary runs).
    pub fn shipped(name: &str) -> Result<Self> {
        let (_, spec_file, spec_text, urdf_file, urdf_text) = SHIPPED
            .iter()
            .find(|s| s.0 == name)
            .ok_or_else(|| Error::UnknownVehicle {
                name: name.to_string(),
                known: SHIPPED_VEHICLES.join(", "),
            })?;
        Vehicle::from_strs(spec_text, spec_file, urdf_text, urdf_file)
    }

    /// A shipped vehicle name, or else a path to a sidecar file.
    pub fn load(name_or_path: &str) -> Result<Self> {
        let path = Path::new(name_or_path);
        if SHIPPED_VEHICLES.contains(&name_or_path) {
            Vehicle::shipped(name_or_path)
        } else if !path.exists() && path.extension().is_none() {
            // Neither a shipped name nor a file: say what the names are.
            Vehicle::shipped(name_or_path)
        } else {
            Vehicle::from_file(path)
        }
    }

    /// Pose of the LiDAR in the vehicle frame (the sidecar's `lidar.xyz_m` and `lidar.rpy_rad`).
    pub fn vehicle_from_lidar(&self) -> nalgebra::Isometry3<f64> {
        self.spec.lidar.vehicle_from_lidar()
    }

    /// Its wingspan, metres: the sidecar's `wingspan_m` (the real aircraft's) or else the parts'
    /// span ([`Self::span_m`]). An aircraft's ICAO code letter follows from it.
    pub fn wingspan_m(&self) -> f64 {
        self.spec.wingspan_m.unwrap_or_else(|| self.span_m())
    }

    /// The parts' span: twice the farthest any part reaches from the centreline (y = 0), metres.
    pub fn span_m(&self) -> f64 {
        self.parts
            .iter()
            .map(|p| {
                let (low, high) = p.footprint().bounds();
                low.y.abs().max(high.y.abs())
            })
            .fold(0.0, f64::max)
            * 2.0
    }

    /// The radius of its tightest turn, at the reference point (rear axle, main gear): wheelbase
    /// over the tangent of the largest steering angle, metres.
    pub fn min_turn_radius_m(&self) -> f64 {
        self.spec.motion.wheelbase_m / self.spec.motion.max_steering_angle_rad.tan()
    }

    /// The vehicle's top: the highest point of its collision parts above the ground, metres
    /// (0 for a vehicle without parts).
    pub fn top_m(&self) -> f64 {
        self.parts.iter().map(|p| p.top_m()).fold(0.0, f64::max)
    }

    /// The map's ceiling for this vehicle: its top plus the sidecar's `overhead_clearance_m`,
    /// metres above the ground. Returns at or above it belong to no level.
    pub fn ceiling_m(&self) -> f64 {
        self.top_m() + self.spec.overhead_clearance_m
    }

    /// Fits the circle model with the spec's heights of interest and fit options.
    pub fn fit(&self) -> Result<FittedModel> {
        self.fit_with(&self.spec.heights_of_interest_m, &self.spec.fit)
    }

    /// Fits the circle model with other heights or options. A run asks for the same fits more
    /// than once (its collision model, then the self-hit filter's banded model for the online map
    /// and again for the localizer's), and every run of a campaign for the same ones: the last
    /// [`FIT_MEMO_SIZE`] fits are kept, process-wide, keyed by the parts, heights and options
    /// exactly (their debug text: floats print in the shortest form that reads back to the same
    /// bits). [`fit_parts`] is a pure function, so a kept fit is the fit.
    pub fn fit_with(&self, heights_m: &[f64], options: &FitOptions) -> Result<FittedModel> {
        let key = format!("{:?}|{heights_m:?}|{options:?}", self.parts);
        let memo = || {
            FIT_MEMO
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        };
        if let Some((_, fit)) = memo().iter().find(|(k, _)| *k == key) {
            return Ok(fit.clone());
        }
        let fit = fit_parts(&self.parts, heights_m, options)?;
        let mut kept = memo();
        if kept.len() >= FIT_MEMO_SIZE {
            kept.remove(0);
        }
        kept.push((key, fit.clone()));
        Ok(fit)
    }
}

/// How many fits [`Vehicle::fit_with`] keeps (a campaign's vehicles: two fits each).
pub const FIT_MEMO_SIZE: usize = 16;

/// The fits kept, oldest first, each under its key.
static FIT_MEMO: std::sync::Mutex<Vec<(String, FittedModel)>> = std::sync::Mutex::new(Vec::new());
