//! OctoMap, the field's reference 3D map, measured through its own code: the revolutions and a
//! sample of pose checks written as NumPy files, `sim/scripts/octomap_bench.py` run on them with
//! the `octomap-python` binding (the library's C++ insertion and queries), its occupied voxels
//! read back and every pose judged on them as the dense voxel grid's are.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use mapper::GridGeometry;
use nalgebra::Point2;
use serde::{Deserialize, Serialize};

use super::drive::{Cloud, FLOOR_M};
use super::spans::{SpanCircle, placed};
use crate::error::{Error, Result};

/// What the script measured (its JSON, the fields the study uses).
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
pub struct OctoMapRun {
    /// The binding's package version.
    pub version: String,
    /// Leaf size, metres.
    pub resolution_m: f64,
    /// Insertion time of one revolution (`insertPointCloud`), ms.
    pub insert_ms: InsertMs,
    /// `memoryUsage()` after the drive, bytes.
    pub memory_bytes: u64,
    /// Nodes of the tree.
    pub nodes: u64,
    /// Occupied voxels exported (window, above the floor, under the ceiling).
    pub occupied_voxels_exported: u64,
    /// One pose check through the binding (its bounding-box leaf iterator), microseconds.
    pub pose_check_us: PoseCheckUs,
    /// The binding's answers at the sampled poses, in order.
    pub pose_answers: Vec<bool>,
    /// How the script checks a pose.
    pub query_method: String,
}

/// Insertion time statistics, ms.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize)]
pub struct InsertMs {
    /// Median over revolutions.
    pub median: f64,
    /// Mean over revolutions.
    pub mean: f64,
}

/// Pose check time statistics, microseconds.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize)]
pub struct PoseCheckUs {
    /// Median over the sampled poses (`None`: none sampled).
    pub median: Option<f64>,
    /// Mean over the sampled poses.
    pub mean: Option<f64>,
}

/// The exchange directory, written once per scene.
pub struct Exchange {
    /// Where it is.
    pub dir: PathBuf,
}

fn io<'a>(what: &'static str, path: &'a Path) -> impl FnOnce(std::io::Error) -> Error + 'a {
    move |source| Error::Io {
        what,
        path: path.to_path_buf(),
        source,
    }
}

/// Writes a NumPy `.npy` file of `shape` and little-endian `descr` (`<f4`, `<f8`, `<i8`).
fn write_npy(path: &Path, descr: &str, shape: &[usize], body: &[u8]) -> Result<()> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape = if dims.len() == 1 {
        format!("({},)", dims[0])
    } else {
        format!("({})", dims.join(", "))
    };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    bytes.extend_from_slice(body);
    mapper::write_atomically(path, &bytes)?;
    Ok(())
}

/// Reads a float32 (N, 3) `.npy` file (the script's voxels).
fn read_points_npy(path: &Path) -> Result<Vec<[f32; 3]>> {
    let bytes = std::fs::read(path).map_err(io("reading OctoMap's voxels", path))?;
    let bad = |what: &str| Error::Invalid(format!("{}: {what}", path.display()));
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("not a .npy file"));
    }
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(bytes.get(10..10 + len).ok_or_else(|| bad("cut short"))?)
        .map_err(|_| bad("header not text"))?;
    if !header.contains("'<f4'") || !header.contains("False") {
        return Err(bad("not little-endian float32 in C order"));
    }
    let body = &bytes[10 + len..];
    if body.len() % 12 != 0 {
        return Err(bad("not rows of three float32"));
    }
    Ok(body
        .chunks_exact(12)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            [f(0), f(4), f(8)]
        })
        .collect())
}

impl Exchange {
    /// Starts an exchange in `dir` (created).
    pub fn create(dir: &Path) -> Result<Self> {
        std::fs::create_dir_all(dir).map_err(io("creating the OctoMap exchange", dir))?;
        Ok(Exchange {
            dir: dir.to_path_buf(),
        })
    }

