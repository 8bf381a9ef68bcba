//! The tracker's unit tests: clearing what movers leave, never what static or hidden objects
//! hold, and what is offered for prediction.

use nalgebra::{Isometry2, Point2, Vector2};

use super::*;

/// The cells of a `w` x `h` cell box with its lower-left cell at `(x, y)`.
fn block(x: i64, y: i64, w: i64, h: i64) -> Vec<WorldCell> {
    let mut v = Vec::new();
    for j in y..y + h {
        for i in x..x + w {
            v.push((i, j));
        }
    }
    v
}

/// A 4.4 m object driving at 4 m/s: once it has travelled 1.5 times its extent its old cells
/// are handed back, and never those within its extent plus the margin of where it is now.
#[test]
fn a_moving_object_clears_the_cells_it_left() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let mut cleared = Vec::new();
    for k in 0..80 {
        let y = k * 2; // 0.4 m a revolution at 0.2 m cells: 4 m/s at 10 Hz
        let now = block(0, y, 9, 22);
        cleared.extend(t.update(k as f64 * 0.1, &now));
        for c in &cleared {
            // The centre is at row y + 11, the extent 4.75 m: 5.75 m (28.75 cells) clear.
            assert!(
                c.1 < y + 11 - 28,
                "cleared {c:?} next to the object at row {y}"
            );
        }
    }
    assert!(!cleared.is_empty());
    assert!(cleared.contains(&(4, 0)), "its first cells are cleared");
    assert_eq!(t.moving_objects().len(), 1);
}

/// A static object seen from changing sides (its hits jump about within it, as a vehicle
/// driving by sees first its front, then its side, then its back) never moves.
#[test]
fn a_static_object_seen_from_every_side_never_moves() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    // An 8 x 6 m object.
    let faces = [
        block(0, 0, 40, 1),
        block(39, 0, 1, 30),
        block(0, 29, 40, 1),
        block(0, 0, 1, 30),
    ];
    for k in 0..200 {
        let face = &faces[(k / 10) % 4];
        assert!(t.update(k as f64 * 0.1, face).is_empty(), "revolution {k}");
    }
    assert!(t.moving_objects().is_empty());
}

/// A static object hidden little by little (its visible part shrinks towards one end) and
/// then lost keeps every cell, and so does an object that moved but is no longer seen.
#[test]
fn what_is_hidden_is_never_cleared() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    for k in 0..8 {
        assert!(t.update(k as f64 * 0.1, &block(k, 0, 8 - k, 5)).is_empty());
    }
    for k in 8..100 {
        assert!(t.update(k as f64 * 0.1, &[]).is_empty());
    }
    assert_eq!(t.last_hit_s((0, 0)), Some(0.0));
}

/// A moving object passing next to a static one: the static one's cells, hit again every
/// revolution, are never cleared.
#[test]
fn a_mover_passing_a_static_object_leaves_it_alone() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let post = block(10, 40, 2, 2); // 0.2 m from the mover's side: one cluster with it
    for k in 0..60 {
        let mut hits = block(0, k * 2, 9, 22);
        hits.extend(&post);
        hits.sort_unstable();
        hits.dedup();
        let cleared = t.update(k as f64 * 0.1, &hits);
        assert!(cleared.iter().all(|c| !post.contains(c)), "{cleared:?}");
    }
}

/// Walls and buildings (larger than `max_object_m`) never move, however their visible
/// stretch slides.
#[test]
fn a_long_wall_sliding_into_view_never_moves() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    for k in 0..100 {
        let wall = block(k * 2, 0, 100, 2); // 20 m of wall, sliding with the vehicle
        assert!(t.update(k as f64 * 0.1, &wall).is_empty());
    }
}

