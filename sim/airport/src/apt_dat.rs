//! The `apt.dat` reader: X-Plane's airport format, versions 1000 through 1200, the rows taxi-sim
//! uses read into latitudes and longitudes as the file has them (`model` puts them in metres).
//!
//! Rows read: airport headers `1`/`16`/`17`, runways `100`, pavement `110` and linear features
//! `120` (boundaries `130` are read past) with their nodes `111`-`116`, windsocks `19`, signs
//! `20`, lighting objects `21`, the taxi routing network `1200`/`1201`/`1202`/`1204`, stands
//! `1300`/`1301`, metadata `1302`. Every other row code is skipped; a row of a code read here
//! that is malformed is an error naming the file, the line and the field (`AirportError::Field`).

use std::path::Path;

use crate::error::AirportError;
use crate::geodesy::LatLon;
use crate::row::Row;

/// The versions read (the number on the file's second line).
pub const VERSIONS: [u32; 5] = [1000, 1050, 1100, 1130, 1200];

/// The first version with taxiway size classes (`taxiway_A`..`taxiway_F`), stand metadata
/// (`1301`) and airport metadata (`1302`).
pub const SIZE_CLASSES_SINCE: u32 = 1050;
/// The first version with the asphalt (20-38) and concrete (50-57) shades.
pub const SURFACE_SHADES_SINCE: u32 = 1200;

/// A file as read: its version and its airports.
#[derive(Debug, Clone)]
pub struct AptDat {
    /// The format version (second line).
    pub version: u32,
    /// The airports, in file order.
    pub airports: Vec<RawAirport>,
}

/// One airport's rows, in latitude and longitude.
#[derive(Debug, Clone, Default)]
pub struct RawAirport {
    /// Line of its header row.
    pub line: usize,
    /// The ICAO (or local) code of the header.
    pub code: String,
    /// Its name.
    pub name: String,
    /// Elevation (ft above mean sea level).
    pub elevation_ft: f64,
    /// `1302` metadata: line, key and value.
    pub metadata: Vec<(usize, String, String)>,
    /// `100` rows.
    pub runways: Vec<RawRunway>,
    /// `110` pavements.
    pub pavements: Vec<RawPavement>,
    /// `120` linear features.
    pub lines: Vec<RawLineFeature>,
    /// `20` signs.
    pub signs: Vec<RawSign>,
    /// `21` lighting objects.
    pub lights: Vec<RawLight>,
    /// `19` windsocks.
    pub windsocks: Vec<LatLon>,
    /// `1201` taxi network nodes.
    pub nodes: Vec<RawNode>,
    /// `1202` taxi network edges (with their `1204` rows).
    pub edges: Vec<RawEdge>,
    /// `1300` stands (with their `1301` row).
    pub stands: Vec<RawStand>,
}

/// A runway end of a `100` row.
#[derive(Debug, Clone)]
pub struct RawRunwayEnd {
    /// Its number (`10`, `28L`).
    pub number: String,
    /// Its centreline point at the runway's end.
    pub at: LatLon,
    /// Displaced threshold (m).
    pub displaced_m: f64,
}

/// A `100` row.
#[derive(Debug, Clone)]
pub struct RawRunway {
    /// Line of the row.
    pub line: usize,
    /// Width (m).
    pub width_m: f64,
    /// Surface code.
    pub surface: u32,
    /// The two ends.
    pub ends: [RawRunwayEnd; 2],
}

/// A node of a pavement outline or a line feature (`111`-`116`).
#[derive(Debug, Clone)]
pub struct RawChainNode {
    /// Line of the row.
    pub line: usize,
    /// The node.
    pub at: LatLon,
    /// The Bezier control point (`112`, `114`, `116`): the curve leaves the node toward it and
    /// arrives at the node from its mirror image.
    pub control: Option<LatLon>,
    /// Painted line type of the segment leaving this node (1-99), if any.
    pub line_type: Option<u32>,
    /// Lighting type of the segment leaving this node (101-199), if any.
    pub lighting: Option<u32>,
}

/// A chain of nodes: a ring (closed by `113`/`114`) or an open string (ended by `115`/`116`).
#[derive(Debug, Clone, Default)]
pub struct RawChain {
    /// Its nodes.
    pub nodes: Vec<RawChainNode>,
    /// Closed (the last node joins the first).
    pub closed: bool,
}

