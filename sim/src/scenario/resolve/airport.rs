//! The resolver's airport: the `[airport]` file read, the world taken from it (its extent on grass
//! unless `[world]` crops it), its ground areas, painted lines, signs and lights, the aircraft
//! parked at its stands, and `route.taxi` planned on its network.

use std::collections::HashMap;

use airport::Airport;
use nalgebra::{Point2, Vector2};
use toml::Spanned;

use super::Resolver;
use crate::airports::{AirportWorld, Furniture, GRASS_REMISSION, airport_world, plan_taxi};
use crate::scenario::model::{Ground, Route, ScenarioVehicle, Survey};
use crate::scenario::spec::{AirportSpec, RouteSpec, SurveyedStands, TaxiSpec, VehicleEntry};
use crate::toml_file::LocatedError;
use crate::world::{ObjectKind, Patch, Solid, SolidShape};

/// Grass beyond the airport's extent in a world taken from it, metres.
const MARGIN_M: f64 = 100.0;

/// An `[airport]` read and made a world.
pub(super) struct LoadedAirport {
    pub airport: Airport,
    pub made: AirportWorld,
}

impl Resolver<'_> {
    pub(super) fn load_airport(
        &self,
        spec: &Spanned<AirportSpec>,
    ) -> Result<LoadedAirport, LocatedError> {
        let a = spec.get_ref();
        let path = self.dir.join(a.file.get_ref());
        let airport = Airport::read(&path, a.code.as_deref()).map_err(|e| {
            self.err(
                a.file.span(),
                "airport.file",
                format!("cannot read the airport: {e}"),
            )
        })?;
        let made = airport_world(
            &airport,
            Furniture {
                signs: a.signs,
                lights: a.lights,
            },
        );
        Ok(LoadedAirport { airport, made })
    }

    /// The world of an airport scenario without `[world]`: its extent and a margin, on grass.
    pub(super) fn airport_ground(loaded: &LoadedAirport) -> Ground {
        let (low, high) = loaded.airport.extent();
        Ground {
            min_m: [low.x - MARGIN_M, low.y - MARGIN_M],
            max_m: [high.x + MARGIN_M, high.y + MARGIN_M],
            ground_remission: GRASS_REMISSION,
            pavement_texture: 0.05,
            areas: Vec::new(),
        }
    }

    /// `route.taxi`: the taxi route planned for the vehicle on the airport's network.
    pub(super) fn taxi_route(
        &self,
        r: &Spanned<RouteSpec>,
        taxi: &Spanned<TaxiSpec>,
        loaded: Option<&LoadedAirport>,
        vehicle: &VehicleEntry,
        world: &Ground,
    ) -> Result<Route, LocatedError> {
        let spec = r.get_ref();
        if let Some(span) = spec
            .waypoints_m
            .as_ref()
            .map(Spanned::span)
            .or_else(|| spec.pose_file.as_ref().map(Spanned::span))
        {
            return Err(self.err(
                span,
                "route.taxi",
                "give one of waypoints_m, pose_file and taxi",
            ));
        }
        if spec.closed {
            return Err(self.err(taxi.span(), "route.closed", "a taxi route is not closed"));
        }
        let Some(loaded) = loaded else {
            return Err(self.err(taxi.span(), "route.taxi", "a taxi route needs an [airport]"));
        };
        let t = taxi.get_ref();
        let description = self.load_vehicle(&vehicle.description, "vehicle.description")?;
        let turn_radius_m = spec
            .turn_radius_m
            .map_or(crate::airports::DEFAULT_TURN_RADIUS_M, |r| r.0);
        let planned = plan_taxi(
            &loaded.airport,
            &description,
            &t.from,
            &t.to,
            &t.via,
            turn_radius_m,
            spec.speed_m_s.0,
        )
        .map_err(|e| self.err(taxi.span(), "route.taxi", e.to_string()))?;
        let waypoints_m: Vec<Point2<f64>> = planned
            .path
            .points
            .iter()
            .map(|p| Point2::new(p.x, p.y))
            .collect();
        if let Some(p) = waypoints_m.iter().find(|p| {
            p.x < world.min_m[0]
                || p.x > world.max_m[0]
                || p.y < world.min_m[1]
                || p.y > world.max_m[1]
        }) {
            return Err(self.err(
                taxi.span(),
                "route.taxi",
                format!(
                    "the route passes ({:.1}, {:.1}), outside the world",
                    p.x, p.y
                ),
            ));
        }
        Ok(Route {
            yaws_rad: vec![None; waypoints_m.len()],
            waypoints_m,
            closed: false,
            speed_m_s: spec.speed_m_s.0,
            speed_limits_m_s: Some(planned.path.speed_m_s.clone()),
            pushback: planned.pushback,
        })
    }

    /// The airport's objects inside the world (signs, lights; ids claimed), the aircraft parked at
    /// its stands and their ground equipment; and its painted lines inside the world.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn airport_objects(
        &self,
        spec: &Spanned<AirportSpec>,
        loaded: &LoadedAirport,
        world: &Ground,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
        seed: u64,
        route_stands: &[String],
        (way, towed): (&[nalgebra::Isometry2<f64>], usize),
    ) -> Result<AirportObjects, LocatedError> {
        let inside = |x: f64, y: f64| {
            x >= world.min_m[0] && x <= world.max_m[0] && y >= world.min_m[1] && y <= world.max_m[1]
        };
        let mut solids = Vec::new();
        for solid in loaded.made.solids.iter().filter(|s| inside(s.x_m, s.y_m)) {
            self.claim(
                ids,
                &solid.id,
                spec.span(),
                "airport",
                format!("the airport's {}", solid.kind.name()),
                "",
            )?;
            self.no_start_overlap(vehicle, solid, "airport", spec.span())?;
            solids.push(solid.clone());
        }
        let furniture = solids.len();
        for (stand, description, span) in self.occupied_stands(spec, loaded, seed, route_stands)? {
            let id = format!("stand_{}", stand.name.replace(' ', "_"));
            self.claim(
                ids,
                &id,
                span.clone(),
                "airport.occupancy",
                "`airport.occupancy`".into(),
                "",
            )?;
            let here = stand_solids(
                &id,
                &description,
                stand.at,
                stand.yaw_rad,
                spec.get_ref().ground_equipment,
            );
            if stays_empty(vehicle, way, &here, &inside) {
                ids.remove(&id);
                continue;
            }
            solids.extend(here);
        }
        let drawn = solids.len();
        for (i, parked) in spec.get_ref().parked.iter().enumerate() {
            let field = format!("airport.parked[{i}]");
            let p = parked.get_ref();
            let stand = loaded
                .airport
                .find_stand(p.stand.get_ref())
                .map_err(|why| {
                    self.err(
                        p.stand.span(),
                        &format!("{field}.stand"),
                        format!("{why} ({})", loaded.airport.file.display()),
                    )
                })?;
            let description = self.load_vehicle(&p.vehicle, &format!("{field}.vehicle"))?;
            let id = format!("stand_{}", stand.name.replace(' ', "_"));
            self.claim(
                ids,
                &id,
                p.stand.span(),
                &format!("{field}.stand"),
                format!("`{field}`"),
                "",
            )?;
            let here = stand_solids(
                &id,
                &description,
                stand.at,
                stand.yaw_rad,
                spec.get_ref().ground_equipment,
            );
            for solid in here {
                self.inside_world(world, &field, p.stand.span(), solid.x_m, solid.y_m)?;
                self.no_start_overlap(vehicle, &solid, &field, p.stand.span())?;
                self.not_in_the_tow(vehicle, &way[..towed], &solid, &field, p.stand.span())?;
                solids.push(solid);
            }
        }
        let patches = loaded
            .made
            .patches
            .iter()
            .filter(|p| inside(p.x_m, p.y_m))
            .cloned()
            .collect();
        // What the survey saw of them: the furniture, and the `parked` aircraft unless empty.
        let seen = match spec.get_ref().surveyed_stands {
            SurveyedStands::AsRun => None,
            SurveyedStands::Parked => Some([&solids[..furniture], &solids[drawn..]].concat()),
            SurveyedStands::Empty => Some(solids[..furniture].to_vec()),
        };
        let survey = seen.map(|objects| Survey {
            objects,
            legs: survey_legs(&loaded.airport, &inside),
        });
        Ok(AirportObjects {
            solids,
            survey,
            patches,
        })
    }
}

