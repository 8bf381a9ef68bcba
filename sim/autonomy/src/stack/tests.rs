//! The driver's unit tests: an empty map, a straight route.

use super::*;
use crate::online_map::ForgettingConfig;
use mapper::{Circle, Levels, MapConfig, MultiHeightMap};

fn driver() -> Driver {
    let route = RoutePath::new(&[Point2::new(0.0, 0.0), Point2::new(200.0, 0.0)], false);
    let circle = |x_m| Circle {
        x_m,
        y_m: 0.0,
        radius_m: 1.0,
        level: 0,
    };
    let collision = CollisionModel::new(vec![circle(0.0), circle(2.0)], vec![0.0]).unwrap();
    Driver::new(
        route,
        VehicleModel {
            collision,
            wheelbase_m: 2.5,
            deceleration_m_s2: 3.0,
            acceleration_m_s2: 1.0,
            behaviour: Behaviour::Deviate,
        },
        AutonomyConfig::default(),
        5.0,
        40.0,
    )
}

fn empty_map() -> OnlineMap {
    started(unstarted_map(), 20.0)
}

/// An empty map centred at (20, 0) that no revolution has reached.
fn unstarted_map() -> OnlineMap {
    let config = MapConfig {
        block_cells: 100,
        max_distance_m: 5.0,
        ..MapConfig::default()
    };
    let levels = Levels::cumulative(vec![0.0]).unwrap();
    let map = MultiHeightMap::new(config, levels, Point2::new(20.0, 0.0)).unwrap();
    let self_filter = CollisionModel::new(
        vec![mapper::Circle {
            x_m: 1.0,
            y_m: 0.0,
            radius_m: 1.5,
            level: 0,
        }],
        vec![0.0],
    )
    .unwrap();
    OnlineMap::new(map, self_filter, ForgettingConfig::default(), 0.1, 1.0)
}

/// `map` after an empty revolution at an exact pose at `x_m` (where it is centred):
/// mapping has started.
fn started(mut map: OnlineMap, x_m: f64) -> OnlineMap {
    assert!(!map.mapping_started());
    map.update(&crate::LidarRevolution {
        t_s: 0.0,
        scan: mapper::Scan::new(1, Vec::new(), Vec::new()).unwrap(),
        more_scans: Vec::new(),
        world_from_vehicle_estimate: nalgebra::Isometry2::translation(x_m, 0.0),
        estimate_covariance: nalgebra::Matrix3::zeros(),
    })
    .unwrap();
    assert!(map.mapping_started());
    map
}

/// Until mapping has started (no revolution yet, or none taken at an estimate trusted out
/// to the obstacle test's range), the vehicle is held, whatever the estimate.
#[test]
fn the_vehicle_is_held_until_mapping_has_started() {
    let mut map = unstarted_map();
    let mut d = driver();
    d.on_pose(at(0.0, 10.0, 0.0, 0.0));
    let revolution = |t_s: f64, sigma_rad: f64| crate::LidarRevolution {
        t_s,
        scan: mapper::Scan::new(1, Vec::new(), Vec::new()).unwrap(),
        more_scans: Vec::new(),
        world_from_vehicle_estimate: nalgebra::Isometry2::translation(10.0, 0.0),
        estimate_covariance: nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(
            0.0025,
            0.0025,
            sigma_rad * sigma_rad,
        )),
    };
    d.plan(&mut map).unwrap();
    assert_eq!(d.speed_command_m_s(), 0.0);
    // 2 x 0.01 rad x 70 m = 1.4 m: not yet.
    map.update(&revolution(0.0, 0.01)).unwrap();
    d.plan(&mut map).unwrap();
    assert!(!map.mapping_started());
    assert_eq!(d.speed_command_m_s(), 0.0);
    // 2 x 0.004 rad x 70 m = 0.56 m (with 0.1 m of position): mapping starts, the vehicle goes.
    map.update(&revolution(0.1, 0.004)).unwrap();
    d.plan(&mut map).unwrap();
    assert!(map.mapping_started());
    assert!(d.speed_command_m_s() > 0.0);
}

