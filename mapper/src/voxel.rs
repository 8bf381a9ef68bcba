//! `VoxelGrid`: a dense 3D log-odds occupancy grid with an exact 3D distance transform, the
//! 3D baseline the multi-height 2D grids are compared against.
//!
//! The box: the cells of a [`GridGeometry`] in x-y, and `layers` layers of the same resolution
//! from `floor_m` (the bottom of layer 0) up to `floor_m + layers * resolution` (the "box top",
//! at or just above the `top_m` asked for). Voxels are stored layer after layer, each layer row
//! after row as the 2D grids are: `index = (layer * height + y) * width + x`.
//!
//! Log-odds per voxel, f32: 0 is unknown (the prior p = 0.5), > 0 occupied, clamped to
//! +-`l_max` after every scan as the 2D map is.
//!
//! Insertion rule (OctoMap's `insertPointCloud`): within one scan each voxel is updated at most
//! once. The voxel holding an endpoint inside the box gets `l_occ`; every other voxel a ray
//! crosses inside the box (Amanatides-Woo, clipped to the box) gets `l_free`; a voxel that holds
//! an endpoint of this scan is never freed by this scan (occupied wins).
//!
//! Collision convention (the 2D map's, [`crate::odm::DistanceMap::distance_at`] and
//! [`crate::collision`]): a circle of radius r centred at c collides with an occupied voxel
//! column when `distance < r`, where `distance` is what the 2D EDT stores for the cell holding c:
//! the distance between that cell's centre and the column's cell centre, computed as
//! `sqrt(d2 as f32) * (resolution as f32)` (d2 the squared offset in cells), compared with
//! `r as f32`. A centre outside the grid reads distance 0, as the 2D map reads outside.

use nalgebra::{Point2, Point3};
use rayon::prelude::*;

use crate::error::{MapError, Result, finite};
use crate::grid::GridGeometry;
use crate::occupancy::OccupancyParams;
use crate::scan::Scan;

/// A 1D squared distance meaning "no occupied voxel on this line".
const NONE: u64 = u64::MAX;

/// A dense 3D occupancy grid over the cells of a 2D geometry.
#[derive(Clone, Debug)]
pub struct VoxelGrid {
    geometry: GridGeometry,
    floor_m: f64,
    layers: usize,
    params: OccupancyParams,
    /// Log-odds per voxel; 0 = unknown.
    log_odds: Vec<f32>,
    /// Distance (metres) from each voxel centre to the nearest occupied voxel centre, as of the
    /// last [`VoxelGrid::update_distances`]; empty before the first.
    distances: Vec<f32>,
    /// Whether `distances` holds the transform of the current log-odds.
    distances_current: bool,
}

impl VoxelGrid {
    /// A grid of unknown voxels over the cells of `geometry`, with
    /// `ceil((top_m - floor_m) / resolution)` layers from `floor_m` (a ratio within 1e-9 of an
    /// integer counts as that integer). `floor_m < top_m`, both finite; `params` as the 2D map
    /// takes them (`l_occ > 0`, `l_free < 0`, `l_max > 0`, all finite).
    pub fn new(
        geometry: GridGeometry,
        floor_m: f64,
        top_m: f64,
        params: OccupancyParams,
    ) -> Result<Self> {
        let layers = layer_count("voxel grid", &geometry, floor_m, top_m)?;
        check_params(&params)?;
        let n = geometry
            .len()
            .checked_mul(layers)
            .filter(|&n| n <= i32::MAX as usize)
            .ok_or_else(|| {
                MapError::invalid(
                    "voxel grid",
                    format!(
                        "{} x {} x {layers} voxels is too large",
                        geometry.width(),
                        geometry.height()
                    ),
                )
            })?;
        let mut log_odds = Vec::new();
        log_odds.try_reserve_exact(n).map_err(|e| {
            MapError::invalid("voxel grid", format!("{n} voxels cannot be allocated: {e}"))
        })?;
        log_odds.resize(n, 0.0);
        Ok(VoxelGrid {
            geometry,
            floor_m,
            layers,
            params,
            log_odds,
            distances: Vec::new(),
            distances_current: false,
        })
    }

