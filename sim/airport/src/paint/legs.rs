//! The paint each leg of a route follows: the centreline segments along it, chosen where
//! several overlap by how far their line goes on with the route and how well it continues the
//! line followed so far; a curve followed into the node it passes through and on into the next
//! leg; and the straights a node at either end of the leg moves onto.

use super::centreline::Paint;
use super::geometry::{Frame, Line};
use super::{FOLLOW_DEG, MAX_OFFSET_M, MIN_LINE_M, ON_NETWORK_M, PARALLEL_DEG, V2, node_reach_m};
use crate::model::Airport;
use crate::network::{EdgeClass, NetworkRoute};

/// How far along the route a candidate line's paint is followed to judge how far it goes with
/// the route (m).
const LOOKAHEAD_M: f64 = 150.0;
/// Lines going on with the route as far as each other, to within this, are as good (m).
const SAME_REACH_M: f64 = 5.0;

/// A paint segment over a leg, in its frame (`s0 < s1`).
#[derive(Debug, Clone, Copy)]
struct Piece {
    s0: f64,
    d0: f64,
    s1: f64,
    d1: f64,
    segment: usize,
}

impl Piece {
    fn d(&self, s: f64) -> f64 {
        self.d0 + (self.d1 - self.d0) * (s - self.s0) / (self.s1 - self.s0)
    }
}

/// A run of paint followed along a leg: its `(s, d)` points (stations rising), and between each
/// two the paint segment it lies on and whether that is on the network (within
/// [`ON_NETWORK_M`] of the leg).
#[derive(Debug, Clone)]
pub(super) struct Chain {
    pub(super) points: Vec<V2>,
    spans: Vec<(usize, bool)>,
    /// Followed into the node at the leg's start along a curve (see [`into_node`]).
    into_start: bool,
    /// ... at its end: the segment that reaches the node, and whether the chain heads up its
    /// run (to higher points) there.
    into_end: Option<(usize, bool)>,
}

impl Chain {
    fn length(&self) -> f64 {
        self.points[self.points.len() - 1].x - self.points[0].x
    }

    /// The lines a node at the leg's end (`at_end`) or start moves onto: that of the paint's
    /// straight nearest it if it reaches within `reach` of it off the network - past the chords
    /// of a curve between it and the node, and only if there are none.
    fn node_lines(
        &self,
        paint: &Paint,
        frame: &Frame,
        at_end: bool,
        reach: f64,
    ) -> (Option<Line>, Option<Line>) {
        let into = if at_end {
            self.into_end.is_some()
        } else {
            self.into_start
        };
        if into {
            return (None, None);
        }
        let mut spans: Vec<((usize, bool), &[V2])> = self
            .spans
            .iter()
            .copied()
            .zip(self.points.windows(2))
            .collect();
        if at_end {
            spans.reverse();
        }
        for (k, ((segment, on_network), w)) in spans.into_iter().enumerate() {
            let near = if at_end {
                w[1].x >= frame.length - reach
            } else {
                w[0].x <= reach
            };
            if on_network || !near {
                return (None, None);
            }
            let (a, b) = paint.ends(segment);
            if (b - a).norm() >= MIN_LINE_M {
                let line = Line::through(a, b);
                // A straight stopping short of the leg's end is no line to move that end onto.
                let (sa, sb) = (frame.sd(a).x, frame.sd(b).x);
                let abeam = if at_end {
                    sa.max(sb) >= frame.length - MIN_LINE_M
                } else {
                    sa.min(sb) <= MIN_LINE_M
                };
                return (line, if k == 0 && abeam { line } else { None });
            }
        }
        (None, None)
    }

    /// Whether the paint stops short of the node at the leg's end (`at_end`) or start: the
    /// chain's paint there is off the network, ends more than [`MIN_LINE_M`] before abeam the
    /// node, and goes on nowhere (no curve or other run takes it further).
    fn stops_short(&self, paint: &Paint, frame: &Frame, at_end: bool) -> bool {
        let (point, (segment, on_network), into) = if at_end {
            let last = self.points.len() - 1;
            (
                self.points[last],
                self.spans[last - 1],
                self.into_end.is_some(),
            )
        } else {
            (self.points[0], self.spans[0], self.into_start)
        };
        if on_network || into {
            return false;
        }
        let (a, b) = paint.ends(segment);
        // Which way along the run the chain heads toward the node, and the paint's end there.
        let up = ((b - a).dot(&frame.u) > 0.0) == at_end;
        let end = frame.sd(if up { b } else { a });
        let short = if at_end {
            end.x < frame.length - MIN_LINE_M
        } else {
            end.x > MIN_LINE_M
        };
        // The chain reaches the paint's end (is not cut off there by the band round the leg).
        let reached = (end - point).norm() <= STOP_MATCH_M;
        short && reached && paint.walk(segment, up).next().is_none()
    }
}

