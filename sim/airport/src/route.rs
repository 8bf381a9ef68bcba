//! Taxi routes: from a stand, a network node or a runway to a runway's hold point, a stand or a
//! node, along the named taxiways in order; the shortest such path on the network that admits
//! the aircraft's code letter, keeps one-way edges' direction, never enters the zone of the
//! runway it is bound for, and never turns back on itself or through more than
//! [`MAX_DEFLECTION_DEG`] at a node; then moved onto the painted taxiway centreline where the
//! network strays from it ([`crate::paint`]). `smooth` then rounds it into a path the aircraft
//! can drive.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::Vector2;

use crate::error::AirportError;
use crate::model::Airport;
pub use crate::network::NetworkRoute;
use crate::network::{EdgeClass, Network};
use crate::size::SizeClass;

/// The sharpest turn at a node a route takes (deflection from straight on, degrees).
pub const MAX_DEFLECTION_DEG: f64 = 135.0;

/// Where a route starts or ends, as a scenario writes it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Place {
    /// A stand, by its name (`Gate 4 South A`).
    Stand(String),
    /// A network node by id (`node 12`).
    Node(u32),
    /// A runway end (`runway 28`): as a destination its hold point, as a start its threshold's
    /// end of the runway (vacating it after landing).
    Runway(String),
}

impl Place {
    /// `node 12`, `runway 28`, or a stand's name.
    #[must_use]
    pub fn parse(text: &str) -> Self {
        let text = text.trim();
        if let Some(id) = text
            .strip_prefix("node ")
            .and_then(|id| id.trim().parse().ok())
        {
            return Self::Node(id);
        }
        if let Some(number) = text.strip_prefix("runway ") {
            return Self::Runway(number.trim().to_string());
        }
        Self::Stand(text.to_string())
    }
}

impl std::fmt::Display for Place {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Stand(name) => write!(f, "stand {name}"),
            Self::Node(id) => write!(f, "node {id}"),
            Self::Runway(number) => write!(f, "runway {number}"),
        }
    }
}

/// What a route is asked to be.
#[derive(Debug, Clone)]
pub struct RouteRequest {
    /// Start.
    pub from: Place,
    /// End.
    pub to: Place,
    /// Taxiway names to follow, in order.
    pub via: Vec<String>,
    /// The aircraft's code letter.
    pub code: SizeClass,
}

/// A directed arc of the search graph: a network edge (or part of one) in one direction.
#[derive(Debug, Clone, Copy)]
struct Arc {
    tail: usize,
    head: usize,
    edge: usize,
    length_m: f64,
}

/// The graph searched: the network's nodes, then a virtual start and end on edges.
struct Graph<'a> {
    network: &'a Network,
    points: Vec<Vector2<f64>>,
    arcs: Vec<Arc>,
    leaving: Vec<Vec<usize>>,
}

impl Graph<'_> {
    fn add_point(&mut self, at: Vector2<f64>) -> usize {
        self.points.push(at);
        self.leaving.push(Vec::new());
        self.points.len() - 1
    }

    fn add_arc(&mut self, tail: usize, head: usize, edge: usize) {
        let length_m = (self.points[head] - self.points[tail]).norm();
        self.leaving[tail].push(self.arcs.len());
        self.arcs.push(Arc {
            tail,
            head,
            edge,
            length_m,
        });
    }
}

/// Finds the route asked for on `airport`'s network and moves it onto the painted taxiway
/// centreline where the network strays from it ([`crate::paint::follow`]).
///
/// # Errors
/// As [`find_on_network`].
pub fn find(airport: &Airport, request: &RouteRequest) -> Result<NetworkRoute, AirportError> {
    find_on_network(airport, request).map(|route| crate::paint::follow(airport, &route))
}

