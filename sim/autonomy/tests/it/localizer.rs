//! The particle filter on an analytic scene: a painted ground and a few solids, mapped from
//! exact HDL-32E scans; then driven with biased odometry from a wrong fix. It must converge, agree
//! with the straightforward measurement update, repeat itself from a seed, and on a featureless
//! field stay uncertain instead of confidently wrong.

use autonomy::localizer::{
    LocalizerConfig, MeasurementModel, Observation, Particle, ParticleFilter, weigh,
    weigh_straightforward,
};
use autonomy::{LidarRevolution, Odometry};
use mapper::synthetic::{Lidar, Scene, Solid, car_sensor_mount};
use mapper::{Levels, MapConfig, MultiHeightMap, Return, Scan};
use nalgebra::{Isometry2, Point2, Vector2};

const WHEELBASE_M: f64 = 2.6;

/// Painted rectangles on a 0.15 asphalt: dashes along the centreline, bay lines across, and
/// irregular patches (a hash of the 3 m square).
fn paint(x: f64, y: f64) -> f32 {
    if y.abs() < 0.1 && x.rem_euclid(4.0) < 2.0 {
        return 0.7;
    }
    if (y.abs() - 5.0).abs() < 2.5 && x.rem_euclid(2.7) < 0.15 {
        return 0.6;
    }
    let (i, j) = ((x / 3.0).floor() as i64, (y / 3.0).floor() as i64);
    let h = (i.wrapping_mul(73_856_093) ^ j.wrapping_mul(19_349_663)).rem_euclid(7);
    if h == 0 && x.rem_euclid(3.0) < 1.5 && y.rem_euclid(3.0) < 1.0 {
        return 0.45;
    }
    0.15
}

fn scene(solids: bool) -> Scene {
    let mut s = Scene {
        solids: Vec::new(),
        ground_intensity: 0.15,
        solid_intensity: 0.5,
    };
    if solids {
        for k in 0..8 {
            let x = 8.0 * k as f64 - 4.0;
            s.solids
                .push(Solid::standing_box(x, 9.0 + (k % 3) as f64, 2.0, 1.0, 1.5));
            s.solids
                .push(Solid::post(x + 3.0, -7.0 - (k % 2) as f64, 0.2, 2.0));
        }
    }
    s
}

/// A revolution from `pose`, the ground painted (or not).
fn scan(scene: &Scene, pose: &Isometry2<f64>, painted: bool) -> Scan {
    let raw = Lidar::hdl32e()
        .scan(scene, pose, &car_sensor_mount(), |_, _| 0.0)
        .expect("scan");
    let returns: Vec<Option<Return>> = raw
        .returns()
        .iter()
        .map(|r| {
            r.map(|mut r| {
                if painted && r.point_in_world.z.abs() < 1e-6 {
                    r.intensity = paint(r.point_in_world.x, r.point_in_world.y);
                }
                r
            })
        })
        .collect();
    Scan::new(raw.beams(), raw.columns().to_vec(), returns).expect("scan")
}

fn levels() -> Levels {
    Levels::new(vec![0.0, 2.0], mapper::LevelMode::Cumulative, None).expect("levels")
}

/// The map of the scene from revolutions every 2 m along y = 0, x in [-10, 70].
fn mapped(scene: &Scene, painted: bool) -> MultiHeightMap {
    let config = MapConfig {
        max_distance_m: 1.0,
        ..MapConfig::default()
    };
    let mut map = MultiHeightMap::new(config, levels(), Point2::new(30.0, 0.0)).expect("map");
    for k in 0..=40 {
        let pose = Isometry2::new(Vector2::new(-10.0 + 2.0 * k as f64, 0.0), 0.0);
        map.insert_scan(&scan(scene, &pose, painted), None)
            .expect("insert");
    }
    map
}

fn revolution(scene: &Scene, truth: &Isometry2<f64>, painted: bool, t_s: f64) -> LidarRevolution {
    LidarRevolution {
        t_s,
        scan: scan(scene, truth, painted),
        more_scans: Vec::new(),
        world_from_vehicle_estimate: *truth,
        estimate_covariance: nalgebra::Matrix3::zeros(),
    }
}

