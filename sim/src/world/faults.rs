//! Faults injected between the world and the stack under test: revolutions lost (singly or in
//! bursts) or delivered late (latency and jitter), beams that drop out (at random, or dead for the
//! whole run), extra range noise, spurious returns (rain- or dust-like, near the sensor), a pose
//! estimate biased or drifting beyond its source's own error, and a stale offline map (the
//! mapping drive made with static objects moved, missing or extra). Every draw is seeded by the
//! run's seed and the revolution's index, so a run with faults is as reproducible as one without.

use mapper::{Return, Scan};
use nalgebra::{Point3, Vector3};
use rand::{RngExt as _, SeedableRng as _};
use serde::{Deserialize, Serialize};

/// The `[faults]` of a run configuration (or a scenario's `[config.faults]`). All off by default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FaultsConfig {
    /// Chance, per revolution, that a burst of lost revolutions starts there. Default 0.
    pub lost_revolution_probability: f64,
    /// Revolutions a burst loses (the first included). Default 1.
    pub lost_burst_revolutions: u32,
    /// Chance that a beam's return is lost, per return. Default 0.
    pub beam_dropout_probability: f64,
    /// Beams (0 = lowest) that never return. Default none.
    pub dead_beams: Vec<usize>,
    /// Standard deviation of Gaussian range noise added to every return, metres. Default 0.
    pub extra_range_noise_m: f64,
    /// Mean number of spurious returns a revolution (Poisson): points 1-15 m from the sensor in
    /// random columns and beams, where a raindrop or dust would answer. Default 0.
    pub spurious_returns_per_revolution: f64,
    /// A constant error of the pose estimate beyond the pose source's own, in the vehicle frame:
    /// `[along, across]` metres (positive: the estimate is ahead, left of the truth). Default 0.
    pub pose_bias_m: [f64; 2],
    /// A constant heading error of the estimate, radians. Default 0.
    pub pose_bias_rad: f64,
    /// An across-track error growing with time (a localizer drifting off), metres per second.
    /// Default 0.
    pub pose_drift_m_per_s: f64,
    /// Time from a revolution's end to its delivery to the stack, seconds. Default 0.
    pub lidar_latency_s: f64,
    /// Extra delay drawn uniformly in `[0, lidar_jitter_s]` for each revolution, seconds
    /// (revolutions still arrive in order). Default 0.
    pub lidar_jitter_s: f64,
    /// How the world of the mapping drive differed from the run's. Default: not at all.
    pub stale_map: StaleMap,
}

/// A stale offline map: the mapping drive was made in a world whose movable static objects
/// (cones, containers, markers, parked cars, debris, vehicles; not buildings, lamp posts or
/// plain boxes and cylinders, which scenarios use for structures) stood elsewhere, were missing, or had company that
/// has since gone. Seeded by the scenario's seed (the map's own).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StaleMap {
    /// Each movable object stood this far from where it stands now, in a seeded direction,
    /// metres. Default 0.
    pub moved_m: f64,
    /// The fraction of movable objects (seeded choice) that were not there yet: the map does not
    /// know them. Default 0.
    pub removed_fraction: f64,
    /// Objects that stood near the route at the mapping drive and are gone now: ghosts in the
    /// map. Each a copy of a movable object of the scenario (a cone if it has none), within 4 m
    /// of the route's centre line. Default 0.
    pub added_objects: u32,
}

impl StaleMap {
    /// Whether the map is stale at all.
    pub fn any(&self) -> bool {
        *self != StaleMap::default()
    }
}

impl Default for FaultsConfig {
    fn default() -> Self {
        FaultsConfig {
            lost_revolution_probability: 0.0,
            lost_burst_revolutions: 1,
            beam_dropout_probability: 0.0,
            dead_beams: Vec::new(),
            extra_range_noise_m: 0.0,
            spurious_returns_per_revolution: 0.0,
            pose_bias_m: [0.0, 0.0],
            pose_bias_rad: 0.0,
            pose_drift_m_per_s: 0.0,
            lidar_latency_s: 0.0,
            lidar_jitter_s: 0.0,
            stale_map: StaleMap::default(),
        }
    }
}