    /// Writes the revolutions, the window and the sampled checks (`cylinders[pose][part]` as
    /// x, y, radius, z_lo, z_hi in the world).
    pub fn write(
        &self,
        clouds: &[Cloud],
        window: (Point2<f64>, Point2<f64>, f64),
        cylinders: &[Vec<[f64; 5]>],
    ) -> Result<()> {
        let (mut points, mut offsets, mut origins) = (Vec::new(), vec![0i64], Vec::new());
        for c in clouds {
            for p in &c.points {
                for v in p {
                    points.extend_from_slice(&v.to_le_bytes());
                }
            }
            offsets.push(offsets.last().copied().unwrap_or(0) + c.points.len() as i64);
            for v in [c.origin.x, c.origin.y, c.origin.z] {
                origins.extend_from_slice(&v.to_le_bytes());
            }
        }
        let m = points.len() / 12;
        write_npy(&self.dir.join("points.npy"), "<f4", &[m, 3], &points)?;
        let offsets: Vec<u8> = offsets.iter().flat_map(|o| o.to_le_bytes()).collect();
        write_npy(
            &self.dir.join("offsets.npy"),
            "<i8",
            &[clouds.len() + 1],
            &offsets,
        )?;
        write_npy(
            &self.dir.join("origins.npy"),
            "<f8",
            &[clouds.len(), 3],
            &origins,
        )?;
        let parts = cylinders.iter().map(Vec::len).max().unwrap_or(0);
        let mut body = Vec::new();
        for pose in cylinders {
            for k in 0..parts {
                let row = pose.get(k).copied().unwrap_or([0.0; 5]);
                body.extend(row.iter().flat_map(|v| v.to_le_bytes()));
            }
        }
        write_npy(
            &self.dir.join("cylinders.npy"),
            "<f8",
            &[cylinders.len(), parts, 5],
            &body,
        )?;
        let (lo, hi, top) = window;
        let meta = serde_json::json!({
            "max_range_m": 100.0,
            "z_shift_m": -FLOOR_M,
            "window": {"x0": lo.x, "y0": lo.y, "x1": hi.x, "y1": hi.y, "z_top": top},
        });
        mapper::write_atomically(&self.dir.join("meta.json"), meta.to_string().as_bytes())?;
        Ok(())
    }

    /// Runs the script with `python` at `resolution_m`: `Ok(None)` when the binding is not
    /// installed (the script exits 3), its figures and occupied voxels otherwise. With `reuse`,
    /// a finished run's files already in the directory are read instead (the drive and the
    /// poses are reproducible: the same options give the same exchange).
    pub fn run(
        &self,
        python: &Path,
        resolution_m: f64,
        reuse: bool,
    ) -> Result<Option<(OctoMapRun, Vec<[f32; 3]>)>> {
        let json = self.dir.join(format!("octomap_{resolution_m}.json"));
        let voxels = self.dir.join(format!("octomap_{resolution_m}_voxels.npy"));
        if !(reuse && json.is_file() && voxels.is_file())
            && self
                .run_script(python, resolution_m, (&json, &voxels))?
                .is_none()
        {
            return Ok(None);
        }
        let text =
            std::fs::read_to_string(&json).map_err(io("reading OctoMap's figures", &json))?;
        let run: OctoMapRun = serde_json::from_str(&text)
            .map_err(|e| Error::Invalid(format!("{}: {e}", json.display())))?;
        Ok(Some((run, read_points_npy(&voxels)?)))
    }

    fn run_script(
        &self,
        python: &Path,
        resolution_m: f64,
        (json, voxels): (&Path, &Path),
    ) -> Result<Option<()>> {
        let script = script_path()?;
        let output = Command::new(python)
            .arg(&script)
            .arg(&self.dir)
            .args(["--resolution", &resolution_m.to_string()])
            .arg("--out")
            .arg(json)
            .arg("--voxels")
            .arg(voxels)
            .output()
            .map_err(io("running the OctoMap script", python))?;
        std::io::stderr().write_all(&output.stderr).ok();
        match output.status.code() {
            Some(0) => {}
            Some(3) => return Ok(None),
            _ => {
                return Err(Error::Invalid(format!(
                    "{}: {} ({})",
                    script.display(),
                    String::from_utf8_lossy(&output.stderr).trim(),
                    output.status
                )));
            }
        }
        Ok(Some(()))
    }
}

/// The script, beside the workspace's `sim` crate (`TAXI_SIM_OCTOMAP_SCRIPT` overrides it).
fn script_path() -> Result<PathBuf> {
    if let Some(p) = std::env::var_os("TAXI_SIM_OCTOMAP_SCRIPT") {
        return Ok(PathBuf::from(p));
    }
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/octomap_bench.py");
    let local = PathBuf::from("sim/scripts/octomap_bench.py");
    [p, local]
        .into_iter()
        .find(|p| p.is_file())
        .ok_or_else(|| Error::Invalid("sim/scripts/octomap_bench.py not found (run from the repository's root or set TAXI_SIM_OCTOMAP_SCRIPT)".into()))
}

/// OctoMap's occupied voxels by column on its own lattice (x, y on multiples of the resolution;
/// z layers from the floor) over the window, for the same span check as the dense grid's: per
/// column its occupied layers, sorted (compressed rows: `starts[column]..starts[column + 1]`).
pub struct VoxelSet {
    starts: Vec<u32>,
    layers: Vec<i32>,
    resolution_m: f64,
    origin: (i64, i64),
    size: (usize, usize),
    geometry: GridGeometry,
}

