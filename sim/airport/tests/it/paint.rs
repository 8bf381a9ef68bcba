//! Routes on the painted centreline where the network strays from it (`airport::paint`), on
//! small airports drawn in metres for one case each: paint beside an edge, paint ending, no
//! paint, paint too far or crossing, a turn, a runway crossing, odd paint; and the fictional
//! airport, whose network lies on its paint, routed as before.

use airport::model::LineRun;
use airport::paint::{MAX_OFFSET_M, TAPER_DEG};
use airport::{
    Airport, LatLon, LocalFrame, NetworkRoute, PathOptions, Place, RouteRequest, SizeClass,
};
use nalgebra::Vector2;

use super::fixture::xtsm;

type V2 = Vector2<f64>;

/// An airport drawn in metres east and north of its datum.
struct Drawing {
    frame: LocalFrame,
    body: String,
}

impl Drawing {
    fn new() -> Self {
        Self {
            frame: LocalFrame::new(LatLon {
                lat: 43.0,
                lon: -76.0,
            }),
            body: String::new(),
        }
    }

    fn at(&self, x: f64, y: f64) -> String {
        let p = self.frame.to_lat_lon(V2::new(x, y));
        format!("{:.9} {:.9}", p.lat, p.lon)
    }

    fn node(mut self, id: u32, x: f64, y: f64) -> Self {
        self.body += &format!("1201 {} both {id} n{id}\n", self.at(x, y));
        self
    }

    fn edge(mut self, from: u32, to: u32, kind: &str, name: &str) -> Self {
        self.body += &format!("1202 {from} {to} twoway {kind} {name}\n");
        self
    }

    /// A painted line of type `code` through `points`.
    fn paint(mut self, code: u32, points: &[(f64, f64)]) -> Self {
        self.body += "120 line\n";
        for (i, &(x, y)) in points.iter().enumerate() {
            if i + 1 < points.len() {
                self.body += &format!("111 {} {code}\n", self.at(x, y));
            } else {
                self.body += &format!("115 {}\n", self.at(x, y));
            }
        }
        self
    }

    /// A 30 m wide runway 09/27 from `(x0, y)` to `(x1, y)`.
    fn runway(mut self, x0: f64, x1: f64, y: f64) -> Self {
        self.body += &format!(
            "100 30.00 1 0 0.25 1 2 0 09 {} 0 0 3 0 0 0 27 {} 0 0 3 0 0 0\n",
            self.at(x0, y),
            self.at(x1, y)
        );
        self
    }

    fn read(self, name: &str) -> Airport {
        let text = format!(
            "I\n1100 test\n\n1 500 0 0 TEST Test\n1302 datum_lat 43.0\n1302 datum_lon -76.0\n{}99\n",
            self.body
        );
        let path =
            std::env::temp_dir().join(format!("taxi_sim_paint_{name}_{}.dat", std::process::id()));
        std::fs::write(&path, text).expect("write");
        let a = Airport::read(&path, None).expect("reads");
        std::fs::remove_file(&path).ok();
        a
    }
}

fn request(from: &str, to: &str, via: &[&str]) -> RouteRequest {
    RouteRequest {
        from: Place::parse(from),
        to: Place::parse(to),
        via: via.iter().map(|v| (*v).to_string()).collect(),
        code: SizeClass::C,
    }
}

/// The network's route and the route on the paint.
fn routes(a: &Airport, from: &str, to: &str, via: &[&str]) -> (NetworkRoute, NetworkRoute) {
    let r = request(from, to, via);
    let network = airport::find_on_network(a, &r).expect("a route on the network");
    let painted = airport::find(a, &r).expect("a route");
    (network, painted)
}

fn node_at(a: &Airport, r: &NetworkRoute, id: u32) -> V2 {
    let k = a.network.node_by_id(id).expect("node");
    let i = r
        .nodes
        .iter()
        .position(|&n| n == Some(k))
        .expect("on the route");
    r.points[i]
}