    /// The x-y geometry (the same cells as the 2D maps it is compared with).
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }
    /// Number of layers.
    pub fn layers(&self) -> usize {
        self.layers
    }
    /// Bottom of layer 0, metres.
    pub fn floor_m(&self) -> f64 {
        self.floor_m
    }
    /// Top of the last layer, metres (at or above the `top_m` the grid was made with).
    pub fn box_top_m(&self) -> f64 {
        self.floor_m + self.layers as f64 * self.geometry.resolution_m()
    }
    /// Height of the centre of layer `k`, metres; `None` past the last layer.
    pub fn layer_center_m(&self, k: usize) -> Option<f64> {
        (k < self.layers).then(|| self.floor_m + (k as f64 + 0.5) * self.geometry.resolution_m())
    }
    /// The occupancy parameters.
    pub fn params(&self) -> &OccupancyParams {
        &self.params
    }
    /// Log-odds of voxel (x, y, layer) (0 = unknown); `None` outside the grid.
    pub fn log_odds(&self, x: usize, y: usize, layer: usize) -> Option<f32> {
        let g = &self.geometry;
        (x < g.width() && y < g.height() && layer < self.layers)
            .then(|| self.log_odds[(layer * g.height() + y) * g.width() + x])
    }
    /// Voxels whose log-odds is > 0.
    pub fn occupied_voxels(&self) -> usize {
        self.log_odds.iter().filter(|&&l| l > 0.0).count()
    }
    /// Bytes of the buffers the grid keeps: log-odds, and distances once computed. The scratch
    /// of an insertion or a transform is freed when it returns and is not counted.
    pub fn memory_bytes(&self) -> usize {
        (self.log_odds.capacity() + self.distances.capacity()) * std::mem::size_of::<f32>()
    }
    /// True when the distances are those of the current log-odds (no scan inserted since the
    /// last [`Self::update_distances`]).
    pub fn distances_up_to_date(&self) -> bool {
        self.distances_current
    }

    /// The voxel box in voxel units.
    fn voxel_box(&self) -> VoxelBox {
        let g = &self.geometry;
        VoxelBox {
            dims: [g.width(), g.height(), self.layers],
            origin: [g.origin_m().x, g.origin_m().y, self.floor_m],
            inv_res: 1.0 / g.resolution_m(),
        }
    }

    /// Inserts one revolution (see the module's insertion rule). Beams without a return are
    /// skipped; a return below the floor (the ground) or outside the box is no hit, but its ray
    /// still frees what it crosses inside the box. With `floor_m` at 0 a ground return at
    /// z = 0 would be a hit in layer 0: put the floor above the ground (e.g. 0.05 m, the 2D
    /// map's safe height).
    pub fn insert_scan(&mut self, scan: &Scan) {
        let bx = self.voxel_box();
        // 0 untouched, 1 freed, 2 hit (this scan).
        let mut mark = vec![0u8; self.log_odds.len()];
        let mut touched: Vec<usize> = Vec::new();
        for r in scan.returns().iter().flatten() {
            if let Some(v) = bx.voxel_of(bx.to_units(&r.point_in_world)) {
                let i = bx.index(v);
                if mark[i] != 2 {
                    if mark[i] == 0 {
                        touched.push(i);
                    }
                    mark[i] = 2;
                }
            }
        }
        for c in 0..scan.column_count() {
            let Some((col, returns)) = scan.column(c) else {
                continue;
            };
            let origin = Point3::from(col.world_from_sensor.translation.vector);
            let a = bx.to_units(&origin);
            for r in returns.iter().flatten() {
                let b = bx.to_units(&r.point_in_world);
                walk(&bx, a, b, bx.voxel_of(b), |v| {
                    let i = bx.index(v);
                    if mark[i] == 0 {
                        mark[i] = 1;
                        touched.push(i);
                    }
                });
            }
        }
        let p = self.params;
        for i in touched {
            let l = &mut self.log_odds[i];
            let delta = if mark[i] == 2 { p.l_occ } else { p.l_free };
            *l = (*l + delta).clamp(-p.l_max, p.l_max);
        }
        self.distances_current = false;
    }

    /// Recomputes, whole, the exact 3D Euclidean distance transform of the occupied voxels
    /// (log-odds > 0): per voxel, the distance in metres between its centre and the nearest
    /// occupied voxel's centre, `sqrt(d2 as f32) * (resolution as f32)` as the 2D EDT computes
    /// it, infinity when no voxel is occupied. Separable: exact 1D lower envelopes of parabolas
    /// (Meijster's separator, integer arithmetic) along x, then y, then z, lines in parallel.
    pub fn update_distances(&mut self) {
        let [w, h, l] = [self.geometry.width(), self.geometry.height(), self.layers];
        let n = self.log_odds.len();
        let log_odds = &self.log_odds;
        // Along x, into a layout [layer][y][x].
        let mut a = vec![0u64; n];
        envelope_pass(&mut a, w, |line, x| {
            if log_odds[line * w + x] > 0.0 {
                0
            } else {
                NONE
            }
        });
        // Along y, into [layer][x][y].
        let mut b = vec![0u64; n];
        envelope_pass(&mut b, h, |line, y| a[((line / w) * h + y) * w + line % w]);
        // Along z, into [y][x][layer] (a's buffer again).
        envelope_pass(&mut a, l, |line, k| b[(k * w + line % w) * h + line / w]);
        let res = self.geometry.resolution_m() as f32;
        self.distances.resize(n, 0.0);
        self.distances
            .par_chunks_mut(w)
            .enumerate()
            .for_each(|(line, out)| {
                let (k, y) = (line / h, line % h);
                for (x, d) in out.iter_mut().enumerate() {
                    let d2 = a[(y * w + x) * l + k];
                    *d = if d2 == NONE {
                        f32::INFINITY
                    } else {
                        (d2 as f32).sqrt() * res
                    };
                }
            });
        self.distances_current = true;
    }

    /// The distance (metres) stored for the voxel holding `p`, as of the last
    /// [`Self::update_distances`] (infinity before the first); 0 outside the box, as the 2D
    /// map reads outside (the unknown beyond the map is never free).
    pub fn distance_at(&self, p: Point3<f64>) -> f32 {
        let bx = self.voxel_box();
        match bx.voxel_of(bx.to_units(&p)) {
            None => 0.0,
            Some(v) => self
                .distances
                .get(bx.index(v))
                .copied()
                .unwrap_or(f32::INFINITY),
        }
    }

    /// Whether a vertical cylinder of radius `radius_m` around `centre` from `z_lo_m` to `z_hi_m`
    /// holds an occupied voxel: one whose layer centre lies within [z_lo, z_hi] and whose column
    /// collides with the circle under the module's convention. Exact. A centre outside the grid
    /// collides when `radius_m > 0` (it reads distance 0); a NaN argument collides
    /// (conservative); `z_lo > z_hi` is an empty span.
    ///
    /// With distances up to date, a layer is skipped when the 3D distance at (centre's cell,
    /// layer centre) is >= r: the 3D distance to any voxel of the layer is its 2D distance, so
    /// the layer's nearest voxel is at least that far. Only the layers failing that test are
    /// enumerated. With distances stale this is [`Self::span_collides_plain`].
    pub fn span_collides(
        &self,
        centre: Point2<f64>,
        radius_m: f64,
        z_lo_m: f64,
        z_hi_m: f64,
    ) -> bool {
        let circle = match CellCircle::new(&self.geometry, centre, radius_m, z_lo_m, z_hi_m) {
            Ok(c) => c,
            Err(collides) => return collides,
        };
        if !self.distances_current {
            return self.span_collides_plain(centre, radius_m, z_lo_m, z_hi_m);
        }
        let plane = self.geometry.len();
        let q = self.geometry.width() * circle.qy as usize + circle.qx as usize;
        self.layers_in(z_lo_m, z_hi_m)
            .filter(|&k| self.distances[k * plane + q] < circle.r)
            .any(|k| self.layer_collides(&circle, k))
    }

    /// [`Self::span_collides`] by enumeration alone: every voxel of the span's layers within the
    /// circle's bounding box. The reference the distance early out is tested against.
    pub fn span_collides_plain(
        &self,
        centre: Point2<f64>,
        radius_m: f64,
        z_lo_m: f64,
        z_hi_m: f64,
    ) -> bool {
        match CellCircle::new(&self.geometry, centre, radius_m, z_lo_m, z_hi_m) {
            Ok(circle) => self
                .layers_in(z_lo_m, z_hi_m)
                .any(|k| self.layer_collides(&circle, k)),
            Err(collides) => collides,
        }
    }

    /// The layers whose centre lies within [z_lo, z_hi] (finite or infinite, not NaN).
    fn layers_in(&self, z_lo_m: f64, z_hi_m: f64) -> impl Iterator<Item = usize> + '_ {
        let res = self.geometry.resolution_m();
        let last = self.layers as i64 - 1;
        // A guess one layer wide either side, then the exact test on each centre.
        let lo = (((z_lo_m - self.floor_m) / res - 0.5).floor() as i64).clamp(0, last);
        let hi = (((z_hi_m - self.floor_m) / res - 0.5).ceil() as i64).clamp(0, last);
        (lo as usize..=hi as usize).filter(move |&k| {
            let c = self.floor_m + (k as f64 + 0.5) * res;
            z_lo_m <= c && c <= z_hi_m
        })
    }

    /// Whether layer `k` has an occupied voxel within the circle.
    fn layer_collides(&self, circle: &CellCircle, k: usize) -> bool {
        let g = &self.geometry;
        let (xs, ys) = circle.cells(g.width(), g.height());
        let layer = &self.log_odds[k * g.len()..(k + 1) * g.len()];
        ys.into_iter().any(|y| {
            let row = &layer[y * g.width()..(y + 1) * g.width()];
            xs.clone()
                .any(|x| row[x] > 0.0 && circle.within(x as i64, y as i64))
        })
    }
}

