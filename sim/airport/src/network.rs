//! The taxi routing network (`1201` nodes, `1202` edges with their `1204` runway zones) as a graph
//! in metres, and a route on it ([`NetworkRoute`]: what `route` finds, `paint` moves and `path`
//! smooths, so each of them names it here).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use nalgebra::Vector2;

use crate::apt_dat::RawAirport;
use crate::error::AirportError;
use crate::geodesy::LocalFrame;
use crate::size::SizeClass;

/// A network node.
#[derive(Debug, Clone)]
pub struct Node {
    /// Its id in the file.
    pub id: u32,
    /// Where.
    pub at: Vector2<f64>,
    /// `dest`, `init`, `both` or `junc`.
    pub usage: String,
    /// Its name (often empty).
    pub name: String,
}

/// What an edge is, and the largest aircraft a taxiway takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeClass {
    /// Part of a runway.
    Runway,
    /// A taxiway and the largest code letter it takes (version 1000's `taxiway`: E, as
    /// WorldEditor takes it).
    Taxiway(SizeClass),
}

/// An edge.
#[derive(Debug, Clone)]
pub struct Edge {
    /// Line of its `1202` row.
    pub line: usize,
    /// Index of its start node in [`Network::nodes`].
    pub from: usize,
    /// Index of its end node.
    pub to: usize,
    /// Driven from -> to only.
    pub one_way: bool,
    /// Runway or taxiway, and the taxiway's size.
    pub class: EdgeClass,
    /// The taxiway's (or runway's) name; may be empty.
    pub name: String,
    /// Runway ends whose active zone it lies in (`1204`, any of arrival, departure, ILS).
    pub zone_runways: Vec<String>,
}

impl Edge {
    /// Whether an aircraft of code `code` may use it.
    #[must_use]
    pub fn admits(&self, code: SizeClass) -> bool {
        match self.class {
            EdgeClass::Runway => true,
            EdgeClass::Taxiway(class) => class >= code,
        }
    }

    /// Whether it lies in the active zone of runway end `number`.
    #[must_use]
    pub fn in_zone_of(&self, number: &str) -> bool {
        self.zone_runways.iter().any(|r| r == number)
    }
}

/// The network.
#[derive(Debug, Clone, Default)]
pub struct Network {
    /// Nodes.
    pub nodes: Vec<Node>,
    /// Edges.
    pub edges: Vec<Edge>,
}

impl Network {
    /// The network of `raw`'s `1201`/`1202`/`1204` rows.
    ///
    /// # Errors
    /// Two nodes with one id; an edge naming a node that is not there, or joining a node to
    /// itself.
    pub fn from_raw(
        file: &Path,
        raw: &RawAirport,
        frame: &LocalFrame,
    ) -> Result<Self, AirportError> {
        let mut index: HashMap<u32, usize> = HashMap::new();
        let mut nodes = Vec::with_capacity(raw.nodes.len());
        for node in &raw.nodes {
            if let Some(&first) = index.get(&node.id) {
                return Err(AirportError::Field {
                    file: file.to_path_buf(),
                    line: node.line,
                    code: 1201,
                    index: 4,
                    field: "node id",
                    what: format!(
                        "{} is already the id of the node on line {}",
                        node.id, raw.nodes[first].line
                    ),
                });
            }
            index.insert(node.id, nodes.len());
            nodes.push(Node {
                id: node.id,
                at: frame.to_local(node.at),
                usage: node.usage.clone(),
                name: node.name.clone(),
            });
        }
        let mut edges = Vec::with_capacity(raw.edges.len());
        for edge in &raw.edges {
            let find = |id: u32, field_index: usize, field: &'static str| {
                index.get(&id).copied().ok_or_else(|| AirportError::Field {
                    file: file.to_path_buf(),
                    line: edge.line,
                    code: 1202,
                    index: field_index,
                    field,
                    what: format!("no taxi node (1201) has id {id}"),
                })
            };
            let (from, to) = (
                find(edge.from, 1, "start node")?,
                find(edge.to, 2, "end node")?,
            );
            if from == to {
                return Err(AirportError::Field {
                    file: file.to_path_buf(),
                    line: edge.line,
                    code: 1202,
                    index: 2,
                    field: "end node",
                    what: format!("the edge joins node {} to itself", edge.from),
                });
            }
            let class = match edge.kind.strip_prefix("taxiway_") {
                _ if edge.kind == "runway" => EdgeClass::Runway,
                Some(letter) => EdgeClass::Taxiway(
                    letter
                        .chars()
                        .next()
                        .and_then(SizeClass::from_letter)
                        .unwrap_or(SizeClass::E),
                ),
                None => EdgeClass::Taxiway(SizeClass::E),
            };
            let zone_runways = edge
                .zones
                .iter()
                .flat_map(|(_, runways)| runways.iter().cloned())
                .collect();
            edges.push(Edge {
                line: edge.line,
                from,
                to,
                one_way: edge.one_way,
                class,
                name: edge.name.clone(),
                zone_runways,
            });
        }
        Ok(Self { nodes, edges })
    }

    /// An edge's length (m).
    #[must_use]
    pub fn edge_length_m(&self, edge: &Edge) -> f64 {
        (self.nodes[edge.to].at - self.nodes[edge.from].at).norm()
    }

    /// Every edge's length, summed (m).
    #[must_use]
    pub fn length_m(&self) -> f64 {
        self.edges.iter().map(|e| self.edge_length_m(e)).sum()
    }

    /// Taxiway names (runway edges left out) with their edges' total length (m).
    #[must_use]
    pub fn taxiways(&self) -> BTreeMap<String, f64> {
        let mut names = BTreeMap::new();
        for edge in self
            .edges
            .iter()
            .filter(|e| e.class != EdgeClass::Runway && !e.name.is_empty())
        {
            *names.entry(edge.name.clone()).or_insert(0.0) += self.edge_length_m(edge);
        }
        names
    }

    /// The number of connected components (edges taken both ways).
    #[must_use]
    pub fn components(&self) -> usize {
        let mut parent: Vec<usize> = (0..self.nodes.len()).collect();
        fn root(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        for edge in &self.edges {
            let (a, b) = (root(&mut parent, edge.from), root(&mut parent, edge.to));
            parent[a] = b;
        }
        (0..self.nodes.len())
            .filter(|&i| root(&mut parent, i) == i)
            .count()
    }

    /// The node with id `id`.
    #[must_use]
    pub fn node_by_id(&self, id: u32) -> Option<usize> {
        self.nodes.iter().position(|n| n.id == id)
    }
}

/// A route on the network (moved onto the paint by [`crate::route::find`]), before smoothing.
#[derive(Debug, Clone)]
pub struct NetworkRoute {
    /// Where it starts, as asked.
    pub from: String,
    /// Where it ends, as asked.
    pub to: String,
    /// Its corner points: start, the nodes passed, end (a stand: the point on the taxilane
    /// abeam it, then the stand); following the paint, the points between where it leaves and
    /// rejoins a network edge's line.
    pub points: Vec<Vector2<f64>>,
    /// The network node of each point, if it is one (where the paint moved it, a node is no
    /// longer exactly at the network's position).
    pub nodes: Vec<Option<usize>>,
    /// The network edge each leg (`points[i]` to `points[i + 1]`) runs along; `None` for the
    /// lead-in to a stand.
    pub edges: Vec<Option<usize>>,
    /// Taxiway names in the order driven (each run once).
    pub taxiways: Vec<String>,
    /// Runway ends whose zones it enters on the way (runway crossings).
    pub crossings: Vec<String>,
    /// Length (m).
    pub length_m: f64,
}