/// Distance from `p` to the segment `a`-`b` (to `a` when it has no length).
pub(crate) fn segment_distance(p: V2, a: V2, b: V2) -> f64 {
    let d = b - a;
    let t = if d.norm_squared() > 0.0 {
        ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * t - p).norm()
}

fn polyline_distance(p: V2, line: &[V2]) -> f64 {
    line.windows(2)
        .map(|w| segment_distance(p, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Points along a polyline at most `step` apart.
pub(crate) fn samples(line: &[V2], step: f64) -> Vec<V2> {
    let mut out = Vec::new();
    for w in line.windows(2) {
        let n = ((w[1] - w[0]).norm() / step).ceil().max(1.0) as usize;
        out.extend((0..n).map(|k| w[0] + (w[1] - w[0]) * (k as f64 / n as f64)));
    }
    out.extend(line.last().copied());
    out
}

/// The furthest the route strays from the network's route (m).
fn furthest_from_network(network: &NetworkRoute, painted: &NetworkRoute) -> f64 {
    samples(&painted.points, 0.5)
        .iter()
        .map(|&p| polyline_distance(p, &network.points))
        .fold(0.0, f64::max)
}

/// The route's height (y) where it passes `x` (a route heading east).
fn y_at(r: &NetworkRoute, x: f64) -> f64 {
    r.points
        .windows(2)
        .find(|w| (w[0].x - x) * (w[1].x - x) <= 0.0 && w[0].x != w[1].x)
        .map(|w| w[0].y + (w[1].y - w[0].y) * (x - w[0].x) / (w[1].x - w[0].x))
        .expect("the route passes x")
}

fn drivable(r: &NetworkRoute) {
    for min in [5.0, 12.0] {
        let options = PathOptions {
            turn_radius_m: 30.0,
            max_corner_cut_m: 2.5,
            min_turn_radius_m: min,
            straight_speed_m_s: 8.0,
            lateral_acceleration_m_s2: 1.0,
            deceleration_m_s2: 0.5,
        };
        airport::smooth(r, &options).unwrap_or_else(|e| panic!("{min} m: {e}"));
    }
}

/// Nodes 0, 1, 2 along y = 0 at x = 0, 400, 800 (taxiway A); a centreline 10 m north of the
/// first edge from x = 0 to 300.
fn beside() -> Drawing {
    Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 400.0, 0.0)
        .node(2, 800.0, 0.0)
        .edge(0, 1, "taxiway_E", "A")
        .edge(1, 2, "taxiway_E", "A")
        .paint(1, &[(0.0, 10.0), (300.0, 10.0)])
}

#[test]
fn a_route_lies_on_paint_ten_metres_off_its_edge_and_rejoins_the_network_where_it_ends() {
    let a = beside().read("beside");
    let (network, r) = routes(&a, "node 0", "node 2", &[]);
    // The start moves sideways onto the paint; along it the route is on the paint.
    assert!(
        (r.points[0] - V2::new(0.0, 10.0)).norm() < 0.02,
        "{}",
        r.points[0]
    );
    for x in (1..300).map(f64::from) {
        assert!((y_at(&r, x) - 10.0).abs() < 0.03, "{x}: {}", y_at(&r, x));
    }
    // Where the paint ends it tapers back at 15 degrees, on the network's line 37.3 m on.
    let rejoins = 300.0 + 10.0 / TAPER_DEG.to_radians().tan();
    assert!((y_at(&r, 300.0 + 0.5 * (rejoins - 300.0)) - 5.0).abs() < 0.05);
    for x in [rejoins + 0.1, 350.0, 399.0, 401.0, 600.0, 799.0] {
        assert!(
            (y_at(&r, x) - y_at(&network, x)).abs() < 1e-6,
            "{x}: {}",
            y_at(&r, x)
        );
    }
    // Where no paint runs along an edge, its line is the network's: nodes 1 and 2 stay, and
    // nothing is added between them.
    assert_eq!(node_at(&a, &r, 1), a.network.nodes[1].at);
    assert_eq!(node_at(&a, &r, 2), a.network.nodes[2].at);
    assert_eq!(
        r.points.len() - r.nodes.iter().position(|&n| n == Some(1)).unwrap(),
        2
    );
    assert_eq!(r.edges.len() + 1, r.points.len());
    assert!(furthest_from_network(&network, &r) <= 10.01);
    // Longer by the taper's slant only.
    let taper = rejoins - 300.0;
    let longer = (taper * taper + 100.0).sqrt() - taper;
    assert!(
        (r.length_m - network.length_m - longer).abs() < 0.01,
        "{} {}",
        r.length_m,
        network.length_m
    );
    drivable(&r);
    // The same again.
    assert_eq!(
        airport::find(&a, &request("node 0", "node 2", &[]))
            .unwrap()
            .points,
        r.points
    );
}

#[test]
fn a_node_where_the_route_turns_moves_to_where_the_paint_lines_cross() {
    // An L: east along y = 0, then north along x = 300; its paint 8 m inside the corner.
    let a = Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 300.0, 0.0)
        .node(2, 300.0, 300.0)
        .edge(0, 1, "taxiway_E", "A")
        .edge(1, 2, "taxiway_E", "B")
        .paint(51, &[(0.0, 8.0), (292.0, 8.0), (292.0, 300.0)])
        .read("turn");
    let (network, r) = routes(&a, "node 0", "node 2", &[]);
    let corner = node_at(&a, &r, 1);
    assert!((corner - V2::new(292.0, 8.0)).norm() < 0.02, "{corner}");
    for p in samples(&r.points, 1.0) {
        let off = polyline_distance(
            p,
            &[
                V2::new(0.0, 8.0),
                V2::new(292.0, 8.0),
                V2::new(292.0, 300.0),
            ],
        );
        assert!(off < 0.03, "{p}: {off}");
    }
    assert!(furthest_from_network(&network, &r) <= MAX_OFFSET_M);
    drivable(&r);
}

#[test]
fn a_node_on_a_runway_centreline_moves_to_where_the_paint_crosses_it() {
    // Taxiway W crosses runway 09/27 (along y = 0) at its node 11 on the centreline; W's paint,
    // slanting a little (5 m east of the network at one end, 15 m at the other), crosses the
    // centreline 10 m east of the node - not where the paint is abeam the node (9.99, -0.25).
    let a = Drawing::new()
        .runway(-500.0, 500.0, 0.0)
        .node(20, -500.0, 0.0)
        .node(21, 500.0, 0.0)
        .node(10, 0.0, -200.0)
        .node(11, 0.0, 0.0)
        .node(12, 0.0, 200.0)
        .edge(20, 11, "runway", "09/27")
        .edge(11, 21, "runway", "09/27")
        .edge(10, 11, "taxiway_E", "W")
        .edge(11, 12, "taxiway_E", "W")
        .paint(1, &[(5.0, -200.0), (15.0, 200.0)])
        .read("crossing");
    let (network, r) = routes(&a, "node 10", "node 12", &["W"]);
    assert_eq!(r.taxiways, ["W"]);
    let crossing = node_at(&a, &r, 11);
    assert!((crossing - V2::new(10.0, 0.0)).norm() < 0.02, "{crossing}");
    let paint = [V2::new(5.0, -200.0), V2::new(15.0, 200.0)];
    for p in samples(&r.points, 1.0) {
        assert!(polyline_distance(p, &paint) < 0.03, "{p}");
    }
    assert!(furthest_from_network(&network, &r) <= MAX_OFFSET_M);
    drivable(&r);
}

#[test]
fn paint_far_off_or_across_the_edge_is_passed_over() {
    // Paint 30 m beside the edge, crossing it at right angles, and at 20 degrees to it: the
    // route is the network's, point for point.
    let a = Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 400.0, 0.0)
        .edge(0, 1, "taxiway_E", "A")
        .paint(1, &[(0.0, 30.0), (400.0, 30.0)])
        .paint(1, &[(200.0, -50.0), (200.0, 50.0)])
        .paint(51, &[(250.0, -6.0), (290.0, 8.6)])
        .read("far");
    let (network, r) = routes(&a, "node 0", "node 1", &[]);
    assert_eq!(r.points, network.points);
    assert_eq!(r.nodes, network.nodes);
    // No paint at all: the network's route too.
    let bare = Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 400.0, 0.0)
        .node(2, 400.0, 400.0)
        .edge(0, 1, "taxiway_E", "A")
        .edge(1, 2, "taxiway_E", "A")
        .read("bare");
    let (network, r) = routes(&bare, "node 0", "node 2", &[]);
    assert_eq!(r.points, network.points);
}

