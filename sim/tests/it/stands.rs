//! Stands as the file places the aircraft on them (`airport::leave_stand`, `route::stand_place`):
//! a route from a gate starts on the stand, on its heading, and the tug pushes the aircraft tail
//! first down the stand's axis and turns it onto the taxilane, never sideways; a tie-down facing
//! its taxilane is left on the aircraft's own power; a route to a stand ends parked on it, on its
//! heading; and in the closed loop the push-back is towed, the stack localizes through it, and
//! the report says how near it came to what stands beside the stand; a stand whose drawn
//! aircraft would block the vehicle's way - its tow or its taxi in - stays empty. On the
//! shipped XTSM.

use std::path::PathBuf;

use aircraft::Vehicle;
use airport::Airport;
use nalgebra::Vector2;
use sim::airports::{DEFAULT_TAXI_SPEED_M_S, DEFAULT_TURN_RADIUS_M, PlannedTaxi, plan_taxi};

fn xtsm_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/airports/xtsm/apt.dat")
}

fn plan(airport: &Airport, from: &str, to: &str) -> PlannedTaxi {
    let praetor = Vehicle::shipped("praetor600").unwrap();
    plan_taxi(
        airport,
        &praetor,
        from,
        to,
        &[],
        DEFAULT_TURN_RADIUS_M,
        DEFAULT_TAXI_SPEED_M_S,
    )
    .unwrap()
}

/// The smaller angle between two headings, degrees.
fn apart_deg(a: f64, b: f64) -> f64 {
    sim::world::wrap_angle(a - b).abs().to_degrees()
}

fn heading(from: Vector2<f64>, to: Vector2<f64>) -> f64 {
    (to.y - from.y).atan2(to.x - from.x)
}

/// S3 is a gate parked nose north, its taxilane 50 m behind it: the route starts on the stand,
/// on its heading; every pose of the tow has the aircraft's tail where it moves (within 2
/// degrees: pushed, never dragged sideways); the tug lets go on the taxilane facing the way the
/// route goes.
#[test]
fn a_gate_is_left_tail_first_from_the_stand_to_its_taxilane() {
    let airport = Airport::read(&xtsm_file(), None).unwrap();
    let s3 = airport.find_stand("S3").unwrap().clone();
    let planned = plan(&airport, "S3", "runway 27");
    let tow = planned
        .pushback
        .as_ref()
        .expect("a gate is pushed back from");
    let (start, yaw) = tow.poses[0];
    assert!((start - s3.at).norm() < 1.0 && apart_deg(yaw, s3.yaw_rad) < 2.0);
    // Between two poses the aircraft turns evenly from one heading to the next: half way, it
    // must point its tail the way it moves.
    for w in tow.poses.windows(2) {
        let ((a, yaw_a), (b, yaw_b)) = (w[0], w[1]);
        if (b - a).norm() > 0.05 {
            let midway = yaw_a + sim::world::wrap_angle(yaw_b - yaw_a) / 2.0;
            assert!(
                apart_deg(midway, heading(b, a)) < 2.0,
                "between {a:?} and {b:?}: heading {midway} moving towards {}",
                heading(a, b)
            );
        }
    }
    let (release, yaw_end) = tow.poses[tow.poses.len() - 1];
    let path = &planned.path.points;
    assert!((path[0] - release).norm() < 1e-6);
    assert!(apart_deg(yaw_end, heading(path[0], path[1])) < 2.0);
    // 50 m down the axis, a quarter turn, released 5 m on: about 60 m.
    assert!((50.0..70.0).contains(&tow.length_m), "{}", tow.length_m);
}

/// A route to a stand ends parked on it: the last point the stand's, the last leg on its
/// heading (nose in, as the file places the aircraft).
#[test]
fn an_arrival_ends_parked_on_the_stand_on_its_heading() {
    let airport = Airport::read(&xtsm_file(), None).unwrap();
    let s3 = airport.find_stand("S3").unwrap().clone();
    let planned = plan(&airport, "runway 27", "S3");
    assert!(planned.pushback.is_none());
    let p = &planned.path.points;
    let (last, before) = (p[p.len() - 1], p[p.len() - 2]);
    assert!((last - s3.at).norm() < 1.0, "{last:?} against {:?}", s3.at);
    assert!(apart_deg(heading(before, last), s3.yaw_rad) < 2.0);
}

