//! Where the nodes of a route go on the paint: where its legs' paint lines meet, abeam on them
//! going straight on, where the paint crosses a runway's centreline; and back where the network
//! has them where a move would fold or skew a leg.

use super::centreline::Paint;
use super::geometry::{Frame, Line};
use super::legs::Leg;
use super::{MAX_OFFSET_M, PARALLEL_DEG, V2, finite};
use crate::model::Airport;
use crate::network::NetworkRoute;

/// How far from where two legs' paint lines meet the paint's curve round the turn is looked
/// for (m): the middle of a 30 m fillet in a 90-degree turn lies 12 m inside its tangents' corner.
const CURVE_SNAP_M: f64 = MAX_OFFSET_M;
/// Two paint lines meeting at a node at less than this are one line going straight on
/// (degrees): their intersection is ill-defined; the node goes abeam onto them instead.
const COLLINEAR_DEG: f64 = 10.0;
/// A node within this of a runway's centreline is on it (m).
const ON_RUNWAY_M: f64 = 1.5;
/// A route turning less than this at a node on a runway crosses the runway (degrees).
const CROSSING_DEG: f64 = 45.0;
/// A leg between moved nodes must keep this share of its length along the network's edge ...
const MIN_ALONG: f64 = 0.5;
/// ... and turn no more than 45 degrees from it (tan 45 degrees).
const MAX_SKEW: f64 = 1.0;

/// Where each point of the route may go, best first and last where the network has it: onto
/// the paint of its legs where they have some near it, never further than [`MAX_OFFSET_M`] from
/// where the network has it.
pub(super) fn place_nodes(
    airport: &Airport,
    route: &NetworkRoute,
    legs: &[Leg],
    paint: &Paint,
    pinned: &[bool],
) -> Vec<Vec<V2>> {
    let p = &route.points;
    let n = p.len();
    (0..n)
        .map(|i| {
            let before = (i > 0).then(|| &legs[i - 1]);
            let after = (i + 1 < n).then(|| &legs[i]);
            let mut places = if pinned[i] {
                Vec::new()
            } else {
                place_node(airport, paint, p[i], before, after)
            };
            for q in &mut places {
                let moved = *q - p[i];
                if moved.norm() > MAX_OFFSET_M {
                    *q = p[i] + moved * (MAX_OFFSET_M / moved.norm());
                }
            }
            places.retain(|q| finite(*q));
            places.push(p[i]);
            places
        })
        .collect()
}

/// Where one point may go, best first (none: where it is). See the module's doc; after the
/// place a turn or a runway crossing gives it, the point abeam it on its legs' paint.
fn place_node(
    airport: &Airport,
    paint: &Paint,
    p: V2,
    before: Option<&Leg>,
    after: Option<&Leg>,
) -> Vec<V2> {
    let sideways = |frame: Option<Frame>, line: Option<Line>| {
        let normal = Line {
            at: p,
            dir: frame?.n,
        };
        normal.meet(&line?)
    };
    let (a, b) = match (before, after) {
        (None, Some(leg)) => return sideways(leg.frame, leg.first_direct).into_iter().collect(),
        (Some(leg), None) => return sideways(leg.frame, leg.last_direct).into_iter().collect(),
        (Some(x), Some(y)) => (x, y),
        (None, None) => return Vec::new(),
    };
    let (Some(fa), Some(fb)) = (a.frame, b.frame) else {
        return Vec::new();
    };
    let (paint_a, paint_b) = (a.last, b.first);
    if paint_a.is_none() && paint_b.is_none() {
        return Vec::new();
    }
    if let Some(places) = short_of_bare(p, (a, fa), (b, fb)) {
        return places;
    }
    let feet: Vec<V2> = [paint_a, paint_b]
        .iter()
        .flatten()
        .map(|l| l.foot(p))
        .collect();
    let abeam = feet.iter().sum::<V2>() / feet.len() as f64;
    let (la, lb) = (paint_a.unwrap_or(fa.line()), paint_b.unwrap_or(fb.line()));
    let mut places = Vec::new();
    let crossing = fa.u.dot(&fb.u) > CROSSING_DEG.to_radians().cos();
    if crossing && !a.runway && !b.runway {
        places.extend(runway_crossing(
            airport,
            paint,
            p,
            [(a.last, fa.u), (b.first, fb.u)],
        ));
    }
    if la.sin_to(&lb) >= COLLINEAR_DEG.to_radians().sin()
        && let Some(meet) = la.meet(&lb)
    {
        let on = (a.followed && b.followed).then(|| on_curve(paint, meet, fa.u, fb.u));
        places.push(on.flatten().unwrap_or(meet));
    }
    places.push(abeam);
    places
}

/// Where a node goes whose one leg's paint stops short of it while the other leg has none
/// there (`None`: not such a node): where the paint's line, extended, meets the bare leg's
/// network line, so that leg keeps it; where the network has it if that point is further than
/// [`MAX_OFFSET_M`] or the lines are near parallel ([`COLLINEAR_DEG`]).
fn short_of_bare(p: V2, (a, fa): (&Leg, Frame), (b, fb): (&Leg, Frame)) -> Option<Vec<V2>> {
    let (line, bare) = match (a.last, b.first) {
        (Some(line), _) if a.last_stops && b.bare_at(false) => (line, fb.line()),
        (_, Some(line)) if b.first_stops && a.bare_at(true) => (line, fa.line()),
        _ => return None,
    };
    let meet = (line.sin_to(&bare) >= COLLINEAR_DEG.to_radians().sin())
        .then(|| line.meet(&bare))
        .flatten()
        .filter(|q| (q - p).norm() <= MAX_OFFSET_M);
    Some(meet.into_iter().collect())
}