#[test]
fn odd_paint_and_odd_routes_are_passed_over() {
    let mut a = beside().read("odd");
    let (_, clean) = routes(&a, "node 0", "node 2", &[]);
    let nan = V2::new(f64::NAN, 5.0);
    for points in [
        vec![],
        vec![V2::new(50.0, 5.0)],
        vec![V2::new(50.0, 5.0), V2::new(50.0, 5.0)],
        vec![nan, V2::new(100.0, 5.0), nan],
        vec![
            V2::new(f64::INFINITY, 0.0),
            V2::new(10.0, f64::NEG_INFINITY),
        ],
    ] {
        a.painted.push(LineRun { code: 1, points });
    }
    let (_, r) = routes(&a, "node 0", "node 2", &[]);
    assert_eq!(r.points, clean.points);
    // A route with a point that is not a number, or its lists out of step, is returned as it is.
    let mut odd = clean.clone();
    odd.points[1] = nan;
    let back = airport::paint::follow(&a, &odd);
    assert!(back.points[1].x.is_nan() && back.points.len() == odd.points.len());
    odd.edges.clear();
    assert_eq!(
        airport::paint::follow(&a, &odd).points.len(),
        odd.points.len()
    );
}

/// The fictional airport's network is drawn on its paint (its painted fillets round the
/// network's corners): every route on it is the network's, point for point, so its routes and
/// paths are as they were.
#[test]
fn routes_on_the_fictional_airport_are_the_networks() {
    let a = xtsm();
    let mut places: Vec<String> = a
        .network
        .nodes
        .iter()
        .map(|n| format!("node {}", n.id))
        .collect();
    places.extend(a.stands.iter().map(|s| s.name.clone()));
    places.extend(["runway 09".to_string(), "runway 27".to_string()]);
    let mut compared = 0;
    for from in &places {
        for to in &places {
            for code in [SizeClass::A, SizeClass::C] {
                let r = RouteRequest {
                    code,
                    ..request(from, to, &[])
                };
                if let (Ok(network), Ok(painted)) =
                    (airport::find_on_network(&a, &r), airport::find(&a, &r))
                {
                    assert_eq!(network.points, painted.points, "{from} -> {to}");
                    compared += 1;
                }
            }
        }
    }
    assert!(compared > 700, "{compared}");
}