/// A chain's end is where its paint ends if within this of it (m).
const STOP_MATCH_M: f64 = 1e-3;

/// A leg of the route and the paint along it.
#[derive(Debug, Clone)]
pub(super) struct Leg {
    pub(super) frame: Option<Frame>,
    pub(super) runway: bool,
    /// A taxiway leg: one that follows the paint.
    pub(super) followed: bool,
    pub(super) chains: Vec<Chain>,
    /// The paint line a node at the leg's start moves onto: a straight of the paint that
    /// reaches within [`node_reach_m`] of it, off the network (past a curve rounding a turn
    /// there).
    pub(super) first: Option<Line>,
    /// ... and at its end.
    pub(super) last: Option<Line>,
    /// The straight the paint reaches the leg's start on (to within [`MIN_LINE_M`] of abeam
    /// it), if it does not curve before it: the line a route's first point moves sideways onto.
    pub(super) first_direct: Option<Line>,
    /// ... its end, for its last point.
    pub(super) last_direct: Option<Line>,
    /// The paint of `first` stops short of the leg's start: its line is the paint's last
    /// there, ending more than [`MIN_LINE_M`] before abeam the node.
    pub(super) first_stops: bool,
    /// ... of `last`, short of its end.
    pub(super) last_stops: bool,
}

impl Leg {
    /// Whether the leg has no paint of its own at its end (`at_end`) or start: no straight
    /// off the network near the node, nor a curve followed into it.
    pub(super) fn bare_at(&self, at_end: bool) -> bool {
        let (line, chain) = if at_end {
            (self.last, self.chains.last())
        } else {
            (self.first, self.chains.first())
        };
        let into = chain.is_some_and(|c| {
            if at_end {
                c.into_end.is_some()
            } else {
                c.into_start
            }
        });
        line.is_none() && !into
    }
}

/// The legs, their paint chosen in order along the route (each continuing the last).
pub(super) fn legs(airport: &Airport, route: &NetworkRoute, paint: &Paint) -> Vec<Leg> {
    let edges = &airport.network.edges;
    let mut reference: Option<Line> = None;
    // The curve the last leg followed into its end node, going on into this leg.
    let mut carry: Option<(usize, bool)> = None;
    let mut out = Vec::with_capacity(route.edges.len());
    for (i, edge) in route.edges.iter().enumerate() {
        let frame = Frame::of(route.points[i], route.points[i + 1]);
        let class = edge.and_then(|e| edges.get(e)).map(|e| e.class);
        let mut leg = Leg {
            frame,
            runway: class == Some(EdgeClass::Runway),
            followed: matches!(class, Some(EdgeClass::Taxiway(_))),
            chains: Vec::new(),
            first: None,
            last: None,
            first_direct: None,
            last_direct: None,
            first_stops: false,
            last_stops: false,
        };
        let Some(frame) = frame.filter(|_| leg.followed) else {
            reference = frame.map(|f| f.line());
            carry = None;
            out.push(leg);
            continue;
        };
        let mut candidates = pieces(&frame, paint);
        if let Some(from) = carry {
            candidates.extend(carried(&frame, paint, from));
        }
        let ahead = route_ahead(&route.points[i..]);
        let mut reach = std::collections::BTreeMap::new();
        for p in &candidates {
            reach
                .entry(p.segment)
                .or_insert_with(|| goes_on(&frame, paint, p.segment, &ahead));
        }
        let beyond = |p: &Piece| reach.get(&p.segment).copied().unwrap_or(0.0);
        let mut chains = select(&frame, &candidates, reference, &beyond);
        if let Some(c) = chains.first_mut() {
            into_node(c, &frame, paint, false);
        }
        if let Some(c) = chains.last_mut() {
            into_node(c, &frame, paint, true);
        }
        chains.retain(|c| c.length() >= MIN_LINE_M || c.into_start || c.into_end.is_some());
        let reach = node_reach_m();
        let lines = |c: Option<&Chain>, at_end: bool| {
            c.map_or((None, None), |c| c.node_lines(paint, &frame, at_end, reach))
        };
        (leg.first, leg.first_direct) = lines(chains.first(), false);
        (leg.last, leg.last_direct) = lines(chains.last(), true);
        let stops = |c: Option<&Chain>, at_end: bool| {
            c.is_some_and(|c| c.stops_short(paint, &frame, at_end))
        };
        leg.first_stops = leg.first.is_some() && stops(chains.first(), false);
        leg.last_stops = leg.last.is_some() && stops(chains.last(), true);
        // The next leg continues the paint this one ends on.
        carry = chains.last().and_then(|c| c.into_end);
        reference = match chains.last() {
            Some(c) if c.points[c.points.len() - 1].x >= frame.length - reach => {
                let (a, b) = paint.ends(c.spans[c.spans.len() - 1].0);
                Line::through(a, b)
            }
            _ => Some(frame.line()),
        };
        leg.chains = chains;
        out.push(leg);
    }
    out
}

