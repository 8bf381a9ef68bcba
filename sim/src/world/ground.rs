//! The ground's remission prepared for the LiDAR's many lookups ([`GroundTexture`]): the same
//! answers as [`Scene::ground_remission_at`], without a sine and cosine per patch and point, a
//! search of every patch or a polygon test per area.
//!
//! A lookup tests the patches binned near the point ([`PatchBins`]), then asks a coarse grid of
//! [`UniformCells`]: most of an airport's ground is inside one area (or none), where the answer is
//! that area's (or the bare ground's) remission whatever the point. Elsewhere, near an area's
//! edge, it searches the areas cut into rows ([`AreaRows`]).

use super::scene::{Area, Scene, crossings, pavement};

/// [`Scene::ground_remission_at`] with each patch's rotation computed once, and the patches
/// binned on a coarse grid so that a point tests only the few whose box reaches its bin.
#[derive(Clone, Debug)]
pub struct GroundTexture {
    ground_remission: f32,
    pavement_texture: f32,
    /// Last painted first.
    patches: Vec<PreparedPatch>,
    bins: PatchBins,
    areas: AreaRows,
    uniform: UniformCells,
}

/// The areas cut into rows of [`AREA_ROW_M`]: each row's disjoint x intervals with the remission
/// of the last area covering them at the row's middle (an area's edge is placed to within half a
/// row in y, exactly in x). A point outside every row is on no area.
#[derive(Clone, Debug, Default)]
struct AreaRows {
    y0: f64,
    /// Row r's intervals, sorted: `(x_from, x_to, remission)`.
    rows: Vec<Vec<(f64, f64, f32)>>,
}

/// Height of a row of [`AreaRows`], metres.
pub const AREA_ROW_M: f64 = 0.25;

impl AreaRows {
    fn new(areas: &[Area]) -> Self {
        let ys = areas.iter().flat_map(|a| a.outline.iter().map(|p| p[1]));
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
            (l.min(y), h.max(y))
        });
        if !(lo.is_finite() && hi.is_finite()) {
            return Self::default();
        }
        let count = ((hi - lo) / AREA_ROW_M).ceil() as usize + 1;
        let rows = (0..count)
            .map(|r| Self::row(areas, lo + (r as f64 + 0.5) * AREA_ROW_M))
            .collect();
        Self { y0: lo, rows }
    }

    /// One row: each area's even-odd intervals, the later over the earlier.
    fn row(areas: &[Area], y: f64) -> Vec<(f64, f64, f32)> {
        let mut row: Vec<(f64, f64, f32)> = Vec::new();
        for area in areas {
            let mut xs: Vec<f64> = std::iter::once(&area.outline)
                .chain(&area.holes)
                .flat_map(|ring| crossings(ring, y))
                .collect();
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                let (from, to) = (pair[0], pair[1]);
                // Cut what it covers out of the row, then put it in.
                let mut next = Vec::with_capacity(row.len() + 2);
                for &(a, b, r) in &row {
                    if b <= from || a >= to {
                        next.push((a, b, r));
                        continue;
                    }
                    if a < from {
                        next.push((a, from, r));
                    }
                    if b > to {
                        next.push((to, b, r));
                    }
                }
                next.push((from, to, area.remission));
                next.sort_by(|p, q| p.0.total_cmp(&q.0));
                row = next;
            }
        }
        // Neighbours of one remission as one interval (areas drawn edge to edge, a taxiway's
        // segments): the same answers, fewer intervals to search, more cells uniform.
        let mut merged: Vec<(f64, f64, f32)> = Vec::with_capacity(row.len());
        for iv in row {
            match merged.last_mut() {
                Some(last) if last.1 == iv.0 && last.2.to_bits() == iv.2.to_bits() => last.1 = iv.1,
                _ => merged.push(iv),
            }
        }
        merged
    }

    fn at(&self, x: f64, y: f64) -> Option<f32> {
        let r = (y - self.y0) / AREA_ROW_M;
        if !(r >= 0.0 && r < self.rows.len() as f64) {
            return None;
        }
        let row = &self.rows[r as usize];
        let i = row.partition_point(|iv| iv.1 <= x);
        row.get(i).filter(|iv| iv.0 <= x).map(|iv| iv.2)
    }
}

#[derive(Clone, Copy, Debug)]
struct PreparedPatch {
    x: f64,
    y: f64,
    sin: f64,
    cos: f64,
    half_length: f64,
    half_width: f64,
    extent: [f64; 2],
    remission: f32,
}

