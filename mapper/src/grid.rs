//! `Grid<T>`: a 2D array of cells laid on the world's x-y plane, with world <-> cell conversion.
//!
//! Conventions (the ROS `map_server` ones): cell `(x, y)` = (column, row); row 0 holds the
//! lowest y; `origin_m` is the world position of the lower-left corner of cell (0, 0); data are
//! stored row after row, `index = y * width + x`. Every lookup by world position or by signed
//! cell coordinates returns `Option` instead of panicking when it falls outside the grid.

use nalgebra::Point2;

use crate::error::{MapError, Result, finite, positive};

/// A cell of a grid: column `x`, row `y` (row 0 = lowest world y).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Cell {
    /// Column, growing with world x.
    pub x: usize,
    /// Row, growing with world y.
    pub y: usize,
}

/// Where a grid lies in the world and how big it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridGeometry {
    origin_m: Point2<f64>,
    resolution_m: f64,
    inv_resolution: f64,
    width: usize,
    height: usize,
}

impl GridGeometry {
    /// A grid of `width` x `height` cells of `resolution_m` metres whose lower-left corner is at
    /// `origin_m` in the world frame.
    pub fn new(
        origin_m: Point2<f64>,
        resolution_m: f64,
        width: usize,
        height: usize,
    ) -> Result<Self> {
        positive("resolution_m", resolution_m)?;
        // A cell of a micrometre or less is a mistake, and 1 / resolution must stay finite.
        if resolution_m < 1e-6 {
            return Err(MapError::invalid(
                "resolution_m",
                format!("{resolution_m} m: cells must be at least 1e-6 m"),
            ));
        }
        finite("origin_m.x", origin_m.x)?;
        finite("origin_m.y", origin_m.y)?;
        if width == 0 || height == 0 {
            return Err(MapError::invalid(
                "grid size",
                format!("{width} x {height} cells: both must be > 0"),
            ));
        }
        if width
            .checked_mul(height)
            .is_none_or(|n| n > (i32::MAX as usize))
        {
            return Err(MapError::invalid(
                "grid size",
                format!("{width} x {height} cells is too large"),
            ));
        }
        Ok(GridGeometry {
            origin_m,
            resolution_m,
            inv_resolution: 1.0 / resolution_m,
            width,
            height,
        })
    }

