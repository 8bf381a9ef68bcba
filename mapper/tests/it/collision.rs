//! Circle collision checks against distance maps: exact margins, the early out, trajectories.

use mapper::edt::EdtScratch;
use mapper::{Circle, CollisionModel, DistanceMap, DistanceMaps, GridGeometry, LevelMode};
use nalgebra::{Isometry2, Point2, Vector2};
use proptest::prelude::*;

/// Two levels, 40 x 40 m at 0.2 m: a cone at (10, 0) in level 0 only, a container at (10, 8) in both.
fn maps(mode: LevelMode) -> DistanceMaps {
    let g = GridGeometry::new(Point2::new(-20.0, -20.0), 0.2, 200, 200).unwrap();
    let cone = g.index_of(&Point2::new(10.0, 0.0)).unwrap();
    let container = g.index_of(&Point2::new(10.0, 8.0)).unwrap();
    let mut s = EdtScratch::default();
    let l0 = DistanceMap::compute(
        g,
        30.0,
        |i| i == cone || (mode == LevelMode::Cumulative && i == container),
        &mut s,
    );
    let l1 = DistanceMap::compute(g, 30.0, |i| i == container, &mut s);
    DistanceMaps::new(mode, vec![l0, l1]).unwrap()
}

/// A car (3 body circles at level 0) with a wing circle at level 1 sticking out to the left.
fn winged_car() -> CollisionModel {
    CollisionModel::new(
        vec![
            Circle {
                x_m: 0.0,
                y_m: 0.0,
                radius_m: 1.0,
                level: 0,
            },
            Circle {
                x_m: 1.5,
                y_m: 0.0,
                radius_m: 1.0,
                level: 0,
            },
            Circle {
                x_m: 3.0,
                y_m: 0.0,
                radius_m: 1.0,
                level: 0,
            },
            Circle {
                x_m: 3.0,
                y_m: 1.8,
                radius_m: 0.5,
                level: 1,
            },
        ],
        vec![0.0, 0.7],
    )
    .unwrap()
}

#[test]
fn the_wing_passes_over_a_cone_but_not_a_container() {
    let maps = maps(LevelMode::Cumulative);
    let model = winged_car();
    let checker = model.checker(&maps).unwrap();
    // Wing circle centred right over the cone: level 1 has no cone, body circles are 1.8 m away.
    let over_cone = checker.check_pose(&Isometry2::new(Vector2::new(7.0, -1.8), 0.0), 0.1);
    assert!(!over_cone.colliding, "{over_cone:?}");
    // Wing circle over the container: level 1 has it.
    let into_container = checker.check_pose(&Isometry2::new(Vector2::new(7.0, 6.2), 0.0), 0.1);
    assert!(
        into_container.colliding && into_container.nearest_circle == Some(3),
        "{into_container:?}"
    );
    // Body over the cone: collision, reported on the front body circle.
    let body = checker.check_pose(&Isometry2::new(Vector2::new(7.0, 0.0), 0.0), 0.1);
    assert!(body.colliding && body.nearest_circle == Some(2), "{body:?}");
    let expected = 0.0 - (1.0 + 0.1);
    assert!(
        (body.margin_m - expected).abs() < 0.15,
        "margin {}",
        body.margin_m
    );
}

#[test]
fn far_from_everything_the_early_out_answers_with_a_safe_lower_bound() {
    let maps = maps(LevelMode::Cumulative);
    let model = winged_car();
    let checker = model.checker(&maps).unwrap();
    let pose = Isometry2::new(Vector2::new(-12.0, -12.0), 0.4);
    let quick = checker.check_pose(&pose, 0.2);
    let exact = checker.clearance(&pose, 0.2);
    assert_eq!(quick.nearest_circle, None, "early out taken");
    assert!(!quick.colliding && quick.margin_m <= exact.margin_m);
}

#[test]
fn banded_parts_check_every_band_above_their_underside() {
    let maps = maps(LevelMode::Banded);
    let model = winged_car();
    let checker = model.checker(&maps).unwrap();
    // The body (level 0) meets the container, which is only in band 1: banded checks bands 0 and 1.
    let pose = Isometry2::new(Vector2::new(7.0, 8.0), 0.0);
    assert!(checker.check_pose(&pose, 0.1).colliding);
}

#[test]
fn trajectory_reports_the_first_collision() {
    let maps = maps(LevelMode::Cumulative);
    let model = winged_car();
    let checker = model.checker(&maps).unwrap();
    let poses: Vec<_> = (0..40)
        .map(|i| Isometry2::new(Vector2::new(-5.0 + 0.5 * i as f64, 0.0), 0.0))
        .collect();
    let t = checker.check_trajectory(&poses, 0.1);
    // Front circle at x + 3 reaches 10 - 1.1 - cell slack: first collision around x = 5.9.
    let first = t.first_collision.unwrap();
    assert!(
        (poses[first].translation.x - 5.9).abs() <= 0.5,
        "first collision at x = {}",
        poses[first].translation.x
    );
    assert!(t.min_margin_m < 0.0);
}