impl PreparedPatch {
    fn contains(&self, x: f64, y: f64) -> bool {
        let (dx, dy) = (x - self.x, y - self.y);
        if dx.abs() > self.extent[0] || dy.abs() > self.extent[1] {
            return false;
        }
        let (along, across) = (
            self.cos * dx + self.sin * dy,
            -self.sin * dx + self.cos * dy,
        );
        along.abs() <= self.half_length && across.abs() <= self.half_width
    }
}

/// A grid of square bins over the patches' boxes, each listing (in paint order, last first) the
/// patches whose box reaches it or a neighbouring bin (a bin of slack against rounding at the
/// edges). A point outside the grid is on no patch.
#[derive(Clone, Debug, Default)]
struct PatchBins {
    origin: [f64; 2],
    inv_side: f64,
    size: [usize; 2],
    /// Bin b lists `indices[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    indices: Vec<u32>,
}

impl PatchBins {
    /// Bins of 2 m, larger where the patches spread so far that there would be over 2^20.
    fn new(patches: &[PreparedPatch]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in patches {
            for (a, c) in [p.x, p.y].into_iter().enumerate() {
                lo[a] = lo[a].min(c - p.extent[a]);
                hi[a] = hi[a].max(c + p.extent[a]);
            }
        }
        if !(lo[0].is_finite() && lo[1].is_finite() && hi[0].is_finite() && hi[1].is_finite()) {
            return PatchBins::default();
        }
        let mut side = 2.0_f64;
        let cells = |side: f64| -> [usize; 2] {
            [0, 1].map(|a| ((hi[a] - lo[a]) / side).floor() as usize + 3)
        };
        while cells(side)[0] * cells(side)[1] > 1 << 20 {
            side *= 2.0;
        }
        let size = cells(side);
        // One bin of slack below, so the bins of a box never go negative.
        let origin = [lo[0] - side, lo[1] - side];
        let inv_side = 1.0 / side;
        let bin = |v: f64, a: usize| ((v - origin[a]) * inv_side).floor() as i64;
        let range = |p: &PreparedPatch, a: usize| {
            let c = [p.x, p.y][a];
            let first = (bin(c - p.extent[a], a) - 1).max(0) as usize;
            let last = ((bin(c + p.extent[a], a) + 1).max(0) as usize).min(size[a] - 1);
            first..=last
        };
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); size[0] * size[1]];
        for (i, p) in patches.iter().enumerate() {
            for by in range(p, 1) {
                for bx in range(p, 0) {
                    lists[by * size[0] + bx].push(i as u32);
                }
            }
        }
        let mut start = Vec::with_capacity(lists.len() + 1);
        let mut indices = Vec::new();
        for l in &lists {
            start.push(indices.len() as u32);
            indices.extend_from_slice(l);
        }
        start.push(indices.len() as u32);
        PatchBins {
            origin,
            inv_side,
            size,
            start,
            indices,
        }
    }

    /// The patches that may hold (x, y), in paint order (last first).
    fn at(&self, x: f64, y: f64) -> &[u32] {
        let (bx, by) = (
            (x - self.origin[0]) * self.inv_side,
            (y - self.origin[1]) * self.inv_side,
        );
        // NaN and points off the grid compare false. On the grid `as` truncates, which is the
        // floor there (and `f64::floor` a libm call on baseline x86-64, once a LiDAR return).
        if !(bx >= 0.0 && by >= 0.0 && bx < self.size[0] as f64 && by < self.size[1] as f64) {
            return &[];
        }
        let b = by as usize * self.size[0] + bx as usize;
        &self.indices[self.start[b] as usize..self.start[b + 1] as usize]
    }
}

/// A coarse grid over the areas: each cell holds the one remission (before the pavement's
/// texture) the areas give every point in it - in every area row it spans one interval covers it
/// whole, or none touches it - or none: search the rows. A point off the grid is on no area. A
/// cell is a byte, an index into the few remissions the areas have (a quarter of the f32's memory
/// at an airport: 1.6 MB at KSYR).
#[derive(Clone, Debug, Default)]
struct UniformCells {
    origin: [f64; 2],
    inv_side: f64,
    size: [usize; 2],
    /// Each cell's index into `remissions`, or [`MIXED`].
    cells: Vec<u8>,
    remissions: Vec<f32>,
}

/// A cell the areas do not give one remission (or one of more than 255 remissions).
const MIXED: u8 = u8::MAX;

