//! Parts of one object tracked apart: a track dropped or lost standing that was part of
//! another mover, found by where that one was, drove or carried it ([`part_of_another`],
//! [`driven_over`], [`carried_part`], [`stood_in_its_body`]), or where it stands
//! ([`lost_on_a_standing_object`]).

use mapper::TrackState;
use nalgebra::{Point2, Vector2};

use super::body::cell_m;
use super::rules::MoverPath;
use super::{TrafficConfig, moved_beyond_its_extent};

/// A mover going at this speed or more, m/s (a slow walk; a train of carts at 1.2 m/s whose
/// centre seemed to slow to 0.6 m/s as the airframe hid it), may have taken a part of it, or a
/// mover lost at the body, on with it (`TrafficRules::left_with_others`).
pub(super) const LEFT_WITH_M_S: f64 = 0.5;
/// Where a mover drove through where another was last seen: its centre within this of it,
/// metres (and on beyond it by as much): two objects do not stand in one place (a train's
/// carts, each followed by the next along one path).
pub(super) const DRIVEN_THROUGH_M: f64 = 0.75;
/// Where a mover was is read from its motion for at most this long, seconds, when its kept path
/// does not reach back (a candidate then).
pub(super) const CARRIED_BACK_S: f64 = 3.0;

/// Whether `t`, a track dropped, lay when last seen within the extent of another of `movers`
/// (the movers, and the candidates that were movers lately) where that one was then (on its
/// kept path, else within [`CARRIED_BACK_S`] as its motion says), no smaller than it by more
/// than [`PART_SMALLER`] of its extent and hit in a level it was, seen after it: now, or
/// [`SEEN_AFTER_S`] or more after `t` was last seen where it cannot reach the body (`reaches`
/// says whether it can; two that went out of view together, a tug and its cart into the blind
/// zone under the nose, tell nothing of each other). A part of it tracked apart, or the same
/// object tracked twice - a fuel truck's split-off part that seemed to move the other way, a
/// van's front (variants 27 and 32 of `traffic_jet.toml`, waited for as lost until the pilot was
/// called), a follow-me car's front heading for the jet before the car backed aside (variant
/// 41; variant 92: the car, slow as it backed, a candidate again); a follow-me car making room
/// 40 m ahead, tracked twice, one track dropped as it swung round at 4 m/s the wrong way, the
/// other seen on for a second as the car stood aside and no longer after (variant 287). Two vans
/// in convoy closer than their length would be taken for one.
pub(super) fn part_of_another(
    t: &TrackState,
    movers: &[TrackState],
    paths: &[MoverPath],
    now_s: f64,
    reaches: impl Fn(&TrackState) -> bool,
) -> bool {
    movers.iter().any(|o| {
        let kept = (paths.iter().find(|p| p.id == o.id)).and_then(|p| p.at(t.t_s));
        let Some(then) = kept.or_else(|| read_back(o, t.t_s)) else {
            return false;
        };
        let seen_after = now_s - o.t_s <= 0.25 || (o.t_s - t.t_s >= SEEN_AFTER_S && !reaches(o));
        o.id != t.id
            && seen_after
            && o.levels & t.levels != 0
            && o.extent_m >= (1.0 - PART_SMALLER) * t.extent_m
            && (then - t.position).norm() <= o.extent_m
    })
}

/// What a part tracked apart may seem larger than the object it is part of, as a fraction of
/// its extent: the largest extents two tracks of one object were seen with differ by a cell or
/// two (variant 399 of `traffic_jet.toml`: a follow-me car tracked as 5.2 m and 5.0 m, the
/// first dropped 48 m ahead of the jet in plain view, a pilot called for it). A person (0.9 m)
/// is not part of a cart half their size.
const PART_SMALLER: f64 = 0.1;

/// A dropped track's other track, seen since but not now, was seen this long after it, seconds
/// ([`part_of_another`]).
const SEEN_AFTER_S: f64 = 0.5;

