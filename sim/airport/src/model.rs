//! An airport in metres: the rows of one airport of an `apt.dat` put in the local frame at its
//! datum (`1302 datum_lat/datum_lon`; the first runway's midpoint when the file has none).

use std::path::{Path, PathBuf};

use nalgebra::Vector2;

use crate::apt_dat::{self, RawAirport, RawChain};
use crate::bezier::{self, LocalNode};
use crate::error::AirportError;
use crate::geodesy::{LatLon, LocalFrame};
use crate::network::Network;
use crate::size::SizeClass;

/// A pavement's or runway's surface, from its code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Surface {
    /// 1, and 1200's asphalt shades 20-38.
    Asphalt,
    /// 2, and 1200's concrete shades 50-57.
    Concrete,
    /// 3 grass, 4 dirt, 5 gravel, 12 dry lakebed.
    Unpaved,
    /// 13.
    Water,
    /// 14.
    Snow,
    /// 15: an outline that carries markings only; the ground under it shows.
    Transparent,
    /// Anything else.
    Other,
}

impl Surface {
    /// The surface of a code.
    #[must_use]
    pub fn of(code: u32) -> Self {
        match code {
            1 | 20..=38 => Self::Asphalt,
            2 | 50..=57 => Self::Concrete,
            3 | 4 | 5 | 12 => Self::Unpaved,
            13 => Self::Water,
            14 => Self::Snow,
            15 => Self::Transparent,
            _ => Self::Other,
        }
    }
}

/// A runway end.
#[derive(Debug, Clone)]
pub struct RunwayEnd {
    /// Its number (`10`, `28L`).
    pub number: String,
    /// The centreline at the runway's end.
    pub at: Vector2<f64>,
    /// Displaced threshold (m).
    pub displaced_m: f64,
}

/// A runway.
#[derive(Debug, Clone)]
pub struct Runway {
    /// Width (m).
    pub width_m: f64,
    /// Surface.
    pub surface: Surface,
    /// Its two ends.
    pub ends: [RunwayEnd; 2],
}

impl Runway {
    /// End to end along the centreline (m).
    #[must_use]
    pub fn length_m(&self) -> f64 {
        (self.ends[1].at - self.ends[0].at).norm()
    }

    /// `10/28`.
    #[must_use]
    pub fn name(&self) -> String {
        format!("{}/{}", self.ends[0].number, self.ends[1].number)
    }
}

/// A pavement: an outline and its holes, counter-clockwise or not as the file has them.
#[derive(Debug, Clone)]
pub struct Pavement {
    /// Its name.
    pub name: String,
    /// Its surface.
    pub surface: Surface,
    /// The outline.
    pub outline: Vec<Vector2<f64>>,
    /// Holes in it.
    pub holes: Vec<Vec<Vector2<f64>>>,
}

/// A run of painted line or of lights along a line feature or a pavement's edge.
#[derive(Debug, Clone)]
pub struct LineRun {
    /// The line type (1-99) or lighting type (101-199).
    pub code: u32,
    /// Its points.
    pub points: Vec<Vector2<f64>>,
}

/// Painted line types (a few): what the localizer, the picture and the routes use (apt.dat's line
/// type table: 1-9 yellow markings, 51-59 the same with a black border for contrast).
pub mod line_type {
    /// Solid yellow taxiway centreline.
    pub const TAXIWAY_CENTRELINE: u32 = 1;
    /// Solid yellow centreline with a broken yellow line each side: a taxiway centreline in a
    /// runway's safety zone.
    pub const SAFETY_ZONE_CENTRELINE: u32 = 7;
    /// [`TAXIWAY_CENTRELINE`] with a black border.
    pub const TAXIWAY_CENTRELINE_BORDERED: u32 = 51;
    /// [`SAFETY_ZONE_CENTRELINE`] with a black border.
    pub const SAFETY_ZONE_CENTRELINE_BORDERED: u32 = 57;

    /// Whether line type `code` is a painted taxiway centreline (1, 7, 51, 57): the line pilots
    /// taxi along.
    #[must_use]
    pub fn is_taxiway_centreline(code: u32) -> bool {
        matches!(
            code,
            TAXIWAY_CENTRELINE
                | SAFETY_ZONE_CENTRELINE
                | TAXIWAY_CENTRELINE_BORDERED
                | SAFETY_ZONE_CENTRELINE_BORDERED
        )
    }
    /// Runway hold-short line (two solid, two dashed yellow).
    pub const RUNWAY_HOLD: u32 = 4;
    /// Taxiway edge (double solid yellow).
    pub const TAXIWAY_EDGE: u32 = 3;
    /// Taxiway edge lights (blue).
    pub const EDGE_LIGHTS: u32 = 102;
}

