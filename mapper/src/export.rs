//! Map files for other tools: ROS `map_server` maps (PGM + YAML), PNG pictures, NumPy `.npy`.
//!
//! ROS maps follow `map_saver`'s trinary convention so Nav2 and RViz load them as they are:
//! binary PGM (`P5`), rows written top (highest y) first, 254 free, 0 occupied, 205 unknown;
//! the YAML's `origin` is the world position of the lower-left pixel, and its thresholds are
//! map_saver's (0.65 / 0.196) so 205 reads back as unknown. `.npy` arrays are float32,
//! shape (rows, columns), row 0 = lowest y (so `array[iy, ix]` matches the grid's cells).
//! Every file is written atomically. A picture larger than memory should hold (a whole route's
//! level) is written row by row with [`PngRows`], never held whole.

use std::path::{Path, PathBuf};

use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
use image::{ExtendedColorType, ImageEncoder};
use serde::{Deserialize, Serialize};

use crate::blocks::{persist_synced, temp_beside, write_atomically};
use crate::error::{MapError, Result};
use crate::grid::{Grid, GridGeometry};
use crate::odm::DistanceMap;

/// Pixel values of a trinary ROS map.
pub const ROS_FREE: u8 = 254;
/// Occupied pixel.
pub const ROS_OCCUPIED: u8 = 0;
/// Unknown pixel.
pub const ROS_UNKNOWN: u8 = 205;

/// A cell of a trinary map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Trinary {
    /// Known free.
    Free,
    /// Known occupied.
    Occupied,
    /// Not observed or undecided.
    Unknown,
}

/// Thresholds of the trinary classification (map_saver's defaults 0.65 / 0.25).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrinaryThresholds {
    /// p above this is occupied.
    pub occupied: f32,
    /// p below this is free.
    pub free: f32,
}

impl Default for TrinaryThresholds {
    fn default() -> Self {
        TrinaryThresholds {
            occupied: 0.65,
            free: 0.25,
        }
    }
}

impl TrinaryThresholds {
    /// The ROS map pixel of a probability (negative = unknown).
    pub fn pixel(&self, p: f32) -> u8 {
        pixel(self.classify(p))
    }
    /// Classifies a probability (negative = unknown, CARMEN's -1).
    pub fn classify(&self, p: f32) -> Trinary {
        if p.is_nan() || p < 0.0 {
            Trinary::Unknown
        } else if p > self.occupied {
            Trinary::Occupied
        } else if p < self.free {
            Trinary::Free
        } else {
            Trinary::Unknown
        }
    }
}

fn pixel(t: Trinary) -> u8 {
    match t {
        Trinary::Free => ROS_FREE,
        Trinary::Occupied => ROS_OCCUPIED,
        Trinary::Unknown => ROS_UNKNOWN,
    }
}

/// Pixels top row first (image order) from a grid whose row 0 is the lowest y.
fn image_rows<T>(grid: &Grid<T>, f: impl Fn(&T) -> u8) -> Vec<u8> {
    let (w, h) = (grid.geometry().width(), grid.geometry().height());
    let mut out = Vec::with_capacity(w * h);
    for y in (0..h).rev() {
        out.extend(grid.data()[y * w..(y + 1) * w].iter().map(&f));
    }
    out
}

fn dims(g: &GridGeometry) -> Result<(u32, u32)> {
    let w = u32::try_from(g.width())
        .map_err(|_| MapError::invalid("grid width", "too large for an image"))?;
    let h = u32::try_from(g.height())
        .map_err(|_| MapError::invalid("grid height", "too large for an image"))?;
    Ok((w, h))
}

/// The YAML side of a ROS map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RosMapYaml {
    /// Image file, relative to the YAML's directory.
    pub image: String,
    /// Metres per pixel.
    pub resolution: f64,
    /// World pose (x, y, yaw) of the lower-left pixel.
    pub origin: [f64; 3],
    /// 1 if white means occupied.
    pub negate: i32,
    /// p above this is occupied.
    pub occupied_thresh: f64,
    /// p below this is free.
    pub free_thresh: f64,
    /// `trinary`, `scale` or `raw`.
    #[serde(default)]
    pub mode: Option<String>,
}

