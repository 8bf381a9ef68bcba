//! The resolver's route and vehicle: the route from its waypoints or a pose file, and the
//! vehicle (shipped or a sidecar) at its start pose.

use std::path::Path;

use nalgebra::{Isometry2, Point2, Vector2};
use toml::Spanned;

use super::Resolver;
use crate::scenario::model::{Ground, Route, ScenarioVehicle, WalkAround};
use crate::scenario::spec::{RouteSpec, VehicleEntry, WalkAroundSpec};
use crate::toml_file::LocatedError;

impl Resolver<'_> {
    pub(super) fn route(
        &self,
        r: &Spanned<RouteSpec>,
        world: &Ground,
    ) -> Result<Route, LocatedError> {
        let spec = r.get_ref();
        let min = if spec.closed { 3 } else { 2 };
        let (waypoints_m, yaws_rad, span, field) = match (&spec.waypoints_m, &spec.pose_file) {
            (Some(_), Some(p)) => {
                return Err(self.err(
                    p.span(),
                    "route.pose_file",
                    "give either waypoints_m or pose_file, not both",
                ));
            }
            (None, None) => {
                return Err(self.err(
                    r.span(),
                    "route",
                    "missing the route: give waypoints_m = [[x, y], ...] or pose_file = \"...\"",
                ));
            }
            (Some(w), None) => {
                let pts: Vec<Point2<f64>> = w
                    .get_ref()
                    .iter()
                    .map(|p| Point2::new(p[0].0, p[1].0))
                    .collect();
                let n = pts.len();
                (pts, vec![None; n], w.span(), "route.waypoints_m")
            }
            (None, Some(p)) => {
                let (pts, yaws) = self.pose_file(p)?;
                (pts, yaws, p.span(), "route.pose_file")
            }
        };
        self.polyline(
            &waypoints_m,
            min,
            spec.closed,
            span.clone(),
            field,
            "a route",
        )?;
        for (k, p) in waypoints_m.iter().enumerate() {
            if p.x < world.min_m[0]
                || p.x > world.max_m[0]
                || p.y < world.min_m[1]
                || p.y > world.max_m[1]
            {
                return Err(self.err(
                    span,
                    field,
                    format!("point {k} ({}, {}) lies outside the world", p.x, p.y),
                ));
            }
        }
        if spec.turn_radius_m.is_some() {
            return Err(self.err(span, "route.turn_radius_m", "turn_radius_m goes with taxi"));
        }
        Ok(Route {
            waypoints_m,
            yaws_rad,
            closed: spec.closed,
            speed_m_s: spec.speed_m_s.0,
            speed_limits_m_s: None,
            pushback: None,
        })
    }

    /// Reads a pose file: `x_m,y_m[,yaw_rad]` a line, `#` comments.
    #[allow(clippy::type_complexity)]
    fn pose_file(
        &self,
        name: &Spanned<String>,
    ) -> Result<(Vec<Point2<f64>>, Vec<Option<f64>>), LocatedError> {
        let path = self.dir.join(name.get_ref());
        let text = std::fs::read_to_string(&path).map_err(|e| {
            self.err(
                name.span(),
                "route.pose_file",
                format!("cannot read the pose file {}: {e}", path.display()),
            )
        })?;
        let label = path.display().to_string();
        let mut points = Vec::new();
        let mut yaws = Vec::new();
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let start = offset;
            offset += line.len();
            let content = line.split('#').next().unwrap_or("").trim_end();
            if content.trim().is_empty() {
                continue;
            }
            let mut values = Vec::with_capacity(3);
            let mut col = start;
            for field in content.split(',') {
                let lead = field.len() - field.trim_start().len();
                let token = field.trim();
                let at = col + lead;
                let v: f64 = token
                    .parse()
                    .ok()
                    .filter(|v: &f64| v.is_finite())
                    .ok_or_else(|| {
                        LocatedError::at(
                            &label,
                            &text,
                            at..at + token.len().max(1),
                            "route.pose_file",
                            format!(
                                "`{token}` is not a finite number (a line is x_m,y_m[,yaw_rad])"
                            ),
                        )
                    })?;
                values.push(v);
                col += field.len() + 1;
            }
            if !(2..=3).contains(&values.len()) {
                return Err(LocatedError::at(
                    &label,
                    &text,
                    start..start + content.len(),
                    "route.pose_file",
                    format!("{} values: a line is x_m,y_m[,yaw_rad]", values.len()),
                ));
            }
            points.push(Point2::new(values[0], values[1]));
            yaws.push(values.get(2).copied());
        }
        Ok((points, yaws))
    }

    pub(super) fn vehicle(
        &self,
        v: &VehicleEntry,
        route: &Route,
        world: &Ground,
    ) -> Result<ScenarioVehicle, LocatedError> {
        let vehicle = self.load_vehicle(&v.description, "vehicle.description")?;
        let world_from_start = match &v.start {
            Some(s) => {
                let p = s.get_ref();
                if p.x_m.0 < world.min_m[0]
                    || p.x_m.0 > world.max_m[0]
                    || p.y_m.0 < world.min_m[1]
                    || p.y_m.0 > world.max_m[1]
                {
                    return Err(self.err(
                        s.span(),
                        "vehicle.start",
                        format!("({}, {}) lies outside the world", p.x_m.0, p.y_m.0),
                    ));
                }
                Isometry2::new(Vector2::new(p.x_m.0, p.y_m.0), p.yaw_rad.0)
            }
            // Pushed back: from the stand, on its heading.
            None if route.pushback.is_some() => {
                let first = route.pushback.as_ref().and_then(|t| t.poses.first());
                let (at, yaw) = first.copied().unwrap_or_default();
                Isometry2::new(at, yaw)
            }
            None => {
                let (a, b) = (route.waypoints_m[0], route.waypoints_m[1]);
                let d = b - a;
                Isometry2::new(a.coords, route.yaws_rad[0].unwrap_or(d.y.atan2(d.x)))
            }
        };
        Ok(ScenarioVehicle {
            description: v.description.get_ref().clone(),
            vehicle,
            world_from_start,
            walk_around: self.walk_around(v.walk_around.as_ref())?,
        })
    }

    /// `[vehicle] walk_around`: `"before_start"` (the default), `"none"`, or seconds > 0.
    fn walk_around(&self, w: Option<&Spanned<WalkAroundSpec>>) -> Result<WalkAround, LocatedError> {
        let Some(w) = w else {
            return Ok(WalkAround::BeforeStart);
        };
        match w.get_ref() {
            WalkAroundSpec::Word(s) if s == "before_start" => Ok(WalkAround::BeforeStart),
            WalkAroundSpec::Word(s) if s == "none" => Ok(WalkAround::Never),
            WalkAroundSpec::At(t) if t.is_finite() && *t > 0.0 => Ok(WalkAround::At(*t)),
            other => Err(self.err(
                w.span(),
                "vehicle.walk_around",
                format!(
                    "{}: expected \"before_start\", \"none\" or a time in seconds > 0",
                    match other {
                        WalkAroundSpec::Word(s) => format!("{s:?}"),
                        WalkAroundSpec::At(t) => t.to_string(),
                    }
                ),
            )),
        }
    }

    /// A vehicle description: a shipped name or a sidecar path relative to the scenario file.
    pub(super) fn load_vehicle(
        &self,
        name: &Spanned<String>,
        field: &str,
    ) -> Result<aircraft::Vehicle, LocatedError> {
        let as_path = self.dir.join(name.get_ref());
        let loaded = if aircraft::SHIPPED_VEHICLES.contains(&name.get_ref().as_str())
            || (!as_path.exists() && Path::new(name.get_ref()).extension().is_none())
        {
            // A shipped name, or neither a name nor a file: the error lists the shipped names.
            aircraft::Vehicle::shipped(name.get_ref())
        } else {
            aircraft::Vehicle::from_file(&as_path)
        };
        loaded.map_err(|e| self.err(name.span(), field, format!("cannot load the vehicle: {e}")))
    }
}
