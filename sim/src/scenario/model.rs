//! The scenario, resolved: what a run is given ([`Scenario`]: the [`Ground`], the
//! [`ScenarioVehicle`] at its start pose, the [`Route`], static objects, patches and run-time
//! [`Obstacle`]s with their expectations), read by [`Scenario::from_str`] (which loads the files
//! the text names, a vehicle sidecar or a pose file, relative to the scenario's directory) or
//! [`Scenario::from_file`], and turned into the worlds a run drives in ([`Scenario::full_scene`],
//! [`Scenario::static_scene`]). World frame: x east, y north, z up, metres, radians.

use std::path::{Path, PathBuf};

use nalgebra::{Isometry2, Point2};

use super::resolve::Resolver;
use super::spec::{Expectation, ExpectedEnd, ScenarioFile};
use crate::toml_file::LocatedError;
use crate::world::{Patch, Scene, Solid};

/// The ground.
#[derive(Clone, Debug, PartialEq)]
pub struct Ground {
    /// Lower corner (x, y), metres.
    pub min_m: [f64; 2],
    /// Upper corner (x, y), metres.
    pub max_m: [f64; 2],
    /// Remission of bare ground in [0, 1].
    pub ground_remission: f32,
    /// Amplitude of the pavement's texture (`[world] pavement_texture`).
    pub pavement_texture: f32,
}

/// The vehicle of a scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioVehicle {
    /// The description as written (a shipped name or a sidecar path).
    pub description: String,
    /// The vehicle: sidecar spec and collision parts.
    pub vehicle: aircraft::Vehicle,
    /// Start pose of the vehicle frame in the world.
    pub world_from_start: Isometry2<f64>,
}

/// The route.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// Waypoints in the world, metres (the first is not repeated at the end of a closed route).
    pub waypoints_m: Vec<Point2<f64>>,
    /// Headings given by a pose file, one per waypoint (`None` where not given).
    pub yaws_rad: Vec<Option<f64>>,
    /// True when the last waypoint joins the first.
    pub closed: bool,
    /// Target speed, m/s.
    pub speed_m_s: f64,
}

impl Route {
    /// Length of one lap, metres (with the closing segment of a closed route).
    pub fn length_m(&self) -> f64 {
        let open: f64 = self
            .waypoints_m
            .windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .sum();
        match (
            self.closed,
            self.waypoints_m.first(),
            self.waypoints_m.last(),
        ) {
            (true, Some(first), Some(last)) => open + (first - last).norm(),
            _ => open,
        }
    }
}

/// How a run-time obstacle moves.
#[derive(Clone, Debug, PartialEq)]
pub struct ObstacleMotion {
    /// The polyline followed from its appearance, metres.
    pub path_m: Vec<Point2<f64>>,
    /// Speed along it, m/s.
    pub speed_m_s: f64,
    /// Offset of the obstacle's heading to the heading of the path, radians.
    pub yaw_offset_rad: f64,
}

/// A run-time obstacle.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Its solid at its initial pose (`runtime` is true).
    pub solid: Solid,
    /// What the vehicle must do.
    pub expect: Expectation,
    /// When it appears, seconds.
    pub appears_s: f64,
    /// When it disappears, seconds (`None`: never).
    pub disappears_s: Option<f64>,
    /// Its motion (`None`: static).
    pub motion: Option<ObstacleMotion>,
}

impl Obstacle {
    /// Its pose `(x_m, y_m, yaw_rad)` at time `t_s`, or `None` when it is absent then.
    pub fn pose_at(&self, t_s: f64) -> Option<(f64, f64, f64)> {
        if t_s < self.appears_s || self.disappears_s.is_some_and(|d| t_s >= d) {
            return None;
        }
        let Some(motion) = &self.motion else {
            return Some((self.solid.x_m, self.solid.y_m, self.solid.yaw_rad));
        };
        let mut left_m = motion.speed_m_s * (t_s - self.appears_s);
        let mut last = (self.solid.x_m, self.solid.y_m, self.solid.yaw_rad);
        for w in motion.path_m.windows(2) {
            let d = w[1] - w[0];
            let len = d.norm();
            let yaw = d.y.atan2(d.x) + motion.yaw_offset_rad;
            if left_m <= len {
                let p = w[0] + d * (left_m / len);
                return Some((p.x, p.y, yaw));
            }
            left_m -= len;
            last = (w[1].x, w[1].y, yaw);
        }
        Some(last)
    }
}

/// A validated scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// The file it was read from (or the label given to [`Scenario::from_str`]).
    pub path: PathBuf,
    /// Short human name.
    pub name: String,
    /// Free text.
    pub description: Option<String>,
    /// Seed of every random draw of a run.
    pub seed: u64,
    /// Laps of the route, >= 1.
    pub laps: u32,
    /// The ground.
    pub world: Ground,
    /// The vehicle and its start pose.
    pub vehicle: ScenarioVehicle,
    /// The route.
    pub route: Route,
    /// Static objects (`runtime` false): the `[[objects]]` in file order, then the objects of
    /// each `[[rows]]` in file order.
    pub objects: Vec<Solid>,
    /// Painted patches.
    pub patches: Vec<Patch>,
    /// Run-time obstacles.
    pub obstacles: Vec<Obstacle>,
    /// The danger distance (`[expectations] danger_distance_m`), metres: the smallest
    /// ground-truth clearance between the vehicle and any run-time obstacle must stay at or
    /// above it. `None`: not checked (only a contact fails).
    pub danger_distance_m: Option<f64>,
    /// How the run must end (`[expectations] end`).
    pub expected_end: ExpectedEnd,
    /// The `[config]` table (validated): the run configuration over the defaults.
    pub config: Option<toml::Table>,
}

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn from_file(path: &Path) -> Result<Self, LocatedError> {
        let text = std::fs::read_to_string(path).map_err(|error| LocatedError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        Scenario::from_str(&text, path)
    }

    /// Validates a scenario text; `path` labels errors and anchors the relative paths of the
    /// files it names (vehicle sidecar, pose file), which are read here.
    pub fn from_str(text: &str, path: &Path) -> Result<Self, LocatedError> {
        let file = path.display().to_string();
        let spec: ScenarioFile =
            toml::from_str(text).map_err(|e| LocatedError::toml(&file, text, &e))?;
        Resolver {
            text,
            file: &file,
            dir: path.parent().unwrap_or_else(|| Path::new("")),
        }
        .resolve(spec, path)
    }

    /// The world as a [`Scene`]: ground, static objects, patches and the run-time obstacles at
    /// their initial poses (`Solid::runtime` true): the closed loop's world.
    pub fn full_scene(&self) -> Scene {
        self.scene(true)
    }

    /// The world as a [`Scene`] without its run-time obstacles: the mapping drive's world.
    pub fn static_scene(&self) -> Scene {
        self.scene(false)
    }

    fn scene(&self, include_runtime: bool) -> Scene {
        let mut solids = self.objects.clone();
        if include_runtime {
            solids.extend(self.obstacles.iter().map(|o| o.solid.clone()));
        }
        Scene {
            min_m: self.world.min_m,
            max_m: self.world.max_m,
            ground_remission: self.world.ground_remission,
            pavement_texture: self.world.pavement_texture,
            solids,
            patches: self.patches.clone(),
        }
    }
}