/// Nodes 0-4: east along y = 0 to x = 100, a quarter turn north drawn as two chords (node 2 at
/// its middle), then north along x = 200; the paint a 100 m radius curve through the nodes,
/// drawn as two runs meeting at node 2, each drawn `reversed` or not.
fn chorded_curve(reversed: bool) -> Airport {
    let mut points = vec![(0.0, 0.0)];
    points.extend((0..=157).map(|k| {
        let t = (f64::from(k) / 157.0 - 1.0) * std::f64::consts::FRAC_PI_2;
        (100.0 + 100.0 * t.cos(), 100.0 + 100.0 * t.sin())
    }));
    points.push((200.0, 200.0));
    let (mut first, mut second) = (points[..=80].to_vec(), points[80..].to_vec());
    if reversed {
        first.reverse();
        second.reverse();
    }
    let (x2, y2) = points[80];
    Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 100.0, 0.0)
        .node(2, x2, y2)
        .node(3, 200.0, 100.0)
        .node(4, 200.0, 200.0)
        .edge(0, 1, "taxiway_E", "A")
        .edge(1, 2, "taxiway_E", "A")
        .edge(2, 3, "taxiway_E", "A")
        .edge(3, 4, "taxiway_E", "A")
        .paint(1, &second)
        .paint(1, &first)
        .read(if reversed { "chorded_rev" } else { "chorded" })
}