/// A moving track (stray hits sliding along ahead of a vehicle) that loses its cluster and
/// picks up a static box nearby, then jumps back to its stray hits once the box is hidden,
/// clears nothing of the box: what it took over in a jump is never its to clear.
#[test]
fn a_moving_track_that_jumps_to_a_static_object_never_clears_it() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    // 1.6 m to the side of the stray hits' line, where they are at the 40th revolution.
    let boxed = block(200, 8, 2, 2);
    let mut k = 0;
    // Stray hits sliding at 5 m/s along y = 0 (2 x 2 cells); the box seen all along.
    while k < 40 {
        let mut hits = block(k * 5, 0, 2, 2);
        hits.extend(&boxed);
        t.update(k as f64 * 0.1, &hits);
        k += 1;
    }
    assert_eq!(t.moving_objects().len(), 1);
    // The stray hits vanish for a revolution; only the box is seen.
    t.update(k as f64 * 0.1, &boxed);
    k += 1;
    // The box is hidden; the stray hits come back further on.
    for _ in 0..30 {
        let cleared = t.update(k as f64 * 0.1, &block(k * 5, 0, 2, 2));
        assert!(cleared.iter().all(|c| !boxed.contains(c)), "{cleared:?}");
        k += 1;
    }
}

/// A van's open top is the lowest of its revolutions' (each the highest of its cells'):
/// one cell whose beam above passed over at 1.55 m and one at 1.2 m make 1.55 m; a later
/// revolution bounding it at 1.3 m lowers it; one whose beams above were stopped nearer
/// (infinity), or that says nothing, leaves it; fed no open tops, a track has none.
#[test]
fn a_tracks_open_top_is_the_lowest_of_its_revolutions() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let mut plain = Tracker::new(TrackerConfig::default(), 0.2);
    let mut tops_seen = Vec::new();
    for k in 0..30 {
        let x = (k as f64 * 0.3 / 0.2).round() as i64;
        let cells = block(x, 0, 23, 9);
        let van: Vec<(WorldCell, u32)> = cells.iter().map(|&c| (c, 1)).collect();
        let tops: Vec<(WorldCell, f32)> = match k {
            0..14 => vec![(cells[0], 1.2), (cells[5], 1.55)],
            14..22 => vec![(cells[3], 1.3)],
            22..26 => vec![(cells[3], f32::INFINITY)],
            _ => Vec::new(),
        };
        t.update_except(k as f64 * 0.1, None, &van, &tops, |_| false);
        plain.update_with_levels(k as f64 * 0.1, &van);
        if let Some(m) = t.movers().first() {
            tops_seen.push((k, m.open_top_m));
        }
        if let Some(m) = plain.movers().first() {
            assert_eq!(m.open_top_m, None);
        }
    }
    // Predicted from about a second on.
    assert!(tops_seen.iter().any(|&(k, _)| k < 14), "{tops_seen:?}");
    assert!(tops_seen.iter().any(|&(k, _)| k >= 26), "{tops_seen:?}");
    for (k, top) in tops_seen {
        let want = if k < 14 { 1.55 } else { 1.3 };
        assert_eq!(top, Some(f64::from(want as f32)), "revolution {k}");
    }
}

/// A van (4.6 x 1.8 m) crossing at 3 m/s is offered for prediction about a second after it
/// comes into view, its velocity within 0.3 m/s, and where it will be 2 s later within 0.5 m
/// of the truth, inside twice the standard deviation the track states.
#[test]
fn a_crossing_van_is_predicted_a_few_revolutions_after_it_appears() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let mut first = None;
    for k in 0..40 {
        let x = (k as f64 * 0.3 / 0.2).round() as i64; // 3 m/s at 10 Hz
        let van: Vec<(WorldCell, u32)> = block(x, 0, 23, 9).into_iter().map(|c| (c, 3)).collect();
        t.update_with_levels(k as f64 * 0.1, &van);
        let movers = t.movers();
        if let Some(m) = movers.first() {
            first.get_or_insert(k);
            assert_eq!(m.levels, 3, "both levels it was hit in");
            if k >= 15 {
                assert!(
                    (m.velocity - Vector2::new(3.0, 0.0)).norm() < 0.3,
                    "{k}: {m:?}"
                );
                let (at, sigma) = m.predict(2.0);
                let truth_x = (x as f64 + 11.5) * 0.2 + 6.0;
                let miss = (at - Point2::new(truth_x, 0.9)).norm();
                assert!(
                    miss < 0.5 && miss < 2.0 * sigma + 0.2,
                    "{k}: {miss} {sigma}"
                );
            }
        }
    }
    let first = first.expect("offered for prediction");
    assert!(first <= 12, "first offered at revolution {first}");
}