/// A `110` pavement: its first ring the outline, the others holes.
#[derive(Debug, Clone)]
pub struct RawPavement {
    /// Line of the header.
    pub line: usize,
    /// Surface code.
    pub surface: u32,
    /// Its name.
    pub name: String,
    /// Its rings.
    pub rings: Vec<RawChain>,
}

/// A `120` linear feature.
#[derive(Debug, Clone)]
pub struct RawLineFeature {
    /// Line of the header.
    pub line: usize,
    /// Its name.
    pub name: String,
    /// Its chains.
    pub chains: Vec<RawChain>,
}

/// A `20` sign.
#[derive(Debug, Clone)]
pub struct RawSign {
    /// Line of the row.
    pub line: usize,
    /// Where it stands.
    pub at: LatLon,
    /// Its heading (degrees true).
    pub heading_deg: f64,
    /// Size code 1-5.
    pub size: u32,
    /// Its text in the sign syntax (`{@Y}A{@R}10-28`).
    pub text: String,
}

/// A `21` lighting object.
#[derive(Debug, Clone)]
pub struct RawLight {
    /// Line of the row.
    pub line: usize,
    /// Where it stands.
    pub at: LatLon,
    /// Type code (1 VASI, 2 PAPI-4L, 3 PAPI-4R, ...).
    pub kind: u32,
    /// Heading (degrees true).
    pub heading_deg: f64,
}

/// A `1201` node.
#[derive(Debug, Clone)]
pub struct RawNode {
    /// Line of the row.
    pub line: usize,
    /// Where.
    pub at: LatLon,
    /// `dest`, `init`, `both` or `junc`.
    pub usage: String,
    /// Its id (what edges name).
    pub id: u32,
    /// Its name (often empty).
    pub name: String,
}

/// A `1202` edge with its `1204` rows.
#[derive(Debug, Clone)]
pub struct RawEdge {
    /// Line of the row.
    pub line: usize,
    /// Start node id.
    pub from: u32,
    /// End node id.
    pub to: u32,
    /// `oneway` (from -> to only).
    pub one_way: bool,
    /// `runway`, `taxiway` (version 1000; taken as class E, as WorldEditor does) or
    /// `taxiway_A`..`taxiway_F`.
    pub kind: String,
    /// The taxiway's (or runway's) name.
    pub name: String,
    /// `1204` rows: (`arrival` | `departure` | `ils`, runway numbers).
    pub zones: Vec<(String, Vec<String>)>,
}

/// A `1300` stand with its `1301` row.
#[derive(Debug, Clone)]
pub struct RawStand {
    /// Line of the row.
    pub line: usize,
    /// Where the aircraft's reference point parks.
    pub at: LatLon,
    /// Its heading (degrees true).
    pub heading_deg: f64,
    /// `gate`, `hangar`, `misc` or `tie_down`.
    pub kind: String,
    /// Aircraft types admitted (`heavy|jets|turboprops|props|helos|fighters` or `all`).
    pub aircraft: String,
    /// Its name.
    pub name: String,
    /// `1301` ICAO size class (`A`..`F`), if given.
    pub size_class: Option<char>,
    /// `1301` operation type (`airline`, `cargo`, `general_aviation`, `military`, `none`).
    pub operation: Option<String>,
}

/// What node rows are being added to.
#[derive(Clone, Copy)]
enum Open {
    None,
    Pavement,
    Line,
    Boundary,
}

/// Reads `file`.
///
/// # Errors
/// The file cannot be read, its header is not a version read here, or a row of a code read here
/// is malformed (file, line, field).
pub fn read(file: &Path) -> Result<AptDat, AirportError> {
    let text = std::fs::read(file).map_err(|source| AirportError::Io {
        file: file.to_path_buf(),
        source,
    })?;
    let text = String::from_utf8_lossy(&text);
    parse(file, &text)
}

/// Parses the text of `file`.
///
/// # Errors
/// As [`read`].
pub fn parse(file: &Path, text: &str) -> Result<AptDat, AirportError> {
    let mut lines = text.lines().enumerate();
    let version = header(file, &mut lines)?;
    let mut reader = Reader {
        file,
        version,
        airports: Vec::new(),
        open: Open::None,
        chain: None,
        chain_line: 0,
    };
    for (index, line) in lines {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let Some(first) = fields.first() else {
            continue;
        };
        let Ok(code) = first.parse::<u32>() else {
            return Err(AirportError::File {
                file: file.to_path_buf(),
                line: index + 1,
                what: format!("`{first}` is not a row code (a whole number)"),
            });
        };
        if code == 99 {
            break;
        }
        reader.row(&Row {
            file,
            line: index + 1,
            code,
            fields,
        })?;
    }
    reader.close_feature()?;
    if reader.airports.is_empty() {
        return Err(AirportError::File {
            file: file.to_path_buf(),
            line: 1,
            what: "no airport (row 1, 16 or 17) in the file".into(),
        });
    }
    Ok(AptDat {
        version,
        airports: reader.airports,
    })
}