/// Finds the route asked for on `airport`'s network: its geometry is the network's (nodes and
/// straight edges), as the file draws it.
///
/// # Errors
/// A place or taxiway name that is not there, or no path admitting the code (`AirportError::Route`,
/// saying which).
pub fn find_on_network(
    airport: &Airport,
    request: &RouteRequest,
) -> Result<NetworkRoute, AirportError> {
    let network = &airport.network;
    let fail = |why: String| AirportError::Route {
        from: request.from.to_string(),
        to: request.to.to_string(),
        why,
    };
    for name in &request.via {
        if !network.edges.iter().any(|e| &e.name == name) {
            let known: Vec<String> = network.taxiways().into_keys().collect();
            return Err(fail(format!(
                "no taxiway `{name}` on the network (it has {known:?})"
            )));
        }
    }
    let admitted: Vec<bool> = network
        .edges
        .iter()
        .map(|e| e.admits(request.code))
        .collect();
    if !admitted.iter().any(|&a| a) {
        return Err(fail(format!(
            "no edge of the network admits code {}",
            request.code
        )));
    }
    let mut graph = Graph {
        network,
        points: network.nodes.iter().map(|n| n.at).collect(),
        arcs: Vec::new(),
        leaving: vec![Vec::new(); network.nodes.len()],
    };
    let forbidden_zone = match &request.to {
        Place::Runway(number) => Some(number.clone()),
        _ => None,
    };
    for (index, edge) in network.edges.iter().enumerate() {
        let in_target_zone = forbidden_zone
            .as_deref()
            .is_some_and(|n| edge.in_zone_of(n));
        if !admitted[index] || in_target_zone {
            continue;
        }
        graph.add_arc(edge.from, edge.to, index);
        if !edge.one_way {
            graph.add_arc(edge.to, edge.from, index);
        }
    }
    let (start, start_on) =
        start_point(airport, &mut graph, &request.from, request.code).map_err(&fail)?;
    let (targets, lead_in, end_on) =
        end_points(airport, &mut graph, &request.to, request.code).map_err(&fail)?;
    if let (Some((edge, t0)), Some((end_edge, t1))) = (start_on, end_on)
        && edge == end_edge
        && (!network.edges[edge].one_way || t1 >= t0)
    {
        // Both stands on one taxilane edge: straight along it, not round the network.
        graph.add_arc(start, targets[0], edge);
    }
    // Starting on a runway (vacating it), the route may drive along that runway only.
    let left_runway = match &request.from {
        Place::Runway(number) => runway_end(airport, number).map(|(r, _)| r),
        _ => None,
    };
    let runway_ok = network
        .edges
        .iter()
        .map(|e| {
            e.class == EdgeClass::Runway
                && left_runway.is_some_and(|r| {
                    on_runway(r, &network.nodes[e.from].at) && on_runway(r, &network.nodes[e.to].at)
                })
        })
        .collect();
    let search = Search {
        graph: &graph,
        via: &request.via,
        runway_ok,
    };
    let best = search.run(start, &targets, &request.to, airport).ok_or_else(|| {
        fail(format!(
            "no path{} admitting code {} (one-way edges kept, no turn over {MAX_DEFLECTION_DEG} degrees)",
            if request.via.is_empty() { String::new() } else { format!(" along {}", request.via.join(", ")) },
            request.code
        ))
    })?;
    let mut route = assemble(&graph, start, &best, lead_in, &request.to);
    route.from = request.from.to_string();
    route.to = request.to.to_string();
    Ok(route)
}

/// Whether `p` lies on runway `r` (within half its width of its centreline, ends included).
fn on_runway(r: &crate::model::Runway, p: &Vector2<f64>) -> bool {
    let (a, b) = (r.ends[0].at, r.ends[1].at);
    let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared().max(1e-12)).clamp(0.0, 1.0);
    (a + (b - a) * t - p).norm() <= r.width_m / 2.0 + 1.0
}

