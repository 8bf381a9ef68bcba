//! The Rapier world: ground, objects and the vehicle's collision geometry, and the ground truth
//! that judges a run (contacts and the smallest clearance to each object).
//!
//! The only module (with the LiDAR's generic cast) that touches Rapier, and the one place that
//! converts nalgebra (f64, the autonomy's maths) to Rapier's glam (f32). The vehicle is a
//! kinematic position-based body whose colliders are its URDF collision primitives; objects are
//! fixed colliders; the ground is a thin cuboid (a half-space's bounding box is infinite). No
//! dynamics run: each tick places the vehicle and runs collision detection only, so contacts are
//! those of the current pose (a full `step` reports them one step late).

use std::collections::{HashMap, HashSet};
use std::sync::Mutex;
use std::sync::mpsc::{Receiver, channel};

use aircraft::{Part, Shape, Vehicle};
use nalgebra::{Isometry2, Isometry3, Translation3, UnitQuaternion, Vector3};
use rapier3d::math::{Pose, Rot3, Vector};
use rapier3d::prelude::*;

use super::scene::{ObjectKind, Scene, Solid, SolidShape};

/// Thickness of the ground slab below z = 0, metres.
const GROUND_THICKNESS_M: f64 = 0.1;
/// Objects farther than this beyond the vehicle's bounding radius are not measured for clearance.
const CLEARANCE_RANGE_M: f64 = 15.0;

/// The gap between two boxes (0 when they overlap): a lower bound of the distance between
/// anything they hold.
fn aabb_gap(a: &Aabb, b: &Aabb) -> f64 {
    let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max(Vector::ZERO);
    gap.length() as f64
}

/// nalgebra pose (f64) to Rapier pose (f32): the one conversion at the simulator's edge.
pub fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation.quaternion().coords; // (i, j, k, w)
    Pose::from_parts(
        Vector::new(t.x as f32, t.y as f32, t.z as f32),
        Rot3::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32),
    )
}

/// A planar pose lifted to 3D (z = 0, yaw about z).
pub fn planar_to_3d(pose: &Isometry2<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(pose.translation.x, pose.translation.y, 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), pose.rotation.angle()),
    )
}

/// Parry's cylinders and cones run along +y (a cone's apex at +y): this stands them on z.
fn y_up_to_z_up() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
    )
}

/// Who a collider belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Owner {
    /// The ground slab.
    Ground,
    /// Object `i` of the scene.
    Object(usize),
    /// Collision primitive `i` of the vehicle.
    VehiclePart(usize),
}

/// One contact between the vehicle and an object: ground truth, for judging.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Contact {
    /// Simulation time when the contact started, seconds.
    pub time_s: f64,
    /// The object's id.
    pub object: String,
    /// The object's kind.
    pub kind: ObjectKind,
    /// The vehicle part (URDF link) that touched.
    pub part: String,
}

/// The simulated world.
pub struct World {
    physics: PhysicsWorld,
    scene: Scene,
    /// The ground's remission with the patches prepared and binned, built once (patches do not
    /// move; the LiDAR reads it every revolution).
    ground: super::ground::GroundTexture,
    objects: Vec<ColliderHandle>,
    object_active: Vec<bool>,
    /// When each object last became present (minus infinity: from the start), seconds.
    active_since_s: Vec<f64>,
    owners: HashMap<ColliderHandle, Owner>,
    vehicle: RigidBodyHandle,
    parts: Vec<(ColliderHandle, String)>,
    /// Radius around the vehicle origin holding every part (2D), metres.
    vehicle_radius_m: f64,
    /// Each solid's `footprint_radius_m`, found once: a shape never changes (a mover only
    /// moves), and a parked aircraft's part finds it from its footprint's convex hull - every
    /// physics step for every part, it was 7 % of a KSYR run's CPU.
    footprint_radius_m: Vec<f64>,
    /// Behind a mutex only so the world is `Sync` (the LiDAR reads it from many threads).
    events: Mutex<Receiver<CollisionEvent>>,
    collector: ChannelEventCollector,
    time_s: f64,
    touching: HashSet<(usize, usize)>,
    contacts: Vec<Contact>,
    min_clearance_m: Vec<f64>,
    /// Per vehicle part, the distance to the nearest active object in range at the current pose.
    part_clearance_m: Vec<f64>,
    /// Per vehicle part, that nearest object (index into `scene.solids`).
    part_nearest: Vec<Option<usize>>,
}