fn at(t_s: f64, x: f64, y: f64, yaw: f64) -> PoseEstimate {
    PoseEstimate {
        covariance: nalgebra::Matrix3::zeros(),
        t_s,
        world_from_vehicle: Isometry2::new(Vector2::new(x, y), yaw),
    }
}

#[test]
fn without_an_estimate_the_vehicle_is_held() {
    let mut d = driver();
    let mut map = empty_map();
    d.plan(&mut map).unwrap();
    assert!(d.last_plan().is_none());
    assert_eq!(d.command(), Command::default());
}

/// The plan starts where the estimate is, and the route progress is the estimate's: the
/// driver has nothing else to go by (before, progress came from the true pose every step).
#[test]
fn plans_and_tracks_route_progress_from_its_estimate() {
    let mut d = driver();
    let mut map = empty_map();
    d.on_pose(at(0.0, 10.0, 1.0, 0.0));
    d.plan(&mut map).unwrap();
    assert!((d.route_s_m().unwrap() - 10.0).abs() < 1e-9);
    let first = d.last_plan().unwrap().chosen().poses[0];
    assert!(
        (first.translation.y - 1.0).abs() < 1e-9,
        "starts at the estimate's offset: {first}"
    );
    assert_eq!(d.speed_command_m_s(), 5.0, "nothing in the way");
    d.on_pose(at(0.1, 12.5, -0.5, 0.0));
    d.plan(&mut map).unwrap();
    assert!((d.route_s_m().unwrap() - 12.5).abs() < 1e-9);
    // Steering back towards the route from the left: to the right (negative).
    d.on_pose(at(0.2, 13.0, 1.0, 0.0));
    d.plan(&mut map).unwrap();
    d.on_odometry(Odometry {
        t_s: 0.2,
        speed_m_s: 5.0,
        steering_rad: 0.0,
    });
    let c = d.command();
    assert!(c.speed_m_s == 5.0 && c.steering_rad < 0.0, "{c:?}");
}

/// A route faster than the vehicle can stop from within its longest horizon (60 m at
/// 3 m/s^2: 17.5 m/s) is lowered, and the driver says so; one within it is not.
#[test]
fn a_route_too_fast_to_stop_within_the_horizon_is_lowered() {
    assert_eq!(driver().route_speed_lowered(), None, "5 m/s is allowed");
    let mut fast = driver();
    fast.wanted_speed_m_s = 20.0;
    let (cap, why) = fast.route_speed_lowered().expect("lowered");
    assert_eq!(why, SpeedLimit::Horizon);
    let stopping = cap * 0.5 + cap * cap / 6.0 + 3.0;
    assert!(
        (stopping - 60.0).abs() < 1e-9,
        "{cap} m/s stops in {stopping} m"
    );
    // Maps wide enough for the 60 m horizon the speed needs (blocks of 60 m).
    fast.distance_map_half_size_m = 80.0;
    let config = MapConfig {
        block_cells: 300,
        max_distance_m: 5.0,
        ..MapConfig::default()
    };
    let levels = Levels::cumulative(vec![0.0]).unwrap();
    let wide = MultiHeightMap::new(config, levels, Point2::new(40.0, 0.0)).unwrap();
    let self_filter = fast.vehicle.collision.clone();
    let mut map = started(
        OnlineMap::new(wide, self_filter, ForgettingConfig::default(), 0.1, 1.0),
        40.0,
    );
    fast.on_pose(at(0.0, 10.0, 0.0, 0.0));
    fast.plan(&mut map).unwrap();
    let v = fast.speed_command_m_s();
    assert!((v - cap).abs() < 1e-9, "{v} against {cap}");
}

/// An estimate with a lateral standard deviation `sigma_m` (position only).
fn uncertain(sigma_m: f64) -> PoseEstimate {
    PoseEstimate {
        covariance: nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(
            sigma_m * sigma_m,
            sigma_m * sigma_m,
            0.0,
        )),
        ..at(0.0, 10.0, 0.0, 0.0)
    }
}