/// Whether `t`, a track dropped, was last seen on another of `movers` (the movers, and the
/// candidates that were movers lately) that stands there now: seen now, slower than
/// [`LEFT_WITH_M_S`], first seen before `t` was last seen, never beyond its extent from where it
/// was first seen ([`moved_beyond_its_extent`]: a static object's hits by the tracker's own
/// measure), no smaller than `t` by more than [`PART_SMALLER`], hit in a level `t` was, `t`'s
/// last position within half its extent of its centre. Two objects do not stand in one place:
/// what slid along it and was lost there was the part of it the sensor saw at the time. The visible side of an A320 parked at a stand the survey never saw slid along
/// its fuselage at 6.5 m/s as the airliner went by, was lost 0.9 m from the centre of the
/// fuselage's own 6.3 m track, which was no mover then (so no kept path says where it was),
/// and held the airliner until a pilot call
/// (`tests/found/ksyr_survey_parked_fuselage_held_as_a_mover_lost_coasting.toml`).
pub(super) fn lost_on_a_standing_object(
    t: &TrackState,
    movers: &[TrackState],
    now_s: f64,
    cfg: &TrafficConfig,
) -> bool {
    movers.iter().any(|o| {
        o.id != t.id
            && now_s - o.t_s <= 0.25
            && o.velocity.norm() < LEFT_WITH_M_S
            && o.born_s <= t.t_s
            && !moved_beyond_its_extent(o, cfg)
            && o.levels & t.levels != 0
            && o.extent_m >= (1.0 - PART_SMALLER) * t.extent_m
            && (o.position - t.position).norm() <= 0.5 * o.extent_m
    })
}

/// Whether `t`, a mover lost standing, was a part of another of `movers` (the movers, and the
/// candidates that were movers lately), no smaller than it and hit in a level it was, that
/// drove over it: on that one's kept path, its centre was within its extent of `t` when `t` was
/// last seen, and within [`CARRIED_BACK_S`] after, going [`LEFT_WITH_M_S`] or more over the
/// second before, it was seen within [`DRIVEN_THROUGH_M`] of where `t` stood. Two objects do
/// not stand in one place, and a person standing against a car going on steps no farther in a
/// few seconds: a follow-me car backing aside at 2 m/s, its corner tracked apart as a person
/// for 4 s and lost standing 2.8 m from the car's centre (beyond what [`carried_part`] takes,
/// half its extent), which drove through that spot 1.2 s later (variant 399 of
/// `traffic_jet.toml`, a pilot called for it 30 s on). Not one the other passes later, which
/// may have walked off unseen before.
pub(super) fn driven_over(t: &TrackState, movers: &[TrackState], paths: &[MoverPath]) -> bool {
    movers.iter().any(|o| {
        let Some(path) = paths.iter().find(|p| p.id == o.id) else {
            return false;
        };
        let going = |s: f64, at: &Point2<f64>| {
            path.at(s - 1.0)
                .is_some_and(|before| (at - before).norm() >= LEFT_WITH_M_S)
        };
        o.id != t.id
            && o.levels & t.levels != 0
            && o.extent_m >= t.extent_m
            && (path.at(t.t_s)).is_some_and(|then| (then - t.position).norm() <= o.extent_m)
            && (path.seen.iter()).any(|&(s, at)| {
                s > t.t_s
                    && s - t.t_s <= CARRIED_BACK_S
                    && (at - t.position).norm() <= DRIVEN_THROUGH_M
                    && going(s, &at)
            })
    })
}

/// Whether `t`, a mover lost standing, was a part of another of `movers` (the movers, and the
/// candidates that were movers lately) that carried it on: one seen now, no smaller than it,
/// hit in a level it was, tracked since before `t` was last seen, whose centre was then within
/// half its extent of `t` and that was going at [`LEFT_WITH_M_S`] or more then - on its kept
/// path (its speed over the second before), or within [`CARRIED_BACK_S`] as its motion says.
/// A fuel truck's corner tracked apart as the truck crosses, a follow-me car's front as the car
/// drives off. Not a person beside a truck standing; not decided once where the other was then
/// is no longer known.
pub(super) fn carried_part(
    t: &TrackState,
    movers: &[TrackState],
    paths: &[MoverPath],
    now_s: f64,
) -> bool {
    movers.iter().any(|o| {
        let path = paths.iter().find(|p| p.id == o.id);
        let kept = path.and_then(|p| Some((p.at(t.t_s)?, p.at(t.t_s - 1.0)?)));
        let then = match kept {
            Some((at, before)) => Some((at, (at - before).norm())),
            None => read_back(o, t.t_s).map(|at| (at, o.velocity.norm())),
        };
        o.id != t.id
            && now_s - o.t_s <= 0.25
            && o.levels & t.levels != 0
            && o.extent_m >= t.extent_m
            && o.born_s <= t.t_s
            && then.is_some_and(|(at, speed)| {
                (at - t.position).norm() <= 0.5 * o.extent_m && speed >= LEFT_WITH_M_S
            })
    })
}