    /// World position of the lower-left corner of cell (0, 0).
    pub fn origin_m(&self) -> Point2<f64> {
        self.origin_m
    }
    /// Side of a cell in metres.
    pub fn resolution_m(&self) -> f64 {
        self.resolution_m
    }
    /// Columns.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Rows.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.width * self.height
    }
    /// Always false: a grid has at least one cell.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The cells within `half_m` (rounded to cells) of `center` along each axis, clamped to the
    /// grid: columns and rows; `None` when none is left.
    pub fn cells_around(
        &self,
        center: &Point2<f64>,
        half_m: f64,
    ) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
        let half = (half_m / self.resolution_m()).round() as i64;
        let (cx, cy) = self.cell_coords(center);
        let clamp_x = |v: i64| v.clamp(0, self.width() as i64) as usize;
        let clamp_y = |v: i64| v.clamp(0, self.height() as i64) as usize;
        let (xs, ys) = (
            clamp_x(cx.saturating_sub(half))..clamp_x(cx.saturating_add(half)),
            clamp_y(cy.saturating_sub(half))..clamp_y(cy.saturating_add(half)),
        );
        (!xs.is_empty() && !ys.is_empty()).then_some((xs, ys))
    }

    /// Signed cell coordinates of a world point (may be outside the grid).
    #[inline]
    pub fn cell_coords(&self, point_m: &Point2<f64>) -> (i64, i64) {
        // `as` maps NaN to 0: send it far outside instead, so a NaN never lands in a cell. The
        // floor is taken from the truncation (`f64::floor` is a libm call on baseline x86-64,
        // and this is on the scan insertion's hot path); `as` saturates out of range.
        let to_cell = |v: f64| {
            if v.is_nan() {
                i64::MIN
            } else {
                let t = v as i64;
                t.saturating_sub(((t as f64) > v) as i64)
            }
        };
        (
            to_cell((point_m.x - self.origin_m.x) * self.inv_resolution),
            to_cell((point_m.y - self.origin_m.y) * self.inv_resolution),
        )
    }

    /// The cell holding a world point, `None` outside the grid.
    #[inline]
    pub fn cell_of(&self, point_m: &Point2<f64>) -> Option<Cell> {
        let (x, y) = self.cell_coords(point_m);
        self.cell_at(x, y)
    }

    /// The cell at signed coordinates, `None` outside the grid.
    #[inline]
    pub fn cell_at(&self, x: i64, y: i64) -> Option<Cell> {
        if x >= 0 && y >= 0 && (x as u64) < self.width as u64 && (y as u64) < self.height as u64 {
            Some(Cell {
                x: x as usize,
                y: y as usize,
            })
        } else {
            None
        }
    }

    /// Index into the data of the cell holding a world point, `None` outside the grid.
    #[inline]
    pub fn index_of(&self, point_m: &Point2<f64>) -> Option<usize> {
        self.cell_of(point_m).map(|c| self.index(c))
    }

    /// Index into the data of a cell. The cell must come from this geometry.
    #[inline]
    pub fn index(&self, cell: Cell) -> usize {
        cell.y * self.width + cell.x
    }

    /// The cell at a data index, `None` past the end.
    #[inline]
    pub fn cell_of_index(&self, index: usize) -> Option<Cell> {
        (index < self.len()).then(|| Cell {
            x: index % self.width,
            y: index / self.width,
        })
    }

    /// World position of a cell's centre.
    #[inline]
    pub fn center_of(&self, cell: Cell) -> Point2<f64> {
        Point2::new(
            self.origin_m.x + (cell.x as f64 + 0.5) * self.resolution_m,
            self.origin_m.y + (cell.y as f64 + 0.5) * self.resolution_m,
        )
    }

    /// True when the world point lies inside the grid.
    pub fn contains(&self, point_m: &Point2<f64>) -> bool {
        self.cell_of(point_m).is_some()
    }

    /// The same geometry moved so its origin is `origin_m`.
    pub fn with_origin(&self, origin_m: Point2<f64>) -> GridGeometry {
        GridGeometry { origin_m, ..*self }
    }
}

/// A 2D array of `T` over a [`GridGeometry`].
#[derive(Clone, Debug, PartialEq)]
pub struct Grid<T> {
    geometry: GridGeometry,
    data: Vec<T>,
}

impl<T: Clone> Grid<T> {
    /// A grid with every cell set to `value`.
    pub fn filled(geometry: GridGeometry, value: T) -> Self {
        Grid {
            data: vec![value; geometry.len()],
            geometry,
        }
    }

    /// Sets every cell to `value`.
    pub fn fill(&mut self, value: T) {
        self.data.fill(value);
    }
}

impl<T> Grid<T> {
    /// A grid over `geometry` holding `data` row after row; `data.len()` must equal the cell count.
    pub fn from_vec(geometry: GridGeometry, data: Vec<T>) -> Result<Self> {
        if data.len() != geometry.len() {
            return Err(MapError::invalid(
                "grid data",
                format!(
                    "{} values for {} x {} cells",
                    data.len(),
                    geometry.width(),
                    geometry.height()
                ),
            ));
        }
        Ok(Grid { geometry, data })
    }