#[test]
fn outside_the_map_is_never_free_and_a_nan_pose_collides() {
    let maps = maps(LevelMode::Cumulative);
    let model = winged_car();
    let checker = model.checker(&maps).unwrap();
    assert!(
        checker
            .check_pose(&Isometry2::new(Vector2::new(500.0, 0.0), 0.0), 0.1)
            .colliding
    );
    assert!(
        checker
            .check_pose(&Isometry2::new(Vector2::new(f64::NAN, 0.0), 0.0), 0.1)
            .colliding
    );
}

#[test]
fn a_model_with_more_levels_than_the_map_is_refused() {
    let maps = maps(LevelMode::Cumulative);
    let three = CollisionModel::new(
        vec![Circle {
            x_m: 0.0,
            y_m: 0.0,
            radius_m: 1.0,
            level: 2,
        }],
        vec![0.0, 0.7, 1.5],
    )
    .unwrap();
    assert!(three.checker(&maps).is_err());
    assert!(
        CollisionModel::new(
            vec![Circle {
                x_m: 0.0,
                y_m: 0.0,
                radius_m: -1.0,
                level: 0
            }],
            vec![0.0]
        )
        .is_err()
    );
    assert!(
        CollisionModel::new(
            vec![Circle {
                x_m: 0.0,
                y_m: 0.0,
                radius_m: 1.0,
                level: 1
            }],
            vec![0.0]
        )
        .is_err()
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    /// The early out never turns a colliding pose into a free one, and agrees with the exact check.
    #[test]
    fn early_out_agrees_with_the_exact_check(x in -18.0f64..18.0, y in -18.0f64..18.0, yaw in -3.2f64..3.2, safety in 0.0f32..0.8) {
        let maps = maps(LevelMode::Cumulative);
        let model = winged_car();
        let checker = model.checker(&maps).unwrap();
        let pose = Isometry2::new(Vector2::new(x, y), yaw);
        let quick = checker.check_pose(&pose, safety);
        let exact = checker.clearance(&pose, safety);
        prop_assert_eq!(quick.colliding, exact.colliding);
        prop_assert!(quick.margin_m <= exact.margin_m + 1e-6);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]
    /// The check eight circles at a time (AVX2, where the CPU has it) gives the portable check's
    /// margin and nearest circle bit for bit: poses anywhere, half of them partly or wholly off
    /// the map, models of 1-40 circles on both levels (groups that are not multiples of eight),
    /// cumulative and banded maps.
    #[test]
    fn the_vectorised_check_equals_the_portable_one(
        x in -45.0f64..45.0,
        y in -45.0f64..45.0,
        yaw in -3.2f64..3.2,
        safety in 0.0f32..0.8,
        circles in proptest::collection::vec((-6.0f64..6.0, -6.0f64..6.0, 0.1f64..1.5, 0usize..2), 1..40),
        banded in any::<bool>(),
    ) {
        let maps = maps(if banded { LevelMode::Banded } else { LevelMode::Cumulative });
        let model = CollisionModel::new(
            circles
                .iter()
                .map(|&(x_m, y_m, radius_m, level)| Circle { x_m, y_m, radius_m, level })
                .collect(),
            vec![0.0, 0.7],
        )
        .unwrap();
        let checker = model.checker(&maps).unwrap();
        let pose = Isometry2::new(Vector2::new(x, y), yaw);
        let (fast, portable) = (checker.clearance(&pose, safety), checker.clearance_portable(&pose, safety));
        prop_assert_eq!(fast.margin_m.to_bits(), portable.margin_m.to_bits());
        prop_assert_eq!(fast.nearest_circle, portable.nearest_circle);
        prop_assert_eq!(fast.colliding, portable.colliding);
    }
}

/// The jet's 62 circles on the benchmark's maps (obstacles all round the near pose), the two
/// checks on a grid of poses across the obstacle ring: equal everywhere.
#[test]
fn the_vectorised_check_equals_the_portable_one_for_the_jet_at_the_obstacle_ring() {
    let maps = mapper::workloads::distance_maps_for_checks();
    let jet = mapper::workloads::jet_62_circles();
    let checker = jet.checker(&maps).unwrap();
    #[cfg(target_arch = "x86_64")]
    assert_eq!(checker.vectorised(), is_x86_feature_detected!("avx2"));
    let mut checked = 0;
    for i in 0..60 {
        for j in 0..60 {
            let pose = Isometry2::new(
                Vector2::new(-108.0 + 3.6 * i as f64, -108.0 + 3.6 * j as f64),
                0.1 * (i + j) as f64,
            );
            let (fast, portable) = (
                checker.clearance(&pose, 0.2),
                checker.clearance_portable(&pose, 0.2),
            );
            assert_eq!(
                (fast.margin_m.to_bits(), fast.nearest_circle),
                (portable.margin_m.to_bits(), portable.nearest_circle),
                "{pose}"
            );
            checked += usize::from(fast.colliding);
        }
    }
    assert!(checked > 500, "{checked} colliding poses of 3600");
}
