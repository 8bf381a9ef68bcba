//! The resolver: turns a scenario file as written ([`ScenarioFile`]) into a [`Scenario`], with
//! the cross-field checks (one route source, ids unique across objects, rows, patches and
//! obstacles, everything inside the world, nothing over the vehicle at its start) on the spans
//! toml keeps. Every mistake becomes a [`LocatedError`] naming the file, the line, the column and
//! the field, with the offending line quoted. This file holds the entries ([`Scenario::from_file`],
//! [`Scenario::from_str`] and [`Resolver::resolve`]) and the helpers the parts share: ids, the
//! world and its bounds, polylines, the start overlap.

mod airport;
mod motion;
mod objects;
mod route;
mod rows;

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use nalgebra::Point2;
use toml::Spanned;

use super::model::{Ground, KnownProblem, Scenario, ScenarioVehicle};
use super::overlap::start_overlap;
use super::spec::{ScenarioFile, TodaySpec, WorldSpec};
use crate::toml_file::LocatedError;
use crate::world::Solid;

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn from_file(path: &Path) -> Result<Self, LocatedError> {
        let text = std::fs::read_to_string(path).map_err(|error| LocatedError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        Scenario::from_str(&text, path)
    }

    /// Validates a scenario text; `path` labels errors and anchors the relative paths of the
    /// files it names (vehicle sidecar, pose file), which are read here.
    pub fn from_str(text: &str, path: &Path) -> Result<Self, LocatedError> {
        let file = path.display().to_string();
        let spec: ScenarioFile =
            toml::from_str(text).map_err(|e| LocatedError::toml(&file, text, &e))?;
        Resolver {
            text,
            file: &file,
            dir: path.parent().unwrap_or_else(|| Path::new("")),
        }
        .resolve(spec, path)
    }
}

/// Turns the file as written into a [`Scenario`], with the cross-field checks.
pub(super) struct Resolver<'a> {
    pub(super) text: &'a str,
    pub(super) file: &'a str,
    pub(super) dir: &'a Path,
}

