//! Monte Carlo localization over the offline map, as CARMEN's `localize_ackerman` does it: a
//! particle filter whose motion update is the odometry through the bicycle model (each particle
//! with its own speed-scale and steering errors), whose measurement update compares each LiDAR
//! revolution with the offline map's remission layer (mean and variance of intensity per cell)
//! and/or its level-0 occupancy as a likelihood field (distance to the nearest obstacle cell),
//! and which resamples with the low-variance sampler. The estimate is the particles' weighted
//! mean and its covariance.
//!
//! The map is the offline prior only (no live data): a [`MultiHeightMap`] over the offline
//! blocks, re-centred on the estimate like the online map, from which a [`LocalizationMap`]
//! (per cell: the remission mean and weight, the likelihood field's log-likelihood) is built when
//! the window moves. A pure function of the seed.
//!
//! The files, by job: `map` (the window's tables the measurement update reads),
//! `observation` (a revolution reduced to what the filter weighs), `motion` (the odometry's
//! arc and each particle's own errors), `measurement` (weighing the particles against the
//! map), `resample` (diffusion, the low-variance sampler, the weighted estimate); the filter
//! ([`ParticleFilter`]) and its configuration are here.

mod map;
mod measurement;
mod motion;
mod observation;
mod resample;

use mapper::{CollisionModel, MultiHeightMap};
use nalgebra::{Isometry2, Matrix3, Point2};
use rand::SeedableRng;
use serde::{Deserialize, Serialize};

use crate::messages::{LidarRevolution, Odometry};
use crate::route::wrap_angle;

pub use map::{LocalizationMap, level0_distance};
pub use measurement::{weigh, weigh_parallel, weigh_straightforward};
pub use observation::Observation;
pub use resample::{effective_size, estimate_of};
use resample::{normal, normalise};

/// What a revolution is compared with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeasurementModel {
    /// The ground returns' intensities against the remission map (CARMEN on the aerodrome).
    Remission,
    /// The obstacle returns against the level-0 occupancy's likelihood field.
    LikelihoodField,
    /// Both, their log-likelihoods added. The default.
    #[default]
    Both,
}

/// The particle filter's parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LocalizerConfig {
    /// Particles. Default 300 (CARMEN's).
    pub particles: usize,
    /// What a revolution is compared with. Default both.
    pub measurement: MeasurementModel,
    /// Ground returns (below `ground_height_m`) used per revolution, at most. Default 400.
    pub remission_points: usize,
    /// Obstacle returns (between `obstacle_min_height_m` and `obstacle_max_height_m`) used per
    /// revolution, at most. Default 200.
    pub field_points: usize,
    /// Returns below this height are ground (remission), metres. Default 0.1.
    pub ground_height_m: f64,
    /// Obstacle returns for the likelihood field from this height up, metres. Default 0.3.
    pub obstacle_min_height_m: f64,
    /// ... up to this height, metres. Default 3.
    pub obstacle_max_height_m: f64,
    /// Ground returns farther than this are not used, metres. Default 40.
    pub max_ground_range_m: f64,
    /// Floor of a cell's intensity standard deviation. Default 0.05.
    pub remission_sigma_floor: f64,
    /// A ground return on a cell the map has no intensity for scores as this many standard
    /// deviations off (near a match: the cells a mapping drive never sampled are no evidence). Default 0.5.
    pub remission_unknown_sigmas: f64,
    /// A return's log-likelihood is never below `-0.5 k^2` (outliers: things not in the map).
    /// Default 3.
    pub outlier_sigmas: f64,
    /// Standard deviation of an obstacle return's distance to the map's obstacles, metres.
    /// Default 0.25.
    pub field_sigma_m: f64,
    /// Each return's log-likelihood is multiplied by this (the returns of one revolution are not
    /// independent; CARMEN's particles weight factor). Default 0.05.
    pub likelihood_weight: f64,
    /// Spread of each particle's odometry speed-scale error, drawn afresh at every measurement
    /// update: white, never a per-particle bias, which resampling would turn into one bias
    /// shared by the particles, free to wander wherever nothing along the route says where
    /// along it the vehicle is. CARMEN's velocity noise, 0.15, by default: along a taxiway
    /// whose lines say nothing of the along-track position, the particles must spread far
    /// enough for the next marker or turn to find the odometry's error. Guarded by
    /// `the_filter_converges_from_a_wrong_fix_on_biased_odometry` (odometry 3 % fast).
    pub speed_scale_sigma: f64,
    /// Spread of each particle's steering error, radians, drawn the same way. Default 0.01.
    pub steering_sigma_rad: f64,
    /// Position diffusion per measurement update: this plus `diffusion_per_m` per metre driven,
    /// metres. Default 0.01.
    pub diffusion_m: f64,
    /// Position diffusion per metre driven. Default 0.02.
    pub diffusion_per_m: f64,
    /// Heading diffusion per measurement update, radians (plus 0.01 rad per metre). Default
    /// 0.002.
    pub diffusion_rad: f64,
    /// A revolution updates the particles only once the vehicle has moved this far since the last
    /// update, metres (standing still, the same view would collapse them) - or while the
    /// estimate's standard deviations have not yet been below `settled_sigma_m` and
    /// `settled_sigma_rad` since the fix. Default 0.05.
    pub min_travel_m: f64,
    /// See `min_travel_m`, metres. Default 0.1.
    pub settled_sigma_m: f64,
    /// ... and the heading's below this, radians (a long wing turns a heading error into a
    /// lateral one: the A320's tips are 17 m out). Default 0.005.
    pub settled_sigma_rad: f64,
    /// Resample when the effective sample size falls below this fraction of the particles.
    /// Default 0.5.
    pub resample_ess_fraction: f64,
    /// Standard deviation of the GNSS-like fix the filter starts from, metres. Default 0.5.
    pub fix_sigma_m: f64,
    /// ... in heading, radians. Default 0.05.
    pub fix_sigma_rad: f64,
    /// The particles are drawn around the fix with this many times its standard deviations.
    /// Default 2: a fix 3 sigma off (one in 370) still has particles near the truth. Drawn with
    /// the fix's own spread, a fix 0.147 rad off had none: the filter collapsed onto the
    /// nearest within 0.8 s and reported its heading known to 0.0034 rad while 0.048 rad off
    /// for 5 s (`tests/found/phantom_from_the_first_revolution.toml`; heading RMSE 0.020 ->
    /// 0.0065 rad there).
    pub fix_spread_sigmas: f64,
    /// Estimates published per second. Default 20.
    pub rate_hz: f64,
}