impl World {
    /// The world of `scene`, every solid in it (the run-time obstacles too), with `vehicle` at
    /// `start`: the closed loop's world.
    pub fn with_obstacles(scene: &Scene, vehicle: &Vehicle, start: &Isometry2<f64>) -> Self {
        Self::build(scene, true, vehicle, start)
    }

    /// The world of `scene` without its run-time obstacles (`Solid::runtime`), with `vehicle` at
    /// `start`: the mapping drive's world.
    pub fn static_only(scene: &Scene, vehicle: &Vehicle, start: &Isometry2<f64>) -> Self {
        Self::build(scene, false, vehicle, start)
    }

    fn build(scene: &Scene, runtime: bool, vehicle: &Vehicle, start: &Isometry2<f64>) -> Self {
        let mut physics = PhysicsWorld::new();
        physics.gravity = Vector::ZERO;
        let mut owners = HashMap::new();
        let mut scene = scene.clone();
        scene.solids.retain(|s| runtime || !s.runtime);

        let (cx, cy) = (
            0.5 * (scene.min_m[0] + scene.max_m[0]),
            0.5 * (scene.min_m[1] + scene.max_m[1]),
        );
        let (hx, hy) = (
            0.5 * (scene.max_m[0] - scene.min_m[0]),
            0.5 * (scene.max_m[1] - scene.min_m[1]),
        );
        let ground =
            ColliderBuilder::cuboid(hx as f32, hy as f32, (0.5 * GROUND_THICKNESS_M) as f32)
                .position(to_pose(&Isometry3::translation(
                    cx,
                    cy,
                    -0.5 * GROUND_THICKNESS_M,
                )))
                .build();
        owners.insert(physics.colliders.insert(ground), Owner::Ground);

        let mut objects = Vec::with_capacity(scene.solids.len());
        for (i, solid) in scene.solids.iter().enumerate() {
            let collider = solid_collider(solid).build();
            let handle = physics.colliders.insert(collider);
            owners.insert(handle, Owner::Object(i));
            objects.push(handle);
        }

        let body = RigidBodyBuilder::kinematic_position_based()
            .pose(to_pose(&planar_to_3d(start)))
            .build();
        let vehicle_body = physics.bodies.insert(body);
        let mut parts = Vec::with_capacity(vehicle.parts.len());
        let mut vehicle_radius_m: f64 = 0.0;
        for (i, part) in vehicle.parts.iter().enumerate() {
            let collider = part_collider(part)
                .active_collision_types(
                    ActiveCollisionTypes::default() | ActiveCollisionTypes::KINEMATIC_FIXED,
                )
                .active_events(ActiveEvents::COLLISION_EVENTS)
                .build();
            let handle =
                physics
                    .colliders
                    .insert_with_parent(collider, vehicle_body, &mut physics.bodies);
            owners.insert(handle, Owner::VehiclePart(i));
            parts.push((handle, part.link.clone()));
            let c = part.vehicle_from_part.translation.vector;
            vehicle_radius_m = vehicle_radius_m.max(c.x.hypot(c.y) + part_extent(part));
        }
        let (collision_send, events) = channel();
        let (force_send, _force_recv) = channel();
        let (tear_send, _tear_recv) = channel();
        let collector = ChannelEventCollector::new(collision_send, force_send, tear_send);
        let n = objects.len();
        let footprint_radius_m = (scene.solids.iter())
            .map(|s| s.shape.footprint_radius_m())
            .collect();
        let mut world = World {
            physics,
            ground: super::ground::GroundTexture::new(&scene),
            scene,
            objects,
            object_active: vec![true; n],
            active_since_s: vec![f64::NEG_INFINITY; n],
            owners,
            vehicle: vehicle_body,
            parts,
            vehicle_radius_m,
            footprint_radius_m,
            events: Mutex::new(events),
            collector,
            time_s: 0.0,
            touching: HashSet::new(),
            contacts: Vec::new(),
            min_clearance_m: vec![f64::INFINITY; n],
            part_clearance_m: vec![f64::INFINITY; vehicle.parts.len()],
            part_nearest: vec![None; vehicle.parts.len()],
        };
        world.refresh();
        world
    }

