//! Routes along the painted taxiway centreline where the file's taxi network strays from it.
//!
//! An apt.dat's taxi routing network (`1201`/`1202`) is drawn for X-Plane's AI traffic, and is
//! often metres off the yellow centreline painted on the pavement: at KSYR taxiway W runs 9-14 m
//! off it near the runway 10/28 crossing, close enough to the pavement's edge for a jet's main
//! gear to meet the edge lights. Pilots, and autonomy, follow the paint. [`follow`] takes a route
//! found on the network (the graph search stays the network's) and moves its geometry onto the
//! paint where a painted taxiway centreline ([`line_type::is_taxiway_centreline`]) runs along
//! one of its taxiway legs:
//!
//! - **Along a leg** (`legs`): the centreline segments within [`MAX_OFFSET_M`] of the leg and
//!   within [`PARALLEL_DEG`] of its direction. Where several overlap, of those whose line goes
//!   on furthest with the route (followed along the paint, across the ends of runs that meet,
//!   up to 150 m ahead), the one continuing the line followed so far - at the route's start and
//!   after a turn, the one nearest the network. So a line is followed past the curves that
//!   leave it, and at a fork the branch the route takes. Paint within [`ON_NETWORK_M`] of the leg
//!   is the leg; paint along it for less than [`MIN_LINE_M`] is a curve passing by. A painted
//!   curve that passes through the node at a leg's end (a network drawn as chords of the curve)
//!   is followed into the node, and on into the next leg.
//! - **At a node** (`nodes`): where the two legs' paint lines meet - going straight on, the
//!   point on the paint abeam the node; turning, where the lines cross, or the point of the
//!   paint's curve round the turn nearest that. A node on a runway's centreline that the route
//!   crosses goes where the paint crosses that centreline. Where one leg's paint stops short
//!   of the node (and goes on nowhere) and the other leg has none there, the node goes where the
//!   paint's line, extended, meets the unpainted leg's network line, so that leg keeps it - or
//!   stays where the network has it if that point is more than [`MAX_OFFSET_M`] away or the
//!   lines are near parallel (the painted leg then tapers back). The route's two ends move only
//!   sideways, onto the paint abeam them; a route bound for a runway keeps its hold point where
//!   the network has it (moved sideways it could come nearer the runway).
//! - **Where the paint ends**, or a leg has none near it (`profile`): back to the network's
//!   line at [`TAPER_DEG`] (straight across a gap too short for that).
//!
//! Runway legs and a stand's lead-in keep the network's line. No point moves more than
//! [`MAX_OFFSET_M`] from the network leg it replaces. A node whose move would fold a leg back,
//! or skew it by more than 45 degrees, goes abeam onto the paint instead, or stays where the
//! network has it. A bend the paint adds that taxi-sim's rounding would turn tighter than
//! [`DRIVABLE_RADIUS_M`] is taken out; and where the route still would not round for an
//! aircraft turning no tighter than that where the network's route does, the legs nearest the
//! bend keep the network's line. So `smooth` (at taxi-sim's 30 m turn radius and 2.5 m corner
//! cut) rounds the route wherever it rounds the network's.
//! Where the network lies on the paint (the fictional airport XTSM), the route is the network's
//! point for point. Deterministic; odd paint (empty runs, segments of no length, NaN) is passed
//! over and an odd route returned as it is.

mod centreline;
mod geometry;
mod legs;
mod nodes;
mod profile;

use nalgebra::Vector2;

use crate::model::{Airport, line_type};
use crate::network::NetworkRoute;
use centreline::Paint;
use legs::{Leg, legs};
use nodes::{place_nodes, settle};

type V2 = Vector2<f64>;