/// Number of layers of `resolution` from `floor_m` to `top_m`, or the error naming `what`.
fn layer_count(
    what: &'static str,
    geometry: &GridGeometry,
    floor_m: f64,
    top_m: f64,
) -> Result<usize> {
    finite("floor_m", floor_m)?;
    finite("top_m", top_m)?;
    if top_m <= floor_m {
        return Err(MapError::invalid(
            what,
            format!("top {top_m} m must be above floor {floor_m} m"),
        ));
    }
    let ratio = (top_m - floor_m) / geometry.resolution_m();
    if !(ratio.is_finite() && ratio < i32::MAX as f64) {
        return Err(MapError::invalid(
            what,
            format!(
                "{floor_m} .. {top_m} m is too many layers of {} m",
                geometry.resolution_m()
            ),
        ));
    }
    Ok(((ratio - 1e-9).ceil() as usize).max(1))
}

/// Checks occupancy parameters as [`crate::map::MapConfig::validate`] does.
fn check_params(p: &OccupancyParams) -> Result<()> {
    if !(p.l_occ.is_finite() && p.l_occ > 0.0) {
        return Err(MapError::invalid(
            "voxel grid",
            format!("l_occ {} must be finite and > 0", p.l_occ),
        ));
    }
    if !(p.l_free.is_finite() && p.l_free < 0.0) {
        return Err(MapError::invalid(
            "voxel grid",
            format!("l_free {} must be finite and < 0", p.l_free),
        ));
    }
    if !(p.l_max.is_finite() && p.l_max > 0.0) {
        return Err(MapError::invalid(
            "voxel grid",
            format!("l_max {} must be finite and > 0", p.l_max),
        ));
    }
    Ok(())
}