impl Default for LocalizerConfig {
    fn default() -> Self {
        LocalizerConfig {
            particles: 300,
            measurement: MeasurementModel::Both,
            remission_points: 400,
            field_points: 200,
            ground_height_m: 0.1,
            obstacle_min_height_m: 0.3,
            obstacle_max_height_m: 3.0,
            max_ground_range_m: 40.0,
            remission_sigma_floor: 0.05,
            remission_unknown_sigmas: 0.5,
            outlier_sigmas: 3.0,
            field_sigma_m: 0.25,
            likelihood_weight: 0.05,
            speed_scale_sigma: 0.15,
            steering_sigma_rad: 0.01,
            diffusion_m: 0.01,
            diffusion_per_m: 0.02,
            diffusion_rad: 0.002,
            min_travel_m: 0.05,
            settled_sigma_m: 0.1,
            settled_sigma_rad: 0.005,
            resample_ess_fraction: 0.5,
            fix_sigma_m: 0.5,
            fix_sigma_rad: 0.05,
            fix_spread_sigmas: 2.0,
            rate_hz: 20.0,
        }
    }
}

impl LocalizerConfig {
    /// Checks every field, naming the first wrong one.
    pub fn validate(&self) -> Result<(), String> {
        if self.particles == 0 || self.particles > 100_000 {
            return Err(format!(
                "particles = {}: between 1 and 100000",
                self.particles
            ));
        }
        let non_negative = [
            ("remission_sigma_floor", self.remission_sigma_floor),
            ("remission_unknown_sigmas", self.remission_unknown_sigmas),
            ("outlier_sigmas", self.outlier_sigmas),
            ("likelihood_weight", self.likelihood_weight),
            ("speed_scale_sigma", self.speed_scale_sigma),
            ("steering_sigma_rad", self.steering_sigma_rad),
            ("diffusion_m", self.diffusion_m),
            ("diffusion_per_m", self.diffusion_per_m),
            ("diffusion_rad", self.diffusion_rad),
            ("min_travel_m", self.min_travel_m),
            ("settled_sigma_m", self.settled_sigma_m),
            ("settled_sigma_rad", self.settled_sigma_rad),
            ("fix_sigma_m", self.fix_sigma_m),
            ("fix_sigma_rad", self.fix_sigma_rad),
            ("max_ground_range_m", self.max_ground_range_m),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} = {v}: must be finite and >= 0"));
            }
        }
        let positive = [
            ("field_sigma_m", self.field_sigma_m),
            ("rate_hz", self.rate_hz),
            ("remission_sigma_floor", self.remission_sigma_floor),
            ("fix_spread_sigmas", self.fix_spread_sigmas),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} = {v}: must be finite and > 0"));
            }
        }
        if !(0.0..=1.0).contains(&self.resample_ess_fraction) {
            return Err(format!(
                "resample_ess_fraction = {}: between 0 and 1",
                self.resample_ess_fraction
            ));
        }
        if self
            .obstacle_min_height_m
            .partial_cmp(&self.obstacle_max_height_m)
            != Some(std::cmp::Ordering::Less)
        {
            return Err(format!(
                "obstacle_min_height_m = {} must be below obstacle_max_height_m = {}",
                self.obstacle_min_height_m, self.obstacle_max_height_m
            ));
        }
        Ok(())
    }

    /// The lowest log-likelihood one return can score.
    fn floor(&self) -> f32 {
        (-0.5 * self.outlier_sigmas * self.outlier_sigmas) as f32
    }
}