/// An airport's objects in a scenario's world, and what its map's survey saw of them.
pub(super) struct AirportObjects {
    /// Its furniture, then the aircraft `occupancy` parks, then the `parked` ones.
    pub solids: Vec<Solid>,
    /// The airport's survey (`None`: the map is made of the run's own world).
    pub survey: Option<Survey>,
    /// Its painted lines.
    pub patches: Vec<Patch>,
}

impl Resolver<'_> {
    /// The stands `occupancy` fills (not those named in `parked`, nor the route's), drawn with
    /// the scenario's seed, with the vehicle each takes.
    #[allow(clippy::type_complexity)]
    fn occupied_stands<'a>(
        &self,
        spec: &Spanned<AirportSpec>,
        loaded: &'a LoadedAirport,
        seed: u64,
        route_stands: &[String],
    ) -> Result<
        Vec<(
            &'a airport::Stand,
            aircraft::Vehicle,
            std::ops::Range<usize>,
        )>,
        LocatedError,
    > {
        use rand::{RngExt, SeedableRng};
        let a = spec.get_ref();
        let Some(share) = &a.occupancy else {
            return Ok(Vec::new());
        };
        let named: Vec<&str> = a
            .parked
            .iter()
            .map(|p| p.get_ref().stand.get_ref().as_str())
            .collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed ^ 0x0057_A4D5);
        let mut out = Vec::new();
        for stand in &loaded.airport.stands {
            let draw: f64 = rng.random();
            if draw >= f64::from(share.get_ref().0)
                || named.contains(&stand.name.as_str())
                || route_stands.contains(&stand.name)
            {
                continue;
            }
            let name = match stand.size_class {
                Some(c) if c >= airport::SizeClass::C => "a320",
                Some(airport::SizeClass::B) => "praetor600",
                _ => continue,
            };
            let vehicle = aircraft::Vehicle::shipped(name)
                .map_err(|e| self.err(share.span(), "airport.occupancy", e.to_string()))?;
            out.push((stand, vehicle, share.span()));
        }
        Ok(out)
    }

    /// A parked aircraft named in the file that the vehicle's push-back (`tow`, its poses) would
    /// meet is an error: the tug would push the vehicle into it, and the tow is the world's, not
    /// the stack's to avoid.
    fn not_in_the_tow(
        &self,
        vehicle: &ScenarioVehicle,
        tow: &[nalgebra::Isometry2<f64>],
        solid: &Solid,
        field: &str,
        span: std::ops::Range<usize>,
    ) -> Result<(), LocatedError> {
        let Some((i, hit)) = crate::scenario::overlap::sweep_overlap(&vehicle.vehicle, tow, solid)
        else {
            return Ok(());
        };
        let at = tow[i].translation.vector;
        let along_m: f64 = (tow[..=i].windows(2))
            .map(|w| (w[1].translation.vector - w[0].translation.vector).norm())
            .sum();
        Err(self.err(
            span,
            field,
            format!(
                "`{}` is in the vehicle's push-back: towed {:.1} m, to ({:.1}, {:.1}) m, {hit}; \
                 the tug would push the vehicle into it (park it at another stand, or leave \
                 from another)",
                solid.id, along_m, at.x, at.y
            ),
        ))
    }
}