/// How far the paint may lie from a network edge and still be the edge's taxiway (m). A code
/// E taxiway is 23 m wide (ICAO Annex 14), its edges 11.5 m from its centreline; a network drawn
/// for AI traffic strays to within a few metres of a taxiway's edge at worst (KSYR's W: node 141
/// is 13.6 m from the paint, the edge 9-14 m off it and 3.5 m from the edge lights). Parallel
/// taxiways for code B and larger lie more than 30 m apart centreline to centreline (Annex 14's
/// separations), so paint within 16 m of an edge is its own taxiway's; closer paint (code A
/// taxiways, a runway's lead-on lines) is told apart by where it goes with the route.
pub const MAX_OFFSET_M: f64 = 16.0;
/// How far a painted centreline segment's direction may differ from an edge's and still run
/// along it (degrees). A hand-drawn edge that starts on the paint and ends up to 16 m off it
/// over 90 m or more is within 10 degrees (KSYR's W: 5 degrees); crossing taxiways and the
/// curves turning off run at larger angles.
pub const PARALLEL_DEG: f64 = 10.0;
/// The angle at which the route leaves the paint for the network's line, or joins it, where the
/// paint ends or starts along a leg (degrees): a gentle change of lane (16 m over 60 m), whose
/// two bends (15 degrees) taxi-sim rounds with 4 m of leg each at its 30 m turn radius.
pub const TAPER_DEG: f64 = 15.0;
/// Paint within this of an edge is the edge (m): drawing noise, and the first metres of a
/// junction's painted fillet, where following the paint would only add bends.
pub const ON_NETWORK_M: f64 = 0.5;
/// Paint along a leg for less than this is a curve passing by - the first metres of a junction's
/// painted fillet, more than [`ON_NETWORK_M`] off the leg but not yet [`PARALLEL_DEG`] from it -
/// and a segment shorter than this is a curve's chord, not a line to move a node onto (m).
/// Curves are cut into chords of 1 m at most (`bezier::MAX_CHORD_M`).
pub const MIN_LINE_M: f64 = 5.0;
/// A bend the paint-following adds is taken out if taxi-sim's rounding (30 m radius, 2.5 m
/// corner cut) would turn it tighter than this (m): more than the tightest turn of the aircraft
/// it drives (4.6 m, the Praetor's nose-wheel limit) and the 12 m the route tests ask for.
pub const DRIVABLE_RADIUS_M: f64 = 15.0;

/// A painted curve is followed into the node it passes through while it heads within this of
/// the leg (degrees): a network drawn as chords of the curve, a node every 90 degrees of turn
/// or less.
const FOLLOW_DEG: f64 = 45.0;
/// A line followed on one leg guides the choice of paint on the next unless they meet at more
/// than this (degrees).
const REFERENCE_DEG: f64 = 60.0;
/// Painted points further than this from the datum are dropped (m).
const MAX_COORD_M: f64 = 1e8;
/// Points closer than this to the previous one are dropped (m).
const MIN_STEP_M: f64 = 0.01;

/// How far along a leg a node looks for the paint it moves onto: as far as a taper from the
/// widest offset reaches, so paint that stops short of the node either moves it or leaves room
/// to taper back to it.
fn node_reach_m() -> f64 {
    MAX_OFFSET_M / TAPER_DEG.to_radians().tan()
}

/// `route` (as [`crate::route::find_on_network`] makes it) on the painted taxiway centreline
/// where one runs along its taxiway legs; the route as it is where none does.
#[must_use]
pub fn follow(airport: &Airport, route: &NetworkRoute) -> NetworkRoute {
    let p = &route.points;
    let consistent = route.nodes.len() == p.len() && route.edges.len() + 1 == p.len();
    if p.len() < 2 || !consistent || p.iter().any(|q| !finite(*q)) {
        return route.clone();
    }
    let paint = Paint::of(airport);
    let mut legs = legs(airport, route, &paint);
    let mut pinned = vec![false; p.len()];
    // A route bound for a runway ends at its hold point exactly, as the network places it:
    // moved sideways onto the paint, it could come nearer the runway (a stub at an angle to it).
    if matches!(route.to.split_once(' '), Some(("runway", _))) {
        pinned[p.len() - 1] = true;
    }
    loop {
        let anchors = settle(&legs, &place_nodes(airport, route, &legs, &paint, &pinned));
        let (built, origin) = build(route, &legs, &anchors);
        let Some(j) = profile::less_drivable(&built, route) else {
            return built;
        };
        // Back to the network nearest the bend that got tighter: the legs either side of it,
        // their nodes where the network has them.
        let at = match origin[j] {
            Origin::Node(k) => k as f64 - 0.5,
            Origin::Leg(k) => k as f64,
        };
        let nearest = (0..legs.len())
            .filter(|&k| legs[k].followed)
            .min_by(|&x, &y| {
                (x as f64 - at)
                    .abs()
                    .total_cmp(&(y as f64 - at).abs())
                    .then(x.cmp(&y))
            });
        let Some(k) = nearest else {
            return built;
        };
        let mut ks = vec![k];
        if let Origin::Node(n) = origin[j]
            && n == k + 1
            && n < legs.len()
            && legs[n].followed
        {
            ks.push(n);
        }
        for k in ks {
            legs[k].followed = false;
            legs[k].chains.clear();
            legs[k].first = None;
            legs[k].last = None;
            legs[k].first_direct = None;
            legs[k].last_direct = None;
            legs[k].first_stops = false;
            legs[k].last_stops = false;
            pinned[k] = true;
            pinned[k + 1] = true;
        }
    }
}