    /// Geometry of the grid.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }
    /// Cells row after row (row 0 = lowest y).
    pub fn data(&self) -> &[T] {
        &self.data
    }
    /// Mutable cells row after row.
    pub fn data_mut(&mut self) -> &mut [T] {
        &mut self.data
    }
    /// Consumes the grid, returning its cells.
    pub fn into_vec(self) -> Vec<T> {
        self.data
    }
    /// The value of a cell, `None` outside the grid.
    pub fn get(&self, cell: Cell) -> Option<&T> {
        self.geometry
            .cell_at(cell.x as i64, cell.y as i64)
            .map(|c| &self.data[self.geometry.index(c)])
    }
    /// Mutable value of a cell, `None` outside the grid.
    pub fn get_mut(&mut self, cell: Cell) -> Option<&mut T> {
        let c = self.geometry.cell_at(cell.x as i64, cell.y as i64)?;
        let i = self.geometry.index(c);
        Some(&mut self.data[i])
    }
    /// The value of the cell holding a world point, `None` outside the grid.
    pub fn at(&self, point_m: &Point2<f64>) -> Option<&T> {
        self.geometry.index_of(point_m).map(|i| &self.data[i])
    }
    /// Mutable value of the cell holding a world point, `None` outside the grid.
    pub fn at_mut(&mut self, point_m: &Point2<f64>) -> Option<&mut T> {
        self.geometry.index_of(point_m).map(|i| &mut self.data[i])
    }
    /// One row (y) as a slice, `None` outside the grid.
    pub fn row(&self, y: usize) -> Option<&[T]> {
        (y < self.geometry.height())
            .then(|| &self.data[y * self.geometry.width()..(y + 1) * self.geometry.width()])
    }
    /// Moves the grid so its origin is `origin_m` without touching the data.
    pub(crate) fn set_origin(&mut self, origin_m: Point2<f64>) {
        self.geometry = self.geometry.with_origin(origin_m);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> GridGeometry {
        GridGeometry::new(Point2::new(-1.0, 2.0), 0.2, 10, 5).unwrap()
    }

    #[test]
    fn world_to_cell_and_back() {
        let g = geometry();
        let c = g.cell_of(&Point2::new(-0.95, 2.05)).unwrap();
        assert_eq!(c, Cell { x: 0, y: 0 });
        let c = g.cell_of(&Point2::new(0.99, 2.99)).unwrap();
        assert_eq!(c, Cell { x: 9, y: 4 });
        let centre = g.center_of(Cell { x: 3, y: 1 });
        assert!((centre.x - (-1.0 + 0.7)).abs() < 1e-12 && (centre.y - 2.3).abs() < 1e-12);
        assert_eq!(g.cell_of(&centre), Some(Cell { x: 3, y: 1 }));
    }

    #[test]
    fn a_resolution_whose_inverse_overflows_is_refused() {
        // 1e-320 is positive and finite, but 1 / 1e-320 is infinite (found by fuzzing the ROS
        // map reader).
        for r in [1e-320, 1e-9] {
            let e = GridGeometry::new(Point2::origin(), r, 10, 10).unwrap_err();
            assert!(e.to_string().contains("resolution_m"), "{e}");
        }
        assert!(GridGeometry::new(Point2::origin(), 1e-6, 10, 10).is_ok());
    }

    /// The hand-written floor equals `f64::floor` everywhere, infinities and huge values included.
    #[test]
    fn cell_coords_floor_like_f64_floor() {
        let g = GridGeometry::new(Point2::origin(), 1.0, 10, 10).unwrap();
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1e-300,
            2.999_999_999_999,
            -2.000_000_000_001,
            9.007e15 + 0.5,
            -9.007e15 - 0.5,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..10_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            values.push((state as i64) as f64 / 1e6);
        }
        for v in values {
            let (x, _) = g.cell_coords(&Point2::new(v, 0.0));
            assert_eq!(x, v.floor() as i64, "{v}");
        }
        assert_eq!(g.cell_coords(&Point2::new(f64::NAN, 0.0)).0, i64::MIN);
    }

    #[test]
    fn out_of_bounds_is_none_not_a_panic() {
        let g = geometry();
        let mut grid = Grid::filled(g, 0u8);
        for p in [
            Point2::new(-1.01, 2.5),
            Point2::new(1.0, 2.5),
            Point2::new(0.0, 1.99),
            Point2::new(0.0, 3.0),
        ] {
            assert!(g.cell_of(&p).is_none(), "{p:?}");
            assert!(grid.at(&p).is_none());
            assert!(grid.at_mut(&p).is_none());
        }
        assert!(grid.at(&Point2::new(f64::NAN, 2.5)).is_none());
        assert!(grid.get(Cell { x: 10, y: 0 }).is_none());
        assert!(grid.get(Cell { x: 0, y: 5 }).is_none());
        assert!(grid.row(5).is_none());
        assert!(g.cell_of_index(50).is_none());
    }

    #[test]
    fn bad_geometry_is_an_error() {
        assert!(GridGeometry::new(Point2::origin(), 0.0, 1, 1).is_err());
        assert!(GridGeometry::new(Point2::origin(), f64::NAN, 1, 1).is_err());
        assert!(GridGeometry::new(Point2::origin(), 0.2, 0, 1).is_err());
        assert!(GridGeometry::new(Point2::new(f64::INFINITY, 0.0), 0.2, 1, 1).is_err());
        assert!(Grid::from_vec(geometry(), vec![0u8; 3]).is_err());
    }
}