/// A sign (`20`).
#[derive(Debug, Clone)]
pub struct Sign {
    /// Where it stands.
    pub at: Vector2<f64>,
    /// Heading of its face's normal in the local frame (rad from east).
    pub yaw_rad: f64,
    /// Size code 1-5.
    pub size: u32,
    /// Its text as the file has it.
    pub text: String,
}

/// A lighting object (`21`: VASI, PAPI, ...).
#[derive(Debug, Clone)]
pub struct LightObject {
    /// Where it stands.
    pub at: Vector2<f64>,
    /// Type code.
    pub kind: u32,
    /// Heading in the local frame (rad from east).
    pub yaw_rad: f64,
}

/// A stand (`1300` + `1301`).
#[derive(Debug, Clone)]
pub struct Stand {
    /// Its name (`Gate 1 South A`).
    pub name: String,
    /// Its row's line in the file.
    pub line: usize,
    /// Where the parked aircraft's reference point is.
    pub at: Vector2<f64>,
    /// The parked aircraft's heading in the local frame (rad from east).
    pub yaw_rad: f64,
    /// `gate`, `hangar`, `misc`, `tie-down`.
    pub kind: String,
    /// Aircraft types admitted.
    pub aircraft: String,
    /// ICAO size class of the largest aircraft it takes, when given.
    pub size_class: Option<SizeClass>,
    /// Operation type, when given.
    pub operation: Option<String>,
}

/// One airport in the local frame.
#[derive(Debug, Clone)]
pub struct Airport {
    /// The file it was read from.
    pub file: PathBuf,
    /// The file's format version.
    pub version: u32,
    /// Its code (`KSYR`).
    pub code: String,
    /// Its name.
    pub name: String,
    /// Elevation (m above mean sea level).
    pub elevation_m: f64,
    /// The local frame (x east, y north, origin at the datum).
    pub frame: LocalFrame,
    /// Runways.
    pub runways: Vec<Runway>,
    /// Pavements (taxiways, aprons).
    pub pavements: Vec<Pavement>,
    /// Painted lines.
    pub painted: Vec<LineRun>,
    /// Lighted lines.
    pub lighted: Vec<LineRun>,
    /// Signs.
    pub signs: Vec<Sign>,
    /// Lighting objects.
    pub lights: Vec<LightObject>,
    /// Windsocks.
    pub windsocks: Vec<Vector2<f64>>,
    /// The taxi routing network.
    pub network: Network,
    /// Stands.
    pub stands: Vec<Stand>,
}

impl Airport {
    /// Reads the airport `code` of `file` (the file's only airport when `None`).
    ///
    /// # Errors
    /// As [`apt_dat::read`]; the airport is not in the file, or the file has several and none was
    /// named; a datum or network reference that is wrong (file, line, field).
    pub fn read(file: &Path, code: Option<&str>) -> Result<Self, AirportError> {
        let dat = apt_dat::read(file)?;
        let codes: Vec<&str> = dat.airports.iter().map(|a| a.code.as_str()).collect();
        let error = |what: String| AirportError::File {
            file: file.to_path_buf(),
            line: 1,
            what,
        };
        let raw = match code {
            Some(code) => dat
                .airports
                .iter()
                .find(|a| a.code == code)
                .ok_or_else(|| {
                    error(format!(
                        "no airport `{code}` in the file (it has {codes:?})"
                    ))
                })?,
            None if dat.airports.len() == 1 => &dat.airports[0],
            None => {
                return Err(error(format!(
                    "the file has {} airports ({codes:?}): name one",
                    dat.airports.len()
                )));
            }
        };
        Self::from_raw(file, dat.version, raw)
    }

