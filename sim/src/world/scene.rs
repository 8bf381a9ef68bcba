//! What a world is made of, independent of Rapier: the ground, solid objects, painted patches.
//!
//! Scenario files are read into this (`scenario`), the Rapier world is built from it (`world`)
//! and the LiDAR intensities come from its remissions. World frame: x east, y north, z up,
//! metres; the ground is the plane z = 0.

/// The shape of a solid object, standing on the ground (its base at z = 0) unless `z_min_m` says otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolidShape {
    /// A box of the given full extents (x along the object's heading, y across, z up), metres.
    Box {
        /// Full extents x, y, z.
        size_m: [f64; 3],
    },
    /// A vertical cylinder.
    Cylinder {
        /// Radius.
        radius_m: f64,
        /// Height.
        height_m: f64,
    },
    /// A vertical cone, apex up (a traffic cone).
    Cone {
        /// Base radius.
        radius_m: f64,
        /// Height.
        height_m: f64,
    },
    /// One collision part of a vehicle description (a parked aircraft's wing, engine, fin), in
    /// any orientation: the solid's x, y and yaw place the vehicle frame (its `z_min_m` is 0).
    Part {
        /// The primitive.
        shape: aircraft::Shape,
        /// Its pose in the vehicle frame.
        vehicle_from_part: nalgebra::Isometry3<f64>,
    },
}

impl SolidShape {
    /// Height of the shape's top above its base, metres (a part: above the ground).
    pub fn height_m(&self) -> f64 {
        match *self {
            SolidShape::Box { size_m } => size_m[2],
            SolidShape::Cylinder { height_m, .. } | SolidShape::Cone { height_m, .. } => height_m,
            SolidShape::Part { .. } => self.as_part().map_or(0.0, |p| p.top_m()),
        }
    }

    /// The heights the solid occupies, metres above the ground, for a base at `z_min_m`: a
    /// part's underside to its top (a wing is not a wall down to the ground).
    pub fn z_range_m(&self, z_min_m: f64) -> (f64, f64) {
        match self.as_part() {
            Some(part) => (part.underside_m(), part.top_m()),
            None => (z_min_m, z_min_m + self.height_m()),
        }
    }

    /// A part shape as an `aircraft::Part` (its footprint, underside and top), `None` otherwise.
    pub fn as_part(&self) -> Option<aircraft::Part> {
        match *self {
            SolidShape::Part {
                shape,
                vehicle_from_part,
            } => Some(aircraft::Part {
                link: String::new(),
                collision_index: 0,
                shape,
                vehicle_from_part,
            }),
            _ => None,
        }
    }
    /// Extent along the object's heading, metres (a box's x size, a round shape's diameter): a
    /// train car's length.
    pub fn length_m(&self) -> f64 {
        match *self {
            SolidShape::Box { size_m } => size_m[0],
            SolidShape::Cylinder { radius_m, .. } | SolidShape::Cone { radius_m, .. } => {
                2.0 * radius_m
            }
            SolidShape::Part { .. } => 2.0 * self.footprint_radius_m(),
        }
    }
    /// Radius of the smallest vertical cylinder around the shape's axis holding it, metres.
    /// (A part: around the vehicle frame's origin.)
    pub fn footprint_radius_m(&self) -> f64 {
        match *self {
            SolidShape::Box { size_m } => 0.5 * size_m[0].hypot(size_m[1]),
            SolidShape::Cylinder { radius_m, .. } | SolidShape::Cone { radius_m, .. } => radius_m,
            SolidShape::Part { .. } => self.as_part().map_or(0.0, |p| {
                let (low, high) = p.footprint().bounds();
                [low.x, high.x]
                    .iter()
                    .flat_map(|x| [low.y, high.y].map(|y| x.hypot(y)))
                    .fold(0.0, f64::max)
            }),
        }
    }
}