    /// The scene the world was built from (run-time obstacles included only if asked).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }
    /// The ground's remission texture of the scene (prepared once).
    pub fn ground_texture(&self) -> &super::ground::GroundTexture {
        &self.ground
    }
    /// Simulation time of the last update, seconds.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Places the vehicle at `pose` at time `time_s`, runs collision detection and updates the
    /// ground truth (contacts, clearances).
    pub fn set_vehicle_pose(&mut self, pose: &Isometry2<f64>, time_s: f64) {
        self.time_s = time_s;
        if let Some(body) = self.physics.bodies.get_mut(self.vehicle) {
            body.set_position(to_pose(&planar_to_3d(pose)), true);
        }
        self.refresh();
        self.update_clearances(pose);
    }

    /// Moves object `i` (a moving obstacle) to (x, y, yaw).
    pub fn set_object_pose(&mut self, i: usize, x_m: f64, y_m: f64, yaw_rad: f64) {
        let Some(solid) = self.scene.solids.get_mut(i) else {
            return;
        };
        solid.x_m = x_m;
        solid.y_m = y_m;
        solid.yaw_rad = yaw_rad;
        let pose = to_pose(&solid_pose(solid));
        if let Some(c) = self.physics.colliders.get_mut(self.objects[i]) {
            c.set_position(pose);
        }
    }

    /// Shows or hides object `i` (obstacles that appear or are removed during a run).
    pub fn set_object_active(&mut self, i: usize, active: bool) {
        if let (Some(c), Some(a)) = (
            self.physics.colliders.get_mut(self.objects[i]),
            self.object_active.get_mut(i),
        ) {
            c.set_enabled(active);
            if active && !*a {
                self.active_since_s[i] = self.time_s;
            }
            *a = active;
        }
    }

    /// True when object `i` is present.
    pub fn object_active(&self, i: usize) -> bool {
        self.object_active.get(i).copied().unwrap_or(false)
    }

    fn refresh(&mut self) {
        self.physics.detect_collisions(&(), &self.collector);
        let events: Vec<CollisionEvent> = match self.events.lock() {
            Ok(rx) => rx.try_iter().collect(),
            Err(poisoned) => poisoned.into_inner().try_iter().collect(),
        };
        for event in events {
            let (a, b, started) = match event {
                CollisionEvent::Started(a, b, _) => (a, b, true),
                CollisionEvent::Stopped(a, b, _) => (a, b, false),
            };
            let pair = match (self.owners.get(&a), self.owners.get(&b)) {
                (Some(Owner::Object(o)), Some(Owner::VehiclePart(p)))
                | (Some(Owner::VehiclePart(p)), Some(Owner::Object(o))) => (*o, *p),
                _ => continue,
            };
            if started {
                if self.touching.insert(pair) {
                    let solid = &self.scene.solids[pair.0];
                    self.contacts.push(Contact {
                        time_s: self.time_s,
                        object: solid.id.clone(),
                        kind: solid.kind,
                        part: self.parts[pair.1].1.clone(),
                    });
                }
            } else {
                self.touching.remove(&pair);
            }
        }
    }