/// Slack, metres, on a cell's edges against the rounding of a point's cell (about 1e-12 m here).
const UNIFORM_SLACK_M: f64 = 1e-6;

impl UniformCells {
    /// Cells of 2 m, larger where the ground spreads so far that there would be over 2^22.
    fn new(areas: &AreaRows, ground: f32) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for row in &areas.rows {
            if let (Some(first), Some(last)) = (row.first(), row.last()) {
                lo[0] = lo[0].min(first.0);
                hi[0] = hi[0].max(last.1);
            }
        }
        if !areas.rows.is_empty() {
            lo[1] = areas.y0;
            hi[1] = areas.y0 + areas.rows.len() as f64 * AREA_ROW_M;
        }
        if !(lo.iter().chain(&hi).all(|v| v.is_finite()) && lo[0] <= hi[0] && lo[1] <= hi[1]) {
            return Self::default();
        }
        let mut side = 2.0_f64;
        let cells = |side: f64| [0, 1].map(|a| ((hi[a] - lo[a]) / side).floor() as usize + 1);
        while cells(side)[0] * cells(side)[1] > 1 << 22 {
            side *= 2.0;
        }
        let size = cells(side);
        let mut grid = UniformCells {
            origin: lo,
            inv_side: 1.0 / side,
            size,
            cells: Vec::with_capacity(size[0] * size[1]),
            remissions: Vec::new(),
        };
        let (mut row_values, mut acc) = (vec![0.0f32; size[0]], vec![0.0f32; size[0]]);
        for cy in 0..size[1] {
            let (ya, yb) = (lo[1] + cy as f64 * side, lo[1] + (cy + 1) as f64 * side);
            let row_of = |y: f64| ((y - areas.y0) / AREA_ROW_M).floor() as i64;
            for (k, r) in (row_of(ya) - 1..=row_of(yb) + 1).enumerate() {
                let row = usize::try_from(r).ok().and_then(|r| areas.rows.get(r));
                grid.sweep_row(row.map_or(&[][..], Vec::as_slice), ground, &mut row_values);
                for (v, &w) in acc.iter_mut().zip(&row_values) {
                    if k == 0 {
                        *v = w;
                    } else if v.to_bits() != w.to_bits() {
                        *v = f32::NAN;
                    }
                }
            }
            for &v in &acc {
                let code = grid.code(v);
                grid.cells.push(code);
            }
        }
        grid
    }

    /// The byte of remission `v`: its index, a new one, or [`MIXED`] (NaN, or no index left).
    fn code(&mut self, v: f32) -> u8 {
        if v.is_nan() {
            return MIXED;
        }
        if let Some(i) = self
            .remissions
            .iter()
            .position(|r| r.to_bits() == v.to_bits())
        {
            return i as u8;
        }
        if self.remissions.len() >= usize::from(MIXED) {
            return MIXED;
        }
        self.remissions.push(v);
        (self.remissions.len() - 1) as u8
    }

    /// Each cell of a row of cells against one area row's intervals: the interval's remission
    /// where one covers the cell whole, the ground's where none touches it, else NaN.
    fn sweep_row(&self, row: &[(f64, f64, f32)], ground: f32, out: &mut [f32]) {
        let side = 1.0 / self.inv_side;
        let mut j = 0;
        for (cx, out) in out.iter_mut().enumerate() {
            let x0 = self.origin[0] + cx as f64 * side - UNIFORM_SLACK_M;
            let x1 = self.origin[0] + (cx + 1) as f64 * side + UNIFORM_SLACK_M;
            while j < row.len() && row[j].1 <= x0 {
                j += 1;
            }
            *out = match row.get(j) {
                None => ground,
                Some(&(a, _, _)) if a > x1 => ground,
                Some(&(a, b, v)) if a <= x0 && b > x1 => v,
                Some(_) => f32::NAN,
            };
        }
    }

    /// The uniform remission of the cell holding (x, y), if it has one.
    #[inline]
    fn at(&self, x: f64, y: f64) -> Option<f32> {
        let (bx, by) = (
            (x - self.origin[0]) * self.inv_side,
            (y - self.origin[1]) * self.inv_side,
        );
        // NaN and points off the grid compare false; on the grid `as` truncates, the floor there.
        if !(bx >= 0.0 && by >= 0.0 && bx < self.size[0] as f64 && by < self.size[1] as f64) {
            return None;
        }
        let code = self.cells[by as usize * self.size[0] + bx as usize];
        self.remissions.get(usize::from(code)).copied()
    }
}