/// The paint segments that run along the leg (within [`PARALLEL_DEG`] of it), cut to the part
/// over it and within [`MAX_OFFSET_M`] of it.
fn pieces(frame: &Frame, paint: &Paint) -> Vec<Piece> {
    let tan = PARALLEL_DEG.to_radians().tan();
    (0..paint.segments.len())
        .filter_map(|segment| {
            let (a, b) = paint.ends(segment);
            let (mut p, mut q) = (frame.sd(a), frame.sd(b));
            if q.x < p.x {
                std::mem::swap(&mut p, &mut q);
            }
            let ds = q.x - p.x;
            if ds.is_nan() || ds <= 1e-6 || (q.y - p.y).abs() > tan * ds {
                return None;
            }
            let slope = (q.y - p.y) / ds;
            let (mut lo, mut hi) = (p.x.max(0.0), q.x.min(frame.length));
            if slope.abs() > 1e-12 {
                let (x, y) = (
                    p.x + (MAX_OFFSET_M - p.y) / slope,
                    p.x + (-MAX_OFFSET_M - p.y) / slope,
                );
                lo = lo.max(x.min(y));
                hi = hi.min(x.max(y));
            } else if p.y.abs() > MAX_OFFSET_M {
                return None;
            }
            if (hi - lo).is_nan() || hi - lo <= 1e-6 {
                return None;
            }
            let d = |s: f64| p.y + slope * (s - p.x);
            Some(Piece {
                s0: lo,
                d0: d(lo),
                s1: hi,
                d1: d(hi),
                segment,
            })
        })
        .collect()
}

/// The legs of a route from a leg's start on, as far as [`LOOKAHEAD_M`] past that leg (and a
/// band's width more).
fn route_ahead(points: &[V2]) -> Vec<(V2, V2)> {
    let mut out = Vec::new();
    let mut length = 0.0;
    for w in points.windows(2) {
        let leg = (w[1] - w[0]).norm();
        if leg > 1e-6 {
            out.push((w[0], w[1]));
        }
        if !out.is_empty() && length > LOOKAHEAD_M + MAX_OFFSET_M {
            break;
        }
        // The first leg's length does not count: the look ahead starts anywhere along it.
        if out.len() > 1 {
            length += leg;
        }
    }
    out
}