/// A 9.2 m truck driving along its length at 1.3 m/s is offered for prediction only after
/// it has travelled 0.6 times its extent (4.4 s), but is a candidate mover - worth slowing
/// for - from about a second, with the velocity it has; a candidate never once a mover.
#[test]
fn a_long_slow_truck_is_a_candidate_mover_seconds_before_it_is_predicted() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let (mut candidate, mut mover) = (None, None);
    for k in 0..80 {
        let y = -((k as f64 * 0.13 / 0.2).round() as i64); // 1.3 m/s towards -y at 10 Hz
        t.update(k as f64 * 0.1, &block(0, y, 13, 46));
        let (c, m) = (t.candidate_movers(), t.movers());
        assert!(c.is_empty() || m.is_empty(), "{k}: both {c:?} {m:?}");
        if let Some(c) = c.first() {
            candidate.get_or_insert(k);
            assert!(!c.confirmed);
            if k >= 15 {
                assert!(
                    (c.velocity - Vector2::new(0.0, -1.3)).norm() < 0.3,
                    "{k}: {c:?}"
                );
            }
        }
        if !m.is_empty() {
            mover.get_or_insert(k);
        }
    }
    let (candidate, mover) = (candidate.unwrap(), mover.unwrap());
    assert!(candidate <= 12, "a candidate at revolution {candidate}");
    assert!((42..=50).contains(&mover), "a mover at revolution {mover}");
}

/// A person standing (0.6 m) is a standing object from the fifth revolution on, and stops
/// being one once it walks (a candidate, then a mover); a 3 m cart standing never is one
/// at a 2 m bound.
#[test]
fn a_person_standing_is_a_standing_object_until_they_walk() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let person = |k: i64| block(k, 0, 3, 3);
    let cart = block(40, 40, 15, 5);
    let mut first = None;
    for k in 0..30 {
        let hits: Vec<WorldCell> = person(0).into_iter().chain(cart.clone()).collect();
        t.update(k as f64 * 0.1, &hits);
        let standing = t.standing_objects(2.0);
        assert!(
            standing.iter().all(|s| s.extent_m <= 2.0),
            "{k}: {standing:?}"
        );
        if !standing.is_empty() {
            first.get_or_insert(k);
        }
        assert_eq!(standing.len(), usize::from(k >= 4), "{k}: {standing:?}");
    }
    assert_eq!(first, Some(4));
    // It walks on at 2 m/s along x: standing no more once seen a metre from where it stood.
    let mut left = None;
    for k in 1..30 {
        let hits: Vec<WorldCell> = person(k).into_iter().chain(cart.clone()).collect();
        t.update(3.0 + k as f64 * 0.1, &hits);
        if t.standing_objects(2.0).is_empty() {
            left.get_or_insert(k);
        } else {
            assert!(left.is_none(), "{k}: standing again");
        }
    }
    assert_eq!(left, Some(5), "standing until {left:?}");
    assert_eq!(t.standing_objects(4.0).len(), 1, "the cart at a 4 m bound");
}