/// What an object is, as the scenario names it (reports and the replay use it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectKind {
    /// A traffic cone.
    Cone,
    /// A wheeled container (baggage cart, dolly).
    Container,
    /// A taxiway edge marker.
    Marker,
    /// A building or hangar.
    Building,
    /// A lamp post.
    LampPost,
    /// A parked car.
    ParkedCar,
    /// A vehicle that moves at run time.
    Vehicle,
    /// Foreign object debris.
    Debris,
    /// A plain box.
    Box,
    /// A plain cylinder.
    Cylinder,
    /// A person walking on the ramp (a cylinder).
    Person,
    /// An aircraft tug or baggage tractor (a box); a train's lead.
    Tug,
    /// A baggage cart, lower than a business jet's wing (a box); a train's car.
    BaggageCart,
    /// A fuel truck (a box).
    FuelTruck,
    /// A parked aircraft's collision part (from a vehicle description: `vehicle = "a320"`).
    ParkedAircraft,
    /// An airport sign (a box, sized from its text and size class).
    Sign,
    /// A taxiway edge light (a short cylinder).
    EdgeLight,
    /// A windsock's mast (a cylinder).
    Windsock,
    /// A light unit beside a runway: VASI, PAPI (a box).
    LightUnit,
}

impl ObjectKind {
    /// The snake_case name of the kind, as in files.
    pub fn name(self) -> &'static str {
        match self {
            ObjectKind::Cone => "cone",
            ObjectKind::Container => "container",
            ObjectKind::Marker => "marker",
            ObjectKind::Building => "building",
            ObjectKind::LampPost => "lamp_post",
            ObjectKind::ParkedCar => "parked_car",
            ObjectKind::Vehicle => "vehicle",
            ObjectKind::Debris => "debris",
            ObjectKind::Box => "box",
            ObjectKind::Cylinder => "cylinder",
            ObjectKind::Person => "person",
            ObjectKind::Tug => "tug",
            ObjectKind::BaggageCart => "baggage_cart",
            ObjectKind::FuelTruck => "fuel_truck",
            ObjectKind::ParkedAircraft => "parked_aircraft",
            ObjectKind::Sign => "sign",
            ObjectKind::EdgeLight => "edge_light",
            ObjectKind::Windsock => "windsock",
            ObjectKind::LightUnit => "light_unit",
        }
    }

    /// True for the kinds shaped as a vertical cylinder or cone (`radius_m` and `height_m` in
    /// files), false for the box kinds (`size_m`).
    pub fn is_round(self) -> bool {
        matches!(
            self,
            ObjectKind::Cone
                | ObjectKind::Marker
                | ObjectKind::LampPost
                | ObjectKind::Cylinder
                | ObjectKind::Person
                | ObjectKind::EdgeLight
                | ObjectKind::Windsock
        )
    }

    /// The kind's shape when a file gives no size (`None`: `building`, `box` and `cylinder`
    /// need theirs). Metres: a box's full extents x (along its heading), y, z; a round kind's
    /// radius and height.
    pub fn default_shape(self) -> Option<SolidShape> {
        let cylinder = |radius_m, height_m| Some(SolidShape::Cylinder { radius_m, height_m });
        let cuboid = |x, y, z| Some(SolidShape::Box { size_m: [x, y, z] });
        match self {
            ObjectKind::Cone => Some(SolidShape::Cone {
                radius_m: 0.18,
                height_m: 0.45,
            }),
            ObjectKind::Marker => cylinder(0.10, 0.35),
            ObjectKind::LampPost => cylinder(0.12, 6.0),
            ObjectKind::Person => cylinder(0.25, 1.75),
            ObjectKind::Container => cuboid(0.8, 0.6, 1.1),
            ObjectKind::ParkedCar | ObjectKind::Vehicle => cuboid(4.5, 1.8, 1.5),
            ObjectKind::Debris => cuboid(0.3, 0.3, 0.15),
            ObjectKind::Tug => cuboid(3.0, 1.8, 1.5),
            ObjectKind::BaggageCart => cuboid(2.6, 1.4, 1.0),
            ObjectKind::FuelTruck => cuboid(9.0, 2.5, 3.2),
            ObjectKind::EdgeLight => cylinder(0.06, 0.35),
            ObjectKind::Windsock => cylinder(0.08, 6.0),
            ObjectKind::LightUnit => cuboid(0.6, 1.2, 0.9),
            ObjectKind::Sign => cuboid(0.3, 2.0, 1.07),
            ObjectKind::Building
            | ObjectKind::Box
            | ObjectKind::Cylinder
            | ObjectKind::ParkedAircraft => None,
        }
    }

    /// The kind's remission when a file gives none.
    pub fn default_remission(self) -> f32 {
        match self {
            ObjectKind::Cone => 0.5,
            ObjectKind::Marker => 0.7,
            ObjectKind::Container | ObjectKind::BaggageCart => 0.4,
            ObjectKind::Debris | ObjectKind::Building => 0.2,
            ObjectKind::LampPost
            | ObjectKind::ParkedCar
            | ObjectKind::Vehicle
            | ObjectKind::Box
            | ObjectKind::Cylinder
            | ObjectKind::Person
            | ObjectKind::Tug
            | ObjectKind::FuelTruck
            | ObjectKind::ParkedAircraft
            | ObjectKind::Windsock => 0.3,
            ObjectKind::Sign | ObjectKind::LightUnit => 0.6,
            ObjectKind::EdgeLight => 0.5,
        }
    }
}