/// The image file of a ROS map (`map_server` reads both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RosImage {
    /// `<stem>.pgm`, binary graymap: what `map_saver` writes.
    Pgm,
    /// `<stem>.ros.png`, the same pixels losslessly compressed (a large, mostly unknown map is a
    /// hundredth of the PGM).
    Png,
}

/// Writes a level's probabilities (-1 = unknown) as a ROS map: `<stem>.yaml` naming `<stem>.pgm`.
/// Returns the PGM's path.
pub fn write_ros_map(
    probabilities: &Grid<f32>,
    yaml_path: &Path,
    thresholds: TrinaryThresholds,
) -> Result<PathBuf> {
    write_ros_map_as(probabilities, yaml_path, thresholds, RosImage::Pgm)
}

/// [`write_ros_map`] with the image format chosen. Returns the image's path.
pub fn write_ros_map_as(
    probabilities: &Grid<f32>,
    yaml_path: &Path,
    thresholds: TrinaryThresholds,
    format: RosImage,
) -> Result<PathBuf> {
    let g = probabilities.geometry();
    let (w, h) = dims(g)?;
    let pgm_path = ros_image_path(yaml_path, format);
    let pixels = image_rows(probabilities, |p| thresholds.pixel(*p));
    match format {
        RosImage::Pgm => {
            let mut pgm = Vec::new();
            PnmEncoder::new(&mut pgm)
                .with_subtype(PnmSubtype::Graymap(SampleEncoding::Binary))
                .write_image(&pixels, w, h, ExtendedColorType::L8)
                .map_err(|e| MapError::bad_file(&pgm_path, e.to_string()))?;
            write_atomically(&pgm_path, &pgm)?;
        }
        RosImage::Png => write_png_l8(&pixels, g, &pgm_path)?,
    }
    write_ros_map_yaml(yaml_path, g, format)?;
    Ok(pgm_path)
}

/// The image file a ROS map's YAML names: `<stem>.pgm` or `<stem>.ros.png`.
pub fn ros_image_path(yaml_path: &Path, format: RosImage) -> PathBuf {
    match format {
        RosImage::Pgm => yaml_path.with_extension("pgm"),
        RosImage::Png => yaml_path.with_extension("ros.png"),
    }
}

/// Writes the YAML of a ROS map whose trinary image (written apart, e.g. with [`PngRows`] and
/// [`TrinaryThresholds::pixel`]) covers `geometry`, top row first.
pub fn write_ros_map_yaml(
    yaml_path: &Path,
    geometry: &GridGeometry,
    format: RosImage,
) -> Result<()> {
    dims(geometry)?;
    let image = ros_image_path(yaml_path, format);
    let image_name = image
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| {
            MapError::invalid(
                "map path",
                format!("{} has no usable file name", yaml_path.display()),
            )
        })?
        .to_string();
    let yaml = RosMapYaml {
        image: image_name,
        resolution: geometry.resolution_m(),
        origin: [geometry.origin_m().x, geometry.origin_m().y, 0.0],
        negate: 0,
        // The thresholds the *reader* applies to pixels (map_saver's): 254 -> 0.004 free,
        // 0 -> 1.0 occupied, 205 -> 0.196, not below 0.196, so unknown. A 0.25 here would
        // turn every unknown pixel into free space on reload.
        occupied_thresh: 0.65,
        free_thresh: 0.196,
        mode: Some("trinary".into()),
    };
    let text = serde_yaml_ng::to_string(&yaml)
        .map_err(|e| MapError::bad_file(yaml_path, e.to_string()))?;
    write_atomically(yaml_path, text.as_bytes())
}

