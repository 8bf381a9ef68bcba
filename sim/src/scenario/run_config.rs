//! The run configuration: everything that decides what a run does besides the scenario and the
//! seed - rates, the LiDAR, mapping and forgetting, the planner and avoider, the pose source, the
//! collision model, faults - as one typed value, read from and written to TOML (`taxi-sim run
//! --config FILE`, `taxi-sim config`). A report records the configuration it ran with.

use autonomy::{AutonomyConfig, ForgettingConfig};
use mapper::{Circle, CollisionModel, MapConfig};
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::world::{FaultsConfig, LidarConfig};

/// One run's configuration. Every field has a documented default (`RunConfig::default()`), so a
/// file need only hold what it changes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// Physics rate (vehicle motion, ground truth, moving obstacles), Hz. Default 100.
    pub physics_hz: f64,
    /// LiDAR revolution, map update and planning rate, Hz. Default 10.
    pub scan_hz: f64,
    /// When a revolution is mapped and planned from. Default `overlapped`.
    pub schedule: Schedule,
    /// The synthetic HDL-32E.
    pub lidar: LidarConfig,
    /// The online map, its distance maps and forgetting.
    pub mapping: MappingConfig,
    /// Planner, avoider and follower.
    pub autonomy: AutonomyConfig,
    /// Where the stack's pose estimate comes from. Default the particle filter.
    pub pose_source: PoseSourceConfig,
    /// The vehicle's circle model the stack checks. Default: the vehicle's own fit.
    pub collision_model: CollisionModelConfig,
    /// The odometry's noise and bias (`crate::world`).
    pub odometry: crate::world::OdometryConfig,
    /// Faults injected between the world and the stack (`crate::world`): lost revolutions,
    /// beam dropout, dead beams, range noise, spurious returns, pose bias and drift. None by
    /// default.
    pub faults: FaultsConfig,
}

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig {
            physics_hz: 100.0,
            scan_hz: 10.0,
            schedule: Schedule::Overlapped,
            lidar: LidarConfig::default(),
            mapping: MappingConfig::default(),
            autonomy: AutonomyConfig::default(),
            pose_source: PoseSourceConfig::default(),
            collision_model: CollisionModelConfig::Vehicle,
            odometry: crate::world::OdometryConfig::default(),
            faults: FaultsConfig::default(),
        }
    }
}

/// When each revolution is mapped and planned from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Schedule {
    /// As on the vehicle: a revolution is mapped while the next ten physics steps run and the
    /// LiDAR takes the next one; the plan is made from the pose now over a map one revolution
    /// (0.1 s) old.
    #[default]
    Overlapped,
    /// Each revolution mapped and planned the instant it is taken (no latency; slower).
    Sequential,
}

/// The online map, its distance maps and forgetting.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MappingConfig {
    /// The map (cells, blocks, log-odds, obstacle test, self-hit margin). Default: the mapper's
    /// defaults with a 1.5 m self-hit margin and returns [`OBSTACLE_HEIGHT_M`] (0.1 m) above the
    /// flat ground obstacles whatever the consecutive-beam test says. The offline map is built with the same settings;
    /// its fingerprint holds them. `max_distance_m` is set by the run from the vehicle and planner
    /// (`run::distance_cap_m`). A `[mapping.map]` that names some fields keeps these defaults
    /// for the others (`map_over_the_defaults`), not the mapper's own.
    #[serde(deserialize_with = "map_over_the_defaults")]
    pub map: MapConfig,
    /// Distance maps are kept over a square of this half side around the estimate, metres.
    /// Default `None`: `run::distance_map_half_size_m` of the vehicle and planner.
    pub distance_map_half_size_m: Option<f64>,
    /// How live occupancy no longer seen fades to the offline map.
    pub forgetting: ForgettingConfig,
    /// The heights of interest of the map's levels and of the circle model, metres (h_0 = 0,
    /// increasing). Default `None`: the vehicle's (`heights_of_interest_m` in its sidecar). A
    /// tuning sweep sets it; the offline map follows (its fingerprint holds the levels).
    pub heights_of_interest_m: Option<Vec<f64>>,
    /// Mapping starts with the first revolution whose pose estimate's 2-sigma error moves a
    /// return at the obstacle test's range (70 m) by less than this, metres
    /// (`autonomy::trusted_range_m`; `OnlineMap::update`). Default 1.0: the particle filter
    /// gets there about 0.5 s after its fix. The fix itself, 0.05 rad off (one sigma), puts a
    /// return 70 m away 3.5 m from where it is.
    pub max_return_error_m: f64,
}

