//! A leg's geometry once its paint is chosen and its ends placed: the paint between the ends,
//! joined by tapers; then the route's added points thinned where they add nothing, and where
//! taxi-sim's rounding would turn them too tight.

use super::{DRIVABLE_RADIUS_M, TAPER_DEG, V2};
use crate::network::NetworkRoute;
use crate::path::{PathOptions, STRAIGHT_RAD, corners};

/// The tightest turns an aircraft may be limited to at which a route on the paint must round
/// wherever the network's route does (m). A route that rounds for an aircraft turning no
/// tighter than some radius rounds for any turning tighter, so these cover every aircraft that
/// turns at [`DRIVABLE_RADIUS_M`] or tighter: those taxi-sim drives (3.4-4.6 m) and the 5 m and
/// 12 m the route tests ask for. (A painted curve tighter than 15 m is followed, as the network
/// route would be, only as far as such an aircraft can.)
const CHECK_RADII_M: [f64; 4] = [DRIVABLE_RADIUS_M, 12.0, 8.0, 5.0];

/// Points within this of the line through their neighbours are dropped (m).
const SIMPLIFY_M: f64 = 0.02;
/// taxi-sim's rounding (its `DEFAULT_TURN_RADIUS_M` and `MAX_CORNER_CUT_M`), used to find the
/// bends the paint-following adds that it would turn too tight.
const NOMINAL: PathOptions = PathOptions {
    turn_radius_m: 30.0,
    max_corner_cut_m: 2.5,
    min_turn_radius_m: 0.0,
    straight_speed_m_s: 1.0,
    lateral_acceleration_m_s2: 1.0,
    deceleration_m_s2: 1.0,
};

/// A leg's `(s, d)` points from anchor `a` to anchor `b` along its chains: each chain cut to
/// what lies between; joined straight where the step is gentle (within [`TAPER_DEG`]), by way of
/// the network's line where the gap leaves room for two tapers, and where the step is steeper,
/// by cutting the paint back to where a taper reaches it.
pub(super) fn leg_profile(a: V2, b: V2, chains: &[Vec<V2>]) -> Vec<V2> {
    let k = TAPER_DEG.to_radians().tan();
    let mut out = vec![a];
    for chain in chains {
        let last = out[out.len() - 1];
        let cut = clip(chain, last.x, b.x);
        if cut.len() < 2 {
            continue;
        }
        let to = cut[0];
        if to.x - last.x >= (last.y.abs() + to.y.abs()) / k {
            push_tapers(&mut out, last, to, k);
            out.extend(cut);
        } else if (to.y - last.y).abs() <= k * (to.x - last.x) + 1e-9 {
            out.extend(cut);
        } else if let Some(rest) = first_reachable(last, &cut, k) {
            out.extend(rest);
        }
    }
    // To the end anchor, cutting the paint back as far as a taper to it needs.
    let mut tail = out.split_off(1);
    if let Some(&last) = tail.last() {
        if b.x - last.x >= (last.y.abs() + b.y.abs()) / k {
            push_tapers(&mut tail, last, b, k);
        } else if (b.y - last.y).abs() > k * (b.x - last.x) + 1e-9 {
            tail = last_reachable(&tail, b, k).unwrap_or_default();
        }
    }
    out.extend(tail);
    out.push(b);
    out
}

/// Where the route leaves `from` for the network's line and returns from it to `to` (each at
/// the taper's angle; none where already on it).
fn push_tapers(out: &mut Vec<V2>, from: V2, to: V2, k: f64) {
    let (x0, x1) = (from.x + from.y.abs() / k, to.x - to.y.abs() / k);
    if from.y.abs() > 1e-9 {
        out.push(V2::new(x0, 0.0));
    }
    if to.y.abs() > 1e-9 && x1 > x0 + 1e-9 {
        out.push(V2::new(x1, 0.0));
    }
}

/// The part of a chain (stations rising) between stations `lo` and `hi`.
fn clip(points: &[V2], lo: f64, hi: f64) -> Vec<V2> {
    let mut out = Vec::new();
    for w in points.windows(2) {
        let (p, q) = (w[0], w[1]);
        let (a, b) = (p.x.max(lo), q.x.min(hi));
        if b - a <= 1e-9 {
            continue;
        }
        let at = |s: f64| p + (q - p) * ((s - p.x) / (q.x - p.x));
        if out.is_empty() {
            out.push(at(a));
        }
        out.push(at(b));
    }
    out
}