/// A particle's pose and its own odometry errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    /// Position, metres.
    pub x: f64,
    /// Position, metres.
    pub y: f64,
    /// Heading, radians.
    pub theta: f64,
    /// Its odometry speed is multiplied by `1 + speed_scale`.
    pub speed_scale: f64,
    /// Its steering angle is the odometry's plus this, radians.
    pub steering_rad: f64,
}

/// The filter's estimate: the weighted mean pose and the covariance of (x, y, heading).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The mean pose.
    pub world_from_vehicle: Isometry2<f64>,
    /// Covariance of x, y (metres) and heading (radians), world frame.
    pub covariance: Matrix3<f64>,
}

impl Estimate {
    /// As the stack's message, holding at `t_s`.
    pub fn at(&self, t_s: f64) -> crate::PoseEstimate {
        crate::PoseEstimate {
            t_s,
            world_from_vehicle: self.world_from_vehicle,
            covariance: self.covariance,
        }
    }
    /// Standard deviation across the vehicle's heading, metres.
    pub fn cross_track_sigma_m(&self) -> f64 {
        self.at(0.0).cross_track_sigma_m()
    }
}

/// What one measurement update did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UpdateStats {
    /// Whether the particles were weighed (false: the vehicle had not moved enough).
    pub weighed: bool,
    /// Whether they were resampled.
    pub resampled: bool,
    /// Effective sample size after weighing.
    pub effective_particles: f64,
    /// Ground and obstacle returns used.
    pub points: (usize, usize),
}

/// The particle filter.
pub struct ParticleFilter {
    config: LocalizerConfig,
    wheelbase_m: f64,
    rng: rand::rngs::Xoshiro256PlusPlus,
    particles: Vec<Particle>,
    log_w: Vec<f64>,
    last_odometry: Option<Odometry>,
    travelled_m: f64,
    /// The odometry's own dead-reckoned pose, and its trail over the last `TRAIL_S` (a late
    /// revolution is taken to where the vehicle is now through it).
    odometry_pose: Isometry2<f64>,
    trail: std::collections::VecDeque<(f64, Isometry2<f64>)>,
    /// The odometry's pose when the particles were last moved, and their estimate then.
    propagated_at: Isometry2<f64>,
    at_propagation: Estimate,
    /// Whether the particles have settled since the fix (standing still, they are updated only
    /// until then).
    settled: bool,
    map: MultiHeightMap,
    lmap: Option<LocalizationMap>,
}