/// A less certain estimate means a slower vehicle, then a stopped one: full speed up to
/// 0.15 m, falling linearly to 0 at 0.5 m (the defaults).
#[test]
fn an_uncertain_estimate_slows_then_stops_the_vehicle() {
    let speed = |sigma_m| {
        let mut d = driver();
        let mut map = empty_map();
        d.on_pose(uncertain(sigma_m));
        d.plan(&mut map).unwrap();
        d.speed_command_m_s()
    };
    assert_eq!(speed(0.0), 5.0);
    assert_eq!(speed(0.1), 5.0);
    assert!((speed(0.325) - 2.5).abs() < 1e-9, "{}", speed(0.325));
    assert_eq!(speed(0.5), 0.0);
    assert_eq!(
        speed(f64::NAN),
        0.0,
        "an estimate that knows nothing holds the vehicle"
    );
}

/// The margins widen by two standard deviations: an obstacle the certain estimate passes
/// 0.3 m from (beyond the avoider's 0.2 m) is inside the uncertain estimate's 0.2 + 2 x 0.1.
#[test]
fn an_uncertain_estimate_widens_the_safety_distances() {
    let c = AutonomyConfig::default();
    let (w, factor) = c.under_uncertainty(0.1);
    assert!((w.avoider_safety_m - 0.4).abs() < 1e-6 && (w.planner_safety_m - 0.8).abs() < 1e-6);
    assert_eq!(factor, 1.0);
    let (w0, _) = c.under_uncertainty(0.0);
    assert_eq!(w0, c);
}

/// Between estimates the driver carries its estimate forward on odometry (a localizer slower
/// than the control loop); a new estimate replaces it.
#[test]
fn between_estimates_the_pose_is_dead_reckoned_on_odometry() {
    let mut d = driver();
    d.on_pose(at(0.0, 0.0, 0.0, 0.0));
    let odo = |t_s, steering_rad| Odometry {
        t_s,
        speed_m_s: 2.0,
        steering_rad,
    };
    d.on_odometry(odo(0.0, 0.0));
    d.on_odometry(odo(0.5, 0.2));
    let e = d.estimate().unwrap();
    assert!((e.world_from_vehicle.translation.x - 1.0).abs() < 1e-12 && e.t_s == 0.5);
    // 0.5 s more on the arc of steering 0.2: yaw grows by v t tan(0.2) / wheelbase.
    d.on_odometry(odo(1.0, 0.2));
    let yaw = d.estimate().unwrap().world_from_vehicle.rotation.angle();
    assert!((yaw - 1.0 * 0.2f64.tan() / 2.5).abs() < 1e-12, "{yaw}");
    d.on_pose(at(1.0, 7.0, 0.0, 0.0));
    assert_eq!(d.estimate().unwrap().world_from_vehicle.translation.x, 7.0);
}

/// A zone of 0.5 m cells over x -10..10, y -5..5 of the vehicle frame, blind on level 0 where
/// `blind(x, y)` says (at the cell's centre).
fn zone(blind: impl Fn(f64, f64) -> bool) -> BlindZone {
    let (cell_m, cells) = (0.5, [40, 20]);
    let cell = (0..cells[0] * cells[1])
        .map(|k| {
            let (i, j) = (k % cells[0], k / cells[0]);
            blind(
                -10.0 + (i as f64 + 0.5) * cell_m,
                -5.0 + (j as f64 + 0.5) * cell_m,
            )
        })
        .collect();
    BlindZone {
        min_m: [-10.0, -5.0],
        cell_m,
        cells,
        levels: vec![cell],
    }
}

/// A 1 m circle at the origin on `level` of `heights`.
fn one_circle(level: usize, heights: Vec<f64>) -> CollisionModel {
    let circle = Circle {
        x_m: 0.0,
        y_m: 0.0,
        radius_m: 1.0,
        level,
    };
    CollisionModel::new(vec![circle], heights).unwrap()
}