/// The network's edges an aircraft of `code` may taxi along to or from a stand (no runway), with
/// their indices.
fn taxilanes(
    network: &Network,
    code: SizeClass,
) -> impl Iterator<Item = (usize, &crate::network::Edge)> {
    network
        .edges
        .iter()
        .enumerate()
        .filter(move |(_, e)| e.class != EdgeClass::Runway && e.admits(code))
}

/// The admitting taxiway edge nearest `at`: its index, the nearest point on it and where that
/// lies along it (0 at its start node, 1 at its end). Edges of no length are passed over.
fn nearest_on_edges(
    graph: &Graph,
    at: Vector2<f64>,
    code: SizeClass,
) -> Option<(usize, Vector2<f64>, f64)> {
    let network = graph.network;
    taxilanes(network, code)
        .filter_map(|(i, e)| {
            let (a, b) = (network.nodes[e.from].at, network.nodes[e.to].at);
            let length2 = (b - a).norm_squared();
            (length2 > 1e-6).then(|| {
                let t = ((at - a).dot(&(b - a)) / length2).clamp(0.0, 1.0);
                let p = a + (b - a) * t;
                (i, p, t, (p - at).norm())
            })
        })
        .min_by(|x, y| x.3.total_cmp(&y.3))
        .map(|(i, p, t, _)| (i, p, t))
}

/// Where a stand's axis (the line through it along its heading) meets taxilane `edge`, and how
/// far along the edge (0 at its start node, 1 at its end): the point an aircraft is pushed back
/// to, or turns in at, so that it stands on the stand aligned as the file places it. `None` where
/// the axis runs within 30 degrees of the edge's line, or meets it off the edge.
fn stand_join(
    network: &Network,
    edge: usize,
    stand: &crate::model::Stand,
) -> Option<(Vector2<f64>, f64)> {
    let e = &network.edges[edge];
    let (a, b) = (network.nodes[e.from].at, network.nodes[e.to].at);
    let along = b - a;
    let axis = Vector2::new(stand.yaw_rad.cos(), stand.yaw_rad.sin());
    let cross = |u: &Vector2<f64>, v: &Vector2<f64>| u.x * v.y - u.y * v.x;
    let denominator = cross(&along, &axis);
    if denominator.abs() < 0.5 * along.norm() {
        return None;
    }
    // a + t (b - a) = stand + s axis, solved for t.
    let t = cross(&(stand.at - a), &axis) / denominator;
    (0.0..=1.0).contains(&t).then(|| (a + along * t, t))
}

/// How much farther than the nearest taxilane a stand's axis may meet the one it is joined to
/// (m): an aircraft is pushed straight back to a taxilane its axis meets rather than dragged
/// across to a nearer one beside it.
const AXIS_JOIN_SLACK_M: f64 = 60.0;

/// Where an aircraft leaves or enters `stand` on the network: the admitting taxilane its axis
/// meets nearest (`stand_join`), when no more than [`AXIS_JOIN_SLACK_M`] farther than the
/// nearest taxilane; else the nearest taxilane's point nearest it. (edge, point, where along.)
fn stand_place(
    graph: &Graph,
    stand: &crate::model::Stand,
    code: SizeClass,
) -> Option<(usize, Vector2<f64>, f64)> {
    let (edge, p, t) = nearest_on_edges(graph, stand.at, code)?;
    let nearest = (p - stand.at).norm();
    let network = graph.network;
    taxilanes(network, code)
        .filter_map(|(i, _)| stand_join(network, i, stand).map(|(k, t)| (i, k, t)))
        .filter(|(_, k, _)| (k - stand.at).norm() <= nearest + AXIS_JOIN_SLACK_M)
        .min_by(|a, b| (a.1 - stand.at).norm().total_cmp(&(b.1 - stand.at).norm()))
        .or(Some((edge, p, t)))
}

/// A stand's place on the network: the edge it leaves or joins by, and where along it.
type OnEdge = Option<(usize, f64)>;