/// Height above the ground from which a return is an obstacle whatever the consecutive-beam
/// test says, metres (the mapper's `unsafe_height_above_ground_m`, 1.0 m by default).
///
/// That test sees an object only where it rises more than about half a beam spacing (0.49 x
/// range x 1.33 deg for the HDL-32E): 0.11 m at 10 m, 0.23 m at 20 m, 0.45 m at 40 m. A 0.15 m
/// piece of debris is ground to it beyond about 14 m, and the car's own cabin hides the ground
/// closer than about 10 m straight ahead, so the car of `closed_loop_pose_file` first had the
/// debris in its map 12.7 m ahead: too late to go round it (it stopped against it, forgot it and
/// drove over it). The simulator's ground is flat (z = 0) and a ground return's height is off by
/// under 0.011 m rms (2 cm of range noise at the steepest beam, 30.67 deg, as the sensor had
/// before its calibration; 4 mm since, 0.002 m), so 0.1 m is far
/// outside the noise and below anything the vehicles must not touch (the debris, 0.15 m; the
/// car's body clears 0.2 m, its wheels nothing).
pub const OBSTACLE_HEIGHT_M: f64 = 0.1;

/// Below this height above the ground no hit is an obstacle in the simulator's maps (CARMEN's
/// `safe_height_from_ground`): about 4.5 standard deviations of a ground return's height error
/// with the old 2 cm noise (0.011 m, above); kept for a sensor as noisy as the datasheet allows. Without it, ground hits a
/// few metres ahead of the jet's nose-mounted sensor, 0.15 m apart, read as obstacles often
/// enough to stop a jet whose margins the localizer's uncertainty had widened.
pub const SAFE_HEIGHT_FROM_GROUND_M: f64 = 0.05;

impl Default for MappingConfig {
    fn default() -> Self {
        let map = MapConfig::default();
        MappingConfig {
            map: MapConfig {
                self_hit_margin_m: 1.5,
                obstacle_test: mapper::ObstacleTestParams {
                    unsafe_height_above_ground_m: Some(OBSTACLE_HEIGHT_M),
                    safe_height_from_ground_m: SAFE_HEIGHT_FROM_GROUND_M,
                    ..map.obstacle_test
                },
                ..map
            },
            distance_map_half_size_m: None,
            forgetting: ForgettingConfig::default(),
            heights_of_interest_m: None,
            max_return_error_m: 1.0,
        }
    }
}

/// A `[mapping.map]` table read over [`MappingConfig::default`]'s map: the fields it names
/// replace the defaults', the others keep them (serde's own `default` would take the mapper's
/// defaults for them - a 0.8 m self-hit margin, obstacles only from 1 m up - and a table naming
/// one field would silently change three others).
fn map_over_the_defaults<'de, D: serde::Deserializer<'de>>(d: D) -> Result<MapConfig, D::Error> {
    use serde::de::Error as _;
    let given = toml::Table::deserialize(d)?;
    let mut table =
        toml::Table::try_from(MappingConfig::default().map).map_err(D::Error::custom)?;
    for (key, value) in given {
        crate::toml_file::set_path(&mut table, &key, value);
    }
    MapConfig::deserialize(toml::Value::Table(table)).map_err(D::Error::custom)
}