/// A span query's circle in cell units, the query cell inside the grid.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellCircle {
    /// The cell holding the centre.
    pub(crate) qx: i64,
    pub(crate) qy: i64,
    /// The radius as the 2D check compares it.
    pub(crate) r: f32,
    res: f32,
    /// Cells beyond this offset (either axis) are at least r away.
    reach: i64,
}

impl CellCircle {
    /// The circle of a span query, or `Err(answer)` when the query is answered without looking
    /// at cells: a NaN argument collides; a centre outside the grid collides when r > 0.
    pub(crate) fn new(
        g: &GridGeometry,
        centre: Point2<f64>,
        radius_m: f64,
        z_lo_m: f64,
        z_hi_m: f64,
    ) -> std::result::Result<Self, bool> {
        if radius_m.is_nan() || z_lo_m.is_nan() || z_hi_m.is_nan() {
            return Err(true);
        }
        let r = radius_m as f32;
        let Some(q) = g.cell_of(&centre) else {
            return Err(0.0 < r);
        };
        // f32 rounding of the cell distance is far below a cell: one cell to spare.
        let reach = ((radius_m / g.resolution_m()).ceil().max(0.0) as i64).saturating_add(1);
        Ok(CellCircle {
            qx: q.x as i64,
            qy: q.y as i64,
            r,
            res: g.resolution_m() as f32,
            reach,
        })
    }