    /// Ground truth at the current pose: the distance from each part to each active object in
    /// range, kept as the smallest per object so far and the smallest per part now. A pair's
    /// exact (GJK) distance is computed only when the gap between their bounding boxes, a lower
    /// bound, could lower one of the two.
    fn update_clearances(&mut self, pose: &Isometry2<f64>) {
        let (vx, vy) = (pose.translation.x, pose.translation.y);
        self.part_clearance_m.fill(f64::INFINITY);
        self.part_nearest.fill(None);
        let parts: Vec<(&Collider, Aabb)> = self
            .parts
            .iter()
            .filter_map(|(h, _)| self.physics.colliders.get(*h))
            .map(|c| (c, c.compute_aabb()))
            .collect();
        for (i, solid) in self.scene.solids.iter().enumerate() {
            if !self.object_active[i] {
                continue;
            }
            let reach = self.vehicle_radius_m + self.footprint_radius_m[i] + CLEARANCE_RANGE_M;
            if (solid.x_m - vx).hypot(solid.y_m - vy) > reach {
                continue;
            }
            let Some(obj) = self.physics.colliders.get(self.objects[i]) else {
                continue;
            };
            let obj_box = obj.compute_aabb();
            for (p, (part, part_box)) in parts.iter().enumerate() {
                let bound = aabb_gap(part_box, &obj_box);
                let (per_object, per_part) =
                    (&mut self.min_clearance_m[i], &mut self.part_clearance_m[p]);
                if bound >= *per_object && bound >= *per_part {
                    continue;
                }
                if let Ok(d) = parry3d::query::distance(
                    part.position(),
                    part.shape(),
                    obj.position(),
                    obj.shape(),
                ) {
                    let d = d.distance as f64;
                    *per_object = per_object.min(d);
                    if d < *per_part {
                        *per_part = d;
                        self.part_nearest[p] = Some(i);
                    }
                }
            }
        }
    }

    /// Distance from object `i` to each vehicle part at the current pose, metres (0 when
    /// touching; empty when the object is absent or unknown).
    pub fn distances_to(&self, i: usize) -> Vec<f64> {
        let Some(obj) = self
            .objects
            .get(i)
            .filter(|_| self.object_active(i))
            .and_then(|h| self.physics.colliders.get(*h))
        else {
            return Vec::new();
        };
        self.parts
            .iter()
            .filter_map(|(h, _)| self.physics.colliders.get(*h))
            .map(|part| {
                parry3d::query::distance(part.position(), part.shape(), obj.position(), obj.shape())
                    .map_or(f64::INFINITY, |d| d.distance as f64)
            })
            .collect()
    }