/// The same airport with S3 a tie-down parked nose south, facing its taxilane: no push-back;
/// the route starts on the stand, its first leg on the stand's heading.
#[test]
fn a_tie_down_facing_its_taxilane_is_left_on_the_aircrafts_own_power() {
    let text = std::fs::read_to_string(xtsm_file()).unwrap();
    let turned = text.replace(
        "1300 44.002699973 10.000935090 0.00 gate",
        "1300 44.002699973 10.000935090 180.00 tie_down",
    );
    assert_ne!(text, turned);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("apt.dat");
    std::fs::write(&file, turned).unwrap();
    let airport = Airport::read(&file, None).unwrap();
    let s3 = airport.find_stand("S3").unwrap().clone();
    let planned = plan(&airport, "S3", "runway 27");
    assert!(planned.pushback.is_none());
    let p = &planned.path.points;
    assert!((p[0] - s3.at).norm() < 1.0);
    assert!(apart_deg(heading(p[0], p[1]), s3.yaw_rad) < 2.0);
}

/// The jet taxiing `from` `to` on XTSM with a stand N added at `n_east_m` east of S3 and 25 m
/// behind it, on S3's heading; `airport` more lines of its `[airport]` table.
fn taxiing_by_n(
    from: &str,
    to: &str,
    n_east_m: f64,
    airport: &str,
) -> Result<sim::scenario::Scenario, String> {
    let text = std::fs::read_to_string(xtsm_file()).unwrap();
    // Degrees of latitude and longitude a metre, at 44 degrees north.
    let (north, east) = (
        1.0 / 111_320.0,
        1.0 / (111_320.0 * 44.0027f64.to_radians().cos()),
    );
    let n = format!(
        "1301 B general_aviation\n1300 {:.9} {:.9} 0.00 gate jets|props N\n1301 B general_aviation",
        44.002699973 - 25.0 * north,
        10.000935090 + n_east_m * east
    );
    let with_n = text.replacen("1301 B general_aviation", &n, 1);
    assert_ne!(text, with_n);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("apt.dat"), with_n).unwrap();
    let file = dir.path().join("taxi.toml");
    let scenario = format!(
        "name = \"taxi\"\nseed = 5\n[airport]\nfile = \"apt.dat\"\n{airport}\n\
         [vehicle]\ndescription = \"praetor600\"\n[route]\n\
         taxi = {{ from = \"{from}\", to = \"{to}\" }}\nspeed_m_s = 6.0\n"
    );
    std::fs::write(&file, scenario).unwrap();
    sim::scenario::Scenario::from_file(&file).map_err(|e| e.to_string())
}

/// The ids of the parked aircraft drawn (occupancy 1) when the jet taxis `from` `to` by N.
fn drawn_taxiing(from: &str, to: &str, n_east_m: f64) -> Vec<String> {
    let s = taxiing_by_n(from, to, n_east_m, "occupancy = 1.0").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.route.pushback.is_some(), from == "S3");
    let mut ids: Vec<String> = (s.objects.iter())
        .filter_map(|o| o.id.split('/').next().filter(|id| id.starts_with("stand_")))
        .map(str::to_owned)
        .collect();
    ids.dedup();
    ids
}

/// An aircraft the file parks by name at N, across the push-back: an error naming the field and
/// the tow (the tug would push the jet into it); across the way in of an arrival it is the
/// scenario's to state (the stack must stop for it), and accepted.
#[test]
fn an_aircraft_parked_by_name_across_the_pushback_is_an_error() {
    let parked = "parked = [{ stand = \"N\", vehicle = \"praetor600\" }]";
    let error = taxiing_by_n("S3", "runway 27", -12.0, parked).unwrap_err();
    assert!(
        error.contains("airport.parked[0]") && error.contains("push-back"),
        "{error}"
    );
    assert!(taxiing_by_n("S3", "runway 27", -40.0, parked).is_ok());
    assert!(taxiing_by_n("runway 27", "S3", -12.0, parked).is_ok());
}

/// A Praetor parked at N, 12 m west of S3's axis and 25 m behind S3, reaches its right wing to
/// 1.25 m short of the axis, where the wing of the jet pushed back along it (or taxiing in along
/// it) passes:
/// with every stand drawn occupied, N stays empty; 40 m west, clear of both, it is drawn. The
/// code-C stands S1 and S2 are drawn either way.
#[test]
fn a_stand_whose_aircraft_would_block_the_vehicles_way_stays_empty() {
    let leaving = |east| drawn_taxiing("S3", "runway 27", east);
    assert_eq!(leaving(-12.0), ["stand_S1", "stand_S2"]);
    assert_eq!(leaving(-40.0), ["stand_S1", "stand_S2", "stand_N"]);
    let arriving = |east| drawn_taxiing("runway 27", "S3", east);
    assert_eq!(arriving(-12.0), ["stand_S1", "stand_S2"]);
    assert_eq!(arriving(-40.0), ["stand_S1", "stand_S2", "stand_N"]);
}

