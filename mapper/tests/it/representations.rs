//! The comparison study's other representations: the 3D voxel grid (ray carving, the exact 3D
//! EDT, span queries with the EDT early out against plain enumeration, the 2D map's collision
//! convention) and the 2.5D elevation-interval map (its overhang false alarm).

use mapper::collision::{Circle, CollisionModel};
use mapper::edt::EdtScratch;
use mapper::elevation::ElevationMap;
use mapper::synthetic::{Lidar, Scene, Solid, car_sensor_mount};
use mapper::voxel::VoxelGrid;
use mapper::workloads::XorShift;
use mapper::{
    DistanceMap, DistanceMaps, GridGeometry, LevelMode, Levels, MapConfig, MultiHeightMap,
    OccupancyParams, Return, Scan, ScanColumn,
};
use nalgebra::{Isometry2, Isometry3, Point2, Point3, Vector2};

/// One column per ray: each sensor origin with its returns (one beam each, `None` padding).
fn rays_scan(rays: &[(Point3<f64>, Point3<f64>)]) -> Scan {
    let columns = rays
        .iter()
        .map(|(o, _)| ScanColumn {
            world_from_sensor: Isometry3::translation(o.x, o.y, o.z),
            world_from_vehicle: Isometry2::identity(),
        })
        .collect();
    let returns = rays
        .iter()
        .map(|(o, p)| {
            Some(Return {
                point_in_world: *p,
                range_m: (p - o).norm().min(1e30) as f32,
                intensity: 0.5,
            })
        })
        .collect();
    Scan::new(1, columns, returns).unwrap()
}

/// Each point seen from itself: a zero-length ray marks its voxel and frees nothing.
fn points_scan(points: &[Point3<f64>]) -> Scan {
    rays_scan(&points.iter().map(|p| (*p, *p)).collect::<Vec<_>>())
}

/// 10 x 10 cells of 0.5 m from the origin, 10 layers from 0 to 5 m.
fn small_grid() -> VoxelGrid {
    let g = GridGeometry::new(Point2::origin(), 0.5, 10, 10).unwrap();
    VoxelGrid::new(g, 0.0, 5.0, OccupancyParams::default()).unwrap()
}

/// The centre of voxel (x, y, k) of a grid.
fn centre(v: &VoxelGrid, x: usize, y: usize, k: usize) -> Point3<f64> {
    let c = v.geometry().center_of(mapper::Cell { x, y });
    Point3::new(c.x, c.y, v.layer_center_m(k).unwrap())
}

