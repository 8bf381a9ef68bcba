//! Who was at fault, by the judge alone: the world and the judge driven by hand (no stack), the
//! vehicle and the movers placed step by step. Creeping into a standing box is at fault; a truck
//! pushed into the side of the creeping car is struck while moving, and stays so while the car
//! slides along it, until the car turns into it (at fault); the creeping car's wheel coming into
//! the corner of a van that came down onto its side is at fault; at 8 m/s into a van
//! crossing ahead, at fault.

use autonomy::RoutePath;
use nalgebra::{Isometry2, Point2, Vector2};
use sim::engine::{EndReason, Judge, JudgedContact};
use sim::scenario::{ExpectedEnd, Scenario};
use sim::world::{VehicleState, World};

const WORLD: &str = r#"
name = "judged by hand"
seed = 1

[world]
min_m = [-20.0, -30.0]
max_m = [80.0, 30.0]

[vehicle]
description = "iara_car"

[route]
waypoints_m = [[0.0, 0.0], [60.0, 0.0]]
speed_m_s = 1.0

[expectations]
end = "any"
no_contact_at_fault = true

[[obstacles]]
id = "van"
kind = "vehicle"
path_m = [[1.0, 9.0], [1.0, -30.0]]
speed_m_s = 3.0
expect = "no_contact"

[[obstacles]]
id = "truck"
kind = "fuel_truck"
path_m = [[1.8, 12.0], [1.8, -30.0]]
speed_m_s = 3.0
expect = "no_contact"

[[obstacles]]
id = "box"
kind = "box"
x_m = 40.0
y_m = 0.0
size_m = [0.5, 0.5, 0.5]
expect = "stop"
"#;

/// One step of the car: its state at time `t`.
struct Step {
    t_s: f64,
    x_m: f64,
    y_m: f64,
    yaw_rad: f64,
    speed_m_s: f64,
}

/// Where the van and the truck are (x, y, yaw), the ones not named far off.
type Movers = [(f64, f64, f64); 2];

/// Far from everything.
const FAR: (f64, f64, f64) = (70.0, 25.0, 0.0);

/// The judged contacts of a run where `script` places the vehicle and the movers (the van and
/// the truck, the first two obstacles) at each 0.01 s step from 0 to `end_s`.
fn judged(end_s: f64, script: impl Fn(f64) -> (Step, Movers)) -> Vec<JudgedContact> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("judged.toml");
    std::fs::write(&path, WORLD).unwrap();
    let s = Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let route = RoutePath::new(&s.route.waypoints_m, false);
    let vehicle = &s.vehicle.vehicle;
    let start = Isometry2::identity();
    let mut world = World::with_obstacles(&s.full_scene(), vehicle, &start);
    let first = s.objects.len();
    let parts = vec![0; vehicle.parts.len()];
    let mut judge = Judge::new(&s, &route, 1, parts, 1, first, Point2::origin());
    let steps = (end_s / 0.01).round() as usize;
    for k in 0..=steps {
        let (step, movers) = script(k as f64 * 0.01);
        for (i, (x, y, yaw)) in movers.into_iter().enumerate() {
            world.set_object_pose(first + i, x, y, yaw);
        }
        let pose = Isometry2::new(Vector2::new(step.x_m, step.y_m), step.yaw_rad);
        world.set_vehicle_pose(&pose, step.t_s);
        let state = VehicleState {
            x_m: step.x_m,
            y_m: step.y_m,
            yaw_rad: step.yaw_rad,
            speed_m_s: step.speed_m_s,
            ..Default::default()
        };
        judge.after_step(step.t_s, &state, step.speed_m_s, &world);
    }
    let contacts = world.contacts().to_vec();
    judge
        .verdict(EndReason::Completed, ExpectedEnd::Any, &contacts)
        .contacts
}

/// The car creeping along x at `v` m/s from `x0`, straight.
fn creeping(t: f64, x0: f64, v: f64) -> Step {
    Step {
        t_s: t,
        x_m: x0 + v * t,
        y_m: 0.0,
        yaw_rad: 0.0,
        speed_m_s: v,
    }
}