/// A van seen at 4 m/s that seems to slow to 1 m/s (its visible part shrinking as it goes into
/// the shadow of a wing) keeps its peak speed for about [`PEAK_SPEED_S`]; then the peak gives
/// way to the speed measured since.
#[test]
fn a_movers_peak_speed_is_kept_for_a_few_seconds() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let mut y: f64 = 0.0;
    let speed_at = |k: u32| if k < 40 { 4.0 } else { 1.0 };
    let mut peaks = Vec::new();
    for k in 0..120 {
        y += speed_at(k) * 0.1;
        t.update(k as f64 * 0.1, &block(0, (y / 0.2).round() as i64, 9, 22));
        if let Some(m) = t.movers().first() {
            peaks.push((k, m.peak_speed_m_s, m.velocity.norm()));
        }
    }
    let at = |k: u32| peaks.iter().find(|p| p.0 == k).copied().unwrap();
    // Slowed a second ago: its velocity is below 2 m/s, its peak still about 4.
    assert!(
        at(50).2 < 2.0 && (at(50).1 - 4.0).abs() < 0.4,
        "{:?}",
        at(50)
    );
    // Long slowed: the peak is the speed now.
    assert!((at(119).1 - 1.0).abs() < 0.3, "{:?}", at(119));
    assert!(peaks.iter().all(|p| p.1 >= p.2 - 1e-12));
}

/// A mover's peak speed is one it had going the way it goes now: a van seen at 4 m/s whose
/// centre then comes back at 1 m/s (a train's cars bunching up as it stops) is read at about
/// 1 m/s, not 4.
#[test]
fn a_movers_peak_speed_is_one_it_had_going_its_way() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let mut y: f64 = 0.0;
    let mut last = None;
    for k in 0..70 {
        y += if k < 40 { 0.4 } else { -0.1 };
        t.update(k as f64 * 0.1, &block(0, (y / 0.2).round() as i64, 9, 22));
        last = t.movers().first().map(|m| (m.peak_speed_m_s, m.velocity));
    }
    let (peak, velocity) = last.expect("still a mover");
    assert!(velocity.y < -0.5, "{velocity:?}");
    assert!(
        peak < 1.5 && peak >= velocity.norm(),
        "{peak} at {velocity:?}"
    );
}

/// A parked car revealed from one end (its visible part grows over 3 s, as a vehicle
/// driving by sees more of it), and one seen from every side, are never offered as movers.
#[test]
fn static_objects_revealed_or_seen_from_every_side_are_not_movers() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    for k in 0..30 {
        let length = 1 + (k * 22) / 29; // 0.2 m to 4.6 m
        t.update(k as f64 * 0.1, &block(0, 0, length, 9));
        assert!(t.movers().is_empty(), "revolution {k}: {:?}", t.movers());
    }
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let faces = [
        block(0, 0, 40, 1),
        block(39, 0, 1, 30),
        block(0, 29, 40, 1),
        block(0, 0, 1, 30),
    ];
    for k in 0..200 {
        t.update(k as f64 * 0.1, &faces[(k / 10) % 4]);
        assert!(t.movers().is_empty(), "revolution {k}");
    }
}

/// A person walking at 1.4 m/s, confirmed moving, goes out of view for a second (the blind
/// zone under a nose) and comes back where their motion said: the cells painted before the
/// gap are cleared; one who comes back elsewhere (they stopped, this is someone else) clears
/// nothing.
#[test]
fn a_mover_seen_again_where_its_motion_said_takes_its_cells() {
    let run = |resume_offset_cells: i64| {
        let mut t = Tracker::new(TrackerConfig::default(), 0.2);
        let mut cleared = Vec::new();
        let person = |k: i64| block((k * 14) / 20, 0, 3, 3); // 1.4 m/s: 0.7 cells a revolution
        for k in 0..30 {
            cleared.extend(t.update(k as f64 * 0.1, &person(k)));
        }
        assert!(!t.moving_objects().is_empty());
        let before = cleared.len();
        for k in 30..40 {
            t.update(k as f64 * 0.1, &[]); // out of view for a second
        }
        for k in 40..45 {
            let mut seen = person(k);
            for c in &mut seen {
                c.0 += resume_offset_cells;
            }
            cleared.extend(t.update(k as f64 * 0.1, &seen));
        }
        (before, cleared)
    };
    let (before, cleared) = run(0);
    // The cells it painted just before it went out of view (around x = 2.9 m) are cleared.
    assert!(cleared.len() > before, "{before} {}", cleared.len());
    assert!(cleared.iter().any(|c| c.0 >= 14), "{cleared:?}");
    let (before, cleared) = run(25); // 5 m further than its motion says
    assert_eq!(cleared.len(), before, "nothing more cleared: {cleared:?}");
}