    /// Whether the column of cell (x, y) collides: its centre-to-centre distance from the query
    /// cell, as the 2D EDT computes it, is below r.
    #[inline]
    pub(crate) fn within(&self, x: i64, y: i64) -> bool {
        let (dx, dy) = (x - self.qx, y - self.qy);
        ((dx * dx + dy * dy) as f32).sqrt() * self.res < self.r
    }

    /// The columns and rows of the circle's bounding box, clipped to a `w` x `h` grid.
    pub(crate) fn cells(
        &self,
        w: usize,
        h: usize,
    ) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
        let span = |q: i64, n: usize| {
            let lo = q.saturating_sub(self.reach).max(0) as usize;
            let hi = (q.saturating_add(self.reach).saturating_add(1)).min(n as i64) as usize;
            lo..hi.max(lo)
        };
        (span(self.qx, w), span(self.qy, h))
    }
}

/// The grid's box in voxel units: `[0, w) x [0, h) x [0, l)`.
struct VoxelBox {
    dims: [usize; 3],
    /// World position of the box's lowest corner.
    origin: [f64; 3],
    inv_res: f64,
}

impl VoxelBox {
    fn to_units(&self, p: &Point3<f64>) -> [f64; 3] {
        [0, 1, 2].map(|i| (p[i] - self.origin[i]) * self.inv_res)
    }
    /// The voxel holding a point in voxel units; `None` outside the box or NaN.
    fn voxel_of(&self, u: [f64; 3]) -> Option<[usize; 3]> {
        let mut v = [0usize; 3];
        for i in 0..3 {
            let f = u[i].floor();
            if !(f >= 0.0 && f < self.dims[i] as f64) {
                return None;
            }
            v[i] = f as usize;
        }
        Some(v)
    }
    fn index(&self, v: [usize; 3]) -> usize {
        (v[2] * self.dims[1] + v[1]) * self.dims[0] + v[0]
    }
}