/// Where the stack's pose estimate comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PoseSourceConfig {
    /// The true pose at every physics step.
    Truth,
    /// The true pose with a seeded error, published at a localizer's rate: a first-order
    /// Gauss-Markov drift (the slowly wandering error of a localizer) plus white noise (its
    /// jitter), both in the vehicle frame (along track, across track, heading).
    NoisyTruth(NoisyTruthConfig),
    /// The particle filter over the offline map (`autonomy::localizer`): odometry, the remission
    /// map and/or the likelihood field; the estimate's covariance widens the margins. The
    /// default.
    ParticleFilter(autonomy::localizer::LocalizerConfig),
}

impl Default for PoseSourceConfig {
    fn default() -> Self {
        PoseSourceConfig::ParticleFilter(Default::default())
    }
}

/// The noisy-truth pose source's error model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoisyTruthConfig {
    /// Publication rate, Hz. Default 20 (between estimates the stack dead-reckons on odometry).
    pub rate_hz: f64,
    /// Steady-state standard deviation of the drift in position, metres (each axis). Default 0.
    pub drift_sigma_m: f64,
    /// Steady-state standard deviation of the drift in heading, radians. Default 0.
    pub drift_sigma_rad: f64,
    /// Correlation time of the drift, seconds. Default 5.
    pub drift_time_constant_s: f64,
    /// Standard deviation of the white noise in position, metres (each axis). Default 0.
    pub white_sigma_m: f64,
    /// Standard deviation of the white noise in heading, radians. Default 0.
    pub white_sigma_rad: f64,
}

impl Default for NoisyTruthConfig {
    fn default() -> Self {
        NoisyTruthConfig {
            rate_hz: 20.0,
            drift_sigma_m: 0.0,
            drift_sigma_rad: 0.0,
            drift_time_constant_s: 5.0,
            white_sigma_m: 0.0,
            white_sigma_rad: 0.0,
        }
    }
}

/// The vehicle's circle model the stack checks against the distance maps.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "source", rename_all = "snake_case", deny_unknown_fields)]
pub enum CollisionModelConfig {
    /// Fitted from the vehicle's URDF with its sidecar's fit options.
    #[default]
    Vehicle,
    /// Fitted from the vehicle's URDF with these options (a tuning run's, without editing the
    /// vehicle's files).
    Fit {
        /// The fit options.
        options: aircraft::FitOptions,
    },
    /// These circles as they are, at the vehicle's heights of interest.
    Circles {
        /// `x_m`, `y_m`, `radius_m`, `level` each.
        circles: Vec<Circle>,
    },
}