/// `v` without the items `kept` says are not.
fn retain<T>(v: &mut Vec<T>, kept: &[bool]) {
    let mut k = kept.iter();
    v.retain(|_| *k.next().unwrap_or(&true));
}

/// Where a point of the built route comes from: a network node (or an end) of the route, or
/// the paint along one of its legs.
#[derive(Debug, Clone, Copy)]
enum Origin {
    Node(usize),
    Leg(usize),
}

/// Every painted taxiway centreline of `airport` as a polyline of finite points, no two in a row
/// at one place.
#[must_use]
pub fn centrelines(airport: &Airport) -> Vec<Vec<V2>> {
    airport
        .painted
        .iter()
        .filter(|run| line_type::is_taxiway_centreline(run.code))
        .map(|run| {
            let mut points: Vec<V2> = Vec::with_capacity(run.points.len());
            // Points further than any airport reaches are not paint (and would overflow).
            let sane = |q: &V2| finite(*q) && q.x.abs() <= MAX_COORD_M && q.y.abs() <= MAX_COORD_M;
            for &q in run.points.iter().filter(|q| sane(q)) {
                if points.last().is_none_or(|last| (q - last).norm() > 1e-6) {
                    points.push(q);
                }
            }
            points
        })
        .filter(|points| points.len() >= 2)
        .collect()
}

fn finite(p: V2) -> bool {
    p.x.is_finite() && p.y.is_finite()
}

/// The route through its moved points, along the paint between them, and where each of its
/// points comes from.
fn build(route: &NetworkRoute, legs: &[Leg], anchors: &[V2]) -> (NetworkRoute, Vec<Origin>) {
    let mut points = vec![anchors[0]];
    let mut nodes = vec![route.nodes[0]];
    let mut edges = Vec::new();
    let mut origin = vec![Origin::Node(0)];
    for (i, leg) in legs.iter().enumerate() {
        let inner = match leg.frame {
            Some(frame) if !leg.chains.is_empty() => {
                let (a, b) = (frame.sd(anchors[i]), frame.sd(anchors[i + 1]));
                let chains: Vec<Vec<V2>> = leg.chains.iter().map(|c| c.points.clone()).collect();
                let sd = profile::leg_profile(a, b, &chains);
                let mut world: Vec<V2> = sd.iter().map(|&q| frame.world(q)).collect();
                world[0] = anchors[i];
                let last = world.len() - 1;
                world[last] = anchors[i + 1];
                profile::simplify(&world)
            }
            _ => vec![anchors[i], anchors[i + 1]],
        };
        let last = inner.len() - 1;
        for (k, &q) in inner.iter().enumerate().skip(1) {
            let end = k == last;
            let node_before = matches!(origin[origin.len() - 1], Origin::Node(_));
            if (q - points[points.len() - 1]).norm() < MIN_STEP_M {
                if !end || node_before {
                    continue;
                }
                // The node replaces the point of the paint just before it.
                points.pop();
                nodes.pop();
                edges.pop();
                origin.pop();
            }
            points.push(q);
            nodes.push(if end { route.nodes[i + 1] } else { None });
            edges.push(route.edges[i]);
            origin.push(if end {
                Origin::Node(i + 1)
            } else {
                Origin::Leg(i)
            });
        }
    }
    let mut fixed: Vec<bool> = origin
        .iter()
        .map(|o| matches!(o, Origin::Node(_)))
        .collect();
    let kept = profile::drivable(&mut points, &mut fixed);
    retain(&mut nodes, &kept);
    retain(&mut origin, &kept);
    // The leg leaving a point taken out ran along the same edge as the one arriving.
    retain(&mut edges, &kept[1..]);
    let length_m = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let built = NetworkRoute {
        points,
        nodes,
        edges,
        length_m,
        ..route.clone()
    };
    (built, origin)
}