fn header<'a>(
    file: &Path,
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
) -> Result<u32, AirportError> {
    let error = |line: usize, what: String| AirportError::File {
        file: file.to_path_buf(),
        line,
        what,
    };
    let origin = lines
        .next()
        .map(|(_, l)| l.trim_start_matches('\u{feff}').trim())
        .unwrap_or_default();
    if origin != "I" && origin != "A" {
        return Err(error(
            1,
            format!("the first line is `{origin}`, not `I` or `A`: not an apt.dat file"),
        ));
    }
    let second = lines.next().map(|(_, l)| l).unwrap_or_default();
    let token = second.split_whitespace().next().unwrap_or_default();
    match token.parse::<u32>() {
        Ok(version) if VERSIONS.contains(&version) => Ok(version),
        Ok(version) => Err(error(
            2,
            format!(
                "apt.dat version {version} is not read here (versions {VERSIONS:?}); re-save the airport with WorldEditor"
            ),
        )),
        Err(_) => Err(error(
            2,
            format!("`{token}` is not an apt.dat version number"),
        )),
    }
}

struct Reader<'a> {
    file: &'a Path,
    version: u32,
    airports: Vec<RawAirport>,
    open: Open,
    chain: Option<RawChain>,
    chain_line: usize,
}

impl Reader<'_> {
    fn airport(&mut self, row: &Row) -> Result<&mut RawAirport, AirportError> {
        self.airports
            .last_mut()
            .ok_or_else(|| row.error(0, "row code", "before any airport header (row 1, 16 or 17)"))
    }

    fn row(&mut self, row: &Row) -> Result<(), AirportError> {
        if (111..=116).contains(&row.code) {
            return self.node(row);
        }
        self.close_feature()?;
        if matches!(row.code, 1301 | 1302) && self.version < SIZE_CLASSES_SINCE {
            return Err(row.error(
                0,
                "row code",
                format!(
                    "row {} is version {SIZE_CLASSES_SINCE} and later; the file says {}",
                    row.code, self.version
                ),
            ));
        }
        match row.code {
            1 | 16 | 17 => self.airports.push(RawAirport {
                line: row.line,
                elevation_ft: row.number(1, "elevation")?,
                code: row.text(4, "airport code")?.to_string(),
                name: row.rest(5),
                ..RawAirport::default()
            }),
            100 => {
                let runway = runway(row, self.version)?;
                self.airport(row)?.runways.push(runway);
            }
            110 => {
                let pavement = RawPavement {
                    line: row.line,
                    surface: surface(row, 1, self.version)?,
                    name: row.rest(4),
                    rings: Vec::new(),
                };
                self.airport(row)?.pavements.push(pavement);
                self.open_feature(row, Open::Pavement);
            }
            120 => {
                let feature = RawLineFeature {
                    line: row.line,
                    name: row.rest(1),
                    chains: Vec::new(),
                };
                self.airport(row)?.lines.push(feature);
                self.open_feature(row, Open::Line);
            }
            130 => {
                self.airport(row)?;
                self.open_feature(row, Open::Boundary);
            }
            19 => {
                let at = row.lat_lon(1)?;
                self.airport(row)?.windsocks.push(at);
            }
            20 => {
                let sign = sign(row)?;
                self.airport(row)?.signs.push(sign);
            }
            21 => {
                let light = RawLight {
                    line: row.line,
                    at: row.lat_lon(1)?,
                    kind: row.integer(3, "type")?,
                    heading_deg: row.number(4, "heading")?,
                };
                self.airport(row)?.lights.push(light);
            }
            1201..=1302 => return self.network_row(row),
            _ => {}
        }
        Ok(())
    }

    /// The taxi network's and the stands' rows, and metadata.
    fn network_row(&mut self, row: &Row) -> Result<(), AirportError> {
        match row.code {
            1201 => {
                let node = RawNode {
                    line: row.line,
                    at: row.lat_lon(1)?,
                    usage: one_of(row, 3, "usage", &["dest", "init", "both", "junc"])?.to_string(),
                    id: row.integer(4, "node id")?,
                    name: row.rest(5),
                };
                self.airport(row)?.nodes.push(node);
            }
            1202 => {
                let edge = edge(row, self.version)?;
                self.airport(row)?.edges.push(edge);
            }
            1204 => {
                let zone =
                    one_of(row, 1, "active zone", &["arrival", "departure", "ils"])?.to_string();
                let runways = row
                    .text(2, "runways")?
                    .split(',')
                    .map(str::to_string)
                    .collect();
                let edge = self.airport(row)?.edges.last_mut().ok_or_else(|| {
                    row.error(
                        0,
                        "row code",
                        "an active zone (1204) before any taxi edge (1202)",
                    )
                })?;
                edge.zones.push((zone, runways));
            }
            1300 => {
                let stand = RawStand {
                    line: row.line,
                    at: row.lat_lon(1)?,
                    heading_deg: row.number(3, "heading")?,
                    kind: one_of(
                        row,
                        4,
                        "location type",
                        &["gate", "hangar", "misc", "tie_down", "tie-down"],
                    )?
                    .to_string(),
                    aircraft: row.text(5, "aircraft types")?.to_string(),
                    name: row.rest(6),
                    size_class: None,
                    operation: None,
                };
                self.airport(row)?.stands.push(stand);
            }
            1301 => {
                let class = size_class(row, 1)?;
                let operation = row.text(2, "operation type")?.to_string();
                let stand = self.airport(row)?.stands.last_mut().ok_or_else(|| {
                    row.error(
                        0,
                        "row code",
                        "stand metadata (1301) before any stand (1300)",
                    )
                })?;
                stand.size_class = Some(class);
                stand.operation = Some(operation);
            }
            1302 => {
                let key = row.text(1, "key")?.to_string();
                let value = row.rest(2);
                self.airport(row)?.metadata.push((row.line, key, value));
            }
            _ => {}
        }
        Ok(())
    }

    fn open_feature(&mut self, row: &Row, open: Open) {
        self.open = open;
        self.chain = None;
        self.chain_line = row.line;
    }

    fn node(&mut self, row: &Row) -> Result<(), AirportError> {
        if matches!(self.open, Open::None) {
            return Err(row.error(
                0,
                "row code",
                "a node outside a pavement (110), line (120) or boundary (130)",
            ));
        }
        let bezier = matches!(row.code, 112 | 114 | 116);
        let at = row.lat_lon(1)?;
        let (control, attributes) = if bezier {
            (Some(row.lat_lon(3)?), 5)
        } else {
            (None, 3)
        };
        // Zero, one or two styles, told apart by value: 1-99 a painted line, 101-199 lights, 0 none.
        let (mut line_type, mut lighting) = (None, None);
        for index in attributes..(attributes + 2).min(row.fields.len()) {
            match row.integer(index, "style")? {
                0 => {}
                t @ 1..=99 if line_type.is_none() => line_type = Some(t),
                t @ 101..=199 if lighting.is_none() => lighting = Some(t),
                t => return Err(row.error(index, "style", format!("{t} is not a painted line type (1-99) or lighting type (101-199), or repeats its kind"))),
            }
        }
        let chain = self.chain.get_or_insert_with(RawChain::default);
        chain.nodes.push(RawChainNode {
            line: row.line,
            at,
            control,
            line_type,
            lighting,
        });
        if row.code >= 113 {
            let mut chain = self.chain.take().unwrap_or_default();
            chain.closed = row.code <= 114;
            self.finish_chain(row, chain)?;
        }
        Ok(())
    }

    fn finish_chain(&mut self, row: &Row, chain: RawChain) -> Result<(), AirportError> {
        let needed = if chain.closed { 3 } else { 2 };
        if chain.nodes.len() < needed {
            return Err(row.error(
                0,
                "row code",
                format!(
                    "a {} of {} node(s): at least {needed} are needed",
                    if chain.closed { "ring" } else { "string" },
                    chain.nodes.len()
                ),
            ));
        }
        let open = self.open;
        let airport = self.airport(row)?;
        match open {
            Open::Pavement => {
                if !chain.closed {
                    return Err(row.error(0, "row code", "a pavement's ring ends with an end node (115/116), not a closing node (113/114)"));
                }
                if let Some(pavement) = airport.pavements.last_mut() {
                    pavement.rings.push(chain);
                }
            }
            Open::Line => {
                if let Some(feature) = airport.lines.last_mut() {
                    feature.chains.push(chain);
                }
            }
            Open::Boundary | Open::None => {}
        }
        Ok(())
    }

    /// A feature ends at the next row that is not a node: an unfinished chain is an error.
    fn close_feature(&mut self) -> Result<(), AirportError> {
        if let Some(chain) = self.chain.take()
            && !chain.nodes.is_empty()
        {
            let line = chain.nodes.last().map_or(self.chain_line, |n| n.line);
            return Err(AirportError::File {
                file: self.file.to_path_buf(),
                line,
                what: format!(
                    "the feature begun on line {} ends without a closing (113/114) or end (115/116) node",
                    self.chain_line
                ),
            });
        }
        self.open = Open::None;
        Ok(())
    }
}