impl RunConfig {
    /// Reads a configuration from TOML text; `origin` names it in errors (a file's path), which
    /// give the line, column and field.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, Error> {
        let config: RunConfig = toml::from_str(text)
            .map_err(|e| crate::toml_file::LocatedError::toml(origin, text, &e))?;
        config.validate().map_err(|message| Error::Config {
            origin: origin.to_string(),
            message,
        })?;
        Ok(config)
    }

    /// A configuration from a TOML table (a scenario's `[config]`, a campaign setting): the
    /// message names the field at fault.
    pub fn from_table(table: toml::Table) -> Result<Self, String> {
        let config: RunConfig = toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| e.message().to_string())?;
        config.validate()?;
        Ok(config)
    }

    /// The run configuration of `scenario`: the defaults, its `[config]` over them, and the
    /// file at `path` (a `--config` file) over that.
    pub fn for_scenario(
        scenario: &super::model::Scenario,
        path: Option<&std::path::Path>,
    ) -> Result<Self, Error> {
        let mut table = scenario.config.clone().unwrap_or_default();
        let origin = scenario.path.display().to_string();
        if let Some(p) = path {
            // Read alone first: its mistakes are located in it.
            Self::from_file(p)?;
            let text = std::fs::read_to_string(p).map_err(|source| Error::Io {
                what: "reading the run configuration",
                path: p.to_path_buf(),
                source,
            })?;
            let over: toml::Table = toml::from_str(&text).map_err(|e| {
                crate::toml_file::LocatedError::toml(&p.display().to_string(), &text, &e)
            })?;
            for (k, v) in over {
                crate::toml_file::set_path(&mut table, &k, v);
            }
        }
        Self::from_table(table).map_err(|message| Error::Config { origin, message })
    }

    /// Reads a configuration file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, Error> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            what: "reading the run configuration",
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// The configuration as TOML.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_else(|e| format!("# not representable: {e}\n"))
    }

    /// Checks the values a run relies on; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        // No number of a configuration may be NaN or infinite, whatever field it is in.
        if let Ok(v) = toml::Value::try_from(self)
            && let Some((path, x)) = non_finite(&v, String::new())
        {
            return Err(format!("{path} = {x}: must be a finite number"));
        }
        let positive = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{field} = {v}: must be a finite number > 0"))
            }
        };
        let non_negative = |field: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(format!("{field} = {v}: must be a finite number >= 0"))
            }
        };
        positive("physics_hz", self.physics_hz)?;
        positive("scan_hz", self.scan_hz)?;
        if self.scan_hz > self.physics_hz {
            return Err(format!(
                "scan_hz = {} is above physics_hz = {}: a revolution needs at least one physics step",
                self.scan_hz, self.physics_hz
            ));
        }
        positive(
            "mapping.max_return_error_m",
            self.mapping.max_return_error_m,
        )?;
        if let Some(h) = self.mapping.distance_map_half_size_m {
            positive("mapping.distance_map_half_size_m", h)?;
        }
        self.faults.validate()?;
        positive("autonomy.watchdog_s", self.autonomy.watchdog_s)?;
        if let Some(h) = &self.mapping.heights_of_interest_m {
            aircraft::fit::check_heights(h)
                .map_err(|m| format!("mapping.heights_of_interest_m = {h:?}: {m}"))?;
        }
        positive(
            "mapping.forgetting.time_constant_s",
            self.mapping.forgetting.time_constant_s,
        )?;
        positive(
            "mapping.forgetting.half_size_m",
            self.mapping.forgetting.half_size_m,
        )?;
        if let Some((field, v)) = self.mapping.forgetting.tracking.invalid_field() {
            return Err(format!(
                "mapping.forgetting.tracking.{field} = {v}: out of range (see `taxi-sim config`)"
            ));
        }
        let a = &self.autonomy;
        positive("autonomy.horizon_m", a.horizon_m)?;
        if a.max_horizon_m.partial_cmp(&a.horizon_m) == Some(std::cmp::Ordering::Less)
            || !a.max_horizon_m.is_finite()
        {
            return Err(format!(
                "autonomy.max_horizon_m = {} must be finite and at least autonomy.horizon_m = {}",
                a.max_horizon_m, a.horizon_m
            ));
        }
        if let Some((field, v)) = a.traffic.invalid_field() {
            return Err(format!(
                "autonomy.traffic.{field} = {v}: out of range (see `taxi-sim config`)"
            ));
        }
        positive("autonomy.step_m", a.step_m)?;
        positive("autonomy.offset_step_m", a.offset_step_m)?;
        positive("autonomy.transition_m", a.transition_m)?;
        non_negative("autonomy.max_offset_m", a.max_offset_m)?;
        non_negative("autonomy.planner_safety_m", a.planner_safety_m as f64)?;
        non_negative("autonomy.avoider_safety_m", a.avoider_safety_m as f64)?;
        positive("autonomy.hidden_after_s", a.hidden_after_s)?;
        positive("autonomy.pilot_call_after_s", a.pilot_call_after_s)?;
        positive("autonomy.blocked_call_after_s", a.blocked_call_after_s)?;
        if let Some(r) = a.detection_range_m {
            positive("autonomy.detection_range_m", r)?;
        }
        non_negative("autonomy.uncertainty_sigmas", a.uncertainty_sigmas)?;
        non_negative("autonomy.uncertainty_slow_m", a.uncertainty_slow_m)?;
        if a.uncertainty_stop_m.partial_cmp(&a.uncertainty_slow_m)
            != Some(std::cmp::Ordering::Greater)
        {
            return Err(format!(
                "autonomy.uncertainty_stop_m = {} must be above autonomy.uncertainty_slow_m = {}",
                a.uncertainty_stop_m, a.uncertainty_slow_m
            ));
        }
        self.odometry.validate()?;
        if let PoseSourceConfig::ParticleFilter(l) = &self.pose_source {
            l.validate().map_err(|e| format!("pose_source.{e}"))?;
        }
        if let PoseSourceConfig::NoisyTruth(n) = &self.pose_source {
            positive("pose_source.rate_hz", n.rate_hz)?;
            positive("pose_source.drift_time_constant_s", n.drift_time_constant_s)?;
            for (field, v) in [
                ("pose_source.drift_sigma_m", n.drift_sigma_m),
                ("pose_source.drift_sigma_rad", n.drift_sigma_rad),
                ("pose_source.white_sigma_m", n.white_sigma_m),
                ("pose_source.white_sigma_rad", n.white_sigma_rad),
            ] {
                non_negative(field, v)?;
            }
        }
        Ok(())
    }

    /// The heights of interest this configuration gives `vehicle`: its own unless
    /// `mapping.heights_of_interest_m` says otherwise.
    pub fn heights_of_interest_m<'a>(&'a self, vehicle: &'a aircraft::Vehicle) -> &'a [f64] {
        self.mapping
            .heights_of_interest_m
            .as_deref()
            .unwrap_or(&vehicle.spec.heights_of_interest_m)
    }

    /// The circle model this configuration gives `vehicle`.
    pub fn collision_model(&self, vehicle: &aircraft::Vehicle) -> Result<CollisionModel, Error> {
        let heights = &self.heights_of_interest_m(vehicle).to_vec();
        Ok(match &self.collision_model {
            CollisionModelConfig::Vehicle => vehicle.fit_with(heights, &vehicle.spec.fit)?.model,
            CollisionModelConfig::Fit { options } => vehicle.fit_with(heights, options)?.model,
            CollisionModelConfig::Circles { circles } => {
                CollisionModel::new(circles.clone(), heights.clone()).map_err(|e| {
                    Error::Config {
                        origin: "collision_model.circles".into(),
                        message: e.to_string(),
                    }
                })?
            }
        })
    }
}

