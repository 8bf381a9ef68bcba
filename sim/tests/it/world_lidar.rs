//! The Rapier world and the LiDAR on it: known geometry gives known ranges, the fast path equals
//! the generic cast, noise is seeded, and the ground truth sees contacts where they happen.

use aircraft::Vehicle;
use nalgebra::{Isometry2, Isometry3, Vector2};
use sim::world::{
    Lidar, LidarConfig, ObjectKind, Owner, Scene, Solid, SolidShape, SweepPoses, World,
};

fn solid(id: &str, kind: ObjectKind, shape: SolidShape, x: f64, y: f64, yaw: f64) -> Solid {
    Solid {
        id: id.into(),
        kind,
        shape,
        x_m: x,
        y_m: y,
        z_min_m: 0.0,
        yaw_rad: yaw,
        remission: 0.7,
        runtime: false,
    }
}

fn scene(solids: Vec<Solid>) -> Scene {
    Scene {
        min_m: [-150.0, -150.0],
        max_m: [150.0, 150.0],
        ground_remission: 0.2,
        pavement_texture: 0.0,
        solids,
        patches: vec![],
        areas: Vec::new(),
    }
}

fn noiseless() -> LidarConfig {
    LidarConfig {
        noise_stddev_m: 0.0,
        range_bias_stddev_m: 0.0,
        dropoff_general_rate: 0.0,
        ..Default::default()
    }
}

fn car() -> Vehicle {
    Vehicle::shipped("iara_car_fake_wing").unwrap()
}

/// The car's sensor mount, from its sidecar.
fn mount(v: &Vehicle) -> Isometry3<f64> {
    v.vehicle_from_lidar()
}

#[test]
fn the_ground_is_at_each_beams_analytic_distance() {
    let v = car();
    let origin = Isometry2::identity();
    let world = World::with_obstacles(&scene(vec![]), &v, &origin);
    let lidar = Lidar::new(noiseless(), mount(&v)).unwrap();
    let scan = lidar.scan(&world, &SweepPoses::still(origin), 0, 1);
    let h = v.spec.lidar.xyz_m[2];
    // Column 600 looks left. The lowest beams meet the car's own roof (self-hits, which the
    // mapper filters); every other descending beam within range meets the ground where
    // trigonometry says.
    let (column, first) = (scan.scan.column(600).unwrap().1, 600 * 32);
    let mut on_ground = 0;
    for (b, el) in lidar.elevations_rad().iter().enumerate() {
        let expected = h / (-el).sin();
        match (column[b], scan.owners[first + b]) {
            (Some(_), Some(Owner::VehiclePart(_))) => {
                assert!(*el < -0.3, "beam {b} ({el} rad) hit the car")
            }
            (Some(r), Some(Owner::Ground)) => {
                assert!(
                    (r.range_m as f64 - expected).abs() < 2e-3,
                    "beam {b}: {} vs {expected}",
                    r.range_m
                );
                on_ground += 1;
            }
            (None, _) => assert!(
                *el >= 0.0 || expected > 100.0,
                "beam {b} at {el} rad missed the ground"
            ),
            (Some(r), owner) => panic!("beam {b} hit {owner:?} at {} in an empty world", r.range_m),
        }
    }
    assert!(on_ground >= 15, "{on_ground} beams on the ground");
}