/// The part of segment a -> b inside the box [lo, hi] as (t0, t1), `None` if it misses.
fn clip(a: Point3<f64>, b: Point3<f64>, lo: [f64; 3], hi: [f64; 3]) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for i in 0..3 {
        let d = b[i] - a[i];
        if d == 0.0 {
            if a[i] < lo[i] || a[i] > hi[i] {
                return None;
            }
        } else {
            let (ta, tb) = ((lo[i] - a[i]) / d, (hi[i] - a[i]) / d);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

#[test]
fn a_ray_frees_the_voxels_it_crosses_and_marks_its_endpoint() {
    let p = OccupancyParams::default();
    let mut v = small_grid();
    // Along x through the centres of row 2, layer 2, from voxel 0 to voxel 7.
    v.insert_scan(&rays_scan(&[(centre(&v, 0, 2, 2), centre(&v, 7, 2, 2))]));
    for x in 0..7 {
        assert_eq!(v.log_odds(x, 2, 2), Some(p.l_free), "voxel {x}");
    }
    assert_eq!(v.log_odds(7, 2, 2), Some(p.l_occ));
    assert_eq!(v.log_odds(8, 2, 2), Some(0.0));
    assert_eq!(v.log_odds(3, 3, 2), Some(0.0));
    assert_eq!(v.log_odds(3, 2, 1), Some(0.0));
    assert_eq!(v.occupied_voxels(), 1);
    assert_eq!(v.log_odds(10, 0, 0), None);

    // Random rays, inside and from outside the box: a voxel the segment crosses (by more than
    // a hair) before the endpoint's voxel is freed, one it misses (by more than a hair) is not.
    let mut rng = XorShift::new(3);
    let eps = 1e-6;
    for _ in 0..300 {
        let mut v = small_grid();
        let mut pt = |lo: f64, hi: f64| {
            Point3::new(
                rng.range(lo, hi + 5.0),
                rng.range(lo, hi + 5.0),
                rng.range(lo, hi + 5.0),
            )
        };
        let (a, b) = (pt(-3.0, 3.0), pt(-1.0, 1.0));
        v.insert_scan(&rays_scan(&[(a, b)]));
        let end = [b.x, b.y, b.z].map(|c| (c / 0.5).floor());
        let end_inside = end.iter().all(|&c| (0.0..10.0).contains(&c));
        for (x, y, k) in (0..1000).map(|i| (i % 10, i / 10 % 10, i / 100)) {
            let l = v.log_odds(x, y, k).unwrap();
            if end_inside && [x, y, k].map(|c| c as f64) == end {
                assert_eq!(l, p.l_occ, "{a:?} -> {b:?}");
                continue;
            }
            let lo = [x, y, k].map(|c| c as f64 * 0.5);
            let (shrunk, grown) = (lo.map(|c| c + eps), lo.map(|c| c + 0.5 - eps));
            if clip(a, b, shrunk, grown).is_some_and(|(t0, t1)| t1 - t0 > eps) {
                assert_eq!(l, p.l_free, "({x},{y},{k}) crossed: {a:?} -> {b:?}");
            } else if clip(a, b, lo.map(|c| c - eps), lo.map(|c| c + 0.5 + eps)).is_none() {
                assert_eq!(l, 0.0, "({x},{y},{k}) missed: {a:?} -> {b:?}");
            }
        }
    }
}

#[test]
fn a_ray_from_outside_the_box_is_carved_from_where_it_enters() {
    let p = OccupancyParams::default();
    // From 3 m left of the box along row 2, layer 2, to voxel 4.
    let mut v = small_grid();
    v.insert_scan(&rays_scan(&[(
        Point3::new(-3.0, 1.25, 1.25),
        centre(&v, 4, 2, 2),
    )]));
    for x in 0..4 {
        assert_eq!(v.log_odds(x, 2, 2), Some(p.l_free), "voxel {x}");
    }
    assert_eq!(v.log_odds(4, 2, 2), Some(p.l_occ));
    // From 3 m above the box top (5 m) straight down to layer 1.
    let mut v = small_grid();
    v.insert_scan(&rays_scan(&[(
        Point3::new(1.25, 1.25, 8.0),
        centre(&v, 2, 2, 1),
    )]));
    for k in 2..10 {
        assert_eq!(v.log_odds(2, 2, k), Some(p.l_free), "layer {k}");
    }
    assert_eq!(v.log_odds(2, 2, 1), Some(p.l_occ));
    assert_eq!(v.log_odds(2, 2, 0), Some(0.0));
    // A ray that never enters the box changes nothing.
    let mut v = small_grid();
    v.insert_scan(&rays_scan(&[(
        Point3::new(-3.0, 1.0, 1.0),
        Point3::new(-1.0, 9.0, 1.0),
    )]));
    assert!((0..10).all(|k| (0..100).all(|i| v.log_odds(i % 10, i / 10, k) == Some(0.0))));
}

#[test]
fn ground_returns_below_the_floor_carve_but_do_not_mark() {
    let p = OccupancyParams::default();
    let mut v = small_grid();
    // Down from 3 m to a point 0.3 m below the floor: it crosses z = 0 at (4.34, 2.07).
    v.insert_scan(&rays_scan(&[(
        Point3::new(0.25, 0.25, 3.0),
        Point3::new(4.75, 2.25, -0.3),
    )]));
    assert_eq!(v.occupied_voxels(), 0);
    assert_eq!(v.log_odds(0, 0, 6), Some(p.l_free), "the sensor's voxel");
    assert_eq!(
        v.log_odds(8, 4, 0),
        Some(p.l_free),
        "where it meets the floor"
    );
    assert_eq!(v.log_odds(9, 4, 0), Some(0.0));
}

#[test]
fn within_one_scan_a_voxel_is_updated_once_and_a_hit_is_not_freed() {
    let p = OccupancyParams::default();
    let mut v = small_grid();
    // Two rays along row 2: the longer one crosses the shorter one's endpoint (voxel 3).
    let a = centre(&v, 0, 2, 2);
    v.insert_scan(&rays_scan(&[
        (a, centre(&v, 3, 2, 2)),
        (a, centre(&v, 6, 2, 2)),
        (a, centre(&v, 6, 2, 2)),
    ]));
    assert_eq!(
        v.log_odds(1, 2, 2),
        Some(p.l_free),
        "crossed 3 times, freed once"
    );
    assert_eq!(v.log_odds(3, 2, 2), Some(p.l_occ), "hit wins");
    assert_eq!(v.log_odds(4, 2, 2), Some(p.l_free));
    assert_eq!(v.log_odds(6, 2, 2), Some(p.l_occ), "hit twice, marked once");
    // Over scans the log-odds add up to the clamp.
    let hit = points_scan(&[centre(&v, 6, 2, 2)]);
    for _ in 0..10 {
        v.insert_scan(&hit);
    }
    assert_eq!(v.log_odds(6, 2, 2), Some(p.l_max));
}

/// A grid of `w x h x l` voxels of `res` with voxels occupied at random (each with
/// probability `density`), and their coordinates.
fn random_grid(
    rng: &mut XorShift,
    (w, h, l): (usize, usize, usize),
    res: f64,
    density: f64,
) -> (VoxelGrid, Vec<[usize; 3]>) {
    let g = GridGeometry::new(Point2::new(-1.3, 0.7), res, w, h).unwrap();
    let mut v = VoxelGrid::new(g, 0.1, 0.1 + l as f64 * res, OccupancyParams::default()).unwrap();
    assert_eq!(v.layers(), l);
    let occupied: Vec<[usize; 3]> = (0..w * h * l)
        .filter(|_| rng.next_f64() < density)
        .map(|i| [i % w, i / w % h, i / (w * h)])
        .collect();
    let points: Vec<Point3<f64>> = occupied
        .iter()
        .map(|&[x, y, k]| centre(&v, x, y, k))
        .collect();
    if !points.is_empty() {
        v.insert_scan(&points_scan(&points));
    }
    assert_eq!(v.occupied_voxels(), occupied.len());
    (v, occupied)
}

#[test]
fn the_3d_edt_equals_brute_force() {
    let mut rng = XorShift::new(11);
    let shapes = [
        (1, 1, 1),
        (9, 7, 6),
        (13, 2, 9),
        (3, 17, 4),
        (16, 16, 1),
        (1, 1, 20),
    ];
    for (s, &shape) in shapes.iter().enumerate() {
        for density in [0.0, 0.004, 0.03, 0.2, 0.9] {
            let res = 0.3;
            let (mut v, occupied) = random_grid(&mut rng, shape, res, density);
            v.update_distances();
            assert!(v.distances_up_to_date());
            let (w, h, l) = shape;
            for (x, y, k) in (0..w * h * l).map(|i| (i % w, i / w % h, i / (w * h))) {
                let want = occupied
                    .iter()
                    .map(|o| {
                        let d = [
                            o[0] as i64 - x as i64,
                            o[1] as i64 - y as i64,
                            o[2] as i64 - k as i64,
                        ];
                        let d2 = d.iter().map(|c| c * c).sum::<i64>();
                        (d2 as f32).sqrt() * res as f32
                    })
                    .fold(f32::INFINITY, f32::min);
                let got = v.distance_at(centre(&v, x, y, k));
                assert_eq!(
                    got, want,
                    "shape {s}, density {density}, voxel ({x},{y},{k})"
                );
            }
            // Outside the box reads 0.
            assert_eq!(v.distance_at(Point3::new(-2.0, 1.0, 0.5)), 0.0);
            assert_eq!(v.distance_at(Point3::new(-1.0, 1.0, 0.0)), 0.0);
        }
    }
}

#[test]
fn span_queries_with_the_edt_early_out_equal_plain_enumeration() {
    let mut rng = XorShift::new(5);
    // 10 x 7.5 m at 0.25 m, 12 layers from 0.1 m, 1.5 % occupied.
    let (mut v, _) = random_grid(&mut rng, (40, 30, 12), 0.25, 0.015);
    v.update_distances();
    let (mut yes, mut no) = (0, 0);
    for i in 0..3000 {
        let c = Point2::new(rng.range(-2.5, 10.0), rng.range(-0.5, 9.0));
        let r = rng.range(-0.2, 3.0);
        let z_lo = rng.range(-1.0, 3.5);
        let z_hi = if i % 5 == 0 {
            f64::INFINITY
        } else {
            z_lo + rng.range(-0.3, 2.0)
        };
        let got = v.span_collides(c, r, z_lo, z_hi);
        assert_eq!(
            got,
            v.span_collides_plain(c, r, z_lo, z_hi),
            "{c:?} r {r} [{z_lo}, {z_hi}]"
        );
        if got { yes += 1 } else { no += 1 }
    }
    assert!(
        yes > 300 && no > 300,
        "both answers exercised: {yes} / {no}"
    );
    // After a scan the distances are stale: the query enumerates and still agrees.
    v.insert_scan(&points_scan(&[Point3::new(3.0, 3.0, 1.0)]));
    assert!(!v.distances_up_to_date());
    assert!(v.span_collides(Point2::new(3.0, 3.0), 0.1, 0.9, 1.2));
    assert!(v.span_collides_plain(Point2::new(3.0, 3.0), 0.1, 0.9, 1.2));
}

#[test]
fn an_overhang_collides_only_with_spans_reaching_it_and_the_elevation_map_fills_under_it() {
    let g = GridGeometry::new(Point2::new(-2.0, -2.0), 0.2, 20, 20).unwrap();
    let mut v = VoxelGrid::new(g, 0.0, 4.0, OccupancyParams::default()).unwrap();
    let at = |z: f64| Point3::new(0.1, 0.1, z);
    let overhang: Vec<Point3<f64>> = [3.05, 3.15, 3.25, 3.35].map(at).to_vec();
    v.insert_scan(&points_scan(&overhang));
    v.update_distances();
    assert_eq!(v.occupied_voxels(), 2, "layers 15 and 16: 3.0 .. 3.4 m");
    let c = Point2::new(0.1, 0.1);
    assert!(v.span_collides(c, 0.3, 2.0, 3.5));
    assert!(!v.span_collides(c, 0.3, 0.0, 2.5));

    // A cone (0 .. 0.5 m) under the overhang, in the same cell.
    let cone: Vec<Point3<f64>> = [0.1, 0.3, 0.5].map(at).to_vec();
    let both: Vec<Point3<f64>> = cone.iter().chain(&overhang).copied().collect();
    let mut e = ElevationMap::new(g, 0.05, 4.0).unwrap();
    e.insert_scan(&points_scan(&both));
    assert_eq!(e.occupied_cells(), 1);
    assert_eq!(e.interval(10, 10), Some((0.1, 3.35)));
    v.insert_scan(&points_scan(&cone));
    v.update_distances();
    // The wing's span between them: the interval [0.1, 3.35] covers it, the voxels do not.
    assert!(
        e.span_collides(c, 0.3, 1.5, 2.0),
        "the elevation map's false alarm"
    );
    assert!(!v.span_collides(c, 0.3, 1.5, 2.0));
    assert!(!v.span_collides_plain(c, 0.3, 1.5, 2.0));
    assert!(e.span_collides(c, 0.3, 0.0, 0.2) && v.span_collides(c, 0.3, 0.0, 0.2));
    assert!(!e.span_collides(c, 0.3, 3.5, 4.0) && !v.span_collides(c, 0.3, 3.5, 4.0));
    assert!(!e.span_collides(Point2::new(1.0, 0.1), 0.3, 0.0, 4.0));
}

/// With the span [0, inf) a voxel grid answers as the 2D distance map of its occupied columns:
/// `distance_at(centre) < radius` (collision.rs with no safety distance), the same cells.
#[test]
fn a_full_span_answers_as_the_2d_distance_map_of_the_occupied_columns() {
    let mut rng = XorShift::new(9);
    let (mut v, occupied) = random_grid(&mut rng, (50, 40, 10), 0.2, 0.002);
    v.update_distances();
    let g = *v.geometry();
    let mut columns = vec![false; g.len()];
    for o in &occupied {
        columns[o[1] * g.width() + o[0]] = true;
    }
    let dm = DistanceMap::compute(g, 1000.0, |i| columns[i], &mut EdtScratch::default());
    let maps = DistanceMaps::new(LevelMode::Cumulative, vec![dm.clone()]).unwrap();
    let (mut yes, mut no) = (0, 0);
    for _ in 0..2500 {
        // Centres over the grid (-1.3 .. 8.7, 0.7 .. 8.7) and a margin around it.
        let c = Point2::new(rng.range(-2.5, 10.0), rng.range(-0.5, 10.0));
        let r = rng.range(0.01, 1.5);
        let want = dm.distance_at(&c) < r as f32;
        let model = CollisionModel::new(
            vec![Circle {
                x_m: 0.0,
                y_m: 0.0,
                radius_m: r,
                level: 0,
            }],
            vec![0.0],
        )
        .unwrap();
        let pose = Isometry2::new(Vector2::new(c.x, c.y), 0.0);
        let checked = model
            .checker(&maps)
            .unwrap()
            .clearance(&pose, 0.0)
            .colliding;
        assert_eq!(checked, want, "{c:?} r {r}");
        assert_eq!(
            v.span_collides(c, r, 0.0, f64::INFINITY),
            want,
            "{c:?} r {r}"
        );
        assert_eq!(v.span_collides_plain(c, r, 0.0, f64::INFINITY), want);
        if want { yes += 1 } else { no += 1 }
    }
    assert!(
        yes > 300 && no > 300,
        "both answers exercised: {yes} / {no}"
    );
}

#[test]
fn a_synthetic_revolution_puts_a_box_in_all_three_maps_and_nothing_10_m_away() {
    let scene = Scene {
        solids: vec![Solid::standing_box(8.0, 0.0, 1.0, 1.0, 1.5)],
        ground_intensity: 0.3,
        solid_intensity: 0.8,
    };
    let scan = Lidar::hdl32e()
        .scan(
            &scene,
            &Isometry2::identity(),
            &car_sensor_mount(),
            |_, _| 0.0,
        )
        .unwrap();
    let g = GridGeometry::new(Point2::new(-20.0, -20.0), 0.2, 200, 200).unwrap();
    let mut v = VoxelGrid::new(g, 0.1, 3.0, OccupancyParams::default()).unwrap();
    assert_eq!(v.layers(), 15);
    assert_eq!(v.memory_bytes(), 200 * 200 * 15 * 4);
    v.insert_scan(&scan);
    v.update_distances();
    assert_eq!(v.memory_bytes(), 200 * 200 * 15 * 8);
    let mut e = ElevationMap::new(g, 0.1, 3.0).unwrap();
    e.insert_scan(&scan);
    assert_eq!(e.memory_bytes(), 200 * 200 * 8);
    let levels = Levels::new(vec![0.0, 0.7], LevelMode::Cumulative, None).unwrap();
    let mut m = MultiHeightMap::new(MapConfig::default(), levels, Point2::origin()).unwrap();
    m.insert_scan(&scan, None).unwrap();
    m.update_distance_maps();
    let level0 = m.distance_maps().level(0).unwrap();
    assert!(v.occupied_voxels() > 30, "{}", v.occupied_voxels());
    assert!(e.occupied_cells() > 5, "{}", e.occupied_cells());

    let (at_box, far) = (Point2::new(8.0, 0.0), Point2::new(8.0, -10.0));
    assert!(v.span_collides(at_box, 1.0, 0.0, 2.0));
    assert!(e.span_collides(at_box, 1.0, 0.0, 2.0));
    assert!(level0.distance_at(&at_box) < 1.0);
    assert!(!v.span_collides(far, 1.0, 0.0, 2.0));
    assert!(!e.span_collides(far, 1.0, 0.0, 2.0));
    assert!(level0.distance_at(&far) >= 1.0);
    // Above the box (1.5 m) neither 3D map has it; the sensor's open space was carved.
    assert!(!v.span_collides(at_box, 1.0, 1.8, 3.0));
    assert!(!e.span_collides(at_box, 1.0, 1.8, 3.0));
    assert!(v.log_odds(120, 100, 5).is_some_and(|l| l < 0.0));
}

#[test]
fn bad_arguments_are_errors_or_conservative_answers_never_panics() {
    let g = GridGeometry::new(Point2::origin(), 0.5, 10, 10).unwrap();
    let p = OccupancyParams::default();
    for (floor, top) in [
        (f64::NAN, 1.0),
        (0.0, f64::INFINITY),
        (1.0, 1.0),
        (2.0, 1.0),
        (0.0, 1e300),
    ] {
        assert!(VoxelGrid::new(g, floor, top, p).is_err(), "{floor} {top}");
    }
    for (floor, top) in [(f64::NAN, 1.0), (0.0, f64::INFINITY), (1.0, 1.0)] {
        assert!(ElevationMap::new(g, floor, top).is_err(), "{floor} {top}");
    }
    for bad in [
        OccupancyParams { l_occ: 0.0, ..p },
        OccupancyParams { l_free: 0.1, ..p },
        OccupancyParams {
            l_max: f32::NAN,
            ..p
        },
    ] {
        let e = VoxelGrid::new(g, 0.0, 1.0, bad).unwrap_err();
        assert!(e.to_string().contains("voxel grid"), "{e}");
    }
    let big = GridGeometry::new(Point2::origin(), 0.001, 40_000, 40_000).unwrap();
    assert!(VoxelGrid::new(big, 0.0, 10.0, p).is_err());

    let mut v = small_grid();
    let mut e = ElevationMap::new(g, 0.0, 5.0).unwrap();
    // Far and huge coordinates: nothing inside, nothing panics.
    let far = rays_scan(&[
        (Point3::new(1e12, -1e12, 3.0), Point3::new(-1e12, 1e12, 2.0)),
        (Point3::new(1.0, 1.0, 1.0), Point3::new(1e300, 1.0, 1.0)),
    ]);
    v.insert_scan(&far);
    e.insert_scan(&far);
    assert_eq!(v.occupied_voxels(), 0);
    assert_eq!(e.occupied_cells(), 0);
    v.update_distances();
    let c = Point2::new(2.0, 2.0);
    for (r, lo, hi) in [
        (f64::NAN, 0.0, 1.0),
        (1.0, f64::NAN, 1.0),
        (1.0, 0.0, f64::NAN),
    ] {
        assert!(v.span_collides(c, r, lo, hi) && e.span_collides(c, r, lo, hi));
    }
    // Outside the grid reads distance 0: any positive radius collides, as in the 2D map.
    let out = Point2::new(-1.0, 2.0);
    assert!(v.span_collides(out, 0.1, 0.0, 1.0) && e.span_collides(out, 0.1, 0.0, 1.0));
    assert!(!v.span_collides(out, 0.0, 0.0, 1.0) && !e.span_collides(out, -1.0, 0.0, 1.0));
    assert!(v.span_collides(Point2::new(f64::NAN, 0.0), 0.1, 0.0, 1.0));
    // An empty span, an infinite radius on an empty grid.
    assert!(!v.span_collides(c, 1.0, 2.0, 1.0) && !e.span_collides(c, 1.0, 2.0, 1.0));
    assert!(!v.span_collides(c, f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY));
    assert_eq!(v.layer_center_m(10), None);
    assert_eq!(v.layer_center_m(0), Some(0.25));
}
