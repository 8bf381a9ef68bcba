//! Taxi routes planned for a vehicle (`sim::airports::plan_taxi`) on a small airport drawn in
//! metres: the route follows the painted centreline, which is made to round at 15 m wherever
//! the network's line does (`airport::paint`); for an aircraft that turns no tighter than 20 m
//! and where the paint's line has no room for that but the network's has, the network's own
//! line is taken.

use aircraft::Vehicle;
use airport::{Airport, LatLon, LocalFrame, Place, RouteRequest, SizeClass};
use nalgebra::Vector2;
use sim::airports::{DEFAULT_TAXI_SPEED_M_S, DEFAULT_TURN_RADIUS_M, path_options, plan_taxi};

/// An airport whose taxiway A runs east from node 0 (0, 0) to node 1 (100, 0), then turns left
/// to node 2 (100, `north_m`); centreline paint 10 m north of the first leg (inside the turn)
/// from x = 0 to 90, which moves the corner to (100, 10) and shortens the second leg by 10 m.
fn corner_inside_paint(north_m: f64, name: &str) -> Airport {
    let frame = LocalFrame::new(LatLon {
        lat: 43.0,
        lon: -76.0,
    });
    let at = |x: f64, y: f64| {
        let p = frame.to_lat_lon(Vector2::new(x, y));
        format!("{:.9} {:.9}", p.lat, p.lon)
    };
    let text = format!(
        "I\n1100 test\n\n1 500 0 0 TEST Test\n1302 datum_lat 43.0\n1302 datum_lon -76.0\n\
         1201 {} both 0 n0\n1201 {} both 1 n1\n1201 {} both 2 n2\n\
         1202 0 1 twoway taxiway_E A\n1202 1 2 twoway taxiway_E A\n\
         120 line\n111 {} 1\n115 {}\n99\n",
        at(0.0, 0.0),
        at(100.0, 0.0),
        at(100.0, north_m),
        at(0.0, 10.0),
        at(90.0, 10.0),
    );
    let path =
        std::env::temp_dir().join(format!("taxi_sim_plan_{name}_{}.dat", std::process::id()));
    std::fs::write(&path, text).expect("write");
    let a = Airport::read(&path, None).expect("reads");
    std::fs::remove_file(&path).ok();
    a
}

/// The A320-like airliner with its nose-wheel tiller limited to 32 degrees: it turns no tighter
/// than 20 m (12.6 m wheelbase).
fn wide_turning_airliner() -> Vehicle {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../aircraft/vehicles");
    let spec = std::fs::read_to_string(dir.join("a320.toml")).expect("a320.toml");
    let urdf = std::fs::read_to_string(dir.join("a320.urdf")).expect("a320.urdf");
    let steering = (12.6_f64 / 20.0).atan();
    let spec = spec
        .lines()
        .map(|l| {
            if l.starts_with("max_steering_angle_rad") {
                format!("max_steering_angle_rad = {steering}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let v = Vehicle::from_strs(&spec, "a320.toml", &urdf, "a320.urdf").expect("a vehicle");
    assert!((v.min_turn_radius_m() - 20.0).abs() < 1e-9);
    v
}

/// The second leg is 25 m long on the network and 15 m on the paint's line: the paint's corner
/// rounds at 15 m (the paint keeps it), not at the airliner's 20; the plan takes the network's
/// line, which rounds at 20. The Praetor-like jet (4.6 m) keeps the paint.
#[test]
fn where_the_paints_line_leaves_no_room_to_turn_the_networks_is_taken() {
    let a = corner_inside_paint(25.0, "fallback");
    let v = wide_turning_airliner();
    let request = RouteRequest {
        from: Place::parse("node 0"),
        to: Place::parse("node 2"),
        via: vec![],
        code: SizeClass::C,
    };
    let on_paint = airport::find(&a, &request).expect("a route on the paint");
    let corner = on_paint.points[1];
    assert!(
        (corner - Vector2::new(100.0, 10.0)).norm() < 0.05,
        "{corner}"
    );
    let err = airport::smooth(
        &on_paint,
        &path_options(&v, DEFAULT_TURN_RADIUS_M, DEFAULT_TAXI_SPEED_M_S),
    )
    .expect_err("no room on the paint");
    assert!(err.to_string().contains("turn too sharp"), "{err}");
    let network = airport::find_on_network(&a, &request).expect("a route on the network");
    let plan = |v: &Vehicle| {
        plan_taxi(
            &a,
            v,
            "node 0",
            "node 2",
            &[],
            DEFAULT_TURN_RADIUS_M,
            DEFAULT_TAXI_SPEED_M_S,
        )
        .expect("planned")
    };
    let planned = plan(&v);
    assert_eq!(planned.route.points, network.points);
    assert!(planned.path.tightest_radius_m >= 20.0 - 1e-9);
    let jet = Vehicle::load("praetor600").expect("the shipped jet");
    assert_eq!(plan(&jet).route.points, on_paint.points);
}