/// How far the paint goes on along the route past the far end (along the leg) of `segment`:
/// the progress along the route `ahead` (from the leg's start) of its centreline followed while
/// it lies within [`MAX_OFFSET_M`] of the route and heads within [`FOLLOW_DEG`] of the nearest
/// of its legs, up to [`LOOKAHEAD_M`].
fn goes_on(frame: &Frame, paint: &Paint, segment: usize, ahead: &[(V2, V2)]) -> f64 {
    // Where a point lies along the route: its distance from it, the direction of the leg it is
    // nearest, and how far along the route that is.
    let along_route = |q: V2| {
        let mut start = 0.0;
        let mut best: Option<(f64, V2, f64)> = None;
        for &(s, e) in ahead {
            let length = (e - s).norm();
            let t = ((q - s).dot(&(e - s)) / (length * length)).clamp(0.0, 1.0);
            let distance = (s + (e - s) * t - q).norm();
            if best.is_none_or(|b| distance < b.0) {
                best = Some((distance, (e - s) / length, start + t * length));
            }
            start += length;
        }
        best
    };
    let (a, b) = paint.ends(segment);
    let up = (b - a).dot(&frame.u) > 0.0;
    let mut at = if up { b } else { a };
    let Some((_, _, from)) = along_route(at) else {
        return 0.0;
    };
    let mut reached = from;
    for (next, _, _) in paint.walk(segment, up) {
        // In steps of a few metres, so a long straight counts as far as it stays near the route.
        let pieces = ((next - at).norm() / 5.0).ceil().max(1.0);
        let start = at;
        for k in 1..=pieces as usize {
            let q = start + (next - start) * (k as f64 / pieces);
            let Some((distance, direction, station)) = along_route(q) else {
                return reached - from;
            };
            let step = q - at;
            if distance > MAX_OFFSET_M
                || step.dot(&direction) < FOLLOW_DEG.to_radians().cos() * step.norm()
            {
                return reached - from;
            }
            reached = reached.max(station);
            at = q;
            if reached - from >= LOOKAHEAD_M {
                return reached - from;
            }
        }
    }
    reached - from
}

/// The curve a leg followed into the node at its start (`from`: the segment reaching the node,
/// and whether the curve runs up its run), on over this leg as pieces while it heads within
/// [`FOLLOW_DEG`] of it and within [`MAX_OFFSET_M`] of it.
fn carried(frame: &Frame, paint: &Paint, (segment, up): (usize, bool)) -> Vec<Piece> {
    let (a, b) = paint.ends(segment);
    let first = if up { (a, b) } else { (b, a) };
    let mut steps = vec![(first.0, first.1, segment)];
    let mut at = first.1;
    for (q, s, _) in paint.walk(segment, up) {
        steps.push((at, q, s));
        at = q;
        if frame.sd(q).x >= frame.length {
            break;
        }
    }
    let mut out = Vec::new();
    for (from, to, segment) in steps {
        let (p, q) = (frame.sd(from), frame.sd(to));
        let step = q - p;
        if q.x <= 0.0 {
            continue;
        }
        if step.x < FOLLOW_DEG.to_radians().cos() * step.norm()
            || p.y.abs() > MAX_OFFSET_M
            || q.y.abs() > MAX_OFFSET_M
        {
            break;
        }
        let (s0, s1) = (p.x.max(0.0), q.x.min(frame.length));
        if s1 - s0 > 1e-6 {
            let d = |s: f64| p.y + step.y * (s - p.x) / step.x;
            out.push(Piece {
                s0,
                d0: d(s0),
                s1,
                d1: d(s1),
                segment,
            });
        }
        if q.x >= frame.length {
            break;
        }
    }
    out
}