#[test]
fn a_curve_drawn_in_runs_is_followed_whichever_way_they_are_drawn() {
    let routes_of = |reversed: bool| {
        let a = chorded_curve(reversed);
        [("node 0", "node 4"), ("node 4", "node 0")].map(|(from, to)| routes(&a, from, to, &[]).1)
    };
    let (forward, backward) = (routes_of(false), routes_of(true));
    for (f, b) in forward.iter().zip(&backward) {
        assert_eq!(
            f.points.len(),
            b.points.len(),
            "{:?}\n{:?}",
            f.points,
            b.points
        );
        for (p, q) in f.points.iter().zip(&b.points) {
            assert!((p - q).norm() < 1e-6, "{p} {q}");
        }
    }
}

/// A quarter circle round `centre` of `radius` from angle `from` to `to` (degrees), in chords
/// of about 1 m.
fn arc(centre: (f64, f64), radius: f64, from: f64, to: f64) -> Vec<(f64, f64)> {
    let n = ((to - from).abs().to_radians() * radius).ceil() as usize;
    (0..=n)
        .map(|k| {
            let t = (from + (to - from) * k as f64 / n as f64).to_radians();
            (centre.0 + radius * t.cos(), centre.1 + radius * t.sin())
        })
        .collect()
}

#[test]
fn a_turn_at_a_crossing_moves_onto_the_fillet_inside_the_turn() {
    // An L turning north at (300, 0); its paint 4 m inside: four arms of two centrelines
    // crossing at (296, 4), a 20 m fillet from the west arm to the north inside the turn and an
    // 8 m one from the south arm to the east outside it, whose middle is nearer the crossing.
    let a = Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 300.0, 0.0)
        .node(2, 300.0, 300.0)
        .edge(0, 1, "taxiway_E", "A")
        .edge(1, 2, "taxiway_E", "B")
        .paint(1, &[(0.0, 4.0), (276.0, 4.0)])
        .paint(1, &[(296.0, 24.0), (296.0, 300.0)])
        .paint(1, &[(296.0, -100.0), (296.0, -4.0)])
        .paint(1, &[(304.0, 4.0), (400.0, 4.0)])
        .paint(51, &arc((276.0, 24.0), 20.0, -90.0, 0.0))
        .paint(51, &arc((304.0, -4.0), 8.0, 180.0, 90.0))
        .read("x_fillet");
    let (_, r) = routes(&a, "node 0", "node 2", &[]);
    let corner = node_at(&a, &r, 1);
    // The inside fillet's middle.
    let middle = V2::new(276.0, 24.0) + V2::new(1.0, -1.0) * (10.0 * 2f64.sqrt());
    assert!((corner - middle).norm() < 0.1, "{corner}");
    drivable(&r);
}

#[test]
fn a_routes_end_moves_only_onto_paint_abeam_it() {
    // The paint beside the edge starts 40 m along it: the start is not moved onto its line.
    let a = Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 400.0, 0.0)
        .edge(0, 1, "taxiway_E", "A")
        .paint(1, &[(40.0, 10.0), (400.0, 10.0)])
        .read("short_of_start");
    let (network, r) = routes(&a, "node 0", "node 1", &[]);
    assert!(
        (r.points[0] - network.points[0]).norm() < 1e-6,
        "{}",
        r.points[0]
    );
    drivable(&r);
}

#[test]
fn paint_at_absurd_coordinates_is_passed_over() {
    let mut a = beside().read("absurd");
    let (_, clean) = routes(&a, "node 0", "node 2", &[]);
    a.painted.push(LineRun {
        code: 1,
        points: vec![V2::new(-1e154, 5.0), V2::new(1e154, 5.0)],
    });
    let (_, r) = routes(&a, "node 0", "node 2", &[]);
    assert_eq!(r.points, clean.points);
}