/// A mover that goes out of view is still offered for prediction, from where it was last
/// seen, for `coast_s` - then no longer.
#[test]
fn a_hidden_mover_is_still_predicted_for_a_while() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    for k in 0..30 {
        t.update(k as f64 * 0.1, &block((k * 14) / 20, 0, 3, 3));
    }
    let seen = t.movers();
    assert_eq!(seen.len(), 1);
    for k in 30..90 {
        t.update(k as f64 * 0.1, &[]);
        let now = t.movers();
        if k as f64 * 0.1 - 2.9 <= 6.0 {
            assert_eq!(now.len(), 1, "{k}");
            assert_eq!(now[0].t_s, seen[0].t_s, "from where it was last seen");
        } else {
            assert!(now.is_empty(), "{k}");
        }
    }
}

/// A person (3 x 3 cells, 1.4 m/s) walks out of view; 1.5 s later a single return 20 m
/// away - within the gate of the lost track, beyond its extent - is another object: a new
/// track under a new id, not offered as a mover. Seen again where its motion said, the
/// person keeps their id.
#[test]
fn a_lost_track_taking_over_hits_beyond_its_extent_is_a_new_track() {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let walker = |k: i64| block((k * 7) / 10, 0, 3, 3);
    for k in 0..30 {
        t.update(k as f64 * 0.1, &walker(k));
    }
    let person = t.movers();
    assert_eq!(person.len(), 1);
    let id = person[0].id;
    for k in 30..45 {
        t.update(k as f64 * 0.1, &[]);
    }
    t.update(4.5, &block(120, 0, 1, 1));
    let now = t.movers();
    assert!(now.iter().all(|m| m.id != id), "{now:?}");
    assert!(now.iter().all(|m| m.position.x < 20.0), "{now:?}");
    // The same walk, seen again after the gap where its motion said: the same track.
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    for k in 0..30 {
        t.update(k as f64 * 0.1, &walker(k));
    }
    for k in 30..35 {
        t.update(k as f64 * 0.1, &[]);
    }
    t.update(3.5, &walker(35));
    assert_eq!(t.movers().first().map(|m| m.id), Some(id));
}

#[test]
fn a_disabled_tracker_clears_nothing_but_still_records_hits() {
    let cfg = TrackerConfig {
        enabled: false,
        ..TrackerConfig::default()
    };
    let mut t = Tracker::new(cfg, 0.2);
    for k in 0..80 {
        assert!(t.update(k as f64 * 0.1, &block(0, k * 2, 9, 22)).is_empty());
    }
    assert_eq!(t.last_hit_s((0, 0)), Some(0.0));
}

/// The first revolution (from 0) at which `t` offers a mover, of `n` revolutions of a single
/// cell sliding along row 0 at 4 m/s (two cells a revolution) from column 0, from `t0_s`.
fn first_mover_of_a_sliding_cell(t: &mut Tracker, t0_s: f64, n: i64) -> Option<i64> {
    (0..n).find(|&k| {
        t.update(t0_s + k as f64 * 0.1, &[(2 * k, 0)]);
        !t.movers().is_empty()
    })
}

/// A single cell sliding along the side of a static object the offline map does not hold (a
/// parked aircraft's fuselage at grazing incidence) is its visible part, not a mover, when
/// that side was seen before, though the cell's own extent is tiny; the same slide over
/// ground nothing was ever seen on is a mover, and what the wall's cells hold is kept.
#[test]
fn a_cell_sliding_along_a_side_seen_before_is_no_mover() {
    let mut open = Tracker::new(TrackerConfig::default(), 0.2);
    let k = first_mover_of_a_sliding_cell(&mut open, 4.0, 20).expect("over open ground");
    assert!(k <= 8, "a mover at revolution {k}");

    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let wall = block(0, 0, 40, 1); // 8 m, one cell deep, along the slide
    for k in 0..10 {
        t.update(k as f64 * 0.1, &wall);
    }
    // Out of view for 3 s (its track dropped), then only a cell of it shows, sliding.
    for k in 10..40 {
        assert!(t.update(k as f64 * 0.1, &[]).is_empty());
    }
    let mut cleared = Vec::new();
    for k in 0..20 {
        cleared.extend(t.update(4.0 + k as f64 * 0.1, &[(2 * k, 0)]));
        assert!(t.movers().is_empty(), "revolution {k}: {:?}", t.movers());
        assert!(t.candidate_movers().is_empty(), "revolution {k}");
    }
    assert!(cleared.is_empty(), "cleared {cleared:?}");
}

