//! What a world is made of, independent of Rapier: the ground, solid objects, painted patches.
//!
//! Scenario files are read into this (`scenario`), the Rapier world is built from it (`world`)
//! and the LiDAR intensities come from its remissions. World frame: x east, y north, z up,
//! metres; the ground is the plane z = 0. The ground's remission, prepared for lookups, is
//! [`super::ground`]'s.

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
    /// Extent across the object's heading, metres (a box's y size, a round shape's diameter).
    pub fn width_m(&self) -> f64 {
        match *self {
            SolidShape::Box { size_m } => size_m[1],
            _ => self.length_m(),
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
    /// Whether the airframe feels a contact with this kind of object (the strike sensor,
    /// `EndReason::Struck`): everything but what weighs too little to jolt it - a person, a
    /// cone, a marker, debris, an edge light. A tug, a van, a cart, a building do.
    pub fn felt_on_contact(self) -> bool {
        !matches!(
            self,
            ObjectKind::Person
                | ObjectKind::Cone
                | ObjectKind::Marker
                | ObjectKind::Debris
                | ObjectKind::EdgeLight
        )
    }
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
pub(super) fn crossings(ring: &[[f64; 2]], y: f64) -> impl Iterator<Item = f64> + '_ {
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
}