/// Each laser's range bias is its unit's: the same every revolution and whatever the seed of the
/// noise, another unit's differs, spread as configured; a laser's ground returns lie its bias
/// beyond where trigonometry puts them.
#[test]
fn each_laser_has_its_units_constant_range_bias() {
    let v = car();
    let origin = Isometry2::identity();
    let world = World::with_obstacles(&scene(vec![]), &v, &origin);
    let config = LidarConfig {
        noise_stddev_m: 0.0,
        range_bias_stddev_m: 0.02,
        ..Default::default()
    };
    let lidar = Lidar::new(config.clone(), mount(&v)).unwrap();
    let biases = lidar.range_biases_m();
    // Off by default: no bias at all.
    let unbiased = Lidar::new(LidarConfig::default(), mount(&v)).unwrap();
    assert!(unbiased.range_biases_m().iter().all(|b| *b == 0.0));
    let other = LidarConfig {
        range_bias_unit: 2,
        ..config
    };
    let other = Lidar::new(other, mount(&v)).unwrap().range_biases_m();
    assert_ne!(biases, other);
    // 64 draws of a 0.02-m spread: their rms within 30 % of it (about 3.4 standard errors).
    let rms = (biases.iter().chain(&other).map(|b| b * b).sum::<f64>() / 64.0).sqrt();
    assert!((0.014..0.026).contains(&rms), "{rms}");
    let h = v.spec.lidar.xyz_m[2];
    let mut checked = 0;
    for (index, seed) in [(0, 1), (7, 99)] {
        let scan = lidar.scan(&world, &SweepPoses::still(origin), index, seed);
        let column = scan.scan.column(600).unwrap().1;
        for (b, el) in lidar.elevations_rad().iter().enumerate() {
            if let (Some(r), Some(Owner::Ground)) = (column[b], scan.owners[600 * 32 + b]) {
                let error = r.range_m as f64 - h / (-el).sin();
                assert!(
                    (error - biases[b]).abs() < 2e-3,
                    "beam {b}: {error} vs {}",
                    biases[b]
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 30, "{checked} ground returns checked");
}

#[test]
fn a_wall_face_and_a_cone_are_where_they_are() {
    let v = car();
    let origin = Isometry2::identity();
    let wall = solid(
        "wall",
        ObjectKind::Building,
        SolidShape::Box {
            size_m: [1.0, 10.0, 3.0],
        },
        10.5,
        0.0,
        0.0,
    );
    let cone = solid(
        "cone",
        ObjectKind::Cone,
        SolidShape::Cone {
            radius_m: 0.18,
            height_m: 0.45,
        },
        0.572,
        6.0,
        0.0,
    );
    let world = World::with_obstacles(&scene(vec![wall, cone]), &v, &origin);
    let lidar = Lidar::new(noiseless(), mount(&v)).unwrap();
    let scan = lidar.scan(&world, &SweepPoses::still(origin), 0, 1);
    let sensor_x = v.spec.lidar.xyz_m[0];
    // Column 0: straight ahead; every beam reaching the wall's face (x = 10) below 3 m.
    let mut wall_hits = 0;
    for (b, el) in lidar.elevations_rad().iter().enumerate() {
        let t = (10.0 - sensor_x) / el.cos();
        let z = 2.15 + t * el.sin();
        if (0.0..3.0).contains(&z) && scan.owners[b] == Some(Owner::Object(0)) {
            let r = scan.scan.column(0).unwrap().1[b].unwrap();
            assert!(
                (r.range_m as f64 - t).abs() < 2e-3,
                "beam {b}: {} vs {t}",
                r.range_m
            );
            assert!((r.point_in_world.x - 10.0).abs() < 2e-3);
            wall_hits += 1;
        }
    }
    // From 2.15 m, 9.43 m away, a 3 m wall spans -12.8 to +5.2 deg: 13 beams 1.33 deg apart.
    assert!(wall_hits >= 13, "{wall_hits} beams on the wall");
    // The cone: every hit lies on its lateral surface, radius 0.18 (1 - z / 0.45) from its axis.
    let mut cone_hits = 0;
    for (i, owner) in scan.owners.iter().enumerate() {
        if *owner == Some(Owner::Object(1)) {
            let p = scan.scan.returns()[i].unwrap().point_in_world;
            let radial = (p.x - sensor_x).hypot(p.y - 6.0);
            assert!((radial - 0.18 * (1.0 - p.z / 0.45)).abs() < 3e-3, "{p:?}");
            cone_hits += 1;
        }
    }
    assert!(cone_hits > 5, "{cone_hits} returns on the cone");
}

/// About 150 random boxes, cylinders and cones around the car.
fn cluttered() -> Scene {
    let mut state = 42u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 1_000_000) as f64 / 1_000_000.0
    };
    let mut solids = Vec::new();
    for i in 0..150 {
        let (x, y) = (next() * 120.0 - 60.0, next() * 120.0 - 60.0);
        if x.abs() < 4.0 && y.abs() < 4.0 {
            continue;
        }
        let shape = match i % 3 {
            0 => SolidShape::Box {
                size_m: [0.5 + 4.0 * next(), 0.5 + 4.0 * next(), 0.3 + 5.0 * next()],
            },
            1 => SolidShape::Cylinder {
                radius_m: 0.1 + next(),
                height_m: 0.3 + 6.0 * next(),
            },
            _ => SolidShape::Cone {
                radius_m: 0.15 + 0.3 * next(),
                height_m: 0.3 + next(),
            },
        };
        solids.push(solid(
            &format!("s{i}"),
            ObjectKind::Box,
            shape,
            x,
            y,
            next() * std::f64::consts::TAU,
        ));
    }
    scene(solids)
}

/// A parked aircraft's cylinder part: its frame (the axis along z) from the world's, its radius
/// and half length.
fn cylinder_part(solid: &Solid) -> Option<(Isometry3<f64>, f64, f64)> {
    let SolidShape::Part {
        shape:
            aircraft::Shape::Cylinder {
                radius_m,
                half_length_m,
            },
        vehicle_from_part,
    } = solid.shape
    else {
        return None;
    };
    let world_from_vehicle = Isometry3::new(
        nalgebra::Vector3::new(solid.x_m, solid.y_m, 0.0),
        nalgebra::Vector3::z() * solid.yaw_rad,
    );
    let frame = (world_from_vehicle * vehicle_from_part).inverse();
    Some((frame, radius_m, half_length_m))
}

/// Distance from a point to the surface of a vertical cylinder or cone (apex up), or of a
/// parked aircraft's cylinder part, metres.
fn surface_residual(solid: &Solid, p: &nalgebra::Point3<f64>) -> f64 {
    if let Some((frame, r, half)) = cylinder_part(solid) {
        let q = frame * p;
        let (radial, along) = (q.x.hypot(q.y), q.z.abs());
        // On the side (within its length) or on a cap (within its disc).
        let side = (radial - r).abs().max((along - half).max(0.0));
        let cap = (along - half).abs().max((radial - r).max(0.0));
        return side.min(cap);
    }
    let radial = (p.x - solid.x_m).hypot(p.y - solid.y_m);
    match solid.shape {
        SolidShape::Cylinder { radius_m, height_m } => {
            (radial - radius_m).abs().min((p.z - height_m).abs())
        }
        SolidShape::Cone { radius_m, height_m } => {
            (radial - radius_m * (1.0 - p.z / height_m)).abs()
                * (height_m / radius_m.hypot(height_m))
        }
        SolidShape::Box { .. } | SolidShape::Part { .. } => f64::NAN,
    }
}

/// Distance from a point to a vertical cylinder or cone, or a parked aircraft's cylinder part
/// (0 inside), metres: a bound for grazes.
fn surface_distance(solid: &Solid, p: &nalgebra::Point3<f64>) -> f64 {
    if let Some((frame, r, half)) = cylinder_part(solid) {
        let q = frame * p;
        return (q.x.hypot(q.y) - r)
            .max(0.0)
            .hypot((q.z.abs() - half).max(0.0));
    }
    let radial = (p.x - solid.x_m).hypot(p.y - solid.y_m);
    let (r, h) = match solid.shape {
        SolidShape::Cylinder { radius_m, height_m } => (radius_m, height_m),
        SolidShape::Cone { radius_m, height_m } => (
            radius_m * (1.0 - p.z.clamp(0.0, height_m) / height_m),
            height_m,
        ),
        SolidShape::Box { .. } | SolidShape::Part { .. } => return f64::INFINITY,
    };
    (radial - r).max(0.0).hypot((p.z - h).max(0.0))
}

/// The fast path equals the generic cast: same hits, same owners, ranges within 1 mm - except
/// on cylinders and cones, which parry casts by GJK iterations (a few mm off) and the fast path
/// in closed form: there the fast hit must lie on the true surface (within 0.1 mm). Returns the
/// hits, those more than 1 mm apart and the grazes (one path hit a round solid's edge, the
/// other passed it).
fn assert_same(
    a: &sim::world::LidarScan,
    b: &sim::world::LidarScan,
    scene: &Scene,
) -> (usize, usize, usize) {
    let mut hits = 0;
    let mut gjk_differences = 0;
    let mut grazes = 0;
    // The nearer of two disagreeing hits is on a cylinder or cone, within 5 mm of its surface.
    let grazing = |near: &mapper::Return, owner: Option<Owner>, far: Option<&mapper::Return>| {
        let Some(Owner::Object(o)) = owner else {
            return false;
        };
        far.is_none_or(|f| f.range_m > near.range_m)
            && surface_distance(&scene.solids[o], &near.point_in_world) < 5e-3
    };
    for (i, (ra, rb)) in a.scan.returns().iter().zip(b.scan.returns()).enumerate() {
        let (oa, ob) = (a.owners[i], b.owners[i]);
        match (ra, rb) {
            (Some(x), Some(y)) if oa == ob => {
                if (x.range_m - y.range_m).abs() >= 1e-3 {
                    let Some(Owner::Object(o)) = oa else {
                        panic!("ray {i}: {} vs {}", x.range_m, y.range_m)
                    };
                    let solid = &scene.solids[o];
                    assert!(
                        !matches!(solid.shape, SolidShape::Box { .. }),
                        "ray {i} on a box: {} vs {}",
                        x.range_m,
                        y.range_m
                    );
                    // GJK stops within a few millimetres of the surface: a ray that meets it
                    // at a grazing angle (along a fuselage) can then differ by centimetres.
                    let (rx, ry) = (
                        surface_residual(solid, &x.point_in_world),
                        surface_residual(solid, &y.point_in_world),
                    );
                    assert!(
                        rx < 1e-4 && ry < 2e-3,
                        "ray {i} on {}: {} vs {} m, {rx} and {ry} m off its surface",
                        solid.id,
                        x.range_m,
                        y.range_m,
                    );
                    gjk_differences += 1;
                }
                hits += 1;
            }
            (None, None) => {}
            (Some(x), other) if grazing(x, oa, other.as_ref()) => grazes += 1,
            (other, Some(y)) if grazing(y, ob, other.as_ref()) => grazes += 1,
            _ => panic!("ray {i}: {ra:?} vs {rb:?} ({oa:?} / {ob:?})"),
        }
    }
    (hits, gjk_differences, grazes)
}

/// [`assert_same`] on the cluttered scene: nearly every ray within 1 mm, few grazes.
fn assert_same_cluttered(a: &sim::world::LidarScan, b: &sim::world::LidarScan, scene: &Scene) {
    let (hits, gjk_differences, grazes) = assert_same(a, b, scene);
    assert!(hits > 40_000, "{hits} hits");
    assert!(
        gjk_differences < hits / 100,
        "{gjk_differences} rays differ by more than 1 mm"
    );
    assert!(grazes < 30, "{grazes} grazes");
}

#[test]
fn the_fast_path_equals_the_generic_cast() {
    let v = car();
    let pose = Isometry2::new(Vector2::new(1.0, -2.0), 0.7);
    let scene = cluttered();
    let world = World::with_obstacles(&scene, &v, &pose);
    let lidar = Lidar::new(noiseless(), mount(&v)).unwrap();
    let sweep = SweepPoses::still(pose);
    assert_same_cluttered(
        &lidar.scan(&world, &sweep, 3, 9),
        &lidar.scan_generic(&world, &sweep, 3, 9),
        &scene,
    );
    // Moving during the sweep: every column from its own pose, both paths alike.
    let moving = Lidar::new(
        LidarConfig {
            motion_during_sweep: true,
            ..noiseless()
        },
        mount(&v),
    )
    .unwrap();
    let sweep = SweepPoses {
        start: pose,
        end: Isometry2::new(Vector2::new(2.0, -1.5), 0.9),
    };
    let (fast, generic) = (
        moving.scan(&world, &sweep, 3, 9),
        moving.scan_generic(&world, &sweep, 3, 9),
    );
    assert_same_cluttered(&fast, &generic, &scene);
    let first = fast.scan.columns()[0].world_from_vehicle.translation.vector;
    let last = fast.scan.columns()[2186]
        .world_from_vehicle
        .translation
        .vector;
    assert!(
        (first - pose.translation.vector).norm() < 1e-9
            && (last - Vector2::new(2.0, -1.5)).norm() < 0.01
    );
}

/// Parked A320s around the car, their fuselages, engines and fin cylinders at angles (one rolled
/// a little, as no real one is, to leave no axis special): the fast path casts their cylinder
/// parts in closed form, onto the true surface, and agrees with the generic cast everywhere else.
#[test]
fn parked_aircrafts_cylinders_are_cast_onto_their_surface() {
    let a320 = Vehicle::shipped("a320").unwrap();
    let mut solids = Vec::new();
    for (k, (x, y, yaw)) in [(18.0, 4.0, 0.3), (-6.0, 22.0, 1.9), (-25.0, -14.0, -2.6)]
        .into_iter()
        .enumerate()
    {
        for (i, part) in a320.parts.iter().enumerate() {
            let roll = nalgebra::Isometry3::rotation(nalgebra::Vector3::x() * 0.01 * k as f64);
            let shape = SolidShape::Part {
                shape: part.shape,
                vehicle_from_part: roll * part.vehicle_from_part,
            };
            let mut s = solid(
                &format!("a320_{k}/{i}"),
                ObjectKind::ParkedAircraft,
                shape,
                x,
                y,
                yaw,
            );
            s.z_min_m = 0.0;
            solids.push(s);
        }
    }
    let scene = scene(solids);
    let v = car();
    let pose = Isometry2::new(Vector2::new(1.0, -2.0), 0.4);
    let world = World::with_obstacles(&scene, &v, &pose);
    let lidar = Lidar::new(noiseless(), mount(&v)).unwrap();
    let sweep = SweepPoses::still(pose);
    let fast = lidar.scan(&world, &sweep, 3, 9);
    let (hits, _, grazes) = assert_same(&fast, &lidar.scan_generic(&world, &sweep, 3, 9), &scene);
    // Every fast hit on a cylinder part lies on its surface, and there are many.
    let mut on_cylinders = 0;
    for (i, owner) in fast.owners.iter().enumerate() {
        if let Some(Owner::Object(o)) = owner
            && cylinder_part(&scene.solids[*o]).is_some()
        {
            let p = fast.scan.returns()[i].unwrap().point_in_world;
            let r = surface_residual(&scene.solids[*o], &p);
            assert!(r < 1e-4, "ray {i}: {r} m off {}", scene.solids[*o].id);
            on_cylinders += 1;
        }
    }
    assert!(
        on_cylinders > 1_000,
        "{on_cylinders} returns on cylinder parts"
    );
    assert!(hits > 40_000, "{hits} hits");
    assert!(grazes < 30, "{grazes} grazes");
}

#[test]
fn noise_and_dropout_are_reproducible_by_seed() {
    let v = car();
    let pose = Isometry2::identity();
    let world = World::with_obstacles(&cluttered(), &v, &pose);
    let config = LidarConfig {
        dropoff_general_rate: 0.3,
        ..Default::default()
    };
    let lidar = Lidar::new(config, mount(&v)).unwrap();
    let sweep = SweepPoses::still(pose);
    let bits = |s: &sim::world::LidarScan| {
        s.scan
            .returns()
            .iter()
            .map(|r| r.map(|r| r.range_m.to_bits()))
            .collect::<Vec<_>>()
    };
    let a = lidar.scan(&world, &sweep, 5, 11);
    assert_eq!(
        bits(&a),
        bits(&lidar.scan(&world, &sweep, 5, 11)),
        "same seed and scan: same returns"
    );
    assert_ne!(
        bits(&a),
        bits(&lidar.scan(&world, &sweep, 5, 12)),
        "another seed: other noise"
    );
    assert_ne!(
        bits(&a),
        bits(&lidar.scan(&world, &sweep, 6, 11)),
        "another scan: other noise"
    );
    // Thread count does not matter.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| lidar.scan(&world, &sweep, 5, 11));
    assert_eq!(bits(&a), bits(&one));
    // About 30 % dropped among rays that hit something.
    let noiseless_hits = Lidar::new(noiseless(), mount(&v))
        .unwrap()
        .scan(&world, &sweep, 5, 11)
        .scan
        .returns()
        .iter()
        .flatten()
        .count();
    let kept = a.scan.returns().iter().flatten().count();
    let dropped = 1.0 - kept as f64 / noiseless_hits as f64;
    assert!((dropped - 0.3).abs() < 0.01, "dropped {dropped}");
    // The range noise has the configured spread (4 mm) everywhere, against the exact ranges
    // (biases and drop-off off, so that only the noise differs).
    let exact = Lidar::new(noiseless(), mount(&v))
        .unwrap()
        .scan(&world, &sweep, 5, 11);
    let noise = LidarConfig::default().noise_stddev_m;
    let noisy = LidarConfig {
        noise_stddev_m: noise,
        ..noiseless()
    };
    let noisy = Lidar::new(noisy, mount(&v))
        .unwrap()
        .scan(&world, &sweep, 5, 11);
    let diffs: Vec<f64> = exact
        .scan
        .returns()
        .iter()
        .zip(noisy.scan.returns())
        .filter_map(|(e, n)| Some((n.as_ref()?.range_m - e.as_ref()?.range_m) as f64))
        .collect();
    let sd = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    assert!(
        (sd / noise - 1.0).abs() < 0.05,
        "noise sd {sd} against {noise}"
    );
}

#[test]
fn intensity_follows_remission_and_distance() {
    let v = car();
    let pose = Isometry2::identity();
    let mut s = scene(vec![]);
    s.patches.push(sim::world::Patch {
        id: "line".into(),
        x_m: 8.0,
        y_m: 0.0,
        yaw_rad: 1.57,
        length_m: 40.0,
        width_m: 1.0,
        remission: 0.9,
    });
    let world = World::with_obstacles(&s, &v, &pose);
    let lidar = Lidar::new(noiseless(), mount(&v)).unwrap();
    let scan = lidar.scan(&world, &SweepPoses::still(pose), 0, 1);
    let ground = scan
        .scan
        .returns()
        .iter()
        .zip(&scan.owners)
        .filter(|(_, o)| **o == Some(Owner::Ground));
    let mut on = 0;
    for (r, _) in ground {
        let Some(r) = r else { continue };
        let on_line = (r.point_in_world.x - 8.0).abs() < 0.45 && r.point_in_world.y.abs() < 19.0;
        let off_line = (r.point_in_world.x - 8.0).abs() > 0.55 || r.point_in_world.y.abs() > 21.0;
        let expected = |rem: f64| (rem * (-0.004 * r.range_m as f64).exp()) as f32;
        if on_line {
            assert!((r.intensity - expected(0.9)).abs() < 1e-3);
            on += 1;
        } else if off_line {
            assert!((r.intensity - expected(0.2)).abs() < 1e-3);
        }
    }
    assert!(on > 20, "{on} returns on the painted line");
}

#[test]
fn driving_into_a_cone_is_a_contact_and_the_wing_passes_over_a_short_one() {
    let v = car();
    // The fake wing is on the right (negative y): a 0.45 m cone in its path, another ahead of the body.
    let under_wing = solid(
        "under_wing",
        ObjectKind::Cone,
        SolidShape::Cone {
            radius_m: 0.18,
            height_m: 0.45,
        },
        20.0,
        -1.4,
        0.0,
    );
    let ahead = solid(
        "ahead",
        ObjectKind::Cone,
        SolidShape::Cone {
            radius_m: 0.18,
            height_m: 0.45,
        },
        40.0,
        0.0,
        0.0,
    );
    let mut world =
        World::with_obstacles(&scene(vec![under_wing, ahead]), &v, &Isometry2::identity());
    let mut t = 0.0;
    let mut x = 0.0;
    while x < 30.0 {
        world.set_vehicle_pose(&Isometry2::new(Vector2::new(x, 0.0), 0.0), t);
        x += 0.05;
        t += 0.01;
    }
    assert!(
        world.contacts().is_empty(),
        "the wing passed over: {:?}",
        world.contacts()
    );
    let over = world.min_clearances_m()[0];
    assert!(
        (over - 0.25).abs() < 0.03,
        "the board (0.7 m) clears the cone tip (0.45 m) by {over}"
    );
    while x < 40.0 {
        world.set_vehicle_pose(&Isometry2::new(Vector2::new(x, 0.0), 0.0), t);
        x += 0.05;
        t += 0.01;
    }
    let contacts = world.contacts();
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    assert_eq!(contacts[0].object, "ahead");
    assert_eq!(contacts[0].kind, ObjectKind::Cone);
    // The front bumper meets the cone when x + front reach = 40 - 0.18 (front ~3.47 m ahead).
    assert!(contacts[0].time_s > 0.0 && !contacts[0].part.is_empty());
    assert_eq!(world.min_clearances_m()[1], 0.0);
}

#[test]
fn a_scan_written_as_ply_reads_back_point_for_point() {
    let v = car();
    let pose = Isometry2::new(Vector2::new(3.0, 4.0), 0.5);
    let world = World::with_obstacles(&cluttered(), &v, &pose);
    let lidar = Lidar::new(LidarConfig::default(), mount(&v)).unwrap();
    let scan = lidar.scan(&world, &SweepPoses::still(pose), 0, 1);
    let dir = tempfile::tempdir().unwrap();
    for frame in [
        sim::world::ply::Frame::World,
        sim::world::ply::Frame::Sensor,
    ] {
        let path = dir.path().join("scan.ply");
        sim::world::ply::write(&scan, frame, &path).unwrap();
        let points = sim::world::ply::decode(&std::fs::read(&path).unwrap()).unwrap();
        let returns: Vec<(usize, mapper::Return)> = scan
            .scan
            .returns()
            .iter()
            .enumerate()
            .filter_map(|(i, r)| Some((i, (*r)?)))
            .collect();
        assert_eq!(points.len(), returns.len());
        for (p, (i, r)) in points.iter().zip(&returns) {
            let (c, b) = (i / 32, i % 32);
            assert_eq!((p.column as usize, p.beam as usize), (c, b));
            let expected = match frame {
                sim::world::ply::Frame::World => r.point_in_world,
                sim::world::ply::Frame::Sensor => scan.point_in_sensor(c, b).unwrap(),
            };
            for k in 0..3 {
                assert!((p.xyz[k] as f64 - expected[k]).abs() < 1e-4);
            }
            assert_eq!(p.intensity, r.intensity);
        }
        // Sensor frame: the range is the distance from the origin.
        if frame == sim::world::ply::Frame::Sensor {
            let (p, (_, r)) = (points[100], returns[100]);
            assert!(
                ((p.xyz[0].powi(2) + p.xyz[1].powi(2) + p.xyz[2].powi(2)).sqrt() - r.range_m).abs()
                    < 1e-3
            );
        }
    }
}

#[test]
fn the_bicycle_at_100_hz_drives_the_kinematic_body_into_a_cone() {
    use sim::world::{Bicycle, Command, VehicleState};
    let v = car();
    let cone = solid(
        "cone",
        ObjectKind::Cone,
        SolidShape::Cone {
            radius_m: 0.18,
            height_m: 0.45,
        },
        25.0,
        2.0,
        0.0,
    );
    let mut world = World::with_obstacles(&scene(vec![cone]), &v, &Isometry2::identity());
    let bicycle = Bicycle::new(v.spec.motion.clone());
    let mut state = VehicleState::default();
    // Accelerate to 4 m/s, steering gently left towards the cone 2 m left of the straight line.
    let command = Command {
        speed_m_s: 4.0,
        steering_rad: 0.012,
    };
    let dt = 0.01;
    let mut t = 0.0;
    while t < 15.0 && world.contacts().is_empty() {
        bicycle.step(&mut state, &command, dt);
        t += dt;
        world.set_vehicle_pose(&state.world_from_vehicle(), t);
    }
    let contact = world
        .contacts()
        .first()
        .unwrap_or_else(|| panic!("no contact; vehicle ended at {state:?}"));
    assert_eq!(contact.object, "cone");
    assert!(
        (contact.time_s - t).abs() < 1e-9 && state.x_m > 20.0 && state.x_m < 25.0,
        "contact at {} s, x = {}",
        contact.time_s,
        state.x_m
    );
    assert!(state.y_m > 0.5, "the arc bent left: y = {}", state.y_m);
}

/// The judge's "did the vehicle's own motion bring them together": an object's signed
/// separation from a vehicle part placed at another pose is its separation from that part where
/// the pose puts it (negative: overlapping), and leaves the vehicle where it is.
#[test]
fn an_objects_separation_from_a_part_at_another_pose() {
    let v = car();
    // The car at a turned, offset pose; a van beside it on its left, parallel to it.
    let here = Isometry2::new(Vector2::new(10.0, 5.0), 0.6);
    let left = here * nalgebra::Point2::new(1.0, 2.5);
    let van = solid(
        "van",
        ObjectKind::Vehicle,
        SolidShape::Box {
            size_m: [4.0, 2.0, 2.0],
        },
        left.x,
        left.y,
        0.6,
    );
    let mut world = World::with_obstacles(&scene(vec![van]), &v, &here);
    world.set_vehicle_pose(&here, 0.0);
    let (d0, part) = v
        .parts
        .iter()
        .map(|p| {
            (
                world.part_separation_at_m(0, &p.link, &here),
                p.link.clone(),
            )
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap();
    let exact = world
        .distances_to(0)
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    assert!((d0 - exact).abs() < 2e-3, "{d0} against {exact} ({part})");
    assert!(d0 > 0.2 && d0 < 1.0, "the van beside the car: {d0}");
    // Half a metre along its heading: the van beside its flat side, as far.
    let ahead = here * Isometry2::new(Vector2::new(0.5, 0.0), 0.0);
    assert!((world.part_separation_at_m(0, &part, &ahead) - d0).abs() < 2e-3);
    // Sideways towards the van: 0.1 m short, then 0.1 m into it.
    let nearer = here * Isometry2::new(Vector2::new(0.0, d0 - 0.1), 0.0);
    assert!((world.part_separation_at_m(0, &part, &nearer) - 0.1).abs() < 2e-3);
    let into = here * Isometry2::new(Vector2::new(0.0, d0 + 0.1), 0.0);
    assert!((world.part_separation_at_m(0, &part, &into) + 0.1).abs() < 2e-3);
    // Away from it beyond the query's metre: infinity.
    let away = here * Isometry2::new(Vector2::new(0.0, -2.0), 0.0);
    assert_eq!(world.part_separation_at_m(0, &part, &away), f64::INFINITY);
    // The vehicle itself did not move.
    let after = world
        .distances_to(0)
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    assert_eq!(exact, after);
}