/// Whether a stand `occupancy` draws stays empty (`here`: its aircraft's parts and equipment):
/// one outside the world, or that would touch the vehicle at its start or anywhere on its `way` -
/// pushed back by its tug, or taxiing its route into a stand. The ramp parks no aircraft where it
/// blocks another's way: wing walkers would stop the tow; an arrival would be given another
/// stand.
fn stays_empty(
    vehicle: &ScenarioVehicle,
    way: &[nalgebra::Isometry2<f64>],
    here: &[Solid],
    inside: &dyn Fn(f64, f64) -> bool,
) -> bool {
    use crate::scenario::overlap::{start_overlap, sweep_overlap};
    here.iter().any(|s| {
        !inside(s.x_m, s.y_m)
            || start_overlap(&vehicle.vehicle, &vehicle.world_from_start, s).is_some()
            || sweep_overlap(&vehicle.vehicle, way, s).is_some()
    })
}

/// A parked aircraft's collision parts at a stand (its vehicle frame on the stand's point).
/// An aircraft parked at a stand, with a tug and a cart beside it when `equipment`.
fn stand_solids(
    id: &str,
    vehicle: &aircraft::Vehicle,
    at: Vector2<f64>,
    yaw_rad: f64,
    equipment: bool,
) -> Vec<Solid> {
    let mut solids = parked_parts(id, vehicle, at, yaw_rad);
    if equipment {
        solids.extend(ground_equipment(id, vehicle.span_m(), at, yaw_rad));
    }
    solids
}