impl GroundTexture {
    /// The scene's ground prepared for lookups.
    pub fn new(scene: &Scene) -> Self {
        let patches: Vec<PreparedPatch> = scene
            .patches
            .iter()
            .rev()
            .map(|p| {
                let (s, c) = p.yaw_rad.sin_cos();
                let (hl, hw) = (0.5 * p.length_m, 0.5 * p.width_m);
                // Axis-aligned half extents of the rotated rectangle: a cheap first test.
                let (ex, ey) = (c.abs() * hl + s.abs() * hw, s.abs() * hl + c.abs() * hw);
                PreparedPatch {
                    x: p.x_m,
                    y: p.y_m,
                    sin: s,
                    cos: c,
                    half_length: hl,
                    half_width: hw,
                    extent: [ex, ey],
                    remission: p.remission,
                }
            })
            .collect();
        let bins = PatchBins::new(&patches);
        let areas = AreaRows::new(&scene.areas);
        let uniform = UniformCells::new(&areas, scene.ground_remission);
        GroundTexture {
            ground_remission: scene.ground_remission,
            pavement_texture: scene.pavement_texture,
            patches,
            bins,
            areas,
            uniform,
        }
    }

    /// Remission of the ground at (x, y).
    pub fn remission_at(&self, x: f64, y: f64) -> f32 {
        for &i in self.bins.at(x, y) {
            let p = &self.patches[i as usize];
            if p.contains(x, y) {
                return pavement(p.remission, self.pavement_texture, x, y);
            }
        }
        let base = self
            .uniform
            .at(x, y)
            .unwrap_or_else(|| self.area_or_ground(x, y));
        pavement(base, self.pavement_texture, x, y)
    }

    /// The last area holding (x, y) by its rows, else the bare ground.
    fn area_or_ground(&self, x: f64, y: f64) -> f32 {
        self.areas.at(x, y).unwrap_or(self.ground_remission)
    }