    /// Signed separation of object `i`, where it is now, from the vehicle's part (URDF link)
    /// `part` placed where `pose` puts it, metres: negative when they overlap (the penetration
    /// depth), infinity beyond 1 m, when the object is absent or the shapes unsupported. The
    /// judge's "did the vehicle's own motion bring them together".
    pub fn part_separation_at_m(&self, i: usize, part: &str, pose: &Isometry2<f64>) -> f64 {
        let (Some(obj), Some(body)) = (
            self.objects
                .get(i)
                .filter(|_| self.object_active(i))
                .and_then(|h| self.physics.colliders.get(*h)),
            self.physics.bodies.get(self.vehicle),
        ) else {
            return f64::INFINITY;
        };
        let moved = to_pose(&planar_to_3d(pose)) * body.position().inverse();
        self.parts
            .iter()
            .filter(|(_, name)| name == part)
            .filter_map(|(h, _)| self.physics.colliders.get(*h))
            .filter_map(|c| {
                let at = moved * *c.position();
                parry3d::query::contact(&at, c.shape(), obj.position(), obj.shape(), 1.0)
                    .ok()
                    .flatten()
                    .map(|k| k.dist as f64)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// When object `i` last became present, seconds (minus infinity: present from the start).
    pub fn object_active_since_s(&self, i: usize) -> f64 {
        self.active_since_s
            .get(i)
            .copied()
            .unwrap_or(f64::NEG_INFINITY)
    }

    /// The vehicle's reference point in the world (x, y).
    pub fn vehicle_position(&self) -> nalgebra::Point2<f64> {
        self.physics
            .bodies
            .get(self.vehicle)
            .map_or(nalgebra::Point2::origin(), |b| {
                let t = b.translation();
                nalgebra::Point2::new(t.x as f64, t.y as f64)
            })
    }

    /// Whether object `i` (indexed like `scene().solids`) touches the vehicle now.
    pub fn touches_vehicle(&self, i: usize) -> bool {
        self.touching.iter().any(|&(object, _)| object == i)
    }

    /// Every object and vehicle part touching now, as contacts at this time, in object then
    /// part order.
    pub fn touching_now(&self) -> Vec<Contact> {
        let mut pairs: Vec<(usize, usize)> = self.touching.iter().copied().collect();
        pairs.sort_unstable();
        pairs
            .into_iter()
            .map(|(o, p)| {
                let solid = &self.scene.solids[o];
                Contact {
                    time_s: self.time_s,
                    object: solid.id.clone(),
                    kind: solid.kind,
                    part: self.parts[p].1.clone(),
                }
            })
            .collect()
    }

    /// Contacts so far, in time order.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }
    /// Smallest distance between the vehicle and each object so far (metres; infinity if never
    /// within range), indexed like `scene().solids`.
    pub fn min_clearances_m(&self) -> &[f64] {
        &self.min_clearance_m
    }

    /// Ground truth at the current pose: per vehicle part (in the vehicle's part order), the
    /// distance to the nearest active object whose centre lies within the vehicle's radius plus
    /// the object's footprint radius plus 15 m (infinity if none).
    pub fn part_clearances_m(&self) -> &[f64] {
        &self.part_clearance_m
    }

    /// Ground truth at the current pose: the object nearest to any vehicle part (indexed like
    /// `scene().solids`) and that distance, metres (0 when touching); `None` when no object is
    /// within range (see [`World::part_clearances_m`]).
    pub fn nearest_object_now(&self) -> Option<(usize, f64)> {
        self.part_clearance_m
            .iter()
            .zip(&self.part_nearest)
            .filter_map(|(d, o)| o.map(|o| (o, *d)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Ground truth now: the object present nearest the vertical line through `p` (x, y; the
    /// point at the object's own height) and that distance, metres; `None` without objects.
    pub fn nearest_object_to(&self, p: &nalgebra::Point2<f64>) -> Option<(usize, f64)> {
        (0..self.objects.len())
            .filter(|&i| self.object_active(i))
            .filter_map(|i| {
                let c = self.physics.colliders.get(self.objects[i])?;
                let aabb = c.compute_aabb();
                let z = (aabb.mins.z + aabb.maxs.z) * 0.5;
                let point = Vector::new(p.x as f32, p.y as f32, z);
                let d = c.shape().distance_to_point(c.position(), point, true);
                Some((i, f64::from(d)))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Ground truth at the current pose: how deep the vehicle's deepest touching part is inside
    /// an object, metres (parry's contact; 0 when nothing touches or they only graze).
    pub fn deepest_penetration_m(&self) -> f64 {
        self.touching
            .iter()
            .filter_map(|&(o, p)| {
                let obj = self.physics.colliders.get(*self.objects.get(o)?)?;
                let part = self.physics.colliders.get(self.parts.get(p)?.0)?;
                parry3d::query::contact(
                    part.position(),
                    part.shape(),
                    obj.position(),
                    obj.shape(),
                    0.0,
                )
                .ok()
                .flatten()
                .map(|c| (-c.dist as f64).max(0.0))
            })
            .fold(0.0, f64::max)
    }

    /// Who owns a collider.
    pub fn owner(&self, handle: ColliderHandle) -> Option<Owner> {
        self.owners.get(&handle).copied()
    }

    /// Casts one ray through the environment (everything but the vehicle) with Rapier's generic
    /// query - the BVH, every shape, the ground slab included: distance and owner of the first
    /// hit. The reference the LiDAR's fast path is checked against.
    pub fn cast_ray_generic(
        &self,
        origin: [f32; 3],
        dir: [f32; 3],
        max_m: f32,
    ) -> Option<(f32, Owner)> {
        let ray = Ray::new(
            Vector::new(origin[0], origin[1], origin[2]),
            Vector::new(dir[0], dir[1], dir[2]),
        );
        let environment = |h: ColliderHandle, _: &Collider| {
            !matches!(self.owners.get(&h), Some(Owner::VehiclePart(_)) | None)
        };
        let filter = QueryFilter {
            predicate: Some(&environment),
            ..QueryFilter::default()
        };
        let (handle, toi) = self.physics.cast_ray(&ray, max_m, true, filter)?;
        Some((toi, self.owner(handle)?))
    }

    /// Every enabled object collider (not the ground, not the vehicle): what the LiDAR's fast
    /// path casts against besides its analytic ground.
    pub(crate) fn object_colliders(&self) -> impl Iterator<Item = (Owner, &Collider)> {
        self.physics
            .colliders
            .iter()
            .filter(|(_, c)| c.is_enabled())
            .filter_map(|(h, c)| match self.owners.get(&h) {
                Some(Owner::Object(i)) => Some((Owner::Object(*i), c)),
                _ => None,
            })
    }

    /// The vehicle's parts with their poses in the vehicle frame.
    pub(crate) fn vehicle_parts(
        &self,
    ) -> impl Iterator<Item = (Owner, &dyn parry3d::shape::Shape, Pose)> {
        self.parts.iter().enumerate().filter_map(|(i, (h, _))| {
            let c = self.physics.colliders.get(*h)?;
            Some((
                Owner::VehiclePart(i),
                c.shape(),
                c.position_wrt_parent().copied().unwrap_or_default(),
            ))
        })
    }
}

/// Pose of a solid's collider in the world.
fn solid_pose(s: &Solid) -> Isometry3<f64> {
    let yaw = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), s.yaw_rad);
    if let SolidShape::Part {
        shape,
        vehicle_from_part,
    } = s.shape
    {
        let world_from_vehicle = Isometry3::from_parts(Translation3::new(s.x_m, s.y_m, 0.0), yaw);
        return world_from_vehicle * vehicle_from_part * primitive(&shape).1;
    }
    let h = s.shape.height_m();
    let base = Isometry3::from_parts(Translation3::new(s.x_m, s.y_m, s.z_min_m + 0.5 * h), yaw);
    match s.shape {
        SolidShape::Box { .. } | SolidShape::Part { .. } => base,
        SolidShape::Cylinder { .. } | SolidShape::Cone { .. } => base * y_up_to_z_up(),
    }
}

fn solid_collider(s: &Solid) -> ColliderBuilder {
    let builder = match s.shape {
        SolidShape::Part { shape, .. } => primitive(&shape).0,
        SolidShape::Box { size_m } => ColliderBuilder::cuboid(
            (0.5 * size_m[0]) as f32,
            (0.5 * size_m[1]) as f32,
            (0.5 * size_m[2]) as f32,
        ),
        SolidShape::Cylinder { radius_m, height_m } => {
            ColliderBuilder::cylinder((0.5 * height_m) as f32, radius_m as f32)
        }
        SolidShape::Cone { radius_m, height_m } => {
            ColliderBuilder::cone((0.5 * height_m) as f32, radius_m as f32)
        }
    };
    builder.position(to_pose(&solid_pose(s)))
}

/// A vehicle part's collider, positioned relative to the vehicle body. URDF cylinders and
/// capsules run along z, parry's along y.
fn part_collider(part: &Part) -> ColliderBuilder {
    let (builder, local) = primitive(&part.shape);
    builder.position(to_pose(&(part.vehicle_from_part * local)))
}

/// A URDF primitive's collider, and the turn from its frame to parry's (cylinders and capsules
/// run along z in URDF, along y in parry).
fn primitive(shape: &Shape) -> (ColliderBuilder, Isometry3<f64>) {
    match *shape {
        Shape::Box { half_extents_m: h } => (
            ColliderBuilder::cuboid(h.x as f32, h.y as f32, h.z as f32),
            Isometry3::identity(),
        ),
        Shape::Cylinder {
            radius_m,
            half_length_m,
        } => (
            ColliderBuilder::cylinder(half_length_m as f32, radius_m as f32),
            y_up_to_z_up(),
        ),
        Shape::Capsule {
            radius_m,
            half_length_m,
        } => (
            ColliderBuilder::capsule_y(half_length_m as f32, radius_m as f32),
            y_up_to_z_up(),
        ),
        Shape::Sphere { radius_m } => (
            ColliderBuilder::ball(radius_m as f32),
            Isometry3::identity(),
        ),
    }
}

/// A bound on how far a part reaches from its centre, metres.
fn part_extent(part: &Part) -> f64 {
    match part.shape {
        Shape::Box { half_extents_m: h } => h.norm(),
        Shape::Cylinder {
            radius_m,
            half_length_m,
        }
        | Shape::Capsule {
            radius_m,
            half_length_m,
        } => radius_m.hypot(half_length_m) + radius_m,
        Shape::Sphere { radius_m } => radius_m,
    }
}