fn parked_parts(
    id: &str,
    vehicle: &aircraft::Vehicle,
    at: Vector2<f64>,
    yaw_rad: f64,
) -> Vec<Solid> {
    vehicle
        .parts
        .iter()
        .map(|part| Solid {
            id: format!("{id}/{}#{}", part.link, part.collision_index),
            kind: ObjectKind::ParkedAircraft,
            shape: SolidShape::Part {
                shape: part.shape,
                vehicle_from_part: part.vehicle_from_part,
            },
            x_m: at.x,
            y_m: at.y,
            z_min_m: 0.0,
            yaw_rad,
            remission: ObjectKind::ParkedAircraft.default_remission(),
            runtime: false,
        })
        .collect()
}

/// A tug ahead of a parked aircraft's right wing root and a baggage cart behind it, on the
/// ramp beside the fuselage (its frame: 8 m ahead and 3 m aft, a quarter span to the right).
fn ground_equipment(id: &str, span_m: f64, at: Vector2<f64>, yaw_rad: f64) -> Vec<Solid> {
    let (s, c) = yaw_rad.sin_cos();
    let place = |x: f64, y: f64| at + Vector2::new(c * x - s * y, s * x + c * y);
    [
        (ObjectKind::Tug, 8.0, "tug"),
        (ObjectKind::BaggageCart, -3.0, "cart"),
    ]
    .into_iter()
    .filter_map(|(kind, x, name)| {
        let p = place(x, -0.25 * span_m);
        Some(Solid {
            id: format!("{id}/{name}"),
            kind,
            shape: kind.default_shape()?,
            x_m: p.x,
            y_m: p.y,
            z_min_m: 0.0,
            yaw_rad,
            remission: kind.default_remission(),
            runtime: false,
        })
    })
    .collect()
}

/// The survey's legs: every edge of the network with both ends inside the world, then for each
/// stand inside it a leg from the stand to the nearest point of those edges (the way a tug
/// pushes an aircraft back), so the stands are mapped from close by.
fn survey_legs(airport: &Airport, inside: &dyn Fn(f64, f64) -> bool) -> Vec<[Point2<f64>; 2]> {
    let nodes = &airport.network.nodes;
    let mut legs: Vec<[Point2<f64>; 2]> = airport
        .network
        .edges
        .iter()
        .map(|e| [Point2::from(nodes[e.from].at), Point2::from(nodes[e.to].at)])
        .filter(|[a, b]| inside(a.x, a.y) && inside(b.x, b.y))
        .collect();
    let edges = legs.len();
    for stand in &airport.stands {
        let at = Point2::from(stand.at);
        if !inside(at.x, at.y) {
            continue;
        }
        let nearest = legs[..edges]
            .iter()
            .map(|&[a, b]| {
                let ab = b - a;
                let t = ((at - a).dot(&ab) / ab.norm_squared().max(1e-12)).clamp(0.0, 1.0);
                a + ab * t
            })
            .min_by(|p, q| (p - at).norm().total_cmp(&(q - at).norm()));
        legs.push([at, nearest.unwrap_or(at)]);
    }
    legs
}