/// The chain from its first point that `from` reaches at no steeper than `k` (d per s): the
/// chain cut there, or `None` if it reaches none.
fn first_reachable(from: V2, chain: &[V2], k: f64) -> Option<Vec<V2>> {
    let f = |q: V2| k * (q.x - from.x) - (q.y - from.y).abs();
    if f(chain[0]) >= 0.0 {
        return Some(chain.to_vec());
    }
    for (j, w) in chain.windows(2).enumerate() {
        let (p, q) = (w[0], w[1]);
        let at = |t: f64| p + (q - p) * t;
        // f is concave along the segment: its largest value at an end or where d = from.d.
        let kink = if (q.y - p.y).abs() > 1e-12 {
            ((from.y - p.y) / (q.y - p.y)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let Some(good) = [kink, 1.0].into_iter().find(|&t| f(at(t)) >= 0.0) else {
            continue;
        };
        let (mut lo, mut hi) = (0.0, good);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if f(at(mid)) >= 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let mut rest = vec![at(hi)];
        rest.extend_from_slice(&chain[j + 1..]);
        return Some(rest);
    }
    None
}

/// The chain up to its last point from which `to` is reached at no steeper than `k`.
fn last_reachable(chain: &[V2], to: V2, k: f64) -> Option<Vec<V2>> {
    let mirror = |q: &V2| V2::new(-q.x, q.y);
    let reversed: Vec<V2> = chain.iter().rev().map(mirror).collect();
    let rest = first_reachable(mirror(&to), &reversed, k)?;
    Some(rest.iter().rev().map(mirror).collect())
}

/// Douglas-Peucker: the points within [`SIMPLIFY_M`] of the line through their neighbours
/// dropped (the ends kept).
pub(super) fn simplify(points: &[V2]) -> Vec<V2> {
    if points.len() < 3 {
        return points.to_vec();
    }
    let mut keep = vec![false; points.len()];
    let (first, last) = (0, points.len() - 1);
    keep[first] = true;
    keep[last] = true;
    let mut stack = vec![(first, last)];
    while let Some((i, j)) = stack.pop() {
        let (a, b) = (points[i], points[j]);
        let distance = |p: V2| {
            let length = (b - a).norm();
            if length > 1e-9 {
                (p - a).perp(&(b - a)).abs() / length
            } else {
                (p - a).norm()
            }
        };
        let far = (i + 1..j)
            .map(|m| (m, distance(points[m])))
            .max_by(|x, y| x.1.total_cmp(&y.1).then(y.0.cmp(&x.0)));
        if let Some((m, d)) = far
            && d > SIMPLIFY_M
        {
            keep[m] = true;
            stack.push((i, m));
            stack.push((m, j));
        }
    }
    points
        .iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(*p))
        .collect()
}

/// Takes out added points (not `fixed`) whose bend, or a neighbour's, taxi-sim's rounding would
/// turn tighter than [`DRIVABLE_RADIUS_M`] for want of leg to round it on, the tightest first;
/// which of the points given are kept.
pub(super) fn drivable(points: &mut Vec<V2>, fixed: &mut Vec<bool>) -> Vec<bool> {
    let mut index: Vec<usize> = (0..points.len()).collect();
    let mut kept = vec![true; points.len()];
    loop {
        let c = corners(points, &NOMINAL);
        let n = points.len();
        let removable = |j: usize| j > 0 && j + 1 < n && !fixed[j];
        let tight = (1..n.saturating_sub(1))
            .filter(|&i| c.tangent[i] < c.wanted[i] - 1e-9 && c.deflection[i] > 1e-9)
            .map(|i| (i, c.tangent[i] / (c.deflection[i] / 2.0).tan()))
            .filter(|&(_, r)| r < DRIVABLE_RADIUS_M)
            .filter_map(|(i, r)| {
                let pick = if removable(i) {
                    Some(i)
                } else {
                    [i - 1, i + 1]
                        .into_iter()
                        .filter(|&j| removable(j))
                        .min_by(|&x, &y| {
                            let dx = (points[x] - points[i]).norm();
                            let dy = (points[y] - points[i]).norm();
                            dx.total_cmp(&dy).then(x.cmp(&y))
                        })
                };
                pick.map(|j| (j, r))
            })
            .min_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        let Some((j, _)) = tight else {
            return kept;
        };
        points.remove(j);
        fixed.remove(j);
        kept[index.remove(j)] = false;
    }
}

/// The first point of `route` at which taxi-sim's rounding (at its 30 m turn radius, 2.5 m
/// corner cut) fails for an aircraft turning no tighter than one of [`CHECK_RADII_M`] where it
/// does not fail on `network`: the paint made the route less drivable there.
pub(super) fn less_drivable(route: &NetworkRoute, network: &NetworkRoute) -> Option<usize> {
    CHECK_RADII_M.iter().find_map(|&min| {
        let options = PathOptions {
            min_turn_radius_m: min,
            ..NOMINAL
        };
        let fails = |points: &[V2]| {
            let c = corners(points, &options);
            (1..points.len().saturating_sub(1)).find(|&i| {
                c.deflection[i] >= STRAIGHT_RAD
                    && c.tangent[i] / (c.deflection[i] / 2.0).tan() < min - 1e-9
            })
        };
        if fails(&network.points).is_some() {
            return None;
        }
        fails(&route.points)
    })
}
