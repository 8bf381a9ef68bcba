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

use mapper::{CollisionModel, GridGeometry, MultiHeightMap, RemissionCell};
use nalgebra::{Isometry2, Matrix3, Point2, Vector2};
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::messages::{LidarRevolution, Odometry};
use crate::route::wrap_angle;

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

/// The map as the measurement update reads it, one window: per cell the remission mean and the
/// weight `-0.5 / (variance + floor^2)` (NaN mean: no sample), and the likelihood field's
/// log-likelihood of an obstacle return there.
#[derive(Clone, Debug)]
pub struct LocalizationMap {
    geometry: GridGeometry,
    /// Mean, weight per cell.
    remission: Vec<[f32; 2]>,
    field: Vec<f32>,
}

impl LocalizationMap {
    /// Built from `map`'s window: its remission layer, and the distance to the nearest level-0
    /// obstacle cell of its offline (prior) occupancy, capped at `outlier_sigmas` field sigmas
    /// (an exact EDT of level 0 only; the map's own distance maps would cover every level).
    pub fn from_map(map: &MultiHeightMap, config: &LocalizerConfig) -> Self {
        let floor2 = (config.remission_sigma_floor * config.remission_sigma_floor) as f32;
        let remission = map
            .remission_grid()
            .data()
            .iter()
            .map(|c| remission_entry(c, floor2))
            .collect();
        let sigma = config.field_sigma_m as f32;
        let floor = config.floor();
        let field = match level0_distance(map, config) {
            Some(distance) => distance
                .grid()
                .data()
                .iter()
                .map(|d| (-0.5 * (d / sigma) * (d / sigma)).max(floor))
                .collect(),
            None => vec![floor; map.geometry().len()],
        };
        LocalizationMap {
            geometry: *map.geometry(),
            remission,
            field,
        }
    }

    /// The window's geometry.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }
}

/// The distance from each cell of `map`'s window to the nearest level-0 obstacle cell (the
/// filter's map holds the offline occupancy only), capped at `outlier_sigmas` field sigmas: an exact EDT of level 0
/// only (the map's own distance maps would cover every level). `None` without levels.
pub fn level0_distance(
    map: &MultiHeightMap,
    config: &LocalizerConfig,
) -> Option<mapper::DistanceMap> {
    let (prior, live) = (map.prior_log_odds(0)?.data(), map.live_log_odds(0)?.data());
    let t = map.config().obstacle_threshold;
    let l_obstacle = (t / (1.0 - t)).ln();
    let cap = (config.outlier_sigmas * config.field_sigma_m) as f32;
    let merge = map.config().merge;
    Some(mapper::DistanceMap::compute(
        *map.geometry(),
        cap.max(map.config().resolution_m as f32),
        |i| mapper::map::merge_log_odds(live[i], prior[i], merge).is_some_and(|l| l > l_obstacle),
        &mut mapper::edt::EdtScratch::default(),
    ))
}

#[inline]
fn remission_entry(c: &RemissionCell, floor2: f32) -> [f32; 2] {
    match (c.mean(), c.variance()) {
        (Some(mean), Some(var)) => [mean, -0.5 / (var + floor2)],
        _ => [f32::NAN, 0.0],
    }
}

/// One revolution as the filter uses it, in the vehicle frame: ground returns (x, y, intensity)
/// and obstacle returns (x, y), decimated to the configured counts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Observation {
    /// Ground returns: x, y (metres, vehicle frame), intensity.
    pub ground: Vec<[f64; 3]>,
    /// Obstacle returns: x, y (metres, vehicle frame).
    pub obstacles: Vec<[f64; 2]>,
}

