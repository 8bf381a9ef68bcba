//! `ElevationMap`: a 2.5D elevation-interval map (as grid_map users build one), the 2.5D
//! baseline the multi-height 2D grids are compared against.
//!
//! Per cell of a [`GridGeometry`], the lowest and the highest obstacle height seen, f32 (NaN =
//! nothing seen). Every return whose world z lies in [`floor_m`, `top_m`) widens its cell's
//! interval; returns below the floor (the ground, z = 0) or at or above the top are ignored.
//! Nothing is ever cleared: an interval map keeps what it saw (in a static scene nothing needs
//! clearing). What lies between a cell's lowest and highest hit counts as obstacle, so a cone
//! under an overhang fills the gap between them: the map's known false alarm.
//!
//! Span queries use the voxel grid's collision convention ([`crate::voxel`]): the circle's
//! query cell is the one holding its centre, a cell collides when the 2D EDT's distance between
//! the two cell centres is below the radius, and a centre outside the grid collides.

use nalgebra::Point2;

use crate::error::{MapError, Result, finite};
use crate::grid::GridGeometry;
use crate::scan::Scan;
use crate::voxel::CellCircle;

/// Per cell, the interval of obstacle heights seen.
#[derive(Clone, Debug)]
pub struct ElevationMap {
    geometry: GridGeometry,
    floor_m: f64,
    top_m: f64,
    /// Lowest hit per cell, NaN = none.
    min_m: Vec<f32>,
    /// Highest hit per cell, NaN = none.
    max_m: Vec<f32>,
}

impl ElevationMap {
    /// An empty map over `geometry` keeping heights in [`floor_m`, `top_m`): both finite,
    /// `floor_m < top_m`.
    pub fn new(geometry: GridGeometry, floor_m: f64, top_m: f64) -> Result<Self> {
        finite("floor_m", floor_m)?;
        finite("top_m", top_m)?;
        if top_m <= floor_m {
            return Err(MapError::invalid(
                "elevation map",
                format!("top {top_m} m must be above floor {floor_m} m"),
            ));
        }
        Ok(ElevationMap {
            geometry,
            floor_m,
            top_m,
            min_m: vec![f32::NAN; geometry.len()],
            max_m: vec![f32::NAN; geometry.len()],
        })
    }

    /// The geometry.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }
    /// Lowest height kept, metres.
    pub fn floor_m(&self) -> f64 {
        self.floor_m
    }
    /// Heights at or above this are ignored, metres.
    pub fn top_m(&self) -> f64 {
        self.top_m
    }

    /// Widens the interval of each return's cell by its height (see the module doc). Beams
    /// without a return, and returns outside the grid or the height range, change nothing.
    pub fn insert_scan(&mut self, scan: &Scan) {
        for r in scan.returns().iter().flatten() {
            let p = r.point_in_world;
            if !(p.z >= self.floor_m && p.z < self.top_m) {
                continue;
            }
            if let Some(i) = self.geometry.index_of(&Point2::new(p.x, p.y)) {
                let z = p.z as f32;
                // f32::min / max take the number over NaN.
                self.min_m[i] = self.min_m[i].min(z);
                self.max_m[i] = self.max_m[i].max(z);
            }
        }
    }

    /// The interval (lowest, highest) of cell (x, y), metres; `None` when nothing was seen
    /// there or the cell is outside the grid.
    pub fn interval(&self, x: usize, y: usize) -> Option<(f32, f32)> {
        let g = &self.geometry;
        if x >= g.width() || y >= g.height() {
            return None;
        }
        let i = y * g.width() + x;
        (!self.min_m[i].is_nan()).then(|| (self.min_m[i], self.max_m[i]))
    }

    /// Whether a cell within the circle (the module's convention) has an interval meeting
    /// [z_lo, z_hi]. A centre outside the grid collides when `radius_m > 0`; a NaN argument
    /// collides (conservative); `z_lo > z_hi` is an empty span.
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
        let w = self.geometry.width();
        let (xs, ys) = circle.cells(w, self.geometry.height());
        ys.into_iter().any(|y| {
            xs.clone().any(|x| {
                let i = y * w + x;
                // NaN (no interval) fails both comparisons.
                f64::from(self.min_m[i]) <= z_hi_m
                    && f64::from(self.max_m[i]) >= z_lo_m
                    && circle.within(x as i64, y as i64)
            })
        })
    }

    /// Bytes of the two interval buffers.
    pub fn memory_bytes(&self) -> usize {
        (self.min_m.capacity() + self.max_m.capacity()) * std::mem::size_of::<f32>()
    }
    /// Cells with an interval.
    pub fn occupied_cells(&self) -> usize {
        self.min_m.iter().filter(|v| !v.is_nan()).count()
    }
}
