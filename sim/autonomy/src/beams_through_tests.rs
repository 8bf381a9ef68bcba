//! Beams through a place (`beams_through.rs`) on a made-up revolution: a sensor 3 m up, a
//! column every degree, three beams each down to flat ground.

use mapper::{Return, Scan, ScanColumn, TrackState};
use nalgebra::{Isometry2, Isometry3, Matrix4, Point2, Point3, Vector2, Vector3};

use super::{ColumnIndex, Through, way_seen_empty};

/// The beams' elevations, degrees (below the horizon).
const ELEVATIONS_DEG: [f64; 3] = [-10.0, -5.0, -2.0];
const SENSOR_Z: f64 = 3.0;

/// A revolution over flat ground (z 0) from a sensor at (`x`, 0, 3), one column a degree from
/// -180; `hit` may move a return of a column (its azimuth in degrees, its beam) to a range.
fn revolution(x: f64, hit: Option<(i32, usize, f64)>) -> Scan {
    let at = |az: i32, b: usize| hit.filter(|h| h.0 == az && h.1 == b).map(|h| h.2);
    revolution_with(x, &ELEVATIONS_DEG, at)
}

/// [`revolution`] with beams at `elevations_deg`, and `hit` giving a return's range for a
/// column's azimuth and a beam (`None`: the ground's).
fn revolution_with(
    x: f64,
    elevations_deg: &[f64],
    hit: impl Fn(i32, usize) -> Option<f64>,
) -> Scan {
    let mut columns = Vec::new();
    let mut returns = Vec::new();
    for az in -180..180 {
        let a = (az as f64).to_radians();
        columns.push(ScanColumn {
            world_from_sensor: Isometry3::translation(x, 0.0, SENSOR_Z),
            world_from_vehicle: Isometry2::translation(x, 0.0),
        });
        for (b, e) in elevations_deg.iter().enumerate() {
            let e = e.to_radians();
            let range = hit(az, b).unwrap_or(SENSOR_Z / -e.tan() / e.cos());
            let dir = Vector3::new(a.cos() * e.cos(), a.sin() * e.cos(), e.sin());
            returns.push(Some(Return {
                point_in_world: Point3::new(x, 0.0, SENSOR_Z) + dir * range,
                range_m: range as f32,
                intensity: 0.5,
            }));
        }
    }
    Scan::new(elevations_deg.len(), columns, returns).unwrap()
}

const LOW: Through = Through {
    band_z: (0.15, 0.5),
    lateral_m: 0.25,
    beyond_m: 0.5,
    veto_m: 0.25,
};

/// At 30 m the 5-degree beam passes 0.38 m up and meets the ground at 34.3 m: one beam (the
/// next column is 0.52 m aside). At 20 m none passes low (the 5-degree beam is 1.25 m up, the
/// 10-degree one meets the ground at 17 m), though one passes 1.0-1.5 m up.
#[test]
fn a_beam_passes_low_through_a_place_only_where_it_goes_on_to_the_ground_beyond() {
    let scan = revolution(0.0, None);
    let index = ColumnIndex::new([&scan]);
    assert_eq!(index.beams_through(&Point2::new(30.0, 0.0), &LOW), Some(1));
    assert_eq!(index.beams_through(&Point2::new(0.0, 30.0), &LOW), Some(1));
    assert_eq!(index.beams_through(&Point2::new(20.0, 0.0), &LOW), Some(0));
    let high = Through {
        band_z: (1.0, 1.5),
        ..LOW
    };
    assert_eq!(index.beams_through(&Point2::new(20.0, 0.0), &high), Some(1));
    // Wider, the columns a degree either side count too.
    let wide = Through {
        lateral_m: 0.6,
        ..LOW
    };
    assert_eq!(index.beams_through(&Point2::new(30.0, 0.0), &wide), Some(3));
}

/// A beam that hits something before the place did not pass through it (an object standing
/// in front); one that hits something at it, within the band, says something stands there
/// (`None`, whatever other beams passed).
#[test]
fn a_beam_stopped_before_or_at_the_place_does_not_pass_through_it() {
    let scan = revolution(0.0, Some((0, 1, 25.0)));
    let index = ColumnIndex::new([&scan]);
    assert_eq!(index.beams_through(&Point2::new(30.0, 0.0), &LOW), Some(0));
    let scan = revolution(0.0, Some((0, 1, 30.2)));
    let index = ColumnIndex::new([&scan]);
    assert_eq!(index.beams_through(&Point2::new(30.0, 0.0), &LOW), None);
    let wide = Through {
        lateral_m: 0.6,
        ..LOW
    };
    assert_eq!(index.beams_through(&Point2::new(30.0, 0.0), &wide), None);
    let scan = revolution(0.0, Some((0, 1, 40.0)));
    let index = ColumnIndex::new([&scan]);
    assert_eq!(index.beams_through(&Point2::new(30.0, 0.0), &LOW), Some(1));
}