/// The paint followed along a leg: between each two stations where a piece starts or ends, of
/// the pieces covering it whose paint goes on along the route furthest (to within
/// [`SAME_REACH_M`]; `beyond`: how far past a piece's end), the one that best continues the
/// line followed so far (`reference`; at first the network's leg if none). So a line is
/// followed past the curves that leave it, and at a fork the branch the route takes.
fn select(
    frame: &Frame,
    pieces: &[Piece],
    reference: Option<Line>,
    beyond: &dyn Fn(&Piece) -> f64,
) -> Vec<Chain> {
    let mut stations: Vec<f64> = pieces.iter().flat_map(|p| [p.s0, p.s1]).collect();
    stations.sort_by(f64::total_cmp);
    stations.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let (mut r0, mut r1) = reference
        .and_then(|l| l.in_frame(frame))
        .unwrap_or((0.0, 0.0));
    let mut chains = Vec::new();
    let mut current: Option<Chain> = None;
    for w in stations.windows(2) {
        let (x, y) = (w[0], w[1]);
        let covering: Vec<(&Piece, f64)> = pieces
            .iter()
            .filter(|p| p.s0 <= x + 1e-6 && p.s1 >= y - 1e-6)
            .map(|p| (p, p.s1 - x + beyond(p)))
            .collect();
        let furthest = covering.iter().map(|c| c.1).fold(0.0, f64::max);
        let best = covering
            .iter()
            .filter(|c| c.1 >= furthest.min(LOOKAHEAD_M) - SAME_REACH_M)
            .map(|&(p, _)| {
                let cost = (p.d(x) - (r0 + r1 * x)).abs() + (p.d(y) - (r0 + r1 * y)).abs();
                (p, cost)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((p, _)) = best else {
            chains.extend(current.take());
            continue;
        };
        r1 = (p.d1 - p.d0) / (p.s1 - p.s0);
        r0 = p.d0 - r1 * p.s0;
        let (dx, dy) = (p.d(x), p.d(y));
        let on_network = dx.abs() <= ON_NETWORK_M && dy.abs() <= ON_NETWORK_M;
        let (a, b) = if on_network {
            (V2::new(x, 0.0), V2::new(y, 0.0))
        } else {
            (V2::new(x, dx), V2::new(y, dy))
        };
        match current.as_mut() {
            Some(c) if (c.points[c.points.len() - 1] - a).norm() < 1e-6 => {
                c.points.push(b);
                c.spans.push((p.segment, on_network));
            }
            _ => {
                chains.extend(current.take());
                current = Some(Chain {
                    points: vec![a, b],
                    spans: vec![(p.segment, on_network)],
                    into_start: false,
                    into_end: None,
                });
            }
        }
    }
    chains.extend(current);
    chains
}

/// Follows the paint of a chain's last piece (`at_end`) or first on along its centreline, while
/// it heads within [`FOLLOW_DEG`] of the leg and within [`MAX_OFFSET_M`] of it, into the node at
/// that end of the leg if it passes within [`ON_NETWORK_M`] of it.
fn into_node(chain: &mut Chain, frame: &Frame, paint: &Paint, at_end: bool) {
    let (segment, _) = if at_end {
        chain.spans[chain.spans.len() - 1]
    } else {
        chain.spans[0]
    };
    let (a, b) = paint.ends(segment);
    // Which way along the run the chain heads toward the node.
    let up = ((b - a).dot(&frame.u) > 0.0) == at_end;
    let (sign, node) = if at_end {
        (1.0, V2::new(frame.length, 0.0))
    } else {
        (-1.0, V2::zeros())
    };
    let from = if at_end {
        chain.points[chain.points.len() - 1]
    } else {
        chain.points[0]
    };
    // The points walked, each with the segment reaching it and which way its run is walked.
    let far = frame.sd(if up { b } else { a });
    let mut path = vec![(from, segment, up), (far, segment, up)];
    for (q, s, cursor) in paint.walk(segment, up) {
        path.push((frame.sd(q), s, cursor.up));
        if sign * (frame.sd(q).x - node.x) >= 0.0 {
            break;
        }
    }
    // As far as the paint goes on along the leg, within the band.
    let mut end = 1;
    while end < path.len() {
        let step = path[end].0 - path[end - 1].0;
        let onward = sign * step.x >= FOLLOW_DEG.to_radians().cos() * step.norm();
        if !(onward || step.norm() < 1e-9) || path[end].0.y.abs() > MAX_OFFSET_M {
            break;
        }
        end += 1;
    }
    path.truncate(end);
    let nearest = path
        .windows(2)
        .enumerate()
        .filter(|(_, w)| (w[1].0 - w[0].0).norm() > 1e-9)
        .map(|(j, w)| {
            let (p, q) = (w[0].0, w[1].0);
            let t = ((node - p).dot(&(q - p)) / (q - p).norm_squared()).clamp(0.0, 1.0);
            (j, (p + (q - p) * t - node).norm())
        })
        .chain(std::iter::once((0, (from - node).norm())))
        .min_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
    let Some((j, _)) = nearest.filter(|n| n.1 <= ON_NETWORK_M) else {
        return;
    };
    // The points walked up to the nearest segment's start, then the node itself, on the
    // segment reaching the nearest segment's end.
    let (_, last, last_up) = path.get(j + 1).copied().unwrap_or(path[j]);
    let mut added: Vec<(V2, usize)> = path[1..=j].iter().map(|x| (x.0, x.1)).collect();
    added.push((node, last));
    added.retain(|x| (x.0 - from).norm() > 1e-9);
    if at_end {
        for (q, s) in added {
            chain.points.push(q);
            chain.spans.push((s, false));
        }
        chain.into_end = Some((last, last_up));
    } else {
        let mut points: Vec<V2> = added.iter().rev().map(|x| x.0).collect();
        let mut spans: Vec<(usize, bool)> = added.iter().rev().map(|x| (x.1, false)).collect();
        points.append(&mut chain.points);
        spans.append(&mut chain.spans);
        chain.points = points;
        chain.spans = spans;
        chain.into_start = true;
    }
}