/// One solid object of the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Solid {
    /// Unique name (from the scenario).
    pub id: String,
    /// What it is.
    pub kind: ObjectKind,
    /// Its shape.
    pub shape: SolidShape,
    /// Position of its axis on the ground, metres.
    pub x_m: f64,
    /// Position of its axis on the ground, metres.
    pub y_m: f64,
    /// Height of its base above the ground (0 = standing on it), metres.
    pub z_min_m: f64,
    /// Heading, radians (counter-clockwise from x).
    pub yaw_rad: f64,
    /// LiDAR remission (reflectivity) in [0, 1].
    pub remission: f32,
    /// True for run-time obstacles (absent from the mapping drive and the offline map).
    pub runtime: bool,
}

/// A painted marking on the ground: a rectangle with its own remission (lines, patches).
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// Unique name.
    pub id: String,
    /// Centre, metres.
    pub x_m: f64,
    /// Centre, metres.
    pub y_m: f64,
    /// Heading of its length, radians.
    pub yaw_rad: f64,
    /// Extent along its heading, metres.
    pub length_m: f64,
    /// Extent across, metres.
    pub width_m: f64,
    /// LiDAR remission in [0, 1].
    pub remission: f32,
}

impl Patch {
    /// True when the ground point (x, y) lies on the patch.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        let (dx, dy) = (x - self.x_m, y - self.y_m);
        let (s, c) = self.yaw_rad.sin_cos();
        let (along, across) = (c * dx + s * dy, -s * dx + c * dy);
        along.abs() <= 0.5 * self.length_m && across.abs() <= 0.5 * self.width_m
    }
}

/// A painted or paved area of the ground: a polygon with holes (an airport's pavement, a
/// runway), its own remission. Later areas cover earlier ones; patches cover areas.
#[derive(Clone, Debug, PartialEq)]
pub struct Area {
    /// Unique name.
    pub id: String,
    /// The outline, metres (either winding; not closed by repeating its first point).
    pub outline: Vec<[f64; 2]>,
    /// Holes in it.
    pub holes: Vec<Vec<[f64; 2]>>,
    /// LiDAR remission in [0, 1].
    pub remission: f32,
}

impl Area {
    /// True when the ground point (x, y) lies in the area (even-odd over the outline and holes).
    pub fn contains(&self, x: f64, y: f64) -> bool {
        std::iter::once(&self.outline)
            .chain(&self.holes)
            .map(|ring| crossings(ring, y).filter(|&cx| cx > x).count())
            .sum::<usize>()
            % 2
            == 1
    }
}

/// Where a ring's edges cross the line at height `y` (half-open in y, so a vertex is counted once).
fn crossings(ring: &[[f64; 2]], y: f64) -> impl Iterator<Item = f64> + '_ {
    let n = ring.len();
    (0..n).filter_map(move |i| {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        ((a[1] <= y) != (b[1] <= y)).then(|| a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
    })
}

/// The whole static description of a world.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// Lower corner of the ground (x, y), metres.
    pub min_m: [f64; 2],
    /// Upper corner of the ground (x, y), metres.
    pub max_m: [f64; 2],
    /// Remission of bare ground.
    pub ground_remission: f32,
    /// Amplitude of the ground's texture: each 0.5 m square is off its remission (bare ground or
    /// a patch) by up to this much, the same every time it is seen (aggregate, wear, stains).
    /// 0: a perfectly uniform ground.
    pub pavement_texture: f32,
    /// Solid objects (static and run-time).
    pub solids: Vec<Solid>,
    /// Painted markings (later ones paint over earlier ones and over the areas).
    pub patches: Vec<Patch>,
    /// Paved or painted areas (polygons; later ones cover earlier ones).
    pub areas: Vec<Area>,
}