/// Where a route may end: the search graph's targets, the stand it leads into from the last
/// (if it ends at one), and that stand's place on the network.
type Ends = (Vec<usize>, Option<Vector2<f64>>, OnEdge);

fn start_point(
    airport: &Airport,
    graph: &mut Graph,
    from: &Place,
    code: SizeClass,
) -> Result<(usize, OnEdge), String> {
    match from {
        Place::Node(id) => graph
            .network
            .node_by_id(*id)
            .map(|n| (n, None))
            .ok_or_else(|| format!("no network node has id {id}")),
        Place::Runway(number) => runway_node_at_threshold(airport, number).map(|n| (n, None)),
        Place::Stand(name) => {
            let stand = airport.find_stand(name)?;
            let (edge, p, t) = stand_place(graph, stand, code).ok_or_else(|| {
                format!("no taxiway admitting code {code} to leave stand `{name}` by")
            })?;
            let e = graph.network.edges[edge].clone();
            let s = graph.add_point(p);
            graph.add_arc(s, e.to, edge);
            if !e.one_way {
                graph.add_arc(s, e.from, edge);
            }
            Ok((s, Some((edge, t))))
        }
    }
}

fn end_points(
    airport: &Airport,
    graph: &mut Graph,
    to: &Place,
    code: SizeClass,
) -> Result<Ends, String> {
    match to {
        Place::Node(id) => Ok((
            vec![
                graph
                    .network
                    .node_by_id(*id)
                    .ok_or_else(|| format!("no network node has id {id}"))?,
            ],
            None,
            None,
        )),
        Place::Runway(number) => {
            if runway_end(airport, number).is_none() {
                return Err(format!(
                    "no runway end `{number}` (runways: {:?})",
                    airport
                        .runways
                        .iter()
                        .map(crate::model::Runway::name)
                        .collect::<Vec<_>>()
                ));
            }
            let holds = hold_points(graph.network, number);
            if holds.is_empty() {
                return Err(format!(
                    "the network has no hold point of runway {number} (no edge in its zone, 1204)"
                ));
            }
            Ok((holds, None, None))
        }
        Place::Stand(name) => {
            let stand = airport.find_stand(name)?;
            if let Some(class) = stand.size_class.filter(|&c| c < code) {
                return Err(format!(
                    "stand `{name}` takes aircraft up to code {class}, not {code}"
                ));
            }
            let (edge, p, t) = stand_place(graph, stand, code).ok_or_else(|| {
                format!("no taxiway admitting code {code} to reach stand `{name}` by")
            })?;
            let e = graph.network.edges[edge].clone();
            let end = graph.add_point(p);
            graph.add_arc(e.from, end, edge);
            if !e.one_way {
                graph.add_arc(e.to, end, edge);
            }
            Ok((vec![end], Some(stand.at), Some((edge, t))))
        }
    }
}

fn runway_end<'a>(airport: &'a Airport, number: &str) -> Option<(&'a crate::model::Runway, usize)> {
    airport.runways.iter().find_map(|r| {
        r.ends
            .iter()
            .position(|e| e.number == number)
            .map(|i| (r, i))
    })
}

/// The runway node nearest the threshold of end `number`.
fn runway_node_at_threshold(airport: &Airport, number: &str) -> Result<usize, String> {
    let (runway, end) =
        runway_end(airport, number).ok_or_else(|| format!("no runway end `{number}`"))?;
    let threshold = runway.ends[end].at;
    let network = &airport.network;
    network
        .edges
        .iter()
        .filter(|e| e.class == EdgeClass::Runway)
        .flat_map(|e| [e.from, e.to])
        .min_by(|&a, &b| {
            (network.nodes[a].at - threshold)
                .norm()
                .total_cmp(&(network.nodes[b].at - threshold).norm())
        })
        .ok_or_else(|| format!("the network has no runway edge on runway {}", runway.name()))
}

