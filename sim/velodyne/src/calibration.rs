//! Each laser's corrections, indexed by the channel's place in a block (its DSR number): the
//! sensors' built-in tables (HDL-32E and VLP-16 user manuals: vertical angles only) or a
//! VeloView calibration file (its boost-serialization XML: `distLSB_` and, per laser `px`,
//! `id_`, `vertCorrection_`, `rotCorrection_` in degrees and `distCorrection_`,
//! `vertOffsetCorrection_`, `horizOffsetCorrection_` in centimetres).

use std::path::Path;

use crate::{Product, VelodyneError};

/// The HDL-32E's vertical angles by channel, degrees (manual, firing order; VeloView's
/// `HDL-32.xml` and the ROS driver's `32db.yaml` agree to 0.01 degree): the lower and the
/// upper bank interleaved.
const HDL32E_DEG: [f64; 32] = [
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33, -25.33, -4.00, -24.00, -2.67,
    -22.67, -1.33, -21.33, 0.00, -20.00, 1.33, -18.67, 2.67, -17.33, 4.00, -16.00, 5.33, -14.67,
    6.67, -13.33, 8.00, -12.00, 9.33, -10.67, 10.67,
];

/// The VLP-16's vertical angles by channel, degrees (manual): two firing sequences of 16 per
/// block.
const VLP16_DEG: [f64; 16] = [
    -15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0, 15.0,
];

/// A sensor's lasers.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// Vertical angle of each laser, degrees, by channel number.
    pub vertical_deg: Vec<f64>,
    /// Each laser's azimuth correction, degrees (subtracted from the block's azimuth).
    pub rotation_deg: Vec<f64>,
    /// Each laser's distance correction, metres (added to the distance).
    pub distance_offset_m: Vec<f64>,
    /// Each laser's vertical offset from the sensor's centre, metres.
    pub vertical_offset_m: Vec<f64>,
    /// Each laser's horizontal offset from the sensor's centre, metres.
    pub horizontal_offset_m: Vec<f64>,
    /// Metres per unit of a packet's distance.
    pub distance_unit_m: f64,
}

impl Calibration {
    /// The built-in table of `product` (`None` for a packet that does not say).
    pub fn built_in(product: Product) -> Option<Calibration> {
        let table: &[f64] = match product {
            Product::Hdl32e => &HDL32E_DEG,
            Product::Vlp16 => &VLP16_DEG,
            Product::Unspecified => return None,
        };
        Some(Self::with_vertical(table.to_vec()))
    }

    fn with_vertical(vertical_deg: Vec<f64>) -> Calibration {
        let n = vertical_deg.len();
        Calibration {
            vertical_deg,
            rotation_deg: vec![0.0; n],
            distance_offset_m: vec![0.0; n],
            vertical_offset_m: vec![0.0; n],
            horizontal_offset_m: vec![0.0; n],
            distance_unit_m: crate::packet::DISTANCE_UNIT_M,
        }
    }

    /// The number of lasers.
    pub fn lasers(&self) -> usize {
        self.vertical_deg.len()
    }