fn one_of<'r>(
    row: &'r Row,
    index: usize,
    field: &'static str,
    allowed: &[&str],
) -> Result<&'r str, AirportError> {
    let text = row.text(index, field)?;
    if allowed.contains(&text) {
        Ok(text)
    } else {
        Err(row.error(index, field, format!("`{text}` is not one of {allowed:?}")))
    }
}

fn size_class(row: &Row, index: usize) -> Result<char, AirportError> {
    let text = row.text(index, "size class")?;
    match text.chars().collect::<Vec<_>>()[..] {
        [c] if ('A'..='F').contains(&c) => Ok(c),
        _ => Err(row.error(
            index,
            "size class",
            format!("`{text}` is not an ICAO size class A..F"),
        )),
    }
}

/// A surface code the version knows.
fn surface(row: &Row, index: usize, version: u32) -> Result<u32, AirportError> {
    let code = row.integer(index, "surface type")?;
    let classic = matches!(code, 1..=5 | 12..=15);
    let shade = matches!(code, 20..=38 | 50..=57);
    if classic || (shade && version >= SURFACE_SHADES_SINCE) {
        return Ok(code);
    }
    let why = if shade {
        format!(
            "the asphalt and concrete shades are version {SURFACE_SHADES_SINCE} and later; the file says {version}"
        )
    } else {
        "not a surface code (1-5, 12-15, 20-38, 50-57)".to_string()
    };
    Err(row.error(index, "surface type", format!("{code}: {why}")))
}