/// The swept blind ground is each blind cell whose centre some circle of its level covers,
/// counted once: here one 1 m circle (level 0) at the origin over a blind square 2 m ahead.
#[test]
fn the_unseen_swept_ground_counts_each_blind_cell_a_circle_covers_once() {
    let square = zone(|x, y| (2.0..3.0).contains(&x) && (0.0..1.0).contains(&y));
    let model = one_circle(0, vec![0.0]);
    let here = Isometry2::new(Vector2::new(100.0, 50.0), 0.3);
    let ahead = |x: f64| here * Isometry2::translation(x, 0.0);
    // At the start the circle reaches x 1.0: none of the square (centres 2.25 and 2.75).
    assert_eq!(square.unseen_swept_m2(&model, &here, &[ahead(0.0)]), 0.0);
    // Centred on (2.5, 0): centres (2.25 | 2.75, 0.25 | 0.75) are all within 1 m: 4 cells.
    let all = square.unseen_swept_m2(&model, &here, &[ahead(0.0), ahead(2.5), ahead(2.6)]);
    assert_eq!(all, 4.0 * 0.25);
    // At (1.5, 0): only (2.25, 0.25) is within 1 m (0.79); (2.25, 0.75) is 1.06 away.
    assert_eq!(square.unseen_swept_m2(&model, &here, &[ahead(1.5)]), 0.25);
    // A level the zone does not list has no blind ground.
    let high = one_circle(1, vec![0.0, 1.0]);
    assert_eq!(square.unseen_swept_m2(&high, &here, &[ahead(2.5)]), 0.0);
}

/// Blind ground ahead: the driver does not move off, says why, calls for a pilot after
/// `pilot_call_after_s`, and goes once the walk-around has confirmed the ground.
#[test]
fn blind_ground_ahead_holds_the_vehicle_until_the_walk_around() {
    let mut d = driver();
    d.await_walk_around(zone(|x, _| (3.0..6.0).contains(&x)));
    let mut map = empty_map();
    d.on_pose(at(0.0, 10.0, 0.0, 0.0));
    d.plan(&mut map).unwrap();
    assert_eq!(d.speed_command_m_s(), 0.0);
    let DriverStatus::WaitingForWalkAround { unseen_m2, since_s } = d.status() else {
        panic!("{:?}", d.status());
    };
    // The two circles (x 0 and 2, radius 1) sweep a band 2 m wide along the 3 m of blind x.
    assert!((5.0..=7.0).contains(&unseen_m2), "{unseen_m2}");
    assert_eq!((since_s, d.start_unseen_m2()), (0.0, Some(unseen_m2)));
    // Its cells, in the world: as many as the area says, each in the blind band ahead of the
    // vehicle at (10, 0) and within the circles' reach of its path.
    let (cells, side) = d.start_unseen_cells().unwrap();
    assert_eq!(cells.len() as f64 * side * side, unseen_m2);
    assert!(
        cells
            .iter()
            .all(|c| (13.0..16.0).contains(&c.x) && c.y.abs() < 1.0),
        "{cells:?}"
    );
    let wait = AutonomyConfig::default().pilot_call_after_s;
    d.on_pose(at(wait - 0.1, 10.0, 0.0, 0.0));
    d.plan(&mut map).unwrap();
    assert_eq!(d.calls_for_pilot(wait - 0.1), None);
    assert_eq!(d.calls_for_pilot(wait), Some(PilotCall::WalkAround));
    d.on_walk_around();
    d.plan(&mut map).unwrap();
    assert_eq!(d.status(), DriverStatus::Driving);
    assert_eq!(d.speed_command_m_s(), 5.0);
    assert_eq!(d.calls_for_pilot(wait), None);
}

/// Blind ground the plan does not sweep (behind the vehicle) holds nothing: it moves off at
/// once, and the rule is done.
#[test]
fn blind_ground_behind_the_vehicle_does_not_hold_it() {
    let mut d = driver();
    d.await_walk_around(zone(|x, _| x < -2.0));
    let mut map = empty_map();
    d.on_pose(at(0.0, 10.0, 0.0, 0.0));
    d.plan(&mut map).unwrap();
    assert_eq!(d.status(), DriverStatus::Driving);
    assert_eq!(d.speed_command_m_s(), 5.0);
    assert_eq!(d.start_unseen_m2(), Some(0.0));
}