/// What the faults did in a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FaultCounts {
    /// Revolutions that never reached the stack.
    pub lost_revolutions: u64,
    /// Returns removed (dropout and dead beams).
    pub dropped_returns: u64,
    /// Spurious returns added.
    pub spurious_returns: u64,
    /// Times the stack's watchdog stopped the vehicle for want of a fresh revolution.
    pub watchdog_stops: u64,
    /// Revolutions delivered late (latency or jitter above 0).
    #[serde(default)]
    pub delayed_revolutions: u64,
}

impl FaultsConfig {
    /// Checks the values; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        for (field, p) in [
            (
                "faults.lost_revolution_probability",
                self.lost_revolution_probability,
            ),
            (
                "faults.beam_dropout_probability",
                self.beam_dropout_probability,
            ),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return Err(format!("{field} = {p}: must be a probability in [0, 1]"));
            }
        }
        if self.lost_burst_revolutions == 0 {
            return Err("faults.lost_burst_revolutions = 0: a burst loses at least one".into());
        }
        for (field, v) in [
            ("faults.extra_range_noise_m", self.extra_range_noise_m),
            (
                "faults.spurious_returns_per_revolution",
                self.spurious_returns_per_revolution,
            ),
            ("faults.lidar_latency_s", self.lidar_latency_s),
            ("faults.lidar_jitter_s", self.lidar_jitter_s),
            ("faults.stale_map.moved_m", self.stale_map.moved_m),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{field} = {v}: must be a finite number >= 0"));
            }
        }
        let removed = self.stale_map.removed_fraction;
        if !(0.0..=1.0).contains(&removed) {
            return Err(format!(
                "faults.stale_map.removed_fraction = {removed}: must be a fraction in [0, 1]"
            ));
        }
        if self.lidar_latency_s + self.lidar_jitter_s > 10.0 {
            return Err(format!(
                "faults.lidar_latency_s + faults.lidar_jitter_s = {} s: at most 10 s",
                self.lidar_latency_s + self.lidar_jitter_s
            ));
        }
        Ok(())
    }

    /// How late revolution `index` reaches the stack, seconds (0 without latency or jitter).
    pub fn delay_s(&self, seed: u64, index: u64) -> f64 {
        let jitter = if self.lidar_jitter_s > 0.0 {
            rng(seed, index, 3).random::<f64>() * self.lidar_jitter_s
        } else {
            0.0
        };
        self.lidar_latency_s + jitter
    }

    /// Whether any fault is on.
    pub fn any(&self) -> bool {
        *self != FaultsConfig::default()
    }

    /// The pose estimate at `t_s` with the pose faults applied (`estimate` unchanged without).
    pub fn bias_pose(
        &self,
        t_s: f64,
        estimate: &nalgebra::Isometry2<f64>,
    ) -> nalgebra::Isometry2<f64> {
        let across = self.pose_bias_m[1] + self.pose_drift_m_per_s * t_s;
        if self.pose_bias_m[0] == 0.0 && across == 0.0 && self.pose_bias_rad == 0.0 {
            return *estimate;
        }
        estimate
            * nalgebra::Isometry2::new(
                nalgebra::Vector2::new(self.pose_bias_m[0], across),
                self.pose_bias_rad,
            )
    }
}

/// A generator for revolution `index` of a run seeded `seed` (`stream` separates the uses).
fn rng(seed: u64, index: u64, stream: u64) -> rand::rngs::StdRng {
    let mut z = seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ stream.rotate_left(48);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    rand::rngs::StdRng::seed_from_u64(z ^ (z >> 31))
}

/// Decides, revolution by revolution, which are lost.
#[derive(Debug, Default)]
pub struct LostRevolutions {
    lost_until: u64,
}