/// Reads a ROS map (YAML + image) into a trinary grid, as `map_server` interprets it.
pub fn read_ros_map(yaml_path: &Path) -> Result<Grid<Trinary>> {
    let text = std::fs::read_to_string(yaml_path).map_err(|e| MapError::io(yaml_path, e))?;
    let yaml: RosMapYaml =
        serde_yaml_ng::from_str(&text).map_err(|e| MapError::bad_file(yaml_path, e.to_string()))?;
    if yaml.mode.as_deref().is_some_and(|m| m != "trinary") {
        return Err(MapError::bad_file(
            yaml_path,
            format!("field `mode` = {:?}: only trinary maps are read", yaml.mode),
        ));
    }
    let image_path = yaml_path
        .parent()
        .unwrap_or(Path::new("."))
        .join(&yaml.image);
    let image = image::ImageReader::open(&image_path)
        .map_err(|e| MapError::io(&image_path, e))?
        .with_guessed_format()
        .map_err(|e| MapError::io(&image_path, e))?
        .decode()
        .map_err(|e| MapError::bad_file(&image_path, e.to_string()))?
        .to_luma8();
    let (w, h) = (image.width() as usize, image.height() as usize);
    let origin = nalgebra::Point2::new(yaml.origin[0], yaml.origin[1]);
    let geometry = GridGeometry::new(origin, yaml.resolution, w, h)
        .map_err(|e| MapError::bad_file(yaml_path, e.to_string()))?;
    let mut data = vec![Trinary::Unknown; w * h];
    for (y_img, row) in image.rows().enumerate() {
        let y = h - 1 - y_img;
        for (x, px) in row.enumerate() {
            let v = px.0[0] as f64;
            let p = if yaml.negate != 0 {
                v / 255.0
            } else {
                (255.0 - v) / 255.0
            };
            data[y * w + x] = if p > yaml.occupied_thresh {
                Trinary::Occupied
            } else if p < yaml.free_thresh {
                Trinary::Free
            } else {
                Trinary::Unknown
            };
        }
    }
    Grid::from_vec(geometry, data)
}

/// The picture's pixel of a probability: white free, black occupied, grey (205) unknown.
pub fn occupancy_pixel(p: f32) -> u8 {
    if p < 0.0 || p.is_nan() {
        ROS_UNKNOWN
    } else {
        ((1.0 - p) * 255.0).round() as u8
    }
}

/// Writes a level's probabilities as a PNG (white free, black occupied, grey unknown; north up).
pub fn write_occupancy_png(probabilities: &Grid<f32>, path: &Path) -> Result<()> {
    let pixels = image_rows(probabilities, |p| occupancy_pixel(*p));
    write_png_l8(&pixels, probabilities.geometry(), path)
}

/// An 8-bit grey PNG written row by row, top row first, so a picture is never held whole: the
/// rows go through the encoder into a temporary file beside `path`, renamed over it by
/// [`PngRows::finish`] (a picture left unfinished is never seen at `path`). The same pixels as
/// [`write_png_l8`] would write, compressed the same way.
pub struct PngRows {
    path: PathBuf,
    tmp: tempfile::NamedTempFile,
    stream: png::StreamWriter<'static, std::fs::File>,
    width: usize,
    rows_left: usize,
}

