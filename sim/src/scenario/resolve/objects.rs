//! The resolver's objects: static objects, painted patches and run-time obstacles (their
//! shapes from their kinds, their timing and motion), each inside the world and clear of the
//! vehicle at its start.

use std::collections::HashMap;
use std::ops::Range;

use nalgebra::Point2;
use toml::Spanned;

use super::Resolver;
use crate::scenario::model::{Ground, Obstacle, ScenarioVehicle};
use crate::scenario::numbers::Positive;
use crate::scenario::spec::{ObjectSpec, ObstacleSpec, PatchSpec};
use crate::toml_file::LocatedError;
use crate::world::{ObjectKind, Patch, Solid, SolidShape};

impl Resolver<'_> {
    /// The `[[objects]]` as solids, in file order: ids claimed, shapes checked, each inside the
    /// world and clear of the vehicle at its start.
    pub(super) fn objects(
        &self,
        specs: &[Spanned<ObjectSpec>],
        world: &Ground,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
    ) -> Result<Vec<Solid>, LocatedError> {
        let mut objects = Vec::with_capacity(specs.len());
        for (i, o) in specs.iter().enumerate() {
            let field = format!("objects[{i}]");
            let o_ref = o.get_ref();
            self.claim_id(ids, &o_ref.id, &field)?;
            if o_ref.kind == ObjectKind::ParkedAircraft {
                for solid in self.parked_aircraft(o, &field)? {
                    self.inside_world(world, &field, o_ref.id.span(), solid.x_m, solid.y_m)?;
                    self.no_start_overlap(vehicle, &solid, &field, o_ref.id.span())?;
                    objects.push(solid);
                }
                continue;
            }
            if let Some(v) = &o_ref.vehicle {
                return Err(self.err(
                    v.span(),
                    &format!("{field}.vehicle"),
                    format!(
                        "only a parked_aircraft names a vehicle, not a {}",
                        o_ref.kind.name()
                    ),
                ));
            }
            let shape = self.shape(
                &field,
                o.span(),
                o_ref.kind,
                &o_ref.size_m,
                &o_ref.radius_m,
                &o_ref.height_m,
            )?;
            let solid = Solid {
                id: o_ref.id.get_ref().clone(),
                kind: o_ref.kind,
                shape,
                x_m: o_ref.x_m.0,
                y_m: o_ref.y_m.0,
                z_min_m: o_ref.z_min_m.0,
                yaw_rad: o_ref.yaw_rad.0,
                remission: o_ref
                    .remission
                    .map_or_else(|| o_ref.kind.default_remission(), |r| r.0),
                runtime: false,
            };
            self.inside_world(world, &field, o_ref.id.span(), solid.x_m, solid.y_m)?;
            self.no_start_overlap(vehicle, &solid, &field, o_ref.id.span())?;
            objects.push(solid);
        }
        Ok(objects)
    }

    /// The `[[patches]]`, in file order: ids claimed, each inside the world.
    pub(super) fn patches(
        &self,
        specs: &[Spanned<PatchSpec>],
        world: &Ground,
        ids: &mut HashMap<String, String>,
    ) -> Result<Vec<Patch>, LocatedError> {
        let mut patches = Vec::with_capacity(specs.len());
        for (i, p) in specs.iter().enumerate() {
            let field = format!("patches[{i}]");
            let p = p.get_ref();
            self.claim_id(ids, &p.id, &field)?;
            self.inside_world(world, &field, p.id.span(), p.x_m.0, p.y_m.0)?;
            patches.push(Patch {
                id: p.id.get_ref().clone(),
                x_m: p.x_m.0,
                y_m: p.y_m.0,
                yaw_rad: p.yaw_rad.0,
                length_m: p.length_m.0,
                width_m: p.width_m.0,
                remission: p.remission.map_or(0.8, |r| r.0),
            });
        }
        Ok(patches)
    }

    /// The `[[obstacles]]`, in file order, each followed by the cars of its train: ids claimed,
    /// each (and its path) inside the world, and one present at the start clear of the vehicle
    /// there.
    pub(super) fn obstacles(
        &self,
        specs: &[Spanned<ObstacleSpec>],
        world: &Ground,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
    ) -> Result<Vec<Obstacle>, LocatedError> {
        let mut obstacles = Vec::with_capacity(specs.len());
        for (i, o) in specs.iter().enumerate() {
            let field = format!("obstacles[{i}]");
            self.claim_id(ids, &o.get_ref().id, &field)?;
            let obstacle = self.obstacle(o, &field)?;
            let id_span = o.get_ref().id.span();
            self.inside_world(
                world,
                &field,
                id_span.clone(),
                obstacle.solid.x_m,
                obstacle.solid.y_m,
            )?;
            if let (Some(m), Some(path)) = (&obstacle.motion, &o.get_ref().path_m) {
                for p in &m.path_m {
                    self.inside_world(world, &format!("{field}.path_m"), path.span(), p.x, p.y)?;
                }
            }
            if obstacle.appears_s <= 0.0 {
                self.no_start_overlap(vehicle, &obstacle.solid, &field, id_span)?;
            }
            let lead_index = obstacles.len();
            let cars = self.train(
                o.get_ref(),
                &field,
                lead_index,
                &obstacle,
                world,
                vehicle,
                ids,
            )?;
            obstacles.push(obstacle);
            obstacles.extend(cars);
        }
        Ok(obstacles)
    }

    fn obstacle(&self, o: &Spanned<ObstacleSpec>, field: &str) -> Result<Obstacle, LocatedError> {
        let s = o.get_ref();
        let shape = self.shape(field, o.span(), s.kind, &s.size_m, &s.radius_m, &s.height_m)?;
        let appears_s = s.appears_s.as_ref().map_or(0.0, |a| a.get_ref().0);
        if let Some(d) = &s.disappears_s
            && d.get_ref().0 <= appears_s
        {
            return Err(self.err(
                d.span(),
                &format!("{field}.disappears_s"),
                format!("{} s is not after appears_s ({appears_s} s)", d.get_ref().0),
            ));
        }
        if s.path_m.is_none() {
            self.no_mover_fields(s, field)?;
        }
        let (x_m, y_m, yaw_rad, motion) = match (&s.path_m, &s.speed_m_s) {
            (Some(path), Some(speed)) => {
                if s.x_m.is_some() || s.y_m.is_some() {
                    return Err(self.err(
                        path.span(),
                        &format!("{field}.path_m"),
                        "a moving obstacle starts at the first point of path_m: drop x_m and y_m",
                    ));
                }
                let pts: Vec<Point2<f64>> = path
                    .get_ref()
                    .iter()
                    .map(|p| Point2::new(p[0].0, p[1].0))
                    .collect();
                self.polyline(
                    &pts,
                    2,
                    false,
                    path.span(),
                    &format!("{field}.path_m"),
                    "a path",
                )?;
                let d = pts[1] - pts[0];
                let motion = self.motion(s, field, pts.clone(), speed.get_ref())?;
                (
                    pts[0].x,
                    pts[0].y,
                    d.y.atan2(d.x) + s.yaw_rad.0,
                    Some(motion),
                )
            }
            (Some(path), None) => {
                return Err(self.err(
                    path.span(),
                    &format!("{field}.speed_m_s"),
                    "a moving obstacle (path_m) needs speed_m_s (m/s)",
                ));
            }
            (None, Some(speed)) => {
                return Err(self.err(
                    speed.span(),
                    &format!("{field}.speed_m_s"),
                    "speed_m_s is only for a moving obstacle: give path_m too",
                ));
            }
            (None, None) => match (s.x_m, s.y_m) {
                (Some(x), Some(y)) => (x.0, y.0, s.yaw_rad.0, None),
                (x, _) => {
                    let missing = if x.is_none() { "x_m" } else { "y_m" };
                    return Err(self.err(
                        o.span(),
                        &format!("{field}.{missing}"),
                        format!("missing field `{missing}` (or give path_m and speed_m_s)"),
                    ));
                }
            },
        };
        Ok(Obstacle {
            solid: Solid {
                id: s.id.get_ref().clone(),
                kind: s.kind,
                shape,
                x_m,
                y_m,
                z_min_m: s.z_min_m.0,
                yaw_rad,
                remission: s
                    .remission
                    .map_or_else(|| s.kind.default_remission(), |r| r.0),
                runtime: true,
            },
            expect: s.expect,
            appears_s,
            disappears_s: s.disappears_s.as_ref().map(|d| d.get_ref().0),
            motion,
        })
    }

    pub(super) fn shape(
        &self,
        field: &str,
        table_span: Range<usize>,
        kind: ObjectKind,
        size: &Option<Spanned<[Positive; 3]>>,
        radius: &Option<Spanned<Positive>>,
        height: &Option<Spanned<Positive>>,
    ) -> Result<SolidShape, LocatedError> {
        let name = kind.name();
        if kind == ObjectKind::ParkedAircraft {
            return Err(self.err(
                table_span,
                &format!("{field}.kind"),
                "a parked_aircraft is placed from a vehicle description: only in [[objects]], with vehicle = \"a320\" (or another)",
            ));
        }
        let default = kind.default_shape();
        if kind.is_round() {
            if let Some(s) = size {
                return Err(self.err(
                    s.span(),
                    &format!("{field}.size_m"),
                    format!("a {name} is round: give radius_m and height_m, not size_m"),
                ));
            }
            let (r0, h0) = match default {
                Some(
                    SolidShape::Cone { radius_m, height_m }
                    | SolidShape::Cylinder { radius_m, height_m },
                ) => (Some(radius_m), Some(height_m)),
                _ => (None, None),
            };
            let r = radius.as_ref().map(|r| r.get_ref().0).or(r0);
            let h = height.as_ref().map(|h| h.get_ref().0).or(h0);
            let (Some(radius_m), Some(height_m)) = (r, h) else {
                let missing = if r.is_none() { "radius_m" } else { "height_m" };
                return Err(self.err(
                    table_span,
                    &format!("{field}.{missing}"),
                    format!("a {name} needs radius_m and height_m (metres)"),
                ));
            };
            Ok(if kind == ObjectKind::Cone {
                SolidShape::Cone { radius_m, height_m }
            } else {
                SolidShape::Cylinder { radius_m, height_m }
            })
        } else {
            for (v, key) in [(radius, "radius_m"), (height, "height_m")] {
                if let Some(v) = v {
                    return Err(self.err(
                        v.span(),
                        &format!("{field}.{key}"),
                        format!("a {name} is box-like: give size_m = [x, y, z], not {key}"),
                    ));
                }
            }
            let default = match default {
                Some(SolidShape::Box { size_m }) => Some(size_m),
                _ => None,
            };
            let size_m = size
                .as_ref()
                .map(|s| {
                    let s = s.get_ref();
                    [s[0].0, s[1].0, s[2].0]
                })
                .or(default)
                .ok_or_else(|| {
                    self.err(
                        table_span,
                        &format!("{field}.size_m"),
                        format!("a {name} needs size_m = [x, y, z] (metres)"),
                    )
                })?;
            Ok(SolidShape::Box { size_m })
        }
    }

    /// A `parked_aircraft`: one solid per collision part of its vehicle description, placed by
    /// the object's x, y and heading (ids `<id>/<link>#<k>`).
    fn parked_aircraft(
        &self,
        o: &Spanned<ObjectSpec>,
        field: &str,
    ) -> Result<Vec<Solid>, LocatedError> {
        let s = o.get_ref();
        let Some(name) = &s.vehicle else {
            return Err(self.err(
                o.span(),
                &format!("{field}.vehicle"),
                "a parked_aircraft needs vehicle = \"a320\" (a shipped vehicle or a sidecar path)",
            ));
        };
        for (given, key) in [
            (s.size_m.is_some(), "size_m"),
            (s.radius_m.is_some(), "radius_m"),
            (s.height_m.is_some(), "height_m"),
            (s.z_min_m.0 != 0.0, "z_min_m"),
        ] {
            if given {
                return Err(self.err(
                    o.span(),
                    &format!("{field}.{key}"),
                    format!("a parked_aircraft's shape is its vehicle's: drop {key}"),
                ));
            }
        }
        let vehicle = self.load_vehicle(name, &format!("{field}.vehicle"))?;
        let remission = s
            .remission
            .map_or_else(|| ObjectKind::ParkedAircraft.default_remission(), |r| r.0);
        Ok(vehicle
            .parts
            .iter()
            .map(|part| Solid {
                id: format!("{}/{}#{}", s.id.get_ref(), part.link, part.collision_index),
                kind: ObjectKind::ParkedAircraft,
                shape: SolidShape::Part {
                    shape: part.shape,
                    vehicle_from_part: part.vehicle_from_part,
                },
                x_m: s.x_m.0,
                y_m: s.y_m.0,
                z_min_m: 0.0,
                yaw_rad: s.yaw_rad.0,
                remission,
                runtime: false,
            })
            .collect())
    }
}