    /// The airport of `raw` rows.
    ///
    /// # Errors
    /// A malformed datum, or a network edge naming a node that is not there.
    pub fn from_raw(file: &Path, version: u32, raw: &RawAirport) -> Result<Self, AirportError> {
        let frame = LocalFrame::new(datum(file, raw)?);
        let local = |p: LatLon| frame.to_local(p);
        let runways = raw
            .runways
            .iter()
            .map(|r| Runway {
                width_m: r.width_m,
                surface: Surface::of(r.surface),
                ends: r.ends.clone().map(|e| RunwayEnd {
                    number: e.number,
                    at: local(e.at),
                    displaced_m: e.displaced_m,
                }),
            })
            .collect();
        let (mut painted, mut lighted) = (Vec::new(), Vec::new());
        let mut pavements = Vec::new();
        for pavement in &raw.pavements {
            let rings: Vec<Vec<Vector2<f64>>> = pavement
                .rings
                .iter()
                .map(|ring| chain_points(&frame, ring))
                .collect();
            for ring in &pavement.rings {
                line_runs(&frame, ring, &mut painted, &mut lighted);
            }
            let mut rings = rings.into_iter();
            if let Some(outline) = rings.next() {
                pavements.push(Pavement {
                    name: pavement.name.clone(),
                    surface: Surface::of(pavement.surface),
                    outline,
                    holes: rings.collect(),
                });
            }
        }
        for feature in &raw.lines {
            for chain in &feature.chains {
                line_runs(&frame, chain, &mut painted, &mut lighted);
            }
        }
        let heading = |deg: f64, at: LatLon| frame.heading_to_yaw(deg, at);
        Ok(Self {
            file: file.to_path_buf(),
            version,
            code: raw.code.clone(),
            name: raw.name.clone(),
            elevation_m: raw.elevation_ft * 0.3048,
            runways,
            pavements,
            painted,
            lighted,
            signs: raw
                .signs
                .iter()
                .map(|s| Sign {
                    at: local(s.at),
                    yaw_rad: heading(s.heading_deg, s.at),
                    size: s.size,
                    text: s.text.clone(),
                })
                .collect(),
            lights: raw
                .lights
                .iter()
                .map(|l| LightObject {
                    at: local(l.at),
                    kind: l.kind,
                    yaw_rad: heading(l.heading_deg, l.at),
                })
                .collect(),
            windsocks: raw.windsocks.iter().map(|&w| local(w)).collect(),
            network: Network::from_raw(file, raw, &frame)?,
            stands: raw
                .stands
                .iter()
                .map(|s| Stand {
                    name: s.name.clone(),
                    line: s.line,
                    at: local(s.at),
                    yaw_rad: heading(s.heading_deg, s.at),
                    kind: s.kind.clone(),
                    aircraft: s.aircraft.clone(),
                    size_class: s.size_class.and_then(SizeClass::from_letter),
                    operation: s.operation.clone(),
                })
                .collect(),
            frame,
        })
    }

    /// The stand called `name`; `None` when no stand is, or more than one is (see
    /// [`Self::find_stand`], which says which).
    #[must_use]
    pub fn stand(&self, name: &str) -> Option<&Stand> {
        self.find_stand(name).ok()
    }