/// Behind the sensor, where azimuths wrap from 180 to -180 degrees, and from a sensor that is
/// not at the origin; a scan with no return passes nothing.
#[test]
fn places_behind_the_sensor_are_found_across_the_azimuths_wrap() {
    let scan = revolution(5.0, None);
    let index = ColumnIndex::new([&scan]);
    assert_eq!(
        index.beams_through(&Point2::new(-25.0, 0.01), &LOW),
        Some(1)
    );
    assert_eq!(
        index.beams_through(&Point2::new(-25.0, -0.01), &LOW),
        Some(1)
    );
    assert_eq!(index.beams_through(&Point2::new(35.0, 0.0), &LOW), Some(1));
    // Off the axis: azimuths are taken from the sensor, not the world's origin.
    assert_eq!(index.beams_through(&Point2::new(5.0, 30.0), &LOW), Some(1));
    let empty = Scan::new(3, Vec::new(), Vec::new()).unwrap();
    let index = ColumnIndex::new([&empty]);
    assert_eq!(index.beams_through(&Point2::new(30.0, 0.0), &LOW), Some(0));
}

/// A track of `extent_m` hit in `levels`, last seen at 10 s at (25, 0) going along y at 1 m/s.
fn lost_track(extent_m: f64, levels: u32) -> TrackState {
    TrackState {
        id: 7,
        t_s: 10.0,
        position: Point2::new(25.0, 0.0),
        velocity: Vector2::new(0.0, 1.0),
        covariance: Matrix4::identity() * 0.01,
        extent_m,
        levels,
        open_top_m: None,
        confirmed: true,
        travel_m: 5.0,
        bbox: ((250, 0), (257, 7)),
        size_m: [0.8, 0.8],
        peak_speed_m_s: 1.0,
        born_s: 5.0,
        origin: Point2::new(25.0, -5.0),
    }
}

/// Beams every quarter degree from 1 to 15 degrees down: from 25 m, several pass each place
/// 0.15-1.1 m up (the second level's lowest height, a track hit in both levels).
#[test]
fn a_small_tracks_way_is_seen_empty_only_where_beams_pass_every_place_of_it() {
    let dense: Vec<f64> = (4..=60).map(|k| -0.25 * k as f64).collect();
    let heights = [0.0, 1.1];
    let seen_empty = |scan: &Scan, t: TrackState, now_s: f64| {
        way_seen_empty(&ColumnIndex::new([scan]), &t, now_s, 0.0, &heights)
    };
    let ground = revolution_with(0.0, &dense, |_, _| None);
    // 2 s on: from (25, 0) to (25, 3.4) (1.5 times its way at its peak, and its half-length).
    assert!(seen_empty(&ground, lost_track(0.8, 0b11), 12.0));
    // Larger than a person or a cart, or not hit in the lowest level (a wing passing over the
    // beams?): never.
    assert!(!seen_empty(&ground, lost_track(2.5, 0b11), 12.0));
    assert!(!seen_empty(&ground, lost_track(0.8, 0b10), 12.0));
    // Hit in the lowest level only: beams 0.15-0.3 m up; a place on a column (24.6 or 25.4 m
    // out) has one, and no other column within 0.25 m.
    assert!(!seen_empty(&ground, lost_track(0.8, 0b01), 12.0));
    // Something stands 24 m out at azimuth 0 (the column through where it was last seen).
    let wall = revolution_with(0.0, &dense, |az, _| (az == 0).then_some(24.0));
    assert!(!seen_empty(&wall, lost_track(0.8, 0b11), 12.0));
    // ... or 0.44 m beside the way of one going away from the sensor (azimuth -1 degree):
    // within the width of a 0.8 m track, not of a 0.3 m one.
    let beside = revolution_with(0.0, &dense, |az, _| (az == -1).then_some(24.0));
    let going_away = |extent_m: f64| TrackState {
        velocity: Vector2::new(1.0, 0.0),
        ..lost_track(extent_m, 0b11)
    };
    assert!(!seen_empty(&beside, going_away(0.8), 12.0));
    assert!(seen_empty(&beside, going_away(0.3), 12.0));
    // ... or on its way 2.2 m on (azimuth 5 degrees, 25 m out): not yet reached at 10.5 s
    // (0.75 m, 1.5 times its peak speed, and its half-length: 1.15 m), reached at 12 s, or at
    // 10.5 s had its peak been 2 m/s (it may have gone faster than it was seen going).
    let ahead = revolution_with(0.0, &dense, |az, _| (az == 5).then_some(25.0));
    assert!(seen_empty(&ahead, lost_track(0.8, 0b11), 10.5));
    assert!(!seen_empty(&ahead, lost_track(0.8, 0b11), 12.0));
    let faster = TrackState {
        peak_speed_m_s: 2.0,
        ..lost_track(0.8, 0b11)
    };
    assert!(!seen_empty(&ahead, faster, 10.5));
}