/// A strike felt while driving: the vehicle is commanded to stand at once, calls for a pilot
/// only once odometry says it stands, and plans on a clear road do not move it again; a
/// second strike does not move the time of the first.
#[test]
fn a_felt_strike_stands_the_vehicle_and_calls_a_pilot_once_it_stands() {
    let mut d = driver();
    let mut map = empty_map();
    d.on_pose(at(0.0, 10.0, 0.0, 0.0));
    d.plan(&mut map).unwrap();
    assert_eq!(d.command().speed_m_s, 5.0);
    assert_eq!(d.calls_for_pilot(0.0), None);
    let moving = |t_s, speed_m_s| Odometry {
        t_s,
        speed_m_s,
        steering_rad: 0.0,
    };
    d.on_odometry(moving(1.0, 4.0));
    d.on_strike(1.0);
    assert_eq!(d.command().speed_m_s, 0.0);
    assert_eq!(d.status(), DriverStatus::Struck { at_s: 1.0 });
    // Still rolling: no call yet.
    assert_eq!(d.calls_for_pilot(1.0), None);
    d.on_odometry(moving(2.0, 0.01));
    d.on_pose(at(2.0, 12.0, 0.0, 0.0));
    d.plan(&mut map).unwrap();
    assert_eq!(d.speed_command_m_s(), 0.0);
    assert_eq!(d.command().speed_m_s, 0.0);
    assert_eq!(d.status(), DriverStatus::Struck { at_s: 1.0 });
    assert_eq!(d.calls_for_pilot(2.0), Some(PilotCall::Struck));
    d.on_strike(3.0);
    assert_eq!(d.struck_at_s(), Some(1.0));
}

/// A strike felt rolling by a vehicle that had stood long enough to call its way blocked (the
/// tow's strike, felt as the tug lets go, the stack's stop counted through the tow): no call
/// while it rolls - not the blocked way's - then the strike's once it stands.
#[test]
fn a_struck_vehicle_makes_only_the_strikes_call() {
    let mut d = driver();
    let mut map = empty_map();
    d.on_pose(at(0.0, 10.0, 0.0, 0.0));
    d.plan(&mut map).unwrap();
    d.stopped_since_s = Some(0.0);
    let t = d.config.blocked_call_after_s + 1.0;
    assert_eq!(d.calls_for_pilot(t), Some(PilotCall::Blocked));
    let rolling = |t_s, speed_m_s| Odometry {
        t_s,
        speed_m_s,
        steering_rad: 0.0,
    };
    d.on_odometry(rolling(t, 1.0));
    d.on_strike(t);
    assert_eq!(d.calls_for_pilot(t), None);
    d.on_odometry(rolling(t + 1.0, 0.0));
    assert_eq!(d.calls_for_pilot(t + 1.0), Some(PilotCall::Struck));
}

/// A strike felt standing (a tug into the standing nose): the call comes at once.
#[test]
fn a_strike_felt_standing_calls_a_pilot_at_once() {
    let mut d = driver();
    let mut map = empty_map();
    d.on_pose(at(0.0, 10.0, 0.0, 0.0));
    d.on_odometry(Odometry {
        t_s: 0.0,
        speed_m_s: 0.0,
        steering_rad: 0.0,
    });
    d.on_strike(0.5);
    d.plan(&mut map).unwrap();
    assert_eq!(d.command().speed_m_s, 0.0);
    assert_eq!(d.calls_for_pilot(0.5), Some(PilotCall::Struck));
}

/// With `stand_when_struck` off a strike is ignored: the vehicle drives on, no call.
#[test]
fn with_the_strike_rule_off_a_strike_is_ignored() {
    let mut d = driver();
    d.config.stand_when_struck = false;
    let mut map = empty_map();
    d.on_pose(at(0.0, 10.0, 0.0, 0.0));
    d.on_strike(0.5);
    d.plan(&mut map).unwrap();
    assert_eq!(d.struck_at_s(), None);
    assert_eq!(d.command().speed_m_s, 5.0);
    assert_eq!(d.calls_for_pilot(0.5), None);
}