    /// The stand called `name`, or why not: no stand is (the error lists the stands), or several
    /// are - a file may name two stands alike -, and the error lists each (its line and where it
    /// is) and how to pick one: `name#k`, the k-th stand of that name in file order.
    pub fn find_stand(&self, name: &str) -> Result<&Stand, String> {
        let (base, pick) = match name.rsplit_once('#') {
            Some((base, k)) if !base.is_empty() => match k.trim().parse::<usize>() {
                Ok(k) => (base, Some(k)),
                Err(_) => (name, None),
            },
            _ => (name, None),
        };
        let named: Vec<&Stand> = self.stands.iter().filter(|s| s.name == base).collect();
        let list = |stands: &[&Stand]| {
            stands
                .iter()
                .enumerate()
                .map(|(k, s)| {
                    format!(
                        "`{}#{}` (line {}, at ({:.1}, {:.1}) m)",
                        s.name,
                        k + 1,
                        s.line,
                        s.at.x,
                        s.at.y
                    )
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        match (named.as_slice(), pick) {
            ([], _) => Err(format!(
                "no stand `{base}` at {} (its stands: {:?})",
                self.code,
                self.stands
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
            )),
            ([one], None) => Ok(one),
            (_, None) => Err(format!(
                "stand `{base}` is ambiguous: {} stands at {} have that name: {}; pick one by \
                 its number in file order",
                named.len(),
                self.code,
                list(&named)
            )),
            (_, Some(k)) => named.get(k.wrapping_sub(1)).copied().ok_or_else(|| {
                format!(
                    "stand `{name}`: {} has {} stand(s) named `{base}`: {}",
                    self.code,
                    named.len(),
                    list(&named)
                )
            }),
        }
    }

    /// The lower-left and upper-right corners of everything in it (m).
    #[must_use]
    pub fn extent(&self) -> (Vector2<f64>, Vector2<f64>) {
        let mut points: Vec<Vector2<f64>> = self
            .pavements
            .iter()
            .flat_map(|p| p.outline.iter().copied())
            .collect();
        points.extend(
            self.runways
                .iter()
                .flat_map(|r| r.ends.iter().map(|e| e.at)),
        );
        points.extend(self.network.nodes.iter().map(|n| n.at));
        points.extend(self.stands.iter().map(|s| s.at));
        let mut low = Vector2::repeat(f64::INFINITY);
        let mut high = Vector2::repeat(f64::NEG_INFINITY);
        for p in points {
            low = low.inf(&p);
            high = high.sup(&p);
        }
        if low.x > high.x {
            (Vector2::zeros(), Vector2::zeros())
        } else {
            (low, high)
        }
    }
}

fn datum(file: &Path, raw: &RawAirport) -> Result<LatLon, AirportError> {
    let find = |key: &str| raw.metadata.iter().find(|(_, k, _)| k == key);
    let parse =
        |(line, key, value): &(usize, String, String), range: f64| -> Result<f64, AirportError> {
            match value.trim().parse::<f64>() {
                Ok(v) if v.is_finite() && v.abs() <= range => Ok(v),
                _ => Err(AirportError::Field {
                    file: file.to_path_buf(),
                    line: *line,
                    code: 1302,
                    index: 2,
                    field: "value",
                    what: format!("{key} `{value}` is not a number within +-{range} degrees"),
                }),
            }
        };
    if let (Some(lat), Some(lon)) = (find("datum_lat"), find("datum_lon")) {
        return Ok(LatLon {
            lat: parse(lat, 90.0)?,
            lon: parse(lon, 180.0)?,
        });
    }
    if let Some(runway) = raw.runways.first() {
        let [a, b] = [runway.ends[0].at, runway.ends[1].at];
        return Ok(LatLon {
            lat: 0.5 * (a.lat + b.lat),
            lon: 0.5 * (a.lon + b.lon),
        });
    }
    raw.nodes.first().map(|n| n.at).or_else(|| raw.stands.first().map(|s| s.at)).ok_or_else(|| AirportError::File {
        file: file.to_path_buf(),
        line: raw.line,
        what: format!("airport {} has no datum (1302 datum_lat/datum_lon), runway, taxi node or stand to place it", raw.code),
    })
}

fn local_nodes(frame: &LocalFrame, chain: &RawChain) -> Vec<LocalNode> {
    chain
        .nodes
        .iter()
        .map(|n| LocalNode {
            at: frame.to_local(n.at),
            control: n.control.map(|c| frame.to_local(c)),
        })
        .collect()
}

fn chain_points(frame: &LocalFrame, chain: &RawChain) -> Vec<Vector2<f64>> {
    bezier::polyline(&local_nodes(frame, chain), chain.closed)
}

/// The runs of one line type and of one lighting type along a chain: each node's attributes
/// hold for the segment that leaves it.
fn line_runs(
    frame: &LocalFrame,
    chain: &RawChain,
    painted: &mut Vec<LineRun>,
    lighted: &mut Vec<LineRun>,
) {
    let nodes = local_nodes(frame, chain);
    let count = nodes.len();
    let segments = if chain.closed {
        count
    } else {
        count.saturating_sub(1)
    };
    for (attribute, out) in [(0, painted), (1, lighted)] {
        let mut run: Option<LineRun> = None;
        for i in 0..segments {
            let raw = &chain.nodes[i];
            let code = if attribute == 0 {
                raw.line_type
            } else {
                raw.lighting
            };
            let next = nodes[(i + 1) % count];
            match (code, run.as_mut()) {
                (Some(c), Some(r)) if r.code == c => {
                    r.points
                        .extend(bezier::segment(nodes[i], next).into_iter().skip(1));
                    r.points.push(next.at);
                }
                (code, _) => {
                    out.extend(run.take());
                    if let Some(c) = code {
                        let mut points = bezier::segment(nodes[i], next);
                        points.push(next.at);
                        run = Some(LineRun { code: c, points });
                    }
                }
            }
        }
        out.extend(run);
    }
}