/// Calls `visit` with every voxel the segment `a -> b` (voxel units) passes through inside the
/// box, in order, stopping before `stop` (the endpoint's voxel when it is inside the box): a 3D
/// DDA (Amanatides & Woo 1987) from where the segment enters the box. A non-finite segment, or
/// one that misses the box, visits nothing.
fn walk(
    bx: &VoxelBox,
    a: [f64; 3],
    b: [f64; 3],
    stop: Option<[usize; 3]>,
    mut visit: impl FnMut([usize; 3]),
) {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    if !a.iter().chain(&b).chain(&d).all(|v| v.is_finite()) {
        return;
    }
    // Clip t in [0, 1] to the box (slabs); the box is half-open, so a segment lying in a
    // face at the far side is outside.
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for i in 0..3 {
        let n = bx.dims[i] as f64;
        if d[i] == 0.0 {
            if a[i] < 0.0 || a[i] >= n {
                return;
            }
        } else {
            let (ta, tb) = ((0.0 - a[i]) / d[i], (n - a[i]) / d[i]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
    }
    if t0 >= t1 {
        return;
    }
    let mut v = [0i64; 3];
    let mut step = [0i64; 3];
    let mut t_max = [f64::INFINITY; 3];
    let mut t_delta = [f64::INFINITY; 3];
    for i in 0..3 {
        // The entry voxel, clamped: at a far face the entry point's floor is one past the box.
        let last = bx.dims[i] as i64 - 1;
        v[i] = ((a[i] + t0 * d[i]).floor() as i64).clamp(0, last);
        if d[i] > 0.0 {
            step[i] = 1;
            t_max[i] = (v[i] as f64 + 1.0 - a[i]) / d[i];
            t_delta[i] = 1.0 / d[i];
        } else if d[i] < 0.0 {
            step[i] = -1;
            t_max[i] = (v[i] as f64 - a[i]) / d[i];
            t_delta[i] = -1.0 / d[i];
        }
    }
    // Each step moves one voxel, so the walk leaves the box within w + h + l steps.
    for _ in 0..bx.dims.iter().sum::<usize>() + 3 {
        let cur = v.map(|c| c as usize);
        if stop == Some(cur) {
            return;
        }
        visit(cur);
        let i = if t_max[0] <= t_max[1] && t_max[0] <= t_max[2] {
            0
        } else if t_max[1] <= t_max[2] {
            1
        } else {
            2
        };
        if t_max[i] >= t1 {
            return;
        }
        v[i] += step[i];
        if v[i] < 0 || v[i] >= bx.dims[i] as i64 {
            return;
        }
        t_max[i] += t_delta[i];
    }
}

/// Fills `dst` (lines of `len` values, line after line) with, for each line, the exact 1D lower
/// envelope `out[x] = min_i (x - i)^2 + f(i)` of the values `f(i) = value(line, i)` (`NONE` where
/// there is none), lines in parallel.
fn envelope_pass(dst: &mut [u64], len: usize, value: impl Fn(usize, usize) -> u64 + Sync) {
    dst.par_chunks_mut(len).enumerate().for_each_init(
        || (Vec::new(), Vec::new(), Vec::new()),
        |(f, s, t), (line, out)| {
            f.clear();
            f.extend((0..len).map(|i| value(line, i)));
            envelope(f, out, s, t);
        },
    );
}

/// One line's lower envelope of parabolas (Meijster et al. 2000, phase 2) over the sites whose
/// `f` is not `NONE`; `s` and `t` are scratch (the envelope's sites and where each begins).
fn envelope(f: &[u64], out: &mut [u64], s: &mut Vec<usize>, t: &mut Vec<usize>) {
    let m = f.len();
    let para = |x: usize, i: usize| (x.abs_diff(i) as u64).pow(2) + f[i];
    // The last x at which site i (< u) is no farther than site u.
    let sep = |i: usize, u: usize| {
        let (i, u) = (i as i128, u as i128);
        (u * u - i * i + f[u as usize] as i128 - f[i as usize] as i128).div_euclid(2 * (u - i))
    };
    s.clear();
    t.clear();
    for u in (0..m).filter(|&u| f[u] != NONE) {
        while let (Some(&sq), Some(&tq)) = (s.last(), t.last()) {
            if para(tq, sq) > para(tq, u) {
                s.pop();
                t.pop();
            } else {
                break;
            }
        }
        match s.last() {
            None => {
                s.push(u);
                t.push(0);
            }
            Some(&sq) => {
                let w = 1 + sep(sq, u);
                if w < m as i128 {
                    s.push(u);
                    t.push(w as usize);
                }
            }
        }
    }
    if s.is_empty() {
        out.fill(NONE);
        return;
    }
    let mut q = s.len() - 1;
    for x in (0..m).rev() {
        out[x] = para(x, s[q]);
        if x == t[q] && q > 0 {
            q -= 1;
        }
    }
}