#[test]
fn creeping_at_0_3_m_s_into_a_standing_box_is_at_fault() {
    // The van far away; the car's front (about 3.5 m ahead) meets the box at x = 39.75.
    let j = judged(6.0, |t| (creeping(t, 35.0, 0.3), [FAR, FAR]));
    let boxes: Vec<_> = j.iter().filter(|c| c.contact.object == "box").collect();
    assert!(!boxes.is_empty(), "{j:?}");
    assert!(
        boxes[0].at_fault && !boxes[0].struck_while_moving,
        "{:?}",
        boxes[0]
    );
}

/// Southwards, as a van drives.
const SOUTH: f64 = -std::f64::consts::FRAC_PI_2;

#[test]
fn a_truck_into_the_side_of_the_creeping_car_is_struck_until_the_car_turns_into_it() {
    // The 9 m truck, alongside (yaw 0, spanning x -2.7..6.3, past the car's ends), is pushed
    // south at 3 m/s into the car's left side and halts in it (its near face 0.7 m off the
    // centreline: inside the car's side).
    let script = |t: f64| {
        let ty = (12.0 - 3.0 * t).max(1.25 + 0.7);
        let mut car = creeping(t, 0.0, 0.3);
        if t >= 3.5 {
            // Then the car turns left, into it.
            car.yaw_rad = 0.15 * (t - 3.5);
        }
        (car, [FAR, (1.8, ty, 0.0)])
    };
    let j = judged(5.0, script);
    let truck: Vec<_> = j.iter().filter(|c| c.contact.object == "truck").collect();
    assert!(!truck.is_empty(), "the truck must reach the car: {j:?}");
    assert!(
        truck[0].struck_while_moving && !truck[0].at_fault,
        "the truck came into the car's room: {:?}",
        truck[0]
    );
    // Sliding along the halted truck (its side parallel to the car's) is not driving into it;
    // turning into it is, once for each part it drives in.
    let at_fault: Vec<_> = truck.iter().filter(|c| c.at_fault).collect();
    assert!(!at_fault.is_empty(), "{truck:?}");
    assert!(
        at_fault.iter().all(|c| c.contact.time_s > 3.5),
        "{at_fault:?}"
    );
}

#[test]
fn a_creeping_cars_wheel_into_the_corner_of_a_van_come_onto_its_side_is_at_fault() {
    // The van drives south at 3 m/s, its back (x) face 0.81 m ahead of the rear axle, and halts
    // in the car's side: the rear wheel, creeping forward, comes into the van's corner.
    let j = judged(3.0, |t| {
        let vy = (9.0 - 3.0 * t).max(1.7);
        (creeping(t, 0.0, 0.3), [(1.81, vy, SOUTH), FAR])
    });
    let van: Vec<_> = j.iter().filter(|c| c.contact.object == "van").collect();
    // The van comes down onto the body's side: struck while moving; the wheel comes forward
    // into the van's corner: at fault.
    let body: Vec<_> = van.iter().filter(|c| c.contact.part == "body").collect();
    assert!(
        !body.is_empty() && body.iter().all(|c| c.struck_while_moving),
        "{van:?}"
    );
    let wheel = van
        .iter()
        .find(|c| c.contact.part == "wheel_rear_left")
        .unwrap_or_else(|| panic!("the wheel meets the van: {van:?}"));
    assert!(wheel.at_fault, "{wheel:?}");
}

#[test]
fn at_8_m_s_into_a_van_crossing_ahead_is_at_fault() {
    // The van crosses x = 30 southwards; the car's front reaches it as it is in the lane.
    let j = judged(4.5, |t| {
        let car = creeping(t, 0.0, 8.0);
        (car, [(30.0 + 3.5, 9.0 - 3.0 * t, SOUTH), FAR])
    });
    let van: Vec<_> = j.iter().filter(|c| c.contact.object == "van").collect();
    assert!(!van.is_empty(), "{j:?}");
    assert!(van[0].at_fault, "{:?}", van[0]);
}