impl PngRows {
    /// Starts a `width` x `height` picture at `path`.
    pub fn create(path: &Path, width: usize, height: usize) -> Result<Self> {
        let too_large = |what| MapError::invalid(what, "too large for an image");
        let w = u32::try_from(width).map_err(|_| too_large("picture width"))?;
        let h = u32::try_from(height).map_err(|_| too_large("picture height"))?;
        let tmp = temp_beside(path)?;
        let file = tmp
            .as_file()
            .try_clone()
            .map_err(|e| MapError::io(tmp.path(), e))?;
        let png_err = |e: png::EncodingError| MapError::bad_file(path, e.to_string());
        let mut encoder = png::Encoder::new(file, w, h);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        encoder.set_filter(png::Filter::Adaptive);
        let stream = encoder
            .write_header()
            .and_then(png::Writer::into_stream_writer)
            .map_err(png_err)?;
        Ok(PngRows {
            path: path.to_path_buf(),
            tmp,
            stream,
            width,
            rows_left: height,
        })
    }
    /// Appends the next row (the top one first); it must hold `width` pixels.
    pub fn write_row(&mut self, row: &[u8]) -> Result<()> {
        if row.len() != self.width || self.rows_left == 0 {
            return Err(MapError::invalid(
                "picture row",
                format!(
                    "{}: a row of {} pixels with {} rows left, the picture is {} wide",
                    self.path.display(),
                    row.len(),
                    self.rows_left,
                    self.width
                ),
            ));
        }
        use std::io::Write as _;
        self.stream
            .write_all(row)
            .map_err(|e| MapError::io(&self.path, e))?;
        self.rows_left -= 1;
        Ok(())
    }
    /// Ends the picture (every row written) and puts it at its path.
    pub fn finish(self) -> Result<()> {
        if self.rows_left != 0 {
            return Err(MapError::invalid(
                "picture",
                format!(
                    "{}: {} rows never written",
                    self.path.display(),
                    self.rows_left
                ),
            ));
        }
        self.stream
            .finish()
            .map_err(|e| MapError::bad_file(&self.path, e.to_string()))?;
        persist_synced(self.tmp, &self.path)
    }
}

/// Writes a distance map as a PNG (black at obstacles, white at the cap; north up).
pub fn write_distance_png(map: &DistanceMap, path: &Path) -> Result<()> {
    let cap = map.max_distance_m();
    let pixels = image_rows(map.grid(), |d| {
        ((d / cap).clamp(0.0, 1.0).sqrt() * 255.0).round() as u8
    });
    write_png_l8(&pixels, map.grid().geometry(), path)
}

fn write_png_l8(pixels: &[u8], g: &GridGeometry, path: &Path) -> Result<()> {
    let (w, h) = dims(g)?;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(pixels, w, h, ExtendedColorType::L8)
        .map_err(|e| MapError::bad_file(path, e.to_string()))?;
    write_atomically(path, &png)
}

/// Writes a float grid as a NumPy `.npy` array (float32, shape (rows, columns), row 0 = lowest y).
pub fn write_npy(grid: &Grid<f32>, path: &Path) -> Result<()> {
    let (w, h) = (grid.geometry().width(), grid.geometry().height());
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({h}, {w}), }}");
    // Magic (6) + version (2) + length (2) + header + '\n' must be a multiple of 64.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 4 * w * h);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in grid.data() {
        out.extend_from_slice(&v.to_le_bytes());
    }
    write_atomically(path, &out)
}

/// Reads a float32 `.npy` written by [`write_npy`]: (rows, columns, values row after row).
pub fn read_npy(path: &Path) -> Result<(usize, usize, Vec<f32>)> {
    let bytes = std::fs::read(path).map_err(|e| MapError::io(path, e))?;
    let bad = |why: &str| MapError::bad_file(path, why.to_string());
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("not a .npy file"));
    }
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(
        bytes
            .get(10..10 + header_len)
            .ok_or_else(|| bad("truncated header"))?,
    )
    .map_err(|_| bad("header is not text"))?;
    if !header.contains("'descr': '<f4'") || !header.contains("'fortran_order': False") {
        return Err(bad("only little-endian float32 C-order arrays are read"));
    }
    let shape = header
        .split("'shape': (")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad("no shape"))?;
    let dims: Vec<usize> = shape
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| bad("bad shape"))?;
    let [rows, cols] = dims[..] else {
        return Err(bad("not a 2D array"));
    };
    let data = &bytes[10 + header_len..];
    if data.len() != 4 * rows * cols {
        return Err(bad("data length does not match the shape (truncated?)"));
    }
    Ok((
        rows,
        cols,
        data.chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
    ))
}
