//! A synthetic Velodyne HDL-32E that ray-casts the Rapier world.
//!
//! 32 beams from -30.67 to +10.67 deg, 2187 columns a revolution (69,984 rays), 10 Hz, 100 m,
//! all configurable, with the parameters CARLA's ray-cast lidar users know: Gaussian range noise,
//! intensity = remission x exp(-attenuation x distance), general and intensity-based drop-off;
//! and a constant range bias per laser, as a real unit has (its calibration's residual; off by
//! default). The noise and drop-off defaults are calibrated on a real HDL-32E
//! (`docs/velodyne.md`).
//! Optionally each column is fired from the pose at its firing time (motion during the sweep).
//!
//! The fast path uses what all rays of a column share, their origin: the ground is the analytic
//! plane z = 0 (within the ground's extent); every other collider is culled to its azimuth window
//! (bucketed per column) and elevation window, and a column's candidates are tried nearest first,
//! stopping as soon as the current hit is nearer than the next candidate can be. Each candidate
//! is cast with parry's own shape ray cast, so results equal Rapier's generic query
//! ([`Lidar::scan_generic`], tested) to float precision - except cylinders and cones, upright
//! or a parked aircraft's parts, cast in closed form (`round.rs`) onto their true surface where
//! parry's GJK iterations stop a few millimetres off it. Columns run in parallel (rayon); noise
//! comes from a generator seeded per (seed, scan, column), so a scan does not depend on the
//! thread count.

use nalgebra::{Isometry2, Isometry3, Point3, Vector3};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rapier3d::prelude::*;
use rayon::prelude::*;

use super::physics::{Owner, World, planar_to_3d, to_pose};

mod config;
mod round;
pub use config::LidarConfig;
use round::Round;

/// One revolution: the mapper's input plus what only the simulator knows.
#[derive(Clone, Debug)]
pub struct LidarScan {
    /// Columns x beams in the world frame with the sensor pose per column (the mapper's input).
    pub scan: mapper::Scan,
    /// What each return hit (ground truth, for tests and pictures), like `scan.returns()`.
    pub owners: Vec<Option<Owner>>,
    /// Unit direction of each beam in the sensor frame, `[column * beams + beam]`.
    pub directions_in_sensor: std::sync::Arc<Vec<[f32; 3]>>,
}

impl LidarScan {
    /// A return's point in the sensor frame.
    pub fn point_in_sensor(&self, column: usize, beam: usize) -> Option<Point3<f64>> {
        let i = column * self.scan.beams() + beam;
        let r = self.scan.returns().get(i).copied().flatten()?;
        let d = self.directions_in_sensor[i];
        Some(Point3::new(d[0] as f64, d[1] as f64, d[2] as f64) * r.range_m as f64)
    }
}

/// Where the sensor is during one sweep.
#[derive(Clone, Copy, Debug)]
pub struct SweepPoses {
    /// Vehicle pose when the sweep starts.
    pub start: Isometry2<f64>,
    /// Vehicle pose when it ends (used with `motion_during_sweep`).
    pub end: Isometry2<f64>,
}

impl SweepPoses {
    /// A sweep from a standing vehicle.
    pub fn still(pose: Isometry2<f64>) -> Self {
        SweepPoses {
            start: pose,
            end: pose,
        }
    }
}

/// The sensor.
#[derive(Clone, Debug)]
pub struct Lidar {
    config: LidarConfig,
    vehicle_from_sensor: Isometry3<f64>,
    elevations_rad: Vec<f64>,
    directions: std::sync::Arc<Vec<[f32; 3]>>,
    self_hits: std::sync::OnceLock<Vec<Option<(f32, Owner)>>>,
}

/// A collider as the fast path sees it.
struct Candidate<'a> {
    owner: Owner,
    collider: &'a Collider,
    /// Cylinders and cones are cast in closed form (parry casts them by GJK iterations).
    analytic: Option<Round>,
    /// Horizontal distance from the sweep origin to the collider's bounding box, metres.
    d_min: f32,
    /// Sines of the elevation window seen from the sweep origin, compared with a direction's z
    /// (sin is monotonic): no asin a ray.
    sin_el_min: f32,
    sin_el_max: f32,
}

/// The candidates of every column in one flat list, each column's in the candidates' order:
/// column c's are `flat[start[c]..start[c + 1]]`.
struct Buckets {
    start: Vec<u32>,
    flat: Vec<u32>,
}