impl LostRevolutions {
    /// Whether revolution `index` is lost.
    pub fn is_lost(&mut self, faults: &FaultsConfig, seed: u64, index: u64) -> bool {
        if index < self.lost_until {
            return true;
        }
        if faults.lost_revolution_probability > 0.0
            && rng(seed, index, 1).random::<f64>() < faults.lost_revolution_probability
        {
            self.lost_until = index + u64::from(faults.lost_burst_revolutions);
            return true;
        }
        false
    }
}

/// `scan` with the return faults of revolution `index` applied; adds what it did to `counts`.
pub fn degrade(
    scan: &Scan,
    faults: &FaultsConfig,
    seed: u64,
    index: u64,
    counts: &mut FaultCounts,
) -> Result<Scan, mapper::MapError> {
    let beams = scan.beams();
    let mut returns: Vec<Option<Return>> = scan.returns().to_vec();
    let mut r = rng(seed, index, 2);
    let normal = rand_distr::Normal::new(0.0, faults.extra_range_noise_m).ok();
    for (k, slot) in returns.iter_mut().enumerate() {
        let Some(ret) = slot else { continue };
        let beam = k % beams;
        let drop = faults.dead_beams.contains(&beam)
            || (faults.beam_dropout_probability > 0.0
                && r.random::<f64>() < faults.beam_dropout_probability);
        if drop {
            *slot = None;
            counts.dropped_returns += 1;
            continue;
        }
        if let Some(normal) = normal.filter(|_| faults.extra_range_noise_m > 0.0) {
            let column = &scan.columns()[k / beams];
            let origin = Point3::from(column.world_from_sensor.translation.vector);
            let ray = ret.point_in_world - origin;
            let range = ray.norm();
            if range > 1e-6 {
                let new = (range + r.sample(normal)).max(0.0);
                ret.point_in_world = origin + ray * (new / range);
                ret.range_m = new as f32;
            }
        }
    }
    if faults.spurious_returns_per_revolution > 0.0 && scan.column_count() > 0 {
        let n = match rand_distr::Poisson::new(faults.spurious_returns_per_revolution) {
            Ok(p) => r.sample(p) as u64,
            Err(_) => 0,
        };
        for _ in 0..n {
            let column = r.random_range(0..scan.column_count());
            let beam = r.random_range(0..beams);
            let range = r.random_range(1.0..15.0);
            let sensor = scan.columns()[column].world_from_sensor;
            // Along the beam's direction if it had a return, else level and ahead of the column.
            let dir = returns[column * beams + beam]
                .map(|ret| {
                    (ret.point_in_world - Point3::from(sensor.translation.vector)).normalize()
                })
                .unwrap_or_else(|| sensor.rotation * Vector3::x());
            returns[column * beams + beam] = Some(Return {
                point_in_world: Point3::from(sensor.translation.vector) + dir * range,
                range_m: range as f32,
                intensity: r.random_range(0.0..0.2),
            });
            counts.spurious_returns += 1;
        }
    }
    Scan::new(beams, scan.columns().to_vec(), returns)
}