    /// [`Self::remission_at`] trying every patch, the straightforward way (for tests).
    #[cfg(test)]
    fn remission_at_every_patch(&self, x: f64, y: f64) -> f32 {
        let base = self.patches.iter().find(|p| p.contains(x, y)).map_or_else(
            || self.areas.at(x, y).unwrap_or(self.ground_remission),
            |p| p.remission,
        );
        pavement(base, self.pavement_texture, x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::super::scene::Patch;
    use super::*;

    #[test]
    fn the_prepared_ground_texture_answers_as_the_scene_does() {
        let patch = |id: &str, x, y, yaw, length, width, remission| Patch {
            id: id.into(),
            x_m: x,
            y_m: y,
            yaw_rad: yaw,
            length_m: length,
            width_m: width,
            remission,
        };
        let scene = Scene {
            areas: Vec::new(),
            min_m: [-20.0, -20.0],
            max_m: [20.0, 20.0],
            ground_remission: 0.2,
            pavement_texture: 0.05,
            solids: Vec::new(),
            patches: vec![
                patch("lane", 0.0, 0.0, 0.0, 30.0, 0.3, 0.8),
                patch("arrow", 3.0, 1.0, 0.7, 4.0, 1.0, 0.6),
                patch("cross", 2.0, 0.5, 1.55, 6.0, 3.0, 0.4),
                patch("slant", -5.0, -4.0, -2.4, 8.0, 0.5, 0.9),
            ],
        };
        let texture = GroundTexture::new(&scene);
        let mut painted = 0;
        // Beyond the patches too (x up to 25 m: off the bins' grid).
        for i in -200..=500 {
            for j in -200..=200 {
                let (x, y) = (i as f64 * 0.05 + 0.013, j as f64 * 0.05 - 0.007);
                let want = scene.ground_remission_at(x, y);
                assert_eq!(texture.remission_at(x, y), want, "at ({x}, {y})");
                assert_eq!(
                    texture.remission_at_every_patch(x, y),
                    want,
                    "at ({x}, {y})"
                );
                painted += usize::from(scene.patches.iter().any(|p| p.contains(x, y)));
            }
        }
        assert!(
            painted > 5_000,
            "the patches cover part of the sweep: {painted}"
        );
    }

    /// A pavement with a hole, a runway across it, a painted line on top.
    fn apron_scene() -> Scene {
        Scene {
            min_m: [-50.0, -50.0],
            max_m: [50.0, 50.0],
            ground_remission: 0.1,
            pavement_texture: 0.0,
            solids: Vec::new(),
            patches: vec![Patch {
                id: "line".into(),
                x_m: 0.0,
                y_m: 0.0,
                yaw_rad: 0.3,
                length_m: 20.0,
                width_m: 0.2,
                remission: 0.9,
            }],
            areas: vec![
                Area {
                    id: "apron".into(),
                    outline: vec![[-30.0, -20.0], [25.0, -25.0], [30.0, 20.0], [-20.0, 30.0]],
                    holes: vec![vec![[-5.0, -5.0], [5.0, -5.0], [0.0, 8.0]]],
                    remission: 0.35,
                },
                Area {
                    id: "runway".into(),
                    outline: vec![[-40.0, 10.0], [40.0, 14.0], [40.0, 19.0], [-40.0, 15.0]],
                    holes: Vec::new(),
                    remission: 0.2,
                },
            ],
        }
    }

    /// Areas: the rows give what the polygons give on each row's middle line, exactly in x, and
    /// nothing outside them.
    #[test]
    fn area_rows_give_the_polygons_remission_on_their_middle_lines() {
        let scene = apron_scene();
        let texture = GroundTexture::new(&scene);
        let mut seen = [0usize; 4];
        for r in 0..400 {
            let y = texture.areas.y0 + (r as f64 + 0.5) * AREA_ROW_M;
            for k in 0..200 {
                let x = -45.0 + 0.4513 * k as f64;
                let want = scene.ground_remission_at(x, y);
                assert_eq!(texture.remission_at(x, y), want, "({x}, {y})");
                let i = [0.1, 0.35, 0.2, 0.9]
                    .iter()
                    .position(|&v| v == want)
                    .unwrap();
                seen[i] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n > 20), "{seen:?}");
        // The hole is bare ground, the apron around it concrete.
        let y0 = texture.areas.y0;
        let middle = y0 + (((0.0 - y0) / AREA_ROW_M).floor() + 0.5) * AREA_ROW_M;
        assert_eq!(texture.remission_at(0.0, middle), 0.1);
        assert_eq!(texture.remission_at(-10.0, middle), 0.35);
    }

    /// With the uniform cells a lookup answers as the full one does, bit for bit: random points,
    /// points on and a hair either side of the cells' edges and the area rows' edges; each cell
    /// with a value gives its rows' answer; and most points on the grid are in such cells (else
    /// the test would prove nothing).
    #[test]
    fn uniform_cells_answer_as_the_full_lookup() {
        use rand::{RngExt, SeedableRng};
        let mut scene = apron_scene();
        scene.pavement_texture = 0.05;
        let texture = GroundTexture::new(&scene);
        let cells = &texture.uniform;
        assert_eq!(cells.inv_side, 0.5);
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(3);
        let side = 1.0 / cells.inv_side;
        let mut points: Vec<(f64, f64)> = (0..200_000)
            .map(|_| (rng.random_range(-60.0..60.0), rng.random_range(-60.0..60.0)))
            .collect();
        for k in -30..30 {
            for nudge in [-1e-9, 0.0, 1e-9] {
                let e = k as f64 * side + nudge;
                let (x, y) = (cells.origin[0] + e, cells.origin[1] + e);
                let row = texture.areas.y0 + k as f64 * AREA_ROW_M + nudge;
                points.extend([(x, 3.3), (-7.7, y), (x, y), (11.1, row), (x, row)]);
            }
        }
        let (mut uniform, mut on_grid) = (0, 0);
        for &(x, y) in &points {
            let want = texture.remission_at_every_patch(x, y);
            assert_eq!(
                texture.remission_at(x, y).to_bits(),
                want.to_bits(),
                "at ({x}, {y})"
            );
            if let Some(v) = cells.at(x, y) {
                assert_eq!(v, texture.area_or_ground(x, y), "at ({x}, {y})");
                uniform += 1;
            }
            let (bx, by) = (x - cells.origin[0], y - cells.origin[1]);
            on_grid += usize::from(
                bx >= 0.0
                    && by >= 0.0
                    && bx < cells.size[0] as f64 * side
                    && by < cells.size[1] as f64 * side,
            );
        }
        assert!(
            uniform > on_grid * 6 / 10 && uniform < on_grid,
            "{uniform} of the {on_grid} points on the grid in uniform cells"
        );
        // Off the grid, NaN: the full lookup's answer.
        assert_eq!(cells.at(f64::NAN, 0.0), None);
        assert_eq!(
            texture.remission_at(500.0, 0.0),
            scene.ground_remission_at(500.0, 0.0)
        );
    }
}