/// The dotted path and value of the first non-finite float in `v`.
fn non_finite(v: &toml::Value, path: String) -> Option<(String, f64)> {
    let join = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        toml::Value::Float(x) if !x.is_finite() => Some((path, *x)),
        toml::Value::Table(t) => t.iter().find_map(|(k, x)| non_finite(x, join(k))),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| non_finite(x, format!("{path}[{i}]"))),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `[mapping.map]` naming some fields keeps the run's defaults for the others (a 1.5 m
    /// self-hit margin, obstacles from 0.1 m up), nested tables too; an unknown field is still
    /// refused by name.
    #[test]
    fn a_partial_map_table_keeps_the_runs_defaults_for_the_rest() {
        let c = RunConfig::from_toml(
            "[mapping.map]\nintensity_falloff_per_m = 0.004\n[mapping.map.obstacle_test]\nsigma = 0.5\n",
            "test",
        )
        .expect("config");
        let mut want = RunConfig::default();
        want.mapping.map.intensity_falloff_per_m = 0.004;
        want.mapping.map.obstacle_test.sigma = 0.5;
        assert_eq!(c, want);
        assert_eq!(c.mapping.map.self_hit_margin_m, 1.5);
        assert_eq!(
            c.mapping.map.obstacle_test.unsafe_height_above_ground_m,
            Some(OBSTACLE_HEIGHT_M)
        );
        let e = RunConfig::from_toml("[mapping.map]\nself_hit_margin = 2.0\n", "test")
            .expect_err("an unknown field");
        assert!(e.to_string().contains("self_hit_margin"), "{e}");
    }

    #[test]
    fn a_configuration_survives_toml_both_ways() {
        let mut c = RunConfig {
            schedule: Schedule::Sequential,
            pose_source: PoseSourceConfig::NoisyTruth(NoisyTruthConfig {
                drift_sigma_m: 0.2,
                white_sigma_rad: 0.01,
                ..Default::default()
            }),
            collision_model: CollisionModelConfig::Circles {
                circles: vec![Circle {
                    x_m: 1.0,
                    y_m: -0.5,
                    radius_m: 1.2,
                    level: 0,
                }],
            },
            ..RunConfig::default()
        };
        c.mapping.forgetting.rule = autonomy::ForgettingRule::TimeDecay;
        c.mapping.forgetting.tracking.enabled = false;
        c.autonomy.planner_safety_m = 0.8;
        let text = c.to_toml();
        assert_eq!(RunConfig::from_toml(&text, "t").unwrap(), c, "{text}");
        let fit = RunConfig {
            collision_model: CollisionModelConfig::Fit {
                options: aircraft::FitOptions {
                    max_circles: Some(12),
                    ..Default::default()
                },
            },
            ..RunConfig::default()
        };
        assert_eq!(RunConfig::from_toml(&fit.to_toml(), "t").unwrap(), fit);
    }

    #[test]
    fn a_partial_file_keeps_the_defaults_and_bad_values_name_their_field() {
        let c = RunConfig::from_toml("[autonomy]\nplanner_safety_m = 0.9\n", "f.toml").unwrap();
        assert_eq!(c.autonomy.planner_safety_m, 0.9);
        assert_eq!(c.autonomy.horizon_m, AutonomyConfig::default().horizon_m);
        assert_eq!(c.physics_hz, 100.0);
        for (text, field) in [
            ("scan_hz = 0.0\n", "scan_hz"),
            ("scan_hz = 200.0\n", "scan_hz"),
            (
                "[mapping.forgetting]\ntime_constant_s = -1.0\n",
                "mapping.forgetting.time_constant_s",
            ),
            (
                "[pose_source]\nkind = \"noisy_truth\"\nwhite_sigma_m = nan\n",
                "pose_source.white_sigma_m",
            ),
            ("[autonomy]\nstep_m = 0.0\n", "autonomy.step_m"),
            (
                "[autonomy]\nmax_horizon_m = 20.0\n",
                "autonomy.max_horizon_m",
            ),
            (
                "[autonomy.traffic]\nhorizon_s = 0.0\n",
                "autonomy.traffic.horizon_s",
            ),
            (
                "[autonomy.traffic]\nsigmas = -1.0\n",
                "autonomy.traffic.sigmas",
            ),
            (
                "[lidar]\natmosphere_attenuation_rate = nan\n",
                "lidar.atmosphere_attenuation_rate",
            ),
            ("[autonomy]\nw_offset = inf\n", "autonomy.w_offset"),
            (
                "[mapping]\nheights_of_interest_m = [0.5, 1.0]\n",
                "mapping.heights_of_interest_m",
            ),
            (
                "[mapping]\nheights_of_interest_m = [0.0, 1.0, 1.0]\n",
                "mapping.heights_of_interest_m",
            ),
        ] {
            let e = RunConfig::from_toml(text, "f.toml")
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("f.toml") && e.contains(field), "{text}: {e}");
        }
        let e = RunConfig::from_toml("[pose_source]\nkind = \"gps\"\n", "f.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("f.toml:2:") && e.contains("gps"), "{e}");
    }
}