impl Observation {
    /// The returns of `revolution` in the vehicle frame (each column's points taken back through
    /// the pose the column was placed at), the vehicle's own body left out (`self_filter`, with
    /// `self_margin_m`), spread evenly over the revolution down to the configured counts.
    pub fn from_revolution(
        revolution: &LidarRevolution,
        config: &LocalizerConfig,
        self_filter: Option<&CollisionModel>,
        self_margin_m: f64,
    ) -> Self {
        let scan = &revolution.scan;
        let beams = scan.beams().max(1);
        // Classified by height first (the world point's z is the vehicle frame's), decimated,
        // and only then taken to the vehicle frame: a revolution has ~70,000 returns, the filter
        // uses a few hundred.
        let (mut ground, mut obstacles) = (Vec::new(), Vec::new());
        let max_range = config.max_ground_range_m as f32;
        let heights = config.obstacle_min_height_m..config.obstacle_max_height_m;
        for (i, r) in scan.returns().iter().enumerate() {
            let Some(r) = r else { continue };
            let z = r.point_in_world.z;
            if z < config.ground_height_m {
                if r.range_m <= max_range {
                    ground.push(i);
                }
            } else if heights.contains(&z) {
                obstacles.push(i);
            }
        }
        let in_vehicle = |i: usize| -> Option<(Point2<f64>, &mapper::Return)> {
            let r = scan.returns()[i].as_ref()?;
            let column = scan.columns().get(i / beams)?;
            let p = r.point_in_world;
            Some((
                column.world_from_vehicle.inverse() * Point2::new(p.x, p.y),
                r,
            ))
        };
        let ground = decimate(ground, config.remission_points)
            .into_iter()
            .filter_map(in_vehicle)
            .map(|(v, r)| [v.x, v.y, f64::from(r.intensity)])
            .collect();
        // Four times as many obstacle returns as wanted, then the vehicle's own body left out.
        let obstacles = decimate(obstacles, 4 * config.field_points)
            .into_iter()
            .filter_map(in_vehicle)
            .filter(|(v, r)| {
                !self_filter.is_some_and(|m| m.is_self_hit(v, r.point_in_world.z, self_margin_m))
            })
            .map(|(v, _)| [v.x, v.y])
            .collect();
        Observation {
            ground,
            obstacles: decimate(obstacles, config.field_points),
        }
    }
}

impl Observation {
    /// The returns taken into another frame of the vehicle (`new_from_old`).
    pub fn transform(&mut self, new_from_old: &Isometry2<f64>) {
        for g in &mut self.ground {
            let p = new_from_old * Point2::new(g[0], g[1]);
            (g[0], g[1]) = (p.x, p.y);
        }
        for o in &mut self.obstacles {
            let p = new_from_old * Point2::new(o[0], o[1]);
            *o = [p.x, p.y];
        }
    }
}

/// How long the odometry trail is kept, seconds (a revolution later than this is not used).
const TRAIL_S: f64 = 2.0;