/// The route's points from the route point of node `id` on, at most 0.5 m apart.
fn from_node(a: &Airport, r: &NetworkRoute, id: u32) -> Vec<V2> {
    let k = a.network.node_by_id(id).expect("node");
    let i = r
        .nodes
        .iter()
        .position(|&n| n == Some(k))
        .expect("on the route");
    samples(&r.points[i..], 0.5)
}

/// Nodes 0 (0, 0), 1 (100, 0), 2 (100, 100): east, then a left turn north; taxiway A.
fn corner(paint: &[(f64, f64)], name: &str) -> Airport {
    Drawing::new()
        .node(0, 0.0, 0.0)
        .node(1, 100.0, 0.0)
        .node(2, 100.0, 100.0)
        .edge(0, 1, "taxiway_E", "A")
        .edge(1, 2, "taxiway_E", "A")
        .paint(1, paint)
        .read(name)
}

/// Paint along the first leg 10 m off it that ends 10 m short of the corner: the corner moves
/// to where the paint's line, extended, meets the unpainted second leg's network line, so the
/// second leg keeps the network's line; the route still rounds for every turning radius
/// checked and strays no further than the lateral limit.
#[test]
fn paint_ending_before_a_corner_is_extended_to_the_corner() {
    let a = corner(&[(0.0, -10.0), (90.0, -10.0)], "corner");
    let (network, r) = routes(&a, "node 0", "node 2", &[]);
    drivable(&network);
    drivable(&r);
    assert!(furthest_from_network(&network, &r) <= MAX_OFFSET_M);
    assert!(
        (r.points[0] - V2::new(0.0, -10.0)).norm() < 0.02,
        "{}",
        r.points[0]
    );
    for x in (1..100).map(f64::from) {
        assert!((y_at(&r, x) + 10.0).abs() < 0.03, "{x}: {}", y_at(&r, x));
    }
    let corner = node_at(&a, &r, 1);
    assert!((corner - V2::new(100.0, -10.0)).norm() < 0.02, "{corner}");
    let second = from_node(&a, &r, 1);
    assert!(second.len() > 200, "{}", second.len());
    for p in second {
        assert!((p.x - 100.0).abs() < 0.05 && p.y >= -10.02, "{p}");
    }
    assert_eq!(r.points.last(), network.points.last());
}

/// The mirror case: paint along the second leg 10 m off it that starts 10 m past the corner
/// (drawn from the route's end towards it): the corner moves to where the paint's line meets
/// the unpainted first leg's network line, and the first leg stays on it.
#[test]
fn paint_starting_after_a_corner_is_extended_back_to_the_corner() {
    let a = corner(&[(110.0, 100.0), (110.0, 10.0)], "corner_after");
    let (network, r) = routes(&a, "node 0", "node 2", &[]);
    drivable(&network);
    drivable(&r);
    assert!(furthest_from_network(&network, &r) <= MAX_OFFSET_M);
    assert_eq!(r.points[0], network.points[0]);
    for x in (0..110).map(f64::from) {
        // The network's line, to the drawing's round trip through latitude and longitude.
        assert!(y_at(&r, x).abs() < 1e-3, "{x}: {}", y_at(&r, x));
    }
    let corner = node_at(&a, &r, 1);
    assert!((corner - V2::new(110.0, 0.0)).norm() < 0.02, "{corner}");
    let second = from_node(&a, &r, 1);
    assert!(second.len() > 200, "{}", second.len());
    for p in second {
        assert!((p.x - 110.0).abs() < 0.05 && p.y >= -0.02, "{p}");
    }
    // The route's end moves sideways onto the paint abeam it.
    let end = r.points[r.points.len() - 1];
    assert!((end - V2::new(110.0, 100.0)).norm() < 0.02, "{end}");
}