impl ParticleFilter {
    /// A filter with `config` for a vehicle of wheelbase `wheelbase_m`, over `map` (the offline
    /// prior; the filter computes its own level-0 distance field), seeded with `seed`. It
    /// has no particles until [`Self::initialise`].
    pub fn new(config: LocalizerConfig, wheelbase_m: f64, map: MultiHeightMap, seed: u64) -> Self {
        ParticleFilter {
            wheelbase_m,
            rng: rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x10CA_112E),
            particles: Vec::new(),
            log_w: Vec::new(),
            last_odometry: None,
            travelled_m: 0.0,
            odometry_pose: Isometry2::identity(),
            trail: std::collections::VecDeque::new(),
            propagated_at: Isometry2::identity(),
            at_propagation: estimate_of(&[], &[]),
            settled: false,
            map,
            lmap: None,
            config,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LocalizerConfig {
        &self.config
    }

    /// Particles drawn around `fix` (a GNSS-like fix) with the configured fix spread; the
    /// window re-centred there.
    pub fn initialise(&mut self, fix: &Isometry2<f64>) -> Result<(), mapper::MapError> {
        let c = &self.config;
        let k = c.fix_spread_sigmas;
        let (sm, sr) = (k * c.fix_sigma_m, k * c.fix_sigma_rad);
        let (ss, sst) = (c.speed_scale_sigma, c.steering_sigma_rad);
        let rng = &mut self.rng;
        self.particles = (0..c.particles)
            .map(|_| Particle {
                x: fix.translation.x + sm * normal(rng),
                y: fix.translation.y + sm * normal(rng),
                theta: wrap_angle(fix.rotation.angle() + sr * normal(rng)),
                speed_scale: ss * normal(rng),
                steering_rad: sst * normal(rng),
            })
            .collect();
        self.log_w = vec![0.0; c.particles];
        self.last_odometry = None;
        self.travelled_m = 0.0;
        self.trail.clear();
        self.propagated_at = self.odometry_pose;
        self.refresh();
        self.settled = false;
        self.follow(Point2::new(fix.translation.x, fix.translation.y))
    }

    /// The localization map of the current window (built at [`Self::initialise`]).
    pub fn localization_map(&self) -> Option<&LocalizationMap> {
        self.lmap.as_ref()
    }

    /// The offline map the filter reads.
    pub fn map(&self) -> &MultiHeightMap {
        &self.map
    }

    /// Drops the particles (the vehicle was moved: [`Self::initialise`] again).
    pub fn clear(&mut self) {
        self.particles.clear();
        self.log_w.clear();
        self.last_odometry = None;
        self.trail.clear();
        self.refresh();
    }

    /// Whether the filter has particles.
    pub fn initialised(&self) -> bool {
        !self.particles.is_empty()
    }

    /// The particles, as of the last update.
    pub fn particles(&self) -> &[Particle] {
        &self.particles
    }

    /// The estimate of the particles as they stand, kept for the estimates between updates.
    fn refresh(&mut self) {
        self.at_propagation = estimate_of(&self.particles, &self.log_w);
    }

    /// Measurement update from a revolution already reduced to an [`Observation`]: (once the
    /// vehicle has moved `min_travel_m`) diffuse, weigh against the map, resample when the
    /// effective sample size is low.
    pub fn on_observation(
        &mut self,
        observation: &Observation,
    ) -> Result<UpdateStats, mapper::MapError> {
        let mut stats = UpdateStats {
            points: (observation.ground.len(), observation.obstacles.len()),
            ..Default::default()
        };
        if !self.initialised() {
            return Ok(stats);
        }
        self.propagate();
        // Standing still, the same view again would collapse the particles onto one reading of
        // it, and each update's diffusion would walk them - except at the start, from the fix,
        // until they have settled once.
        let e = self.estimate().at(0.0);
        self.settled |= e.cross_track_sigma_m() < self.config.settled_sigma_m
            && e.heading_sigma_rad() < self.config.settled_sigma_rad;
        if self.travelled_m < self.config.min_travel_m && self.settled {
            return Ok(stats);
        }
        let here = self.estimate().world_from_vehicle.translation.vector;
        self.follow(Point2::from(here))?;
        self.measurement_update(observation, &mut stats);
        self.travelled_m = 0.0;
        Ok(stats)
    }

    /// The measurement update proper, whatever the vehicle did since the last: diffuse, weigh
    /// against the current window, resample when the effective sample size is low.
    pub fn measurement_update(&mut self, observation: &Observation, stats: &mut UpdateStats) {
        self.diffuse();
        let Some(lmap) = &self.lmap else {
            return;
        };
        let ll = weigh(&self.particles, observation, lmap, &self.config);
        for (w, l) in self.log_w.iter_mut().zip(&ll) {
            *w += l;
        }
        normalise(&mut self.log_w);
        let ess = effective_size(&self.log_w);
        stats.weighed = true;
        stats.effective_particles = ess;
        if ess < self.config.resample_ess_fraction * self.particles.len() as f64 {
            self.resample();
            stats.resampled = true;
        }
        self.refresh();
    }

    /// [`Self::on_observation`] of a revolution.
    pub fn on_revolution(
        &mut self,
        revolution: &LidarRevolution,
        self_filter: Option<&CollisionModel>,
        self_margin_m: f64,
    ) -> Result<UpdateStats, mapper::MapError> {
        let mut obs = Observation::from_revolution(
            revolution,
            &self.config,
            self_filter,
            self_margin_m,
            self.map.config(),
        );
        // Taken where the vehicle was then: its returns moved into the vehicle's frame now.
        let Some(now_from_then) = self.now_from_then(revolution.t_s) else {
            return Ok(UpdateStats::default());
        };
        if now_from_then != Isometry2::identity() {
            obs.transform(&now_from_then);
        }
        self.on_observation(&obs)
    }

    /// The weighted mean pose (circular mean of the heading) and covariance.
    /// Between updates, the particles' estimate at the last update carried forward on the
    /// odometry.
    pub fn estimate(&self) -> Estimate {
        Estimate {
            world_from_vehicle: self.at_propagation.world_from_vehicle
                * (self.propagated_at.inverse() * self.odometry_pose),
            covariance: self.at_propagation.covariance,
        }
    }

    /// Re-centres the map window on `here`; the localization map is rebuilt when it moved.
    fn follow(&mut self, here: Point2<f64>) -> Result<(), mapper::MapError> {
        let moved = self.map.recenter(here)?;
        if moved || self.lmap.is_none() {
            self.lmap = Some(LocalizationMap::from_map(&self.map, &self.config));
        }
        Ok(())
    }
}