/// At most `n` of `v`, evenly spaced.
fn decimate<T: Copy>(v: Vec<T>, n: usize) -> Vec<T> {
    if v.len() <= n {
        return v;
    }
    (0..n).map(|k| v[k * v.len() / n]).collect()
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

    /// The odometry's reading since the last: the nominal pose is integrated along its arc (the
    /// particles follow it at the next update or estimate - a hundred readings a second, ten
    /// updates).
    pub fn on_odometry(&mut self, odometry: &Odometry) {
        if let Some(last) = self.last_odometry {
            let dt = odometry.t_s - last.t_s;
            if dt > 0.0 {
                let (v, delta, l) = (last.speed_m_s, last.steering_rad, self.wheelbase_m);
                self.travelled_m += (v * dt).abs();
                let ds = v * dt;
                let dtheta = ds * delta.tan() / l;
                let step = Isometry2::new(
                    Vector2::new(ds * (0.5 * dtheta).cos(), ds * (0.5 * dtheta).sin()),
                    dtheta,
                );
                self.odometry_pose *= step;
            }
        }
        self.last_odometry = Some(*odometry);
        self.trail.push_back((odometry.t_s, self.odometry_pose));
        while self
            .trail
            .front()
            .is_some_and(|(t, _)| *t < odometry.t_s - TRAIL_S)
        {
            self.trail.pop_front();
        }
    }

    /// Motion update: every particle moves by the odometry's displacement since the last
    /// propagation, read with its own errors - its distance times `1 + speed_scale`, its turn
    /// plus the distance times `tan(steering error) / wheelbase`.
    fn propagate(&mut self) {
        let delta = self.propagated_at.inverse() * self.odometry_pose;
        if delta == Isometry2::identity() {
            return;
        }
        let (t, turn) = (delta.translation.vector, delta.rotation.angle());
        let d = t.norm().copysign(t.x);
        for p in &mut self.particles {
            let (s, c) = p.theta.sin_cos();
            let k = 1.0 + p.speed_scale;
            let (dx, dy) = (k * t.x, k * t.y);
            p.x += c * dx - s * dy;
            p.y += s * dx + c * dy;
            p.theta = wrap_angle(p.theta + turn + d * p.steering_rad.tan() / self.wheelbase_m);
        }
        self.propagated_at = self.odometry_pose;
        self.refresh();
    }

    /// The estimate of the particles as they stand, kept for the estimates between updates.
    fn refresh(&mut self) {
        self.at_propagation = estimate_of(&self.particles, &self.log_w);
    }

    /// Where the vehicle was at `t_s` in its frame now, by the odometry (`None`: before the
    /// trail, or no odometry yet).
    pub fn now_from_then(&self, t_s: f64) -> Option<Isometry2<f64>> {
        let (t_last, now) = *self.trail.back()?;
        if t_s >= t_last {
            return Some(Isometry2::identity());
        }
        let k = self.trail.partition_point(|(t, _)| *t <= t_s + 1e-9);
        let (_, then) = if k == 0 {
            // Older than the trail: only at the start, when the trail is shorter than its span.
            (t_last - self.trail.front()?.0 < TRAIL_S - 0.05).then(|| self.trail.front())??
        } else {
            self.trail.get(k - 1)?
        };
        Some(now.inverse() * then)
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
        let mut obs =
            Observation::from_revolution(revolution, &self.config, self_filter, self_margin_m);
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

    /// The per-update diffusion, and each particle's odometry errors until the next update.
    fn diffuse(&mut self) {
        let c = &self.config;
        let d = self.travelled_m;
        let sp = c.diffusion_m + c.diffusion_per_m * d;
        let sh = c.diffusion_rad + 0.01 * d;
        let (ss, sst) = (c.speed_scale_sigma, c.steering_sigma_rad);
        let rng = &mut self.rng;
        for p in &mut self.particles {
            p.x += sp * normal(rng);
            p.y += sp * normal(rng);
            p.theta = wrap_angle(p.theta + sh * normal(rng));
            p.speed_scale = ss * normal(rng);
            p.steering_rad = sst * normal(rng);
        }
    }

    /// Low-variance (systematic) resampling: one uniform draw, particles taken at equal steps
    /// of the cumulative weight; the weights start equal again.
    fn resample(&mut self) {
        let n = self.particles.len();
        let w: Vec<f64> = self.log_w.iter().map(|l| l.exp()).collect();
        let step = w.iter().sum::<f64>() / n as f64;
        let mut u = self.rng.random::<f64>() * step;
        let (mut i, mut cumulative) = (0, w[0]);
        let mut next = Vec::with_capacity(n);
        for _ in 0..n {
            while u > cumulative && i + 1 < n {
                i += 1;
                cumulative += w[i];
            }
            next.push(self.particles[i]);
            u += step;
        }
        self.particles = next;
        self.log_w.iter_mut().for_each(|l| *l = 0.0);
    }
}

fn normal(rng: &mut rand::rngs::Xoshiro256PlusPlus) -> f64 {
    rng.sample(StandardNormal)
}

/// Log-weights shifted so the largest is 0.
fn normalise(log_w: &mut [f64]) {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max.is_finite() {
        log_w.iter_mut().for_each(|l| *l -= max);
    }
}

/// Effective sample size of log-weights: `(sum w)^2 / sum w^2`.
pub fn effective_size(log_w: &[f64]) -> f64 {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (s, s2) = log_w.iter().fold((0.0, 0.0), |(s, s2), l| {
        let w = (l - max).exp();
        (s + w, s2 + w * w)
    });
    if s2 > 0.0 { s * s / s2 } else { 0.0 }
}

/// The weighted mean and covariance of particles with log-weights `log_w`.
pub fn estimate_of(particles: &[Particle], log_w: &[f64]) -> Estimate {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = log_w.iter().map(|l| (l - max).exp()).collect();
    let total: f64 = w.iter().sum();
    if particles.is_empty() || total.is_nan() || total <= 0.0 {
        return Estimate {
            world_from_vehicle: Isometry2::identity(),
            covariance: Matrix3::from_diagonal_element(f64::INFINITY),
        };
    }
    let (mut mx, mut my, mut sc, mut ss) = (0.0, 0.0, 0.0, 0.0);
    for (p, w) in particles.iter().zip(&w) {
        mx += w * p.x;
        my += w * p.y;
        sc += w * p.theta.cos();
        ss += w * p.theta.sin();
    }
    let (mx, my, mt) = (mx / total, my / total, ss.atan2(sc));
    let mut cov = Matrix3::zeros();
    for (p, w) in particles.iter().zip(&w) {
        let e = nalgebra::Vector3::new(p.x - mx, p.y - my, wrap_angle(p.theta - mt));
        cov += (w / total) * e * e.transpose();
    }
    Estimate {
        world_from_vehicle: Isometry2::new(Vector2::new(mx, my), mt),
        covariance: cov,
    }
}

/// Each particle's log-likelihood of `obs` over `lmap`. Point-major over blocks of particles:
/// the particles of a block stand within a few cells of each other, so one return placed from
/// each of them reads the same few cache lines of the tables (particle-major, each particle
/// would sweep the whole window on its own). One thread: in the closed loop the other cores
/// are mapping, so the blocks run one after the other; [`weigh_parallel`] is the parallel form
/// `taxi-sim bench localization` measures against it. Equal to [`weigh_straightforward`] to
/// rounding (`the_tables_weigh_like_the_straightforward_way`).
pub fn weigh(
    particles: &[Particle],
    obs: &Observation,
    lmap: &LocalizationMap,
    config: &LocalizerConfig,
) -> Vec<f64> {
    let mut out = vec![0.0; particles.len()];
    for (out, block) in out
        .chunks_mut(PARTICLE_BLOCK)
        .zip(particles.chunks(PARTICLE_BLOCK))
    {
        weigh_block(block, obs, lmap, config, out);
    }
    out
}

/// [`weigh`] with the blocks in parallel (measured against it by `taxi-sim bench
/// localization`).
pub fn weigh_parallel(
    particles: &[Particle],
    obs: &Observation,
    lmap: &LocalizationMap,
    config: &LocalizerConfig,
) -> Vec<f64> {
    let mut out = vec![0.0; particles.len()];
    out.par_chunks_mut(PARTICLE_BLOCK)
        .zip(particles.par_chunks(PARTICLE_BLOCK))
        .for_each(|(out, block)| weigh_block(block, obs, lmap, config, out));
    out
}

/// Particles weighed together, point by point.
const PARTICLE_BLOCK: usize = 32;

/// [`weigh`] of one block of particles into `out`.
fn weigh_block(
    block: &[Particle],
    obs: &Observation,
    lmap: &LocalizationMap,
    config: &LocalizerConfig,
    out: &mut [f64],
) {
    let g = &lmap.geometry;
    let (w, h) = (g.width(), g.height());
    let (wf, hf) = (w as f64, h as f64);
    let origin = g.origin_m();
    let inv = 1.0 / g.resolution_m();
    let floor = config.floor();
    let unknown = (-0.5 * config.remission_unknown_sigmas * config.remission_unknown_sigmas) as f32;
    let poses: Vec<(f64, f64, f64, f64)> = block
        .iter()
        .map(|p| {
            let (s, c) = p.theta.sin_cos();
            (c, s, p.x, p.y)
        })
        .collect();
    // The cell `GridGeometry::cell_coords` gives, without its NaN and sign handling: a
    // coordinate in [0, w) truncates to its floor, and NaN fails the comparisons.
    let index = |&(c, s, x, y): &(f64, f64, f64, f64), px: f64, py: f64| -> Option<usize> {
        let fx = ((c * px - s * py + x) - origin.x) * inv;
        let fy = ((s * px + c * py + y) - origin.y) * inv;
        (fx >= 0.0 && fy >= 0.0 && fx < wf && fy < hf).then(|| fy as usize * w + fx as usize)
    };
    let mut sums = vec![0.0f32; block.len()];
    if config.measurement != MeasurementModel::LikelihoodField {
        for &[px, py, intensity] in &obs.ground {
            for (sum, pose) in sums.iter_mut().zip(&poses) {
                *sum += match index(pose, px, py) {
                    Some(i) => {
                        let [mean, weight] = lmap.remission[i];
                        if mean.is_nan() {
                            unknown
                        } else {
                            let d = intensity as f32 - mean;
                            (weight * d * d).max(floor)
                        }
                    }
                    None => unknown,
                };
            }
        }
    }
    if config.measurement != MeasurementModel::Remission {
        for &[px, py] in &obs.obstacles {
            for (sum, pose) in sums.iter_mut().zip(&poses) {
                *sum += index(pose, px, py).map_or(floor, |i| lmap.field[i]);
            }
        }
    }
    for (o, s) in out.iter_mut().zip(sums) {
        *o = f64::from(s) * config.likelihood_weight;
    }
}

/// The straightforward measurement update, for comparison: one particle at a time, each return
/// through the particle's `Isometry2`, the map's `Option` lookups, the cell's mean and variance
/// computed from its sums and the likelihood field's Gaussian evaluated at each lookup.
pub fn weigh_straightforward(
    particles: &[Particle],
    obs: &Observation,
    remission: &mapper::Grid<RemissionCell>,
    field: Option<&mapper::DistanceMap>,
    config: &LocalizerConfig,
) -> Vec<f64> {
    let floor = f64::from(config.floor());
    let unknown = -0.5 * config.remission_unknown_sigmas * config.remission_unknown_sigmas;
    let floor2 = config.remission_sigma_floor * config.remission_sigma_floor;

    particles
        .iter()
        .map(|p| {
            let pose = Isometry2::new(Vector2::new(p.x, p.y), p.theta);
            let mut sum = 0.0;
            if config.measurement != MeasurementModel::LikelihoodField {
                for &[px, py, intensity] in &obs.ground {
                    let at = pose * Point2::new(px, py);
                    sum += match remission
                        .at(&at)
                        .and_then(|c| Some((c.mean()?, c.variance()?)))
                    {
                        Some((mean, var)) => {
                            let d = intensity - f64::from(mean);
                            (-0.5 * d * d / (f64::from(var) + floor2)).max(floor)
                        }
                        None => unknown,
                    };
                }
            }
            if config.measurement != MeasurementModel::Remission {
                for &[px, py] in &obs.obstacles {
                    let at = pose * Point2::new(px, py);
                    sum += match (field, remission.geometry().contains(&at)) {
                        (Some(f), true) => {
                            let d = f64::from(f.distance_at(&at)) / config.field_sigma_m;
                            (-0.5 * d * d).max(floor)
                        }
                        _ => floor,
                    };
                }
            }
            sum * config.likelihood_weight
        })
        .collect()
}