fn runway(row: &Row, version: u32) -> Result<RawRunway, AirportError> {
    let end = |base: usize| -> Result<RawRunwayEnd, AirportError> {
        let displaced_m = row.number(base + 3, "displaced threshold")?;
        if displaced_m < 0.0 {
            return Err(row.error(
                base + 3,
                "displaced threshold",
                format!("{displaced_m} is negative"),
            ));
        }
        Ok(RawRunwayEnd {
            number: row.text(base, "runway number")?.to_string(),
            at: row.lat_lon(base + 1)?,
            displaced_m,
        })
    };
    Ok(RawRunway {
        line: row.line,
        width_m: row.positive(1, "width")?,
        surface: surface(row, 2, version)?,
        ends: [end(8)?, end(17)?],
    })
}

fn sign(row: &Row) -> Result<RawSign, AirportError> {
    let size = row.integer(5, "size")?;
    if !(1..=5).contains(&size) {
        return Err(row.error(5, "size", format!("{size} is not a sign size 1-5")));
    }
    let text = row.rest(6);
    if text.is_empty() {
        return Err(row.error(6, "text", "missing: a sign has a text"));
    }
    Ok(RawSign {
        line: row.line,
        at: row.lat_lon(1)?,
        heading_deg: row.number(3, "heading")?,
        size,
        text,
    })
}

fn edge(row: &Row, version: u32) -> Result<RawEdge, AirportError> {
    let direction = one_of(row, 3, "direction", &["oneway", "twoway"])?;
    let kind = row.text(4, "type")?;
    let sized = kind
        .strip_prefix("taxiway_")
        .is_some_and(|c| matches!(c, "A" | "B" | "C" | "D" | "E" | "F"));
    if !(kind == "runway" || kind == "taxiway" || sized) {
        return Err(row.error(
            4,
            "type",
            format!("`{kind}` is not `runway`, `taxiway` or `taxiway_A`..`taxiway_F`"),
        ));
    }
    if sized && version < SIZE_CLASSES_SINCE {
        return Err(row.error(4, "type", format!("`{kind}`: size classes are version {SIZE_CLASSES_SINCE} and later; the file says {version}")));
    }
    Ok(RawEdge {
        line: row.line,
        from: row.integer(1, "start node")?,
        to: row.integer(2, "end node")?,
        one_way: direction == "oneway",
        kind: kind.to_string(),
        name: row.rest(5),
        zones: Vec::new(),
    })
}