/// Whether a paint segment from `a` to `b` heads between directions `u` and `v` (either way
/// along it, with [`PARALLEL_DEG`] to spare): the way a route turning from `u` to `v` goes.
fn heading_between(a: V2, b: V2, u: V2, v: V2) -> bool {
    let Some(bisector) = (u + v).try_normalize(1e-9) else {
        return false;
    };
    let half = 0.5 * u.dot(&v).clamp(-1.0, 1.0).acos() + PARALLEL_DEG.to_radians();
    let within = half.min(std::f64::consts::FRAC_PI_2).cos();
    (b - a).normalize().dot(&bisector).abs() >= within
}

/// The point of the paint nearest `meet` (where two legs' paint lines meet, within
/// [`CURVE_SNAP_M`], inside the turn) on a segment heading between the legs' directions `u` and
/// `v`: where the paint rounds a turn with a curve, the curve's point nearest the corner its
/// lines make.
fn on_curve(paint: &Paint, meet: V2, u: V2, v: V2) -> Option<V2> {
    (0..paint.segments.len())
        .map(|s| paint.ends(s))
        .filter(|&(a, b)| heading_between(a, b, u, v))
        .map(|(a, b)| {
            let t = ((meet - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
            a + (b - a) * t
        })
        .filter(|q| (q - meet).norm() <= CURVE_SNAP_M)
        // Inside the turn, not a fillet round the outside of a crossing.
        .filter(|q| (q - meet).dot(&(v - u)) > 0.0)
        .min_by(|x, y| (x - meet).norm().total_cmp(&(y - meet).norm()))
}

/// Where the paint crosses the centreline of a runway that `p` lies on, the route going from
/// direction `u` to `v` with paint lines `lines` either side: of the paint segments heading the
/// route's way across the centreline within [`MAX_OFFSET_M`] of `p`, the crossing nearest where
/// the lines cross it (or `p`, with no lines crossing it).
fn runway_crossing(
    airport: &Airport,
    paint: &Paint,
    p: V2,
    [(line_in, u), (line_out, v)]: [(Option<Line>, V2); 2],
) -> Option<V2> {
    let runway = airport.runways.iter().find_map(|r| {
        let (a, b) = (r.ends[0].at, r.ends[1].at);
        let centreline = Line::through(a, b)?;
        let t = (p - a).dot(&(b - a)) / (b - a).norm_squared();
        let on = (0.0..=1.0).contains(&t) && (centreline.foot(p) - p).norm() <= ON_RUNWAY_M;
        on.then_some(centreline)
    })?;
    let crossings: Vec<V2> = [line_in, line_out]
        .iter()
        .flatten()
        .filter(|l| l.sin_to(&runway) >= COLLINEAR_DEG.to_radians().sin())
        .filter_map(|l| l.meet(&runway))
        .filter(|q| (q - p).norm() <= MAX_OFFSET_M)
        .collect();
    let guess = if crossings.is_empty() {
        p
    } else {
        crossings.iter().sum::<V2>() / crossings.len() as f64
    };
    let side = |x: V2| (x - runway.at).perp(&runway.dir);
    (0..paint.segments.len())
        .map(|s| paint.ends(s))
        .filter(|&(a, b)| side(a) * side(b) <= 0.0 && side(a) != side(b))
        .filter(|&(a, b)| heading_between(a, b, u, v))
        .map(|(a, b)| a + (b - a) * (side(a) / (side(a) - side(b))))
        .filter(|q| (q - p).norm() <= MAX_OFFSET_M)
        .min_by(|x, y| (x - guess).norm().total_cmp(&(y - guess).norm()))
        .or((!crossings.is_empty()).then_some(guess))
}

/// The points' places: each its best place, the next best taken (down to where the network has
/// it) while a leg between moved points would fold back (keep less than [`MIN_ALONG`] of its
/// length along the edge) or turn more than 45 degrees from it.
pub(super) fn settle(legs: &[Leg], places: &[Vec<V2>]) -> Vec<V2> {
    let mut choice = vec![0; places.len()];
    loop {
        let at = |k: usize, choice: &[usize]| places[k][choice[k]];
        let mut changed = false;
        for (i, leg) in legs.iter().enumerate() {
            let Some(frame) = leg.frame else { continue };
            let (a, b) = (frame.sd(at(i, &choice)), frame.sd(at(i + 1, &choice)));
            let along = b.x - a.x;
            let bad = along < MIN_ALONG * frame.length || (b.y - a.y).abs() > MAX_SKEW * along;
            for k in [i, i + 1] {
                if bad && choice[k] + 1 < places[k].len() {
                    choice[k] += 1;
                    changed = true;
                }
            }
        }
        if !changed {
            return (0..places.len()).map(|k| at(k, &choice)).collect();
        }
    }
}