/// The centre of the cell of side `res` (on multiples of it) holding `x`.
fn snap(x: f64, res: f64) -> f64 {
    ((x / res).floor() + 0.5) * res
}

impl VoxelSet {
    /// The set of `voxels` (centres) at `resolution_m` over `geometry`'s extent (voxels outside
    /// it dropped); queries snap a circle's centre to the centre of the lattice column holding it
    /// (as the 2D maps read their distance maps at their own cells) and answer as colliding
    /// outside `geometry` (as they read 0 there).
    pub fn new(voxels: &[[f32; 3]], resolution_m: f64, geometry: GridGeometry) -> Self {
        let res = resolution_m;
        let g = &geometry;
        let origin = (
            (g.origin_m().x / res).round() as i64,
            (g.origin_m().y / res).round() as i64,
        );
        let scale = g.resolution_m() / res;
        let size = (
            (g.width() as f64 * scale).ceil() as usize,
            (g.height() as f64 * scale).ceil() as usize,
        );
        let mut keyed: Vec<(usize, i32)> = voxels
            .iter()
            .filter_map(|v| {
                let x = (v[0] as f64 / res).floor() as i64 - origin.0;
                let y = (v[1] as f64 / res).floor() as i64 - origin.1;
                let k = ((v[2] as f64 - FLOOR_M) / res).floor() as i32;
                (x >= 0 && y >= 0 && (x as usize) < size.0 && (y as usize) < size.1)
                    .then(|| (y as usize * size.0 + x as usize, k))
            })
            .collect();
        keyed.sort_unstable();
        keyed.dedup();
        let mut starts = vec![0u32; size.0 * size.1 + 1];
        for (column, _) in &keyed {
            starts[column + 1] += 1;
        }
        for i in 1..starts.len() {
            starts[i] += starts[i - 1];
        }
        VoxelSet {
            starts,
            layers: keyed.into_iter().map(|(_, k)| k).collect(),
            resolution_m,
            origin,
            size,
            geometry,
        }
    }

    /// Whether the column at lattice `(x, y)` has an occupied layer within `k0..=k1`.
    fn column_has(&self, x: i64, y: i64, (k0, k1): (i32, i32)) -> bool {
        let (cx, cy) = (x - self.origin.0, y - self.origin.1);
        if cx < 0 || cy < 0 || cx as usize >= self.size.0 || cy as usize >= self.size.1 {
            return false;
        }
        let column = cy as usize * self.size.0 + cx as usize;
        let layers = &self.layers[self.starts[column] as usize..self.starts[column + 1] as usize];
        let first = layers.partition_point(|k| *k < k0);
        layers.get(first).is_some_and(|k| *k <= k1)
    }

    /// Whether an occupied voxel whose centre lies within [z_lo, z_hi] has its column's centre
    /// nearer than `radius_m` to the centre of the lattice column holding `centre`.
    pub fn span_collides(&self, centre: Point2<f64>, radius_m: f64, z_lo: f64, z_hi: f64) -> bool {
        if self.geometry.cell_of(&centre).is_none() {
            return true;
        }
        let res = self.resolution_m;
        let c = Point2::new(snap(centre.x, res), snap(centre.y, res));
        let k0 = (((z_lo - FLOOR_M) / res - 0.5).ceil() as i32).max(0);
        let k1 = ((z_hi - FLOOR_M) / res - 0.5).floor() as i32;
        if k1 < k0 {
            return false;
        }
        let (x0, x1) = (
            ((c.x - radius_m) / res).floor() as i64,
            ((c.x + radius_m) / res).ceil() as i64,
        );
        let (y0, y1) = (
            ((c.y - radius_m) / res).floor() as i64,
            ((c.y + radius_m) / res).ceil() as i64,
        );
        (x0..=x1).any(|x| {
            (y0..=y1).any(|y| {
                let (vx, vy) = ((x as f64 + 0.5) * res, (y as f64 + 0.5) * res);
                (vx - c.x).hypot(vy - c.y) < radius_m && self.column_has(x, y, (k0, k1))
            })
        })
    }
}

/// The sampled poses' parts as the script's cylinders.
pub fn cylinders(circles: &[SpanCircle], poses: &[nalgebra::Isometry2<f64>]) -> Vec<Vec<[f64; 5]>> {
    poses
        .iter()
        .map(|pose| {
            circles
                .iter()
                .map(|c| {
                    let (p, r, lo, hi) = placed(c, pose);
                    [p.x, p.y, r, lo, hi]
                })
                .collect()
        })
        .collect()
}