/// Where track `o` was at `t_s` as its motion says, if `t_s` is within [`CARRIED_BACK_S`] of when
/// it was last seen (further back, its constant velocity tells nothing).
pub(super) fn read_back(o: &TrackState, t_s: f64) -> Option<Point2<f64>> {
    ((o.t_s - t_s).abs() <= CARRIED_BACK_S).then(|| o.position + o.velocity * (t_s - o.t_s))
}

/// Whether `t`, a mover lost standing, stood where the body of another of `movers` (the movers,
/// and the candidates that were movers lately) was when `t` was last seen: one no smaller than
/// it, hit in a level it was, seen now, going [`LEFT_WITH_M_S`] or more then (on its kept path,
/// over the second before) towards every point of the vehicle's centreline, `ends` (its
/// rearmost and foremost points: the sensors lie between them, so the box of its hits, the
/// side facing them, is its front and the rest of it lies behind), within [`ALONG_AN_AXIS_RAD`]
/// of an axis of the map's grid (the box is of grid cells: across a slanted way it is wider
/// than the object), with `t` behind that box's front along its way, no farther back than its
/// extent, and across its way within the box's span (a cell more), the box seen within a
/// revolution of then. Two objects do not stand in one place. What shows of a fuel truck coming
/// on is its front; its side, seen as it passes, is tracked apart in pieces that seem to stand
/// where the beams meet it as it slides by, and are lost as its rear passes (variants 439 and
/// 930 of `traffic_jet.toml`: two of them, lost standing 7 and 9 m behind its front, held the
/// jet until it called a pilot, the truck gone). Not one beside the box's span (a person the
/// truck passes), ahead of its front, farther back than the truck's extent reaches, behind one
/// going away from any part of the vehicle (its box may be its rear: a person may walk behind
/// it), or one going slantwise. The extent is the largest the other was seen with: two tracks
/// merged make it larger, and the window longer (docs/known-problems.md).
pub(super) fn stood_in_its_body(
    t: &TrackState,
    movers: &[TrackState],
    paths: &[MoverPath],
    (now_s, ends): (f64, [Point2<f64>; 2]),
) -> bool {
    movers.iter().any(|o| {
        let Some(path) = paths.iter().find(|p| p.id == o.id) else {
            return false;
        };
        let (Some(at), Some(before)) = (path.at(t.t_s), path.at(t.t_s - 1.0)) else {
            return false;
        };
        let Some((s, (lo, hi))) = path.box_by(t.t_s) else {
            return false;
        };
        let way = at - before;
        let speed = way.norm();
        let slant = way
            .x
            .abs()
            .min(way.y.abs())
            .atan2(way.x.abs().max(way.y.abs()));
        if o.id == t.id
            || now_s - o.t_s > 0.25
            || t.t_s - s > 0.25
            || o.levels & t.levels == 0
            || o.extent_m < t.extent_m
            || speed < LEFT_WITH_M_S
            || slant > ALONG_AN_AXIS_RAD
            || ends.iter().any(|e| way.dot(&(e - at)) <= 0.0)
        {
            return false;
        }
        let (along, across) = (way / speed, Vector2::new(-way.y, way.x) / speed);
        let corners = [lo, hi, Vector2::new(lo.x, hi.y), Vector2::new(hi.x, lo.y)];
        let span = |d: &Vector2<f64>| {
            (corners.iter().map(|c| c.dot(d)))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                })
        };
        let (((_, front), (left, right)), cell) = ((span(&along), span(&across)), cell_m(o));
        let p = t.position.coords;
        let (a, c) = (p.dot(&along), p.dot(&across));
        a <= front && a >= front - o.extent_m && c >= left - cell && c <= right + cell
    })
}

/// How far off an axis of the map's grid a mover's way may be for [`stood_in_its_body`],
/// radians (6 degrees: a 9.6 m truck's box, front and side seen, is then up to 1 m wider across
/// its way than the truck; the centre of a truck crossing along an axis wanders 3 degrees).
const ALONG_AN_AXIS_RAD: f64 = 0.105;