impl Scene {
    /// Remission of the ground at (x, y): the last patch holding the point, else bare ground.
    pub fn ground_remission_at(&self, x: f64, y: f64) -> f32 {
        let area = || {
            self.areas
                .iter()
                .rev()
                .find(|a| a.contains(x, y))
                .map_or(self.ground_remission, |a| a.remission)
        };
        let base = self
            .patches
            .iter()
            .rev()
            .find(|p| p.contains(x, y))
            .map_or_else(area, |p| p.remission);
        pavement(base, self.pavement_texture, x, y)
    }

    /// The ground's remission prepared for many lookups (the LiDAR's ground returns): the same
    /// answers as [`Self::ground_remission_at`] without a sine and cosine per patch and point.
    pub fn ground_texture(&self) -> GroundTexture {
        let patches: Vec<PreparedPatch> = self
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
        GroundTexture {
            ground_remission: self.ground_remission,
            pavement_texture: self.pavement_texture,
            patches,
            bins,
            areas: AreaRows::new(&self.areas),
        }
    }
}

/// The ground's remission at (x, y) where it is `base` untextured: off by up to `amplitude`, a hash of the 0.5 m
/// square holding the point (uniform in [-1, 1]), clamped to [0, 1].
#[inline]
pub fn pavement(base: f32, amplitude: f32, x: f64, y: f64) -> f32 {
    if amplitude == 0.0 {
        return base;
    }
    let (i, j) = (floor_i64(x * 2.0), floor_i64(y * 2.0));
    // SplitMix64 of the square's coordinates.
    let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_add(0x632B_E59B_D9B4_E019);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let u = (z >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0;
    (base + amplitude * u).clamp(0.0, 1.0)
}

/// `v.floor() as i64` without the libm call `f64::floor` is on baseline x86-64 (once per LiDAR
/// ground return here): truncate, then step down where that rounded up.
#[inline]
fn floor_i64(v: f64) -> i64 {
    let t = v as i64;
    t - i64::from((t as f64) > v)
}

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
        row
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

impl GroundTexture {
    /// Remission of the ground at (x, y).
    pub fn remission_at(&self, x: f64, y: f64) -> f32 {
        for &i in self.bins.at(x, y) {
            let p = &self.patches[i as usize];
            if p.contains(x, y) {
                return pavement(p.remission, self.pavement_texture, x, y);
            }
        }
        let base = self.areas.at(x, y).unwrap_or(self.ground_remission);
        pavement(base, self.pavement_texture, x, y)
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
    use super::*;

    /// The floor without libm is the floor, on both sides of zero, on integers and NaN.
    #[test]
    fn floor_without_libm_is_the_floor() {
        for v in [
            -2.5, -2.0, -1.0000001, -0.3, -0.0, 0.0, 0.3, 0.9999999, 1.0, 7.5, 1e12, -1e12,
        ] {
            assert_eq!(floor_i64(v), v.floor() as i64, "{v}");
        }
        assert_eq!(floor_i64(f64::NAN), f64::NAN.floor() as i64);
    }

    /// The pavement's texture: the same value anywhere in a 0.5 m square and every time,
    /// within the amplitude of the base, spread over it (mean near the base, both signs).
    #[test]
    fn the_pavement_texture_is_fixed_per_square_and_within_its_amplitude() {
        assert_eq!(pavement(0.3, 0.0, 1.7, 2.2), 0.3);
        assert_eq!(
            pavement(0.3, 0.05, 1.51, 2.01),
            pavement(0.3, 0.05, 1.99, 2.49)
        );
        let values: Vec<f32> = (0..10_000)
            .map(|k| {
                pavement(
                    0.3,
                    0.05,
                    (k % 100) as f64 * 0.5,
                    (k / 100) as f64 * 0.5 - 20.0,
                )
            })
            .collect();
        assert!(values.iter().all(|v| (v - 0.3).abs() <= 0.05 + 1e-6));
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        assert!((mean - 0.3).abs() < 0.002, "mean {mean}");
        let spread = values.iter().filter(|v| (*v - 0.3).abs() > 0.04).count();
        assert!(spread > 1_000, "{spread} squares beyond 0.04 of the base");
    }

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
        let texture = scene.ground_texture();
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

    /// Areas: a pavement with a hole, a runway across it, a patch on top. The rows give what the
    /// polygons give on each row's middle line, exactly in x, and nothing outside them.
    #[test]
    fn area_rows_give_the_polygons_remission_on_their_middle_lines() {
        let scene = Scene {
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
        };
        let texture = scene.ground_texture();
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
}