/// A cart following its tug's path 3 s behind, over cells the tug hit, is a mover within a
/// few revolutions of when it would be on open ground: what a track offered for prediction hit
/// is no static object's side. The tug is never confirmed (so it clears nothing and its cells
/// keep their records): only its first 1.4 m, hit before it was predicted, count as known.
#[test]
fn a_cart_on_its_tugs_path_is_a_mover() {
    let config = TrackerConfig {
        extent_factor: 100.0,
        ..TrackerConfig::default()
    };
    let first_cart_mover = |tug: bool| {
        let mut t = Tracker::new(config.clone(), 0.2);
        (0..80).find_map(|k| {
            let x = k; // 2 m/s at 10 Hz
            let mut hits = if tug { block(x, 0, 10, 6) } else { Vec::new() }; // the tug, 2 m
            if k >= 30 {
                hits.extend(block(x - 30, 0, 10, 6)); // the cart, 3 s behind on its cells
            }
            t.update(k as f64 * 0.1, &hits);
            let cart = (t.movers().into_iter()).find(|m| m.position.x < (x as f64 - 10.0) * 0.2);
            (k >= 30 && cart.is_some()).then_some(k - 30)
        })
    };
    let alone = first_cart_mover(false).expect("the cart alone is a mover");
    let k = first_cart_mover(true).expect("the cart is a mover");
    assert!(
        k <= alone + 4,
        "a mover {k} revolutions after it appears, alone {alone}"
    );
}

/// The revolution (from 0) at which `t` first offers a candidate mover or a mover, of `n`
/// revolutions of an 8 m truck driving at 2 m/s along x from column `x0`, from `t0_s`.
fn first_travelling_truck(t: &mut Tracker, t0_s: f64, x0: i64, n: i64) -> Option<i64> {
    (0..n).find(|&j| {
        t.update(t0_s + j as f64 * 0.1, &block(x0 + j, 0, 40, 10));
        !(t.candidate_movers().is_empty() && t.movers().is_empty())
    })
}

/// A truck that drove, stood out of view for longer than its track is kept, and drives on
/// from the cells it stood on is a candidate mover as soon as on open ground: its body, hit
/// while it was seen travelling, is no static object's side.
#[test]
fn a_truck_seen_again_on_its_own_cells_travels_at_once() {
    let mut open = Tracker::new(TrackerConfig::default(), 0.2);
    let fresh = first_travelling_truck(&mut open, 10.0, 30, 40).expect("on open ground");

    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    for k in 0..30 {
        t.update(k as f64 * 0.1, &block(k, 0, 40, 10));
    }
    assert!(!t.movers().is_empty(), "predicted as it drives");
    for k in 30..100 {
        t.update(k as f64 * 0.1, &[]);
    }
    let again = first_travelling_truck(&mut t, 10.0, 30, 40).expect("seen again");
    assert_eq!(again, fresh, "fresh {fresh}");
}