/// Nodes where an edge in the zone of runway end `number` meets a taxiway in no runway's zone:
/// where an aircraft bound for that runway holds short (never on, or in the zone of, another
/// runway).
#[must_use]
pub fn hold_points(network: &Network, number: &str) -> Vec<usize> {
    let mut inside = vec![false; network.nodes.len()];
    let mut outside = vec![false; network.nodes.len()];
    for edge in &network.edges {
        if edge.in_zone_of(number) {
            inside[edge.from] = true;
            inside[edge.to] = true;
        } else if edge.class != EdgeClass::Runway && edge.zone_runways.is_empty() {
            outside[edge.from] = true;
            outside[edge.to] = true;
        }
    }
    let on_a_runway = |i: usize| {
        network
            .edges
            .iter()
            .any(|e| e.class == EdgeClass::Runway && (e.from == i || e.to == i))
    };
    (0..network.nodes.len())
        .filter(|&i| inside[i] && outside[i] && !on_a_runway(i))
        .collect()
}

/// Dijkstra over (arc, stage): the stage counts the taxiways of `via` reached in order.
struct Search<'a> {
    graph: &'a Graph<'a>,
    via: &'a [String],
    /// Per network edge: a runway edge the route may drive without naming it (the runway a
    /// route starting on one leaves by).
    runway_ok: Vec<bool>,
}

#[derive(PartialEq)]
struct Entry {
    cost: f64,
    state: usize,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then(other.state.cmp(&self.state))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Search<'_> {
    /// The stage after driving network edge `edge` (named `name`) at `stage` (None: not
    /// allowed). Stage 0: before the first taxiway of `via` (others may lead to it, not those
    /// listed); stage s in 1..=k: on `via[s - 1]`, going on to `via[s]`; stage k + 1: the list
    /// done, any taxiway to the end. A runway is driven only when listed, or when it is the one
    /// the route starts on, before the list begins.
    fn next_stage(&self, stage: usize, edge: usize, name: &str, runway: bool) -> Option<usize> {
        let k = self.via.len();
        let listed = self.via.iter().any(|v| v == name);
        if runway && !listed && !(self.runway_ok[edge] && stage == 0) {
            return None;
        }
        if name.is_empty() || k == 0 || stage == k + 1 {
            return Some(stage);
        }
        if stage >= 1 && self.via[stage - 1] == name {
            return Some(stage);
        }
        if stage < k && self.via[stage] == name {
            return Some(stage + 1);
        }
        match stage {
            0 if !listed => Some(0),
            s if s == k => Some(k + 1),
            _ => None,
        }
    }

    fn turn_ok(&self, a: &Arc, b: &Arc) -> bool {
        if a.edge == b.edge && a.tail == b.head {
            return false;
        }
        let points = &self.graph.points;
        let (u, v) = (
            points[a.head] - points[a.tail],
            points[b.head] - points[b.tail],
        );
        let cos = u.dot(&v) / (u.norm() * v.norm()).max(1e-12);
        cos >= MAX_DEFLECTION_DEG.to_radians().cos() - 1e-9
    }