impl Resolver<'_> {
    fn err(&self, span: Range<usize>, field: &str, message: impl Into<String>) -> LocatedError {
        LocatedError::at(self.file, self.text, span, field, message.into())
    }

    pub(super) fn resolve(
        &self,
        mut spec: ScenarioFile,
        path: &Path,
    ) -> Result<Scenario, LocatedError> {
        let airport = spec
            .airport
            .as_ref()
            .map(|a| self.load_airport(a))
            .transpose()?;
        let mut world = match (&spec.world, &airport) {
            (Some(w), _) => self.world(w)?,
            (None, Some(loaded)) => Self::airport_ground(loaded),
            (None, None) => {
                return Err(self.err(
                    0..0,
                    "world",
                    "missing [world] (min_m, max_m), or an [airport] to take it from",
                ));
            }
        };
        if let Some(loaded) = &airport {
            world.areas.clone_from(&loaded.made.areas);
        }
        let route = match &spec.route.get_ref().taxi {
            Some(taxi) => {
                self.taxi_route(&spec.route, taxi, airport.as_ref(), &spec.vehicle, &world)?
            }
            None => self.route(&spec.route, &world)?,
        };
        let vehicle = self.vehicle(&spec.vehicle, &route, &world)?;
        // Every id, with who uses it (as error messages name it).
        let mut ids: HashMap<String, String> = HashMap::new();
        let (mut objects, mut survey, mut patches) = match (&spec.airport, &airport) {
            (Some(a), Some(loaded)) => {
                let route_stands: Vec<String> = (spec.route.get_ref().taxi.iter())
                    .flat_map(|t| [t.get_ref().from.clone(), t.get_ref().to.clone()])
                    .collect();
                // Its way, half a metre a pose: the ramp parks no aircraft across it.
                let (way, towed) = crate::scenario::overlap::taxi_way(&route, 0.5);
                let (seed, stands) = (spec.seed, &route_stands);
                let way = (&way[..], towed);
                let a =
                    self.airport_objects(a, loaded, &world, &vehicle, &mut ids, seed, stands, way)?;
                (a.solids, a.survey, a.patches)
            }
            _ => (Vec::new(), None, Vec::new()),
        };
        let airport_objects = objects.len();
        objects.extend(self.objects(&spec.objects, &world, &vehicle, &mut ids)?);
        self.rows(&spec.rows, &world, &route, &vehicle, &mut ids, &mut objects)?;
        // The scenario's own objects and rows were there when the airport was surveyed.
        if let Some(survey) = &mut survey {
            survey
                .objects
                .extend_from_slice(&objects[airport_objects..]);
        }
        patches.extend(self.patches(&spec.patches, &world, &mut ids)?);
        let obstacles = self.obstacles(&spec.obstacles, &world, &vehicle, &mut ids)?;
        let known_problem = self.known_problem(&mut spec.expectations)?;
        let golden = self.golden(spec.regress.golden.take())?;
        if let Some(c) = &spec.config {
            crate::scenario::RunConfig::from_table(c.get_ref().clone())
                .map_err(|m| LocatedError::at(self.file, self.text, c.span(), "config", m))?;
        }
        Ok(Scenario {
            path: path.to_path_buf(),
            name: spec.name,
            description: spec.description,
            seed: spec.seed,
            laps: spec.laps.0,
            world,
            vehicle,
            route,
            objects,
            survey,
            patches,
            obstacles,
            danger_distance_m: spec.expectations.danger_distance_m.map(|d| d.0),
            expected_end: spec.expectations.end.unwrap_or_default(),
            no_contact_at_fault: spec.expectations.no_contact_at_fault,
            max_stops: spec.expectations.max_stops,
            max_cross_track_rmse_m: spec.expectations.max_cross_track_rmse_m.map(|d| d.0),
            max_heading_rmse_rad: spec.expectations.max_heading_rmse_rad.map(|d| d.0),
            config: spec.config.map(Spanned::into_inner),
            known_problem,
            quick_laps: spec.regress.quick_laps.map(|q| q.0),
            full_only: spec.regress.full_only,
            golden,
        })
    }

    /// `[regress] golden`: a `.json` file, relative to the scenario's folder.
    fn golden(&self, g: Option<Spanned<String>>) -> Result<Option<PathBuf>, LocatedError> {
        let Some(g) = g else { return Ok(None) };
        if !g.get_ref().ends_with(".json") {
            return Err(self.err(
                g.span(),
                "regress.golden",
                "names the golden numbers' file: a path ending in `.json`",
            ));
        }
        Ok(Some(self.dir.join(g.get_ref())))
    }

    /// `[expectations] known_problem` and `today`: both or neither; `today` states something.
    fn known_problem(
        &self,
        e: &mut crate::scenario::ExpectationsSpec,
    ) -> Result<Option<KnownProblem>, LocatedError> {
        let field = "expectations.known_problem";
        match (e.known_problem.take(), e.today.take()) {
            (None, None) => Ok(None),
            (None, Some(today)) => Err(self.err(
                today.span(),
                "expectations.today",
                "states a known problem's outcome, but `known_problem` (the text saying what goes wrong) is missing",
            )),
            (Some(text), None) => Err(self.err(
                text.span(),
                field,
                "a known problem needs `[expectations.today]`: how the run ends today (end, contacts, contacts_at_fault, contacts_struck or contacts_with)",
            )),
            (Some(text), Some(today)) => {
                if *today.get_ref() == TodaySpec::default() {
                    return Err(self.err(
                        today.span(),
                        "expectations.today",
                        "states nothing: give end, contacts, contacts_at_fault, contacts_struck or contacts_with",
                    ));
                }
                if text.get_ref().trim().is_empty() {
                    return Err(self.err(text.span(), field, "empty: say what goes wrong"));
                }
                Ok(Some(KnownProblem {
                    text: text.into_inner(),
                    today: today.into_inner(),
                }))
            }
        }
    }

    /// Claims `id` in `ids` for `owner` (as error messages name it): an empty id or one
    /// already claimed is refused at `span` under `field`, the message starting with `made`.
    fn claim(
        &self,
        ids: &mut HashMap<String, String>,
        id: &str,
        span: Range<usize>,
        field: &str,
        owner: String,
        made: &str,
    ) -> Result<(), LocatedError> {
        if id.is_empty() {
            return Err(self.err(span, field, "an id must not be empty"));
        }
        if let Some(first) = ids.insert(id.to_string(), owner) {
            return Err(self.err(
                span,
                field,
                format!("{made}duplicate id `{id}` (already used by {first})"),
            ));
        }
        Ok(())
    }

    /// Claims the id of table `field` (`objects[3]`), named `<field>.id` as field and owner.
    fn claim_id(
        &self,
        ids: &mut HashMap<String, String>,
        id: &Spanned<String>,
        field: &str,
    ) -> Result<(), LocatedError> {
        let field = format!("{field}.id");
        self.claim(
            ids,
            id.get_ref(),
            id.span(),
            &field,
            format!("`{field}`"),
            "",
        )
    }

    fn world(&self, w: &WorldSpec) -> Result<Ground, LocatedError> {
        let min_m = [w.min_m[0].0, w.min_m[1].0];
        let max_m = [w.max_m.get_ref()[0].0, w.max_m.get_ref()[1].0];
        if max_m[0] <= min_m[0] || max_m[1] <= min_m[1] {
            return Err(self.err(
                w.max_m.span(),
                "world.max_m",
                format!(
                    "the upper corner {max_m:?} must be above the lower corner {min_m:?} in x and y"
                ),
            ));
        }
        Ok(Ground {
            min_m,
            max_m,
            ground_remission: w.ground_remission.0,
            pavement_texture: w.pavement_texture.0,
            areas: Vec::new(),
        })
    }

    fn inside_world(
        &self,
        world: &Ground,
        field: &str,
        span: Range<usize>,
        x: f64,
        y: f64,
    ) -> Result<(), LocatedError> {
        if x < world.min_m[0] || x > world.max_m[0] || y < world.min_m[1] || y > world.max_m[1] {
            return Err(self.err(
                span,
                field,
                format!(
                    "({x}, {y}) lies outside the world [{}, {}] .. [{}, {}]",
                    world.min_m[0], world.min_m[1], world.max_m[0], world.max_m[1]
                ),
            ));
        }
        Ok(())
    }

    /// Checks a polyline: at least `min` points, no two consecutive equal (nor, when `closed`,
    /// the last and the first).
    #[allow(clippy::too_many_arguments)]
    fn polyline(
        &self,
        points: &[Point2<f64>],
        min: usize,
        closed: bool,
        span: Range<usize>,
        field: &str,
        what: &str,
    ) -> Result<(), LocatedError> {
        if points.len() < min {
            return Err(self.err(
                span,
                field,
                format!(
                    "{} point(s): {}{what} needs at least {min}",
                    points.len(),
                    if closed { "closed, " } else { "" }
                ),
            ));
        }
        for (k, w) in points.windows(2).enumerate() {
            if w[0] == w[1] {
                return Err(self.err(
                    span,
                    field,
                    format!(
                        "points {k} and {} are the same ({}, {})",
                        k + 1,
                        w[0].x,
                        w[0].y
                    ),
                ));
            }
        }
        if closed && points.first() == points.last() {
            return Err(self.err(
                span,
                field,
                "the last point repeats the first: a closed route joins them itself, drop the last",
            ));
        }
        Ok(())
    }

    fn no_start_overlap(
        &self,
        vehicle: &ScenarioVehicle,
        solid: &Solid,
        field: &str,
        span: Range<usize>,
    ) -> Result<(), LocatedError> {
        if let Some(hit) = start_overlap(&vehicle.vehicle, &vehicle.world_from_start, solid) {
            let t = vehicle.world_from_start.translation.vector;
            return Err(self.err(
                span,
                field,
                format!(
                    "`{}` ({}, z {:.2}..{:.2} m) overlaps the vehicle at its start pose ({:.2}, {:.2}) m, yaw {:.3} rad: {hit}",
                    solid.id,
                    solid.kind.name(),
                    solid.shape.z_range_m(solid.z_min_m).0,
                    solid.shape.z_range_m(solid.z_min_m).1,
                    t.x,
                    t.y,
                    vehicle.world_from_start.rotation.angle(),
                ),
            ));
        }
        Ok(())
    }
}