/// Where a single cell slid by `cell_at` (revolution k: its world cell) is first offered as a
/// mover, and whether it was a candidate before, seen from a vehicle at `vehicle_at` (k: its
/// pose), hit in `levels`, with beams passing over it at `open_top_m` (infinity: none seen).
fn first_mover(
    cell_at: impl Fn(i64) -> WorldCell,
    vehicle_at: impl Fn(i64) -> Isometry2<f64>,
    levels: u32,
    open_top_m: f32,
) -> (Option<i64>, bool) {
    let mut t = Tracker::new(TrackerConfig::default(), 0.2);
    let mut candidate = false;
    let mover = (0..40).find(|&k| {
        let cell = cell_at(k);
        let seen_from = SeenFrom {
            vehicle: vehicle_at(k),
            low_below_m: 1.1,
        };
        let tops = [(cell, open_top_m)];
        t.update_except(
            4.0 + k as f64 * 0.1,
            Some(seen_from),
            &[(cell, levels)],
            &tops,
            |_| false,
        );
        candidate |= !t.candidate_movers().is_empty();
        !t.movers().is_empty()
    });
    (mover, candidate)
}

/// A single cell sliding along row 0 at 4 m/s, as a beam coming down to a low wall beside the
/// path shows it while the vehicle drives along at the same speed
/// (`tests/found/low_wall_under_the_wing.toml`): the tracker finds it does not move as seen
/// from the vehicle and offers no mover - only a candidate, its travel over the ground being
/// real (caution, not a stop). Seen from a vehicle standing, the same slide is a mover as over
/// open ground (above); so is the same slide hit in level 1 too (an object that tall is seen
/// whole: a van keeping pace is a mover), and one no beam was seen to pass over (a van under
/// the wing, whose upper part the wing hides, is hit in level 0 alone too).
#[test]
fn a_low_cell_sliding_along_with_the_vehicle_is_no_mover() {
    let slide = |k: i64| (2 * k, 0);
    let driving = |k: i64| Isometry2::translation(0.4 * k as f64 - 30.0, -3.0);
    let standing = |_: i64| Isometry2::translation(-30.0, -3.0);
    let (pacing, cautious) = first_mover(slide, driving, 1, 0.5);
    assert_eq!(
        (pacing, cautious),
        (None, true),
        "sliding along with the vehicle"
    );
    let (seen_standing, _) = first_mover(slide, standing, 1, 0.5);
    assert!(
        seen_standing.is_some_and(|k| k <= 8),
        "seen from a vehicle standing: {seen_standing:?}"
    );
    assert_eq!(
        first_mover(slide, driving, 3, 0.5).0,
        seen_standing,
        "hit in level 1 too"
    );
    assert_eq!(
        first_mover(slide, driving, 1, f32::INFINITY).0,
        seen_standing,
        "no beam over it"
    );
    assert_eq!(
        first_mover(slide, driving, 1, 1.3).0,
        seen_standing,
        "beams over it, 1.3 m up"
    );
}

/// A low cell keeping pace with the vehicle that then drifts toward its path at 1 m/s (a
/// quarter of its speed along) becomes a mover within 2 s, a candidate meanwhile; so does one
/// held in place in the frame of a vehicle turning on a 40 m circle, not at all.
#[test]
fn a_low_cell_keeping_pace_then_drifting_in_becomes_a_mover() {
    let driving = |k: i64| Isometry2::translation(0.4 * k as f64 - 30.0, -3.0);
    let drifting = |k: i64| (2 * k, -(k - 10).max(0) / 2);
    let (mover, cautious) = first_mover(drifting, driving, 1, 0.5);
    assert!(
        cautious && mover.is_some_and(|k| k <= 30),
        "drifting in: {mover:?}"
    );
    // Turning: the vehicle on a circle of 40 m at 4 m/s, the cell 5 m to its right.
    let turning = |k: i64| {
        let a = 0.01 * k as f64;
        Isometry2::new(Vector2::new(40.0 * a.sin(), 40.0 - 40.0 * a.cos()), a)
    };
    let riding = |k: i64| {
        let p = turning(k) * Point2::new(8.0, -5.0);
        ((p.x / 0.2).floor() as i64, (p.y / 0.2).floor() as i64)
    };
    assert_eq!(
        first_mover(riding, turning, 1, 0.5).0,
        None,
        "held in the turning vehicle's frame"
    );
    assert!(
        first_mover(riding, |_| turning(0), 1, 0.5).0.is_some(),
        "the same, seen standing"
    );
}