    fn run(
        &self,
        start: usize,
        targets: &[usize],
        to: &Place,
        airport: &Airport,
    ) -> Option<Vec<usize>> {
        let stages = self.via.len() + 2;
        let arcs = &self.graph.arcs;
        let mut cost = vec![f64::INFINITY; arcs.len() * stages];
        let mut previous = vec![usize::MAX; arcs.len() * stages];
        let mut heap = BinaryHeap::new();
        let runway = |arc: &Arc| self.graph.network.edges[arc.edge].class == EdgeClass::Runway;
        for &a in &self.graph.leaving[start] {
            let arc = &arcs[a];
            if let Some(stage) = self.next_stage(
                0,
                arc.edge,
                &self.graph.network.edges[arc.edge].name,
                runway(arc),
            ) {
                let state = a * stages + stage;
                cost[state] = arc.length_m;
                heap.push(Entry {
                    cost: arc.length_m,
                    state,
                });
            }
        }
        let finished = |stage: usize| self.via.is_empty() || stage >= self.via.len();
        let mut reached: Vec<(usize, f64)> = Vec::new();
        while let Some(Entry { cost: c, state }) = heap.pop() {
            if c > cost[state] {
                continue;
            }
            let (a, stage) = (state / stages, state % stages);
            let arc = &arcs[a];
            if targets.contains(&arc.head) && finished(stage) {
                reached.push((state, c));
            }
            for &b in &self.graph.leaving[arc.head] {
                let next = &arcs[b];
                if !self.turn_ok(arc, next) {
                    continue;
                }
                let Some(s) = self.next_stage(
                    stage,
                    next.edge,
                    &self.graph.network.edges[next.edge].name,
                    runway(next),
                ) else {
                    continue;
                };
                let (n, nc) = (b * stages + s, c + next.length_m);
                if nc < cost[n] {
                    cost[n] = nc;
                    previous[n] = state;
                    heap.push(Entry { cost: nc, state: n });
                }
            }
        }
        let best = choose_target(&reached, to, airport, self.graph, stages)?;
        let mut path = vec![best / stages];
        let mut state = best;
        while previous[state] != usize::MAX {
            state = previous[state];
            path.push(state / stages);
        }
        path.reverse();
        Some(path)
    }
}

/// The shortest way to each target; bound for a runway, the hold point nearest its threshold
/// (a full-length departure).
fn choose_target(
    reached: &[(usize, f64)],
    to: &Place,
    airport: &Airport,
    graph: &Graph,
    stages: usize,
) -> Option<usize> {
    let head = |state: usize| graph.arcs[state / stages].head;
    match to {
        Place::Runway(number) => {
            let threshold = runway_end(airport, number).map(|(r, i)| r.ends[i].at)?;
            reached
                .iter()
                .min_by(|x, y| {
                    let dx = (graph.points[head(x.0)] - threshold).norm();
                    let dy = (graph.points[head(y.0)] - threshold).norm();
                    dx.total_cmp(&dy).then(x.1.total_cmp(&y.1))
                })
                .map(|x| x.0)
        }
        _ => reached
            .iter()
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map(|x| x.0),
    }
}

fn assemble(
    graph: &Graph,
    start: usize,
    arcs: &[usize],
    lead_in: Option<Vector2<f64>>,
    to: &Place,
) -> NetworkRoute {
    let network = graph.network;
    let node_of = |p: usize| (p < network.nodes.len()).then_some(p);
    let mut points = vec![graph.points[start]];
    let mut nodes = vec![node_of(start)];
    let mut edges = Vec::new();
    let mut taxiways: Vec<String> = Vec::new();
    let mut crossings: Vec<String> = Vec::new();
    for &a in arcs {
        let arc = &graph.arcs[a];
        let edge = &network.edges[arc.edge];
        if (graph.points[arc.head] - points[points.len() - 1]).norm() > 1e-6 {
            points.push(graph.points[arc.head]);
            nodes.push(node_of(arc.head));
            edges.push(Some(arc.edge));
        }
        if !edge.name.is_empty() && taxiways.last() != Some(&edge.name) {
            taxiways.push(edge.name.clone());
        }
        for runway in &edge.zone_runways {
            if !crossings.contains(runway) && !matches!(to, Place::Runway(n) if n == runway) {
                crossings.push(runway.clone());
            }
        }
    }
    if let Some(stand) = lead_in {
        points.push(stand);
        nodes.push(None);
        edges.push(None);
    }
    let length_m = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    NetworkRoute {
        from: String::new(),
        to: String::new(),
        points,
        nodes,
        edges,
        taxiways,
        crossings,
        length_m,
    }
}