    /// Reads a VeloView calibration file for a sensor of `lasers` lasers (its ids 0 to
    /// `lasers - 1`; the HDL-32E's file holds 64 entries, the rest zero placeholders).
    pub fn from_veloview_xml(path: &Path, lasers: usize) -> Result<Calibration, VelodyneError> {
        let text = std::fs::read_to_string(path).map_err(|source| VelodyneError::Io {
            file: path.to_path_buf(),
            source,
        })?;
        let bad = |at: usize, what: String| VelodyneError::File {
            file: path.to_path_buf(),
            what: format!("line {}: {what}", line_at(&text, at)),
        };
        let entries = read_xml(&text).map_err(|(line, what)| bad(line, what))?;
        if entries.lasers.is_empty() {
            return Err(VelodyneError::File {
                file: path.to_path_buf(),
                what: "no laser entries (`px`): not a VeloView calibration file".into(),
            });
        }
        let mut out = Self::with_vertical(vec![f64::NAN; lasers]);
        let mut seen = vec![false; lasers];
        if let Some(lsb) = entries.dist_lsb_cm {
            if !(lsb > 0.0 && lsb <= 10.0) {
                return Err(bad(
                    entries.dist_lsb_at,
                    format!("distLSB_ {lsb}: not a length of 0 to 10 cm"),
                ));
            }
            out.distance_unit_m = lsb / 100.0;
        }
        for px in &entries.lasers {
            let Some(id) = px.id else {
                return Err(bad(px.at, "a laser (px) without id_".into()));
            };
            if id >= lasers {
                continue;
            }
            let Some(vertical) = px.vertical_deg else {
                return Err(bad(px.at, format!("laser {id}: no vertCorrection_")));
            };
            if !(-90.0 < vertical && vertical < 90.0) {
                return Err(bad(
                    px.at,
                    format!(
                        "laser {id}: vertCorrection_ {vertical}: not an angle between -90 and 90 degrees"
                    ),
                ));
            }
            for (name, v) in [
                ("distCorrection_", px.distance_cm),
                ("vertOffsetCorrection_", px.vertical_offset_cm),
                ("horizOffsetCorrection_", px.horizontal_offset_cm),
            ] {
                if v.is_some_and(|v| v.abs() > 100.0) {
                    return Err(bad(
                        px.at,
                        format!("laser {id}: {name} {} cm: beyond a metre", v.unwrap_or(0.0)),
                    ));
                }
            }
            let cm = |v: Option<f64>| v.unwrap_or(0.0) / 100.0;
            out.vertical_deg[id] = vertical;
            out.rotation_deg[id] = px.rotation_deg.unwrap_or(0.0);
            out.distance_offset_m[id] = cm(px.distance_cm);
            out.vertical_offset_m[id] = cm(px.vertical_offset_cm);
            out.horizontal_offset_m[id] = cm(px.horizontal_offset_cm);
            seen[id] = true;
        }
        let missing: Vec<usize> = (0..lasers).filter(|&i| !seen[i]).collect();
        if !missing.is_empty() {
            return Err(VelodyneError::File {
                file: path.to_path_buf(),
                what: format!(
                    "lasers missing: {missing:?} (the sensor has {lasers}; {} read)",
                    entries.lasers.len()
                ),
            });
        }
        Ok(out)
    }
}

/// One `px` entry of a VeloView file.
#[derive(Default)]
struct Px {
    /// Byte offset of its start in the file.
    at: usize,
    id: Option<usize>,
    vertical_deg: Option<f64>,
    rotation_deg: Option<f64>,
    distance_cm: Option<f64>,
    vertical_offset_cm: Option<f64>,
    horizontal_offset_cm: Option<f64>,
}

/// What a VeloView file says.
#[derive(Default)]
struct Entries {
    dist_lsb_cm: Option<f64>,
    dist_lsb_at: usize,
    lasers: Vec<Px>,
}

/// The line of byte offset `at` in `text`, from 1 (counted only for an error's message).
fn line_at(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The entries of a VeloView file; an error is (byte offset, what).
fn read_xml(text: &str) -> Result<Entries, (usize, String)> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    let mut out = Entries::default();
    let mut stack: Vec<String> = Vec::new();
    let mut px: Option<Px> = None;
    loop {
        let pos = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| (reader.error_position() as usize, format!("not XML: {e}")))?;
        match event {
            Event::Start(e) => {
                let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
                if name == "px" {
                    px = Some(Px {
                        at: pos as usize,
                        ..Px::default()
                    });
                }
                stack.push(name);
            }
            Event::End(_) => {
                if stack.pop().as_deref() == Some("px")
                    && let Some(p) = px.take()
                {
                    out.lasers.push(p);
                }
            }
            Event::Text(t) => {
                let Some(field) = stack.last() else { continue };
                let value = t
                    .decode()
                    .map_err(|e| (pos as usize, format!("{field}: {e}")))?;
                let value = quick_xml::escape::unescape(&value)
                    .map_err(|e| (pos as usize, format!("{field}: {e}")))?;
                let value = value.trim();
                if value.is_empty() {
                    continue;
                }
                let number = || {
                    value
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            (
                                pos as usize,
                                format!("{field}: {value:?} is not a finite number"),
                            )
                        })
                };
                match (field.as_str(), px.as_mut()) {
                    ("distLSB_", _) => {
                        out.dist_lsb_cm = Some(number()?);
                        out.dist_lsb_at = pos as usize;
                    }
                    ("id_", Some(p)) => {
                        let id = number()?;
                        if id < 0.0 || id.fract() != 0.0 || id > 1024.0 {
                            return Err((pos as usize, format!("id_ {value}: not a laser number")));
                        }
                        p.id = Some(id as usize);
                    }
                    ("vertCorrection_", Some(p)) => p.vertical_deg = Some(number()?),
                    ("rotCorrection_", Some(p)) => p.rotation_deg = Some(number()?),
                    ("distCorrection_", Some(p)) => p.distance_cm = Some(number()?),
                    ("vertOffsetCorrection_", Some(p)) => p.vertical_offset_cm = Some(number()?),
                    ("horizOffsetCorrection_", Some(p)) => p.horizontal_offset_cm = Some(number()?),
                    _ => {}
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    Ok(out)
}