/// The world of a stale map's mapping drive: `scene` (the run's static world) with its movable
/// objects moved, some missing and ghosts added near `route`, as `stale` says, seeded by `seed`.
/// The removed and moved objects keep their ids; ghosts are named `stale-ghost-<k>`.
pub fn stale_scene(
    scene: &super::scene::Scene,
    stale: &StaleMap,
    seed: u64,
    route: &autonomy::RoutePath,
) -> super::scene::Scene {
    use super::scene::{ObjectKind, SolidShape};
    if !stale.any() {
        return scene.clone();
    }
    let movable = |s: &super::scene::Solid| {
        !s.runtime
            && matches!(
                s.kind,
                ObjectKind::Cone
                    | ObjectKind::Container
                    | ObjectKind::Marker
                    | ObjectKind::ParkedCar
                    | ObjectKind::Debris
                    | ObjectKind::Vehicle
            )
    };
    let mut r = rng(seed, 0, 4);
    let mut out = scene.clone();
    out.solids.clear();
    for solid in &scene.solids {
        if !movable(solid) {
            out.solids.push(solid.clone());
            continue;
        }
        // Drawn for every movable object whatever the settings, so one setting's draws do not
        // shift another's.
        let (missing, angle) = (
            r.random::<f64>(),
            r.random_range(0.0..std::f64::consts::TAU),
        );
        if missing < stale.removed_fraction {
            continue;
        }
        let mut moved = solid.clone();
        moved.x_m += stale.moved_m * angle.cos();
        moved.y_m += stale.moved_m * angle.sin();
        out.solids.push(moved);
    }
    let models: Vec<&super::scene::Solid> = scene.solids.iter().filter(|s| movable(s)).collect();
    for k in 0..stale.added_objects {
        let (p, heading) = route.at(r.random_range(0.0..=route.length_m()));
        let across = r.random_range(-4.0..=4.0);
        let at = p + nalgebra::Vector2::new(-heading.sin(), heading.cos()) * across;
        let mut ghost = match models.get(r.random_range(0..models.len().max(1))) {
            Some(model) => (*model).clone(),
            None => super::scene::Solid {
                id: String::new(),
                kind: ObjectKind::Cone,
                shape: SolidShape::Cone {
                    radius_m: 0.2,
                    height_m: 0.7,
                },
                x_m: 0.0,
                y_m: 0.0,
                z_min_m: 0.0,
                yaw_rad: 0.0,
                remission: 0.6,
                runtime: false,
            },
        };
        ghost.id = format!("stale-ghost-{k}");
        (ghost.x_m, ghost.y_m) = (at.x, at.y);
        out.solids.push(ghost);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_bias_is_in_the_vehicle_frame_and_a_drift_grows_with_time() {
        use nalgebra::{Isometry2, Vector2};
        let truth = Isometry2::new(Vector2::new(10.0, 5.0), std::f64::consts::FRAC_PI_2);
        assert_eq!(FaultsConfig::default().bias_pose(3.0, &truth), truth);
        let f = FaultsConfig {
            pose_bias_m: [0.5, 0.2],
            pose_drift_m_per_s: 0.01,
            ..FaultsConfig::default()
        };
        // Heading north: ahead is +y, left is -x; at 10 s the drift adds 0.1 m to the left.
        let e = f.bias_pose(10.0, &truth);
        assert!((e.translation.x - (10.0 - 0.3)).abs() < 1e-12, "{e}");
        assert!((e.translation.y - 5.5).abs() < 1e-12, "{e}");
        assert!((e.rotation.angle() - truth.rotation.angle()).abs() < 1e-12);
        let turned = FaultsConfig {
            pose_bias_rad: 0.05,
            ..FaultsConfig::default()
        }
        .bias_pose(0.0, &truth);
        assert!((turned.rotation.angle() - truth.rotation.angle() - 0.05).abs() < 1e-12);
    }

    #[test]
    fn a_stale_scene_moves_drops_and_adds_only_movable_objects_the_same_way_each_time() {
        use super::super::scene::{ObjectKind, Scene, Solid, SolidShape};
        use nalgebra::Point2;
        let solid = |id: &str, kind, x_m| Solid {
            id: id.into(),
            kind,
            shape: SolidShape::Box {
                size_m: [1.0, 1.0, 1.0],
            },
            x_m,
            y_m: 10.0,
            z_min_m: 0.0,
            yaw_rad: 0.0,
            remission: 0.5,
            runtime: false,
        };
        let mut solids: Vec<Solid> = (0..40)
            .map(|k| solid(&format!("car{k}"), ObjectKind::ParkedCar, k as f64))
            .collect();
        solids.push(solid("hangar", ObjectKind::Building, 100.0));
        let scene = Scene {
            areas: Vec::new(),
            min_m: [-10.0, -10.0],
            max_m: [200.0, 50.0],
            solids,
            ..Scene::default()
        };
        let route =
            autonomy::RoutePath::new(&[Point2::new(0.0, 0.0), Point2::new(100.0, 0.0)], false);
        assert_eq!(stale_scene(&scene, &StaleMap::default(), 1, &route), scene);
        let moved = stale_scene(
            &scene,
            &StaleMap {
                moved_m: 2.0,
                ..StaleMap::default()
            },
            1,
            &route,
        );
        for (a, b) in scene.solids.iter().zip(&moved.solids) {
            let d = ((a.x_m - b.x_m).powi(2) + (a.y_m - b.y_m).powi(2)).sqrt();
            let want = if a.kind == ObjectKind::Building {
                0.0
            } else {
                2.0
            };
            assert!((d - want).abs() < 1e-9, "{} moved {d}", a.id);
        }
        let stale = StaleMap {
            removed_fraction: 0.5,
            added_objects: 6,
            ..StaleMap::default()
        };
        let a = stale_scene(&scene, &stale, 1, &route);
        assert_eq!(a, stale_scene(&scene, &stale, 1, &route));
        assert_ne!(a, stale_scene(&scene, &stale, 2, &route));
        assert!(a.solids.iter().any(|s| s.id == "hangar"));
        let kept = a.solids.iter().filter(|s| s.id.starts_with("car")).count();
        assert!(
            (10..=30).contains(&kept),
            "{kept} of 40 kept at a fraction 0.5 removed"
        );
        let ghosts: Vec<_> = a
            .solids
            .iter()
            .filter(|s| s.id.starts_with("stale-ghost-"))
            .collect();
        assert_eq!(ghosts.len(), 6);
        for g in ghosts {
            assert_eq!(g.kind, ObjectKind::ParkedCar);
            assert!(
                (-1e-9..=100.0 + 1e-9).contains(&g.x_m) && g.y_m.abs() <= 4.0 + 1e-9,
                "{g:?}"
            );
        }
    }

    #[test]
    fn latency_and_jitter_delay_every_revolution_within_their_bounds() {
        let f = FaultsConfig {
            lidar_latency_s: 0.1,
            lidar_jitter_s: 0.05,
            ..FaultsConfig::default()
        };
        let delays: Vec<f64> = (0..1000).map(|i| f.delay_s(3, i)).collect();
        assert!(delays.iter().all(|d| (0.1..=0.15).contains(d)));
        let mean = delays.iter().sum::<f64>() / 1000.0;
        assert!((mean - 0.125).abs() < 0.003, "{mean}");
        assert_eq!(
            delays,
            (0..1000).map(|i| f.delay_s(3, i)).collect::<Vec<_>>()
        );
        assert_eq!(FaultsConfig::default().delay_s(3, 5), 0.0);
        let bad = FaultsConfig {
            stale_map: StaleMap {
                removed_fraction: 2.0,
                ..StaleMap::default()
            },
            ..FaultsConfig::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("faults.stale_map.removed_fraction")
        );
    }

    #[test]
    fn bursts_lose_consecutive_revolutions_at_the_rate_asked_and_the_same_ones_each_run() {
        let faults = FaultsConfig {
            lost_revolution_probability: 0.05,
            lost_burst_revolutions: 4,
            ..FaultsConfig::default()
        };
        let lost = |seed| {
            let mut l = LostRevolutions::default();
            (0..4000)
                .map(|i| l.is_lost(&faults, seed, i))
                .collect::<Vec<bool>>()
        };
        let a = lost(7);
        assert_eq!(a, lost(7));
        assert_ne!(a, lost(8));
        // Runs of lost revolutions are at least a burst long.
        let mut run = 0;
        for (i, &x) in a.iter().enumerate() {
            if x {
                run += 1;
            } else {
                assert!(run == 0 || run >= 4, "a run of {run} ending at {i}");
                run = 0;
            }
        }
        // A burst starts with p = 0.05 at a revolution not already lost: a fraction
        // 4p / (1 + 3p) = 17.4 % of revolutions are lost.
        let fraction = a.iter().filter(|&&x| x).count() as f64 / a.len() as f64;
        assert!((fraction - 0.174).abs() < 0.03, "{fraction}");
        assert!(FaultsConfig::default().validate().is_ok());
        let bad = FaultsConfig {
            beam_dropout_probability: 1.5,
            ..FaultsConfig::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("faults.beam_dropout_probability")
        );
    }
}
