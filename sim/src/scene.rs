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
}

impl SolidShape {
    /// Height of the shape, metres.
    pub fn height_m(&self) -> f64 {
        match *self {
            SolidShape::Box { size_m } => size_m[2],
            SolidShape::Cylinder { height_m, .. } | SolidShape::Cone { height_m, .. } => height_m,
        }
    }
    /// Radius of the smallest vertical cylinder around the shape's axis holding it, metres.
    pub fn footprint_radius_m(&self) -> f64 {
        match *self {
            SolidShape::Box { size_m } => 0.5 * size_m[0].hypot(size_m[1]),
            SolidShape::Cylinder { radius_m, .. } | SolidShape::Cone { radius_m, .. } => radius_m,
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

/// The whole static description of a world.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// Lower corner of the ground (x, y), metres.
    pub min_m: [f64; 2],
    /// Upper corner of the ground (x, y), metres.
    pub max_m: [f64; 2],
    /// Remission of bare ground.
    pub ground_remission: f32,
    /// Solid objects (static and run-time).
    pub solids: Vec<Solid>,
    /// Painted markings (later ones paint over earlier ones).
    pub patches: Vec<Patch>,
}

impl Scene {
    /// Remission of the ground at (x, y): the last patch holding the point, else bare ground.
    pub fn ground_remission_at(&self, x: f64, y: f64) -> f32 {
        self.patches
            .iter()
            .rev()
            .find(|p| p.contains(x, y))
            .map_or(self.ground_remission, |p| p.remission)
    }
}