/// Keeps the vehicle's last pose.
#[derive(Default)]
struct LastPose(Option<(f64, f64, f64)>);

impl sim::engine::Observer for LastPose {
    fn step(&mut self, frame: &sim::engine::StepFrame<'_>) -> sim::error::Result<()> {
        self.0 = Some((frame.state.x_m, frame.state.y_m, frame.state.yaw_rad));
        Ok(())
    }
}

/// In the closed loop, from S3 to S1 with a container 16 m east of S3's axis: the tug pushes
/// the jet back (the stack senses, maps and localizes meanwhile - its estimate within 0.3 m of
/// the truth), lets go after the tow's length at 1 m/s, the jet taxis along the apron and parks
/// on S1 (within 1 m, on its heading within 2 degrees); the report's push-back names the
/// container as the nearest object, at the wing tip's distance from it.
#[test]
fn in_the_loop_the_jet_is_towed_off_its_stand_and_parks_on_another() {
    // The box 16 m east of S3's axis, 20 m behind the stand.
    let airport = Airport::read(&xtsm_file(), None).unwrap();
    let (s3, s1) = (
        airport.find_stand("S3").unwrap().clone(),
        airport.find_stand("S1").unwrap().clone(),
    );
    let axis = Vector2::new(s3.yaw_rad.cos(), s3.yaw_rad.sin());
    let east = Vector2::new(axis.y, -axis.x);
    let box_at = s3.at - axis * 20.0 + east * 16.0;
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("s3_to_s1.toml");
    let text = format!(
        "name = \"S3 to S1\"\nseed = 5\n[airport]\nfile = \"{}\"\n[vehicle]\ndescription = \
         \"praetor600\"\n[route]\ntaxi = {{ from = \"S3\", to = \"S1\" }}\nspeed_m_s = 6.0\n\
         [[objects]]\nid = \"box_by_the_stand\"\nkind = \"container\"\nx_m = {:.3}\n\
         y_m = {:.3}\nsize_m = [2.0, 2.0, 2.5]\n[expectations]\nend = \"completed\"\n",
        xtsm_file().display(),
        box_at.x,
        box_at.y
    );
    std::fs::write(&file, text).unwrap();
    let s = sim::scenario::Scenario::from_file(&file).unwrap();
    let tow_m = s.route.pushback.as_ref().unwrap().length_m;
    let map_dir = dir.path().join("map");
    let config = sim::scenario::RunConfig::default();
    sim::offline_map::map_drive(&s, &config, &map_dir, &mut |_, _| {}).unwrap();
    let mut last = LastPose::default();
    let report = sim::engine::run_with(
        &s,
        &sim::engine::RunSetup::new(map_dir),
        sim::engine::RunHandles {
            stop: None,
            progress: &mut |_| {},
            observer: &mut last,
        },
    )
    .unwrap();
    assert!(
        report.expectations_met && report.contacts.is_empty(),
        "{:?}",
        report.end
    );
    let p = report.pushback.as_ref().expect("pushed back");
    assert!(
        (p.released_s - tow_m / sim::engine::TOW_SPEED_M_S).abs() < 0.05,
        "{} s for {tow_m} m",
        p.released_s
    );
    assert_eq!(p.nearest_object.as_deref(), Some("box_by_the_stand"));
    // The wing tip (10.5 m off the axis) passes the box's near face (15 m off) 4.5 m away.
    assert!(
        (p.min_clearance_m - 4.5).abs() < 0.3,
        "{}",
        p.min_clearance_m
    );
    let localization = report.localization.as_ref().expect("the particle filter");
    assert!(
        localization.run.cross_m.max < 0.6,
        "{:?}",
        localization.run.cross_m
    );
    let (x, y, yaw) = last.0.unwrap();
    assert!(
        (Vector2::new(x, y) - s1.at).norm() < 1.0,
        "parked at ({x}, {y})"
    );
    assert!(apart_deg(yaw, s1.yaw_rad) < 2.0, "heading {yaw}");
}