struct Drive {
    /// Cross-track error, heading error and cross-track sigma after each update.
    cross_track_m: Vec<f64>,
    heading_rad: Vec<f64>,
    sigma_m: Vec<f64>,
}

/// What the field driven on holds: painted ground (remission to match) and solids (obstacles).
#[derive(Clone, Copy)]
struct Field {
    painted: bool,
    solids: bool,
}

/// Paint and solids.
const FULL: Field = Field {
    painted: true,
    solids: true,
};
/// Paint only.
const PAINTED: Field = Field {
    painted: true,
    solids: false,
};
/// Neither.
const FEATURELESS: Field = Field {
    painted: false,
    solids: false,
};

/// 40 m straight at 2 m/s from x = 5 (truth), the filter started from a fix 0.3 m ahead, 0.35 m
/// right and 0.03 rad off, the odometry's speed 3 % high and its steering 0.01 rad left.
fn drive(config: LocalizerConfig, field: Field, seed: u64) -> Drive {
    let Field { painted, solids } = field;
    let scene = scene(solids);
    let map = mapped(&scene, painted);
    let mut pf = ParticleFilter::new(config, WHEELBASE_M, map, seed);
    let start = Isometry2::new(Vector2::new(5.0, 0.0), 0.0);
    let fix = Isometry2::new(Vector2::new(5.3, -0.35), 0.03);
    pf.initialise(&fix).expect("initialise");
    let mut out = Drive {
        cross_track_m: Vec::new(),
        heading_rad: Vec::new(),
        sigma_m: Vec::new(),
    };
    let (v, dt) = (2.0, 0.01);
    for step in 0..2000 {
        let t = step as f64 * dt;
        pf.on_odometry(&Odometry {
            t_s: t,
            speed_m_s: v * 1.03,
            steering_rad: 0.01,
        });
        if step % 10 == 0 && step > 0 {
            let truth = Isometry2::new(Vector2::new(start.translation.x + v * t, 0.0), 0.0);
            pf.on_revolution(&revolution(&scene, &truth, painted, t), None, 0.0)
                .expect("update");
            let e = pf.estimate();
            out.cross_track_m.push(e.world_from_vehicle.translation.y);
            out.heading_rad.push(e.world_from_vehicle.rotation.angle());
            out.sigma_m.push(e.cross_track_sigma_m());
        }
    }
    out
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn the_filter_converges_from_a_wrong_fix_on_biased_odometry() {
    let d = drive(LocalizerConfig::default(), FULL, 1);
    let settled = &d.cross_track_m[50..];
    let heading = &d.heading_rad[50..];
    assert!(rms(settled) < 0.05, "cross-track RMS {}", rms(settled));
    assert!(rms(heading) < 0.01, "heading RMS {}", rms(heading));
    // The fix's spread was 0.5 m; the settled estimate knows it is better than that.
    let sigma = d.sigma_m.last().copied().unwrap_or(f64::NAN);
    assert!(sigma < 0.1, "final cross-track sigma {sigma}");
}

#[test]
fn remission_alone_localizes_on_a_painted_field() {
    let config = LocalizerConfig {
        measurement: MeasurementModel::Remission,
        ..Default::default()
    };
    let d = drive(config, PAINTED, 2);
    let settled = &d.cross_track_m[50..];
    assert!(rms(settled) < 0.1, "cross-track RMS {}", rms(settled));
}

/// Without paint or solids there is nothing to match: the filter must say so (a wide
/// covariance) rather than settle on a wrong pose with confidence.
#[test]
fn on_a_featureless_field_the_covariance_stays_wide() {
    let config = LocalizerConfig {
        measurement: MeasurementModel::Remission,
        ..Default::default()
    };
    let featureless = drive(config.clone(), FEATURELESS, 3);
    let painted = drive(config, PAINTED, 3);
    let last = |d: &Drive| d.sigma_m.last().copied().unwrap_or(f64::NAN);
    assert!(
        last(&featureless) > 3.0 * last(&painted),
        "featureless sigma {} vs painted {}",
        last(&featureless),
        last(&painted)
    );
    // And its error stays within about two of its sigmas.
    let err = featureless
        .cross_track_m
        .last()
        .copied()
        .unwrap_or(f64::NAN);
    assert!(err.abs() < 2.5 * last(&featureless) + 0.05, "error {err}");
}

#[test]
fn the_same_seed_gives_the_same_estimates() {
    let short = |seed| {
        let c = LocalizerConfig {
            particles: 100,
            ..Default::default()
        };
        drive(c, FULL, seed).cross_track_m[..30].to_vec()
    };
    assert_eq!(short(5), short(5));
    assert_ne!(short(5), short(6));
}

#[test]
fn the_tables_weigh_like_the_straightforward_way() {
    let scene = scene(true);
    let map = mapped(&scene, true);
    let mut pf = ParticleFilter::new(LocalizerConfig::default(), WHEELBASE_M, map, 9);
    let truth = Isometry2::new(Vector2::new(20.0, 0.0), 0.0);
    pf.initialise(&truth).expect("initialise");
    for measurement in [
        MeasurementModel::Both,
        MeasurementModel::Remission,
        MeasurementModel::LikelihoodField,
    ] {
        let config = LocalizerConfig {
            measurement,
            ..Default::default()
        };
        let obs = Observation::from_revolution(
            &revolution(&scene, &truth, true, 0.0),
            &config,
            None,
            0.0,
            pf.map().config(),
        );
        assert!(obs.ground.len() == 400 && obs.obstacles.len() == 200);
        let particles: Vec<Particle> = pf.particles().to_vec();
        let lmap = pf.localization_map().expect("map built at initialise");
        let fast = weigh(&particles, &obs, lmap, &config);
        let field = autonomy::localizer::level0_distance(pf.map(), &config);
        let slow = weigh_straightforward(
            &particles,
            &obs,
            &pf.map().remission_grid(),
            field.as_ref(),
            &config,
        );
        for (f, s) in fast.iter().zip(&slow) {
            assert!((f - s).abs() <= 1e-4 * s.abs().max(1.0), "{f} vs {s}");
        }
        // The truth scores best among poses 0.4 m or 0.05 rad off.
        let at = |x: f64, y: f64, theta: f64| Particle {
            x,
            y,
            theta,
            speed_scale: 0.0,
            steering_rad: 0.0,
        };
        let w = weigh(
            &[
                at(20.0, 0.0, 0.0),
                at(20.0, 0.4, 0.0),
                at(20.4, 0.0, 0.0),
                at(20.0, 0.0, 0.05),
            ],
            &obs,
            lmap,
            &config,
        );
        assert!(w[1..].iter().all(|o| *o < w[0]), "{measurement:?}: {w:?}");
    }
}

/// The ground returns the filter weighs are remissions by the calibration of the map it weighs
/// them against: with the map's falloff each intensity is taken back over its range (a ground
/// point `d` m away from the car's sensor, 2.15 m up, was read across `hypot(d, 2.15)`), with
/// none it is the intensity as read.
#[test]
fn ground_intensities_are_weighed_as_the_maps_remissions() {
    let scene = scene(false);
    let truth = Isometry2::new(Vector2::new(20.0, 0.0), 0.3);
    let rev = revolution(&scene, &truth, true, 0.0);
    let config = LocalizerConfig::default();
    let observe = |falloff: f64| {
        let map = MapConfig {
            intensity_falloff_per_m: falloff,
            ..MapConfig::default()
        };
        Observation::from_revolution(&rev, &config, None, 0.0, &map)
    };
    let (raw, calibrated) = (observe(0.0), observe(0.004));
    assert_eq!(raw.ground.len(), calibrated.ground.len());
    assert!(raw.ground.len() > 300);
    let mut far = 0;
    for (r, c) in raw.ground.iter().zip(&calibrated.ground) {
        assert_eq!((r[0], r[1]), (c[0], c[1]), "the same points");
        let range = r[0].hypot(r[1]).hypot(2.15);
        let want = r[2] * (0.004 * range).exp();
        assert!(
            (c[2] - want).abs() <= 2e-6,
            "{r:?}: {} against {want}",
            c[2]
        );
        far += usize::from(range > 20.0 && c[2] > r[2] * 1.08);
    }
    assert!(far > 20, "far returns read brighter once calibrated: {far}");
}