impl Buckets {
    /// Buckets `candidates` (indices into it) by the columns each may be seen from (`None`:
    /// all `columns`): counted, then filled in the candidates' order.
    fn new<T>(candidates: &[(T, Option<std::ops::Range<i64>>)], columns: usize) -> Self {
        let mut start = vec![0u32; columns + 1];
        let each_column = |ks: &Option<std::ops::Range<i64>>, f: &mut dyn FnMut(usize)| match ks {
            None => (0..columns).for_each(&mut *f),
            Some(ks) => ks
                .clone()
                .for_each(|k| f(k.rem_euclid(columns as i64) as usize)),
        };
        for (_, ks) in candidates {
            each_column(ks, &mut |c| start[c + 1] += 1);
        }
        for c in 0..columns {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut flat = vec![0u32; start[columns] as usize];
        for (index, (_, ks)) in candidates.iter().enumerate() {
            each_column(ks, &mut |c| {
                flat[fill[c] as usize] = index as u32;
                fill[c] += 1;
            });
        }
        Buckets { start, flat }
    }

    /// Column `c`'s candidates, nearest first when the candidates are.
    #[inline]
    fn column(&self, c: usize) -> &[u32] {
        &self.flat[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

impl Lidar {
    /// A sensor mounted at `vehicle_from_sensor`.
    pub fn new(config: LidarConfig, vehicle_from_sensor: Isometry3<f64>) -> Result<Self, String> {
        config.validate()?;
        let n = config.channels;
        let elevations_rad: Vec<f64> = (0..n)
            .map(|b| {
                let f = if n == 1 {
                    0.0
                } else {
                    b as f64 / (n - 1) as f64
                };
                (config.lower_fov_deg + f * (config.upper_fov_deg - config.lower_fov_deg))
                    .to_radians()
            })
            .collect();
        let mut directions = Vec::with_capacity(config.columns * n);
        for c in 0..config.columns {
            let az = std::f64::consts::TAU * c as f64 / config.columns as f64;
            for el in &elevations_rad {
                directions.push([
                    (el.cos() * az.cos()) as f32,
                    (el.cos() * az.sin()) as f32,
                    el.sin() as f32,
                ]);
            }
        }
        Ok(Lidar {
            config,
            vehicle_from_sensor,
            elevations_rad,
            directions: std::sync::Arc::new(directions),
            self_hits: std::sync::OnceLock::new(),
        })
    }

    /// Where the sensor is mounted: its pose in the vehicle's frame.
    pub fn vehicle_from_sensor(&self) -> Isometry3<f64> {
        self.vehicle_from_sensor
    }

    /// The configuration.
    pub fn config(&self) -> &LidarConfig {
        &self.config
    }
    /// Rays per revolution.
    pub fn rays(&self) -> usize {
        self.config.columns * self.config.channels
    }

    /// Each beam's constant range bias, metres, lowest beam first: Gaussian with
    /// `range_bias_stddev_m`, from the unit's own generator (`range_bias_unit`).
    pub fn range_biases_m(&self) -> Vec<f64> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(mix(
            self.config.range_bias_unit,
            u64::MAX,
            0x6269_6173,
        ));
        (0..self.config.channels)
            .map(|_| self.config.range_bias_stddev_m * rng.sample::<f64, _>(StandardNormal))
            .collect()
    }

    fn column_poses(&self, sweep: &SweepPoses, c: usize) -> (Isometry2<f64>, Isometry3<f64>) {
        let pose = if self.config.motion_during_sweep {
            let f = c as f64 / self.config.columns as f64;
            let (a, b) = (sweep.start, sweep.end);
            let t = a.translation.vector.lerp(&b.translation.vector, f);
            let yaw = a.rotation.angle()
                + f * super::motion::wrap_angle(b.rotation.angle() - a.rotation.angle());
            Isometry2::new(t, yaw)
        } else {
            sweep.start
        };
        (pose, planar_to_3d(&pose) * self.vehicle_from_sensor)
    }

    /// One revolution with the fast path. `scan_index` and `seed` seed the noise.
    pub fn scan(&self, world: &World, sweep: &SweepPoses, scan_index: u64, seed: u64) -> LidarScan {
        let mut candidates = self.candidates(world, sweep);
        // Nearest first (a stable sort: equals keep the colliders' order), so that every bucket,
        // filled in this order, is sorted without sorting 2187 buckets a revolution.
        candidates.sort_by(|a, b| a.0.d_min.total_cmp(&b.0.d_min));
        let buckets = Buckets::new(&candidates, self.config.columns);
        let candidates: Vec<Candidate> = candidates.into_iter().map(|(c, _)| c).collect();
        let scene = world.scene();
        let ground = (scene.min_m, scene.max_m);
        self.assemble(world, sweep, scan_index, seed, |c, origin, dirs, out| {
            self.cast_column(&candidates, buckets.column(c), ground, origin, dirs, out);
        })
    }

    /// Every object collider as the fast path sees it from the sweep's first column origin,
    /// with the columns it may be seen from (`None`: all of them), in the colliders' order.
    fn candidates<'w>(
        &self,
        world: &'w World,
        sweep: &SweepPoses,
    ) -> Vec<(Candidate<'w>, Option<std::ops::Range<i64>>)> {
        let (_, first) = self.column_poses(sweep, 0);
        let origin = first.translation.vector;
        // How far column origins stray from the first one over the sweep: a culling margin.
        let pad = if self.config.motion_during_sweep {
            (sweep.end.translation.vector - sweep.start.translation.vector).norm() as f32 + 0.5
        } else {
            0.0
        };
        // Each candidate with the columns it may be seen from (`None`: all of them).
        let mut candidates: Vec<(Candidate, Option<std::ops::Range<i64>>)> = Vec::new();
        for (owner, collider) in world.object_colliders() {
            let aabb = collider.compute_aabb();
            let (lo, hi) = (aabb.mins, aabb.maxs);
            let (ox, oy, oz) = (origin.x as f32, origin.y as f32, origin.z as f32);
            // Horizontal distance window from the origin to the box.
            let dx = (lo.x - ox).max(ox - hi.x).max(0.0);
            let dy = (lo.y - oy).max(oy - hi.y).max(0.0);
            let d_min = (dx.hypot(dy) - pad).max(0.0);
            let d_max = (hi.x - ox)
                .abs()
                .max((lo.x - ox).abs())
                .hypot((hi.y - oy).abs().max((lo.y - oy).abs()))
                + pad;
            let elev = |z: f32| {
                let dz = z - oz;
                // Highest (lowest) elevation of a point at height z: seen from as near (far) as possible.
                (
                    dz.atan2(if dz > 0.0 { d_min } else { d_max }),
                    dz.atan2(if dz > 0.0 { d_max } else { d_min.max(1e-3) }),
                )
            };
            let (el_top_max, _) = elev(hi.z + pad);
            let (_, el_bottom_min) = elev(lo.z - pad);
            let analytic = match owner {
                Owner::Object(i) => world.scene().solids.get(i).and_then(Round::of),
                _ => None,
            };
            let candidate = Candidate {
                owner,
                collider,
                analytic,
                d_min,
                sin_el_min: (el_bottom_min.min(el_top_max) - 1e-3)
                    .max(-std::f32::consts::FRAC_PI_2)
                    .sin(),
                sin_el_max: (el_top_max + 1e-3).min(std::f32::consts::FRAC_PI_2).sin(),
            };
            // Azimuth window: all columns when the origin is inside (or near) the box's footprint.
            if d_min <= 0.0 {
                candidates.push((candidate, None));
                continue;
            }
            let ks = self.column_window(sweep, ([lo.x, lo.y], [hi.x, hi.y]), (ox, oy), d_min, pad);
            candidates.push((candidate, Some(ks)));
        }
        candidates
    }

    /// The columns (a range of indices to take modulo the column count) from which a box with
    /// horizontal footprint `lo`..`hi`, `d_min` > 0 metres from the origin `(ox, oy)`, may be
    /// seen: its azimuth window widened by `pad` (the origins' stray) and two columns, rotated
    /// into the sensor's frame at the sweep's start and widened by the sweep's turn.
    fn column_window(
        &self,
        sweep: &SweepPoses,
        (lo, hi): ([f32; 2], [f32; 2]),
        (ox, oy): (f32, f32),
        d_min: f32,
        pad: f32,
    ) -> std::ops::Range<i64> {
        let columns = self.config.columns;
        let corners = [
            (lo[0], lo[1]),
            (hi[0], lo[1]),
            (lo[0], hi[1]),
            (hi[0], hi[1]),
        ];
        let mid_az = (0.5 * (lo[1] + hi[1]) - oy).atan2(0.5 * (lo[0] + hi[0]) - ox);
        let (mut a_lo, mut a_hi) = (0.0f32, 0.0f32);
        for (x, y) in corners {
            let a = (y - oy).atan2(x - ox) - mid_az;
            let a =
                (a + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
            a_lo = a_lo.min(a);
            a_hi = a_hi.max(a);
        }
        let margin = (pad / d_min.max(0.1)).min(std::f32::consts::PI)
            + 2.0 * std::f32::consts::TAU / columns as f32;
        let (a_lo, a_hi) = (mid_az + a_lo - margin, mid_az + a_hi + margin);
        // The sensor's column azimuths are measured in its own frame: rotate the window.
        let yaw0 = sweep.start.rotation.angle() as f32 + sensor_yaw(&self.vehicle_from_sensor);
        let per = columns as f32 / std::f32::consts::TAU;
        let (c_lo, c_hi) = (
            ((a_lo - yaw0) * per).floor() as i64,
            ((a_hi - yaw0) * per).ceil() as i64,
        );
        let span = (c_hi - c_lo + 1).min(columns as i64);
        let yaw_pad = if self.config.motion_during_sweep {
            (super::motion::wrap_angle(sweep.end.rotation.angle() - sweep.start.rotation.angle())
                .abs() as f32
                * per)
                .ceil() as i64
                + 1
        } else {
            0
        };
        (c_lo - yaw_pad)..(c_lo + span + yaw_pad).min(c_lo - yaw_pad + columns as i64)
    }

    /// Casts one column's rays (`dirs`, from `origin`) against the ground plane within `ground`
    /// (its corners) and the column's `bucket` of `candidates` (nearest first), keeping each
    /// ray's nearest hit in `out` (prefilled with the vehicle's self-hits).
    #[inline]
    fn cast_column(
        &self,
        candidates: &[Candidate],
        bucket: &[u32],
        ground: ([f64; 2], [f64; 2]),
        origin: Point3<f64>,
        dirs: &[[f32; 3]],
        out: &mut [Option<(f32, Owner)>],
    ) {
        let o = Vector::new(origin.x as f32, origin.y as f32, origin.z as f32);
        for (b, d) in dirs.iter().enumerate() {
            let dir = Vector::new(d[0], d[1], d[2]);
            let mut best: Option<(f32, Owner)> = None;
            let mut t_best = self.config.range_m as f32;
            if let Some((t, owner)) = out[b] {
                (t_best, best) = (t, Some((t, owner))); // the vehicle itself, from the table
            }
            if dir.z < 0.0 {
                let t = -o.z / dir.z;
                let (x, y) = ((o.x + t * dir.x) as f64, (o.y + t * dir.y) as f64);
                if t <= t_best
                    && x >= ground.0[0]
                    && x <= ground.1[0]
                    && y >= ground.0[1]
                    && y <= ground.1[1]
                {
                    t_best = t;
                    best = Some((t, Owner::Ground));
                }
            }
            let horizontal = (dir.x * dir.x + dir.y * dir.y).sqrt();
            let ray = Ray::new(o, dir);
            for &i in bucket {
                let cand = &candidates[i as usize];
                if t_best * horizontal < cand.d_min {
                    break; // sorted by distance: nothing farther can be nearer than the hit
                }
                if dir.z < cand.sin_el_min || dir.z > cand.sin_el_max {
                    continue;
                }
                let hit = match &cand.analytic {
                    Some(v) => v.cast(&ray, t_best),
                    None => {
                        cand.collider
                            .shape()
                            .cast_ray(cand.collider.position(), &ray, t_best, true)
                    }
                };
                if let Some(t) = hit
                    && t < t_best
                {
                    t_best = t;
                    best = Some((t, cand.owner));
                }
            }
            out[b] = best;
        }
    }

    /// One revolution casting every ray with Rapier's generic query (the BVH over every
    /// collider, the ground slab included): the straightforward way, for tests and benchmarks.
    pub fn scan_generic(
        &self,
        world: &World,
        sweep: &SweepPoses,
        scan_index: u64,
        seed: u64,
    ) -> LidarScan {
        let range = self.config.range_m as f32;
        self.assemble(world, sweep, scan_index, seed, |_, origin, dirs, out| {
            let o = [origin.x as f32, origin.y as f32, origin.z as f32];
            for (b, d) in dirs.iter().enumerate() {
                let own = out[b];
                let env = world.cast_ray_generic(o, *d, own.map_or(range, |(t, _)| t));
                out[b] = match (env, own) {
                    (Some(e), Some(v)) if e.0 < v.0 => Some(e),
                    (Some(e), None) => Some(e),
                    _ => own,
                };
            }
        })
    }

    /// Runs, for every column in parallel, `cast(column, origin, world directions, out hits)`
    /// (prefilled with the vehicle's self-hits) and then the column's noise, intensity and
    /// drop-off from its own seeded generator; the columns are joined in order.
    fn assemble(
        &self,
        world: &World,
        sweep: &SweepPoses,
        scan_index: u64,
        seed: u64,
        cast: impl Fn(usize, Point3<f64>, &[[f32; 3]], &mut [Option<(f32, Owner)>]) + Sync,
    ) -> LidarScan {
        let beams = self.config.channels;
        let self_hits = self.self_hits(world);
        let scene = world.scene();
        let ground = world.ground_texture();
        let biases = self.range_biases_m();
        // Every column writes its own slices of the preallocated outputs: no per-column vectors
        // to join afterwards.
        let n = self.config.columns * beams;
        let mut returns: Vec<Option<mapper::Return>> = vec![None; n];
        let mut owners: Vec<Option<Owner>> = vec![None; n];
        let mut columns = vec![
            mapper::ScanColumn {
                world_from_sensor: Isometry3::identity(),
                world_from_vehicle: Isometry2::identity()
            };
            self.config.columns
        ];
        returns
            .par_chunks_mut(beams)
            .zip(owners.par_chunks_mut(beams))
            .zip(columns.par_iter_mut())
            .enumerate()
            .for_each_init(
                // A worker's scratch, reused from column to column: directions and hits.
                || (Vec::with_capacity(beams), Vec::with_capacity(beams)),
                |(dirs, hits), (c, ((returns, owners), column))| {
                    let (vehicle, sensor) = self.column_poses(sweep, c);
                    // Sensor to world rotation as an f32 matrix: 9 multiplications a ray.
                    let r = sensor
                        .rotation
                        .to_rotation_matrix()
                        .matrix()
                        .map(|v| v as f32);
                    dirs.clear();
                    dirs.extend(self.directions[c * beams..(c + 1) * beams].iter().map(|d| {
                        let w = r * nalgebra::Vector3::new(d[0], d[1], d[2]);
                        [w.x, w.y, w.z]
                    }));
                    hits.clear();
                    hits.extend_from_slice(&self_hits[c * beams..(c + 1) * beams]);
                    let origin = Point3::from(sensor.translation.vector);
                    cast(c, origin, dirs, hits);
                    let mut rng =
                        Xoshiro256PlusPlus::seed_from_u64(mix(seed, scan_index, c as u64));
                    for ((((ret, owner), hit), d), bias) in returns
                        .iter_mut()
                        .zip(owners.iter_mut())
                        .zip(hits.iter())
                        .zip(dirs.iter())
                        .zip(&biases)
                    {
                        let ray = (origin, d, *bias);
                        self.measure(scene, ground, &mut rng, ray, *hit, (ret, owner));
                    }
                    *column = mapper::ScanColumn {
                        world_from_sensor: sensor,
                        world_from_vehicle: vehicle,
                    };
                },
            );
        // Finite poses and points by construction; an error here would be a bug, reported as an empty scan.
        let scan = mapper::Scan::new(beams, columns, returns).unwrap_or_default();
        LidarScan {
            scan,
            owners,
            directions_in_sensor: self.directions.clone(),
        }
    }

    /// One ray's return (`bias`: its laser's range bias): range noise, intensity, drop-off.
    fn measure(
        &self,
        scene: &super::scene::Scene,
        ground: &super::ground::GroundTexture,
        rng: &mut Xoshiro256PlusPlus,
        (origin, d, bias): (Point3<f64>, &[f32; 3], f64),
        hit: Option<(f32, Owner)>,
        (ret, owned): (&mut Option<mapper::Return>, &mut Option<Owner>),
    ) {
        let cfg = &self.config;
        // Three draws a ray, hit or not, so the stream does not depend on what was hit: a standard
        // normal (ziggurat, usually one draw) and two uniforms for the drop-off.
        let z: f64 = rng.sample(StandardNormal);
        let (u3, u4): (f64, f64) = (rng.random(), rng.random());
        let Some((t, owner)) = hit else {
            return; // the outputs start as None
        };
        let noise = bias + cfg.noise_stddev_m * z;
        let range = (t as f64 + noise).max(0.0);
        let point = origin + Vector3::new(d[0] as f64, d[1] as f64, d[2] as f64) * range;
        let remission = match owner {
            Owner::Ground => ground.remission_at(point.x, point.y),
            Owner::Object(i) => scene.solids.get(i).map_or(0.5, |s| s.remission),
            Owner::VehiclePart(_) => 0.5,
        };
        let intensity = (remission as f64 * (-cfg.atmosphere_attenuation_rate * t as f64).exp())
            .clamp(0.0, 1.0);
        // (Tested first: with the rate at 0, its default, `u4 < 0` never holds, and the
        // division a ray is skipped.)
        let drop_by_intensity = cfg.dropoff_zero_intensity > 0.0
            && intensity < cfg.dropoff_intensity_limit
            && u4
                < cfg.dropoff_zero_intensity
                    * (1.0 - intensity / cfg.dropoff_intensity_limit.max(1e-12));
        if u3 < cfg.dropoff_general_rate || drop_by_intensity {
            return;
        }
        *ret = Some(mapper::Return {
            point_in_world: point,
            range_m: range as f32,
            intensity: intensity as f32,
        });
        *owned = Some(owner);
    }

    /// Where each ray meets the vehicle itself, if it does: the sensor is rigidly mounted, so
    /// this is the same every revolution, whatever the vehicle's motion. Parts holding the sensor
    /// (its housing) are not seen. Computed once per sensor (a `Lidar` belongs to one vehicle).
    fn self_hits(&self, world: &World) -> &[Option<(f32, Owner)>] {
        self.self_hits.get_or_init(|| {
            let mount = to_pose(&self.vehicle_from_sensor);
            let origin = mount.translation;
            let parts: Vec<_> = world
                .vehicle_parts()
                .filter(|(_, shape, pose)| !shape.contains_point(pose, origin))
                .collect();
            self.directions
                .par_iter()
                .map(|d| {
                    let dir = mount.rotation * Vector::new(d[0], d[1], d[2]);
                    let ray = Ray::new(origin, dir);
                    let mut best: Option<(f32, Owner)> = None;
                    for (owner, shape, pose) in &parts {
                        let max = best.map_or(self.config.range_m as f32, |(t, _)| t);
                        if let Some(t) = shape.cast_ray(pose, &ray, max, true) {
                            best = Some((t, *owner));
                        }
                    }
                    best
                })
                .collect()
        })
    }

    /// Every ray of a revolution in the vehicle frame, `[column * beams + beam]`: its unit
    /// direction and how far it goes before the vehicle itself stops it (`None`: it does not),
    /// metres - the self-occlusion the casts above use, from the sensor's mount.
    pub fn rays_in_vehicle(&self, world: &World) -> Vec<([f64; 3], Option<f64>)> {
        let rotation = self.vehicle_from_sensor.rotation;
        self.directions
            .iter()
            .zip(self.self_hits(world))
            .map(|(d, hit)| {
                let v = rotation * Vector3::new(f64::from(d[0]), f64::from(d[1]), f64::from(d[2]));
                ([v.x, v.y, v.z], hit.as_ref().map(|(t, _)| f64::from(*t)))
            })
            .collect()
    }

    /// Elevations of the beams, radians, lowest first.
    pub fn elevations_rad(&self) -> &[f64] {
        &self.elevations_rad
    }
}

/// Heading of the sensor in the vehicle frame (about z), radians.
fn sensor_yaw(vehicle_from_sensor: &Isometry3<f64>) -> f32 {
    let x = vehicle_from_sensor.rotation * Vector3::x();
    x.y.atan2(x.x) as f32
}

/// SplitMix64 over (seed, scan, column): independent streams per column.
fn mix(seed: u64, scan: u64, column: u64) -> u64 {
    let mut z = seed
        ^ scan.wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ column.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
