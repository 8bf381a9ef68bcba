//! The resolver's movers: a moving obstacle's motion (its path, speed, acceleration, stops and
//! whether it yields to the vehicle), and the cars a towed train expands into, each a run-time
//! obstacle linked to its lead.

use std::collections::HashMap;

use nalgebra::Point2;
use toml::Spanned;

use super::Resolver;
use crate::scenario::model::{
    Ground, MotionStop, Obstacle, ObstacleMotion, ScenarioVehicle, TrainLink,
};
use crate::scenario::numbers::Positive;
use crate::scenario::spec::{MAX_TRAIN_CARS, ObstacleSpec, StopSpec};
use crate::toml_file::LocatedError;
use crate::world::Solid;

/// The gap between the vehicles of a train when `gap_m` is not given, metres.
const DEFAULT_TRAIN_GAP_M: f64 = 1.0;

impl Resolver<'_> {
    /// The motion of obstacle `field` along `pts` (its checked `path_m`) at `speed`: its
    /// acceleration, stops and reaction checked (`train` is linked later, by [`Self::train`]).
    pub(super) fn motion(
        &self,
        s: &ObstacleSpec,
        field: &str,
        pts: Vec<Point2<f64>>,
        speed: &Positive,
    ) -> Result<ObstacleMotion, LocatedError> {
        let mut motion = ObstacleMotion {
            path_m: pts,
            speed_m_s: speed.0,
            yaw_offset_rad: s.yaw_rad.0,
            acceleration_m_s2: s.acceleration_m_s2.as_ref().map(|a| a.get_ref().0),
            stops: Vec::new(),
            yields_to_vehicle_m: s.yields_to_vehicle_m.as_ref().map(|y| y.get_ref().0),
            makes_room_m: s.makes_room_m.as_ref().map(|y| y.get_ref().0),
            train: None,
        };
        if let Some(room) = &s.makes_room_m {
            let why = if s.yields_to_vehicle_m.is_none() {
                Some("makes_room_m is only for a driver that yields: give yields_to_vehicle_m too")
            } else if s.train.is_some() {
                Some("makes_room_m is not for a train: its cars cannot back aside with it")
            } else {
                None
            };
            if let Some(why) = why {
                return Err(self.err(room.span(), &format!("{field}.makes_room_m"), why));
            }
        }
        if let Some(stops) = &s.stops {
            motion.stops = self.stops(stops.get_ref(), field, motion.length_m())?;
        }
        Ok(motion)
    }

    /// The stops, checked: arc lengths increasing and within the path's `length_m`.
    fn stops(
        &self,
        stops: &[StopSpec],
        field: &str,
        length_m: f64,
    ) -> Result<Vec<MotionStop>, LocatedError> {
        let mut out: Vec<MotionStop> = Vec::with_capacity(stops.len());
        for (k, stop) in stops.iter().enumerate() {
            let at_m = stop.at_m.get_ref().0;
            let here = format!("{field}.stops[{k}].at_m");
            if let Some(before) = out.last()
                && at_m <= before.at_m
            {
                return Err(self.err(
                    stop.at_m.span(),
                    &here,
                    format!(
                        "{at_m} m is not after the previous stop ({} m): stops go in order along the path",
                        before.at_m
                    ),
                ));
            }
            if at_m > length_m {
                return Err(self.err(
                    stop.at_m.span(),
                    &here,
                    format!("{at_m} m lies beyond the path's end ({length_m:.3} m)"),
                ));
            }
            out.push(MotionStop {
                at_m,
                wait_s: stop.wait_s.0,
            });
        }
        Ok(out)
    }

    /// A static obstacle (no `path_m`) must not carry a mover's fields.
    pub(super) fn no_mover_fields(
        &self,
        s: &ObstacleSpec,
        field: &str,
    ) -> Result<(), LocatedError> {
        let given = [
            (
                "acceleration_m_s2",
                s.acceleration_m_s2.as_ref().map(Spanned::span),
            ),
            ("stops", s.stops.as_ref().map(Spanned::span)),
            (
                "yields_to_vehicle_m",
                s.yields_to_vehicle_m.as_ref().map(Spanned::span),
            ),
            ("makes_room_m", s.makes_room_m.as_ref().map(Spanned::span)),
            ("train", s.train.as_ref().map(Spanned::span)),
        ];
        for (key, span) in given {
            if let Some(span) = span {
                return Err(self.err(
                    span,
                    &format!("{field}.{key}"),
                    format!("{key} is only for a moving obstacle: give path_m and speed_m_s too"),
                ));
            }
        }
        Ok(())
    }

    /// The cars of the train `lead` (the obstacle `obstacles[lead_index]`, `field` in the file)
    /// tows, if it has one: ids `<id>_car1`, ... claimed, each car behind the one ahead by half
    /// their lengths and the gap along the path (before its start on the line of its first
    /// segment), inside the world, and (present at t = 0) clear of the vehicle.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn train(
        &self,
        s: &ObstacleSpec,
        field: &str,
        lead_index: usize,
        lead: &Obstacle,
        world: &Ground,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
    ) -> Result<Vec<Obstacle>, LocatedError> {
        let (Some(train), Some(motion)) = (&s.train, &lead.motion) else {
            return Ok(Vec::new());
        };
        let here = format!("{field}.train");
        let spec = train.get_ref();
        let cars = spec.cars.get_ref().0;
        if cars > MAX_TRAIN_CARS {
            return Err(self.err(
                spec.cars.span(),
                &format!("{here}.cars"),
                format!("{cars} cars: a train tows at most {MAX_TRAIN_CARS}"),
            ));
        }
        let kind = spec
            .kind
            .as_ref()
            .map_or(crate::world::ObjectKind::BaggageCart, |k| *k.get_ref());
        let Some(shape) = kind.default_shape() else {
            let span = spec.kind.as_ref().map_or(train.span(), Spanned::span);
            return Err(self.err(
                span,
                &format!("{here}.kind"),
                format!(
                    "a {} has no default size: a train's cars are of a kind that has one",
                    kind.name()
                ),
            ));
        };
        let gap_m = spec.gap_m.map_or(DEFAULT_TRAIN_GAP_M, |g| g.0);
        let mut out = Vec::with_capacity(cars as usize);
        let (mut behind_m, mut ahead_half_m) = (0.0, 0.5 * lead.solid.shape.length_m());
        for k in 1..=cars {
            behind_m += ahead_half_m + gap_m + 0.5 * shape.length_m();
            ahead_half_m = 0.5 * shape.length_m();
            let id = format!("{}_car{k}", lead.solid.id);
            self.claim(
                ids,
                &id,
                train.span(),
                &here,
                format!("`{here}`, its car {k}"),
                &format!("its car {k} is `{id}`: "),
            )?;
            let start = motion.state_at_arc(-behind_m, 0.0);
            let solid = Solid {
                id,
                kind,
                shape,
                x_m: start.x_m,
                y_m: start.y_m,
                z_min_m: 0.0,
                yaw_rad: start.yaw_rad,
                remission: kind.default_remission(),
                runtime: true,
            };
            self.inside_world(world, &here, train.span(), solid.x_m, solid.y_m)?;
            if lead.appears_s <= 0.0 {
                self.no_start_overlap(vehicle, &solid, &here, train.span())?;
            }
            out.push(Obstacle {
                solid,
                expect: lead.expect,
                appears_s: lead.appears_s,
                disappears_s: lead.disappears_s,
                motion: Some(ObstacleMotion {
                    train: Some(TrainLink {
                        lead: lead_index,
                        behind_m,
                    }),
                    ..motion.clone()
                }),
            });
        }
        Ok(out)
    }
}
