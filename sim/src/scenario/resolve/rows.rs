//! The resolver's rows: each `[[rows]]` expanded along its line (its own or the route) into
//! ordinary static objects, station by station and offset by offset.

use std::collections::HashMap;

use nalgebra::{Point2, Vector2};
use toml::Spanned;

use super::Resolver;
use crate::scenario::model::{Ground, Route, ScenarioVehicle};
use crate::scenario::spec::{MAX_ROW_OBJECTS, RowLine, RowSpec};
use crate::toml_file::LocatedError;
use crate::world::{Solid, SolidShape};

impl Resolver<'_> {
    /// Appends the objects of each `[[rows]]`, in file order, to `objects`: the row's id and
    /// each object's id claimed, each object inside the world and clear of the vehicle at its
    /// start.
    pub(super) fn rows(
        &self,
        specs: &[Spanned<RowSpec>],
        world: &Ground,
        route: &Route,
        vehicle: &ScenarioVehicle,
        ids: &mut HashMap<String, String>,
        objects: &mut Vec<Solid>,
    ) -> Result<(), LocatedError> {
        for (i, r) in specs.iter().enumerate() {
            let field = format!("rows[{i}]");
            let id = &r.get_ref().id;
            self.claim_id(ids, id, &field)?;
            for (n, made) in self.row(r, &field, route)?.into_iter().enumerate() {
                let solid = made.solid;
                let what = format!(
                    "object {} (arc length {:.2} m, offset {} m)",
                    n + 1,
                    made.s_m,
                    made.offset_m
                );
                self.claim(
                    ids,
                    &solid.id,
                    id.span(),
                    &format!("{field}.id"),
                    format!("`{field}`, its {what}"),
                    &format!("its {what} is `{}`: ", solid.id),
                )?;
                if !(world.min_m[0]..=world.max_m[0]).contains(&solid.x_m)
                    || !(world.min_m[1]..=world.max_m[1]).contains(&solid.y_m)
                {
                    return Err(self.err(
                        id.span(),
                        &field,
                        format!(
                            "its {what}, `{}` at ({:.3}, {:.3}), lies outside the world [{}, {}] .. [{}, {}]",
                            solid.id,
                            solid.x_m,
                            solid.y_m,
                            world.min_m[0],
                            world.min_m[1],
                            world.max_m[0],
                            world.max_m[1]
                        ),
                    ));
                }
                self.no_start_overlap(vehicle, &solid, &field, id.span())?;
                objects.push(solid);
            }
        }
        Ok(())
    }

    /// Expands a row into its objects (ids, shapes, poses), with the checks that need only the
    /// row and the route; ids, the world and the start overlap are checked by the caller.
    fn row(
        &self,
        r: &Spanned<RowSpec>,
        field: &str,
        route: &Route,
    ) -> Result<Vec<RowObject>, LocatedError> {
        let spec = r.get_ref();
        let shape = self.shape(
            field,
            r.span(),
            spec.kind,
            &spec.size_m,
            &spec.radius_m,
            &spec.height_m,
        )?;
        let line = self.row_line(r, field, route)?;
        let length = line.length_m();
        let offsets = self.row_offsets(spec, field)?;
        let stations = self.row_stations(spec, field, &line, length, offsets.len())?;
        self.place_row(r, field, shape, &line, &offsets, &stations)
    }

    /// A row's line: its own `along_m` (checked as a polyline) or the route (`along = "route"`),
    /// exactly one of them.
    fn row_line(
        &self,
        r: &Spanned<RowSpec>,
        field: &str,
        route: &Route,
    ) -> Result<Polyline, LocatedError> {
        let spec = r.get_ref();
        Ok(match (&spec.along_m, &spec.along) {
            (Some(_), Some(a)) => {
                return Err(self.err(
                    a.span(),
                    &format!("{field}.along"),
                    "give either along_m or along, not both",
                ));
            }
            (None, None) => {
                return Err(self.err(
                    r.span(),
                    field,
                    "missing the row's line: give along_m = [[x, y], ...] or along = \"route\"",
                ));
            }
            (Some(a), None) => {
                let pts: Vec<Point2<f64>> = a
                    .get_ref()
                    .iter()
                    .map(|p| Point2::new(p[0].0, p[1].0))
                    .collect();
                self.polyline(
                    &pts,
                    2,
                    false,
                    a.span(),
                    &format!("{field}.along_m"),
                    "a row's line",
                )?;
                Polyline::new(&pts, false)
            }
            (None, Some(a)) => match a.get_ref() {
                RowLine::Route => Polyline::new(&route.waypoints_m, route.closed),
            },
        })
    }

    /// A row's lateral offsets, metres (default: on the line): at least one, none twice.
    fn row_offsets(&self, spec: &RowSpec, field: &str) -> Result<Vec<f64>, LocatedError> {
        Ok(match &spec.offsets_m {
            None => vec![0.0],
            Some(o) => {
                let v: Vec<f64> = o.get_ref().iter().map(|x| x.0).collect();
                if v.is_empty() {
                    return Err(self.err(
                        o.span(),
                        &format!("{field}.offsets_m"),
                        "no offsets: give at least one, e.g. [0.0] (on the line)",
                    ));
                }
                for (k, a) in v.iter().enumerate() {
                    if v[..k].contains(a) {
                        return Err(self.err(
                            o.span(),
                            &format!("{field}.offsets_m"),
                            format!("offset {a} m is given twice"),
                        ));
                    }
                }
                v
            }
        })
    }

    /// Where along its line (`length` metres long) a row's stations run, checking `end_m`
    /// against `start_m` and the line, `start_m` against the line, and the number of objects
    /// (`offset_count` a station) against [`MAX_ROW_OBJECTS`].
    fn row_stations(
        &self,
        spec: &RowSpec,
        field: &str,
        line: &Polyline,
        length: f64,
        offset_count: usize,
    ) -> Result<RowStations, LocatedError> {
        let start = spec.start_m.as_ref().map_or(0.0, |s| s.get_ref().0);
        // On a closed line without end_m, the station at the full length would repeat s = 0.
        let (end, open_end) = match &spec.end_m {
            Some(e) => {
                let end = e.get_ref().0;
                if end <= start {
                    return Err(self.err(
                        e.span(),
                        &format!("{field}.end_m"),
                        format!("{end} m is not after start_m ({start} m)"),
                    ));
                }
                if end > length + 1e-9 {
                    return Err(self.err(
                        e.span(),
                        &format!("{field}.end_m"),
                        format!("{end} m lies beyond the end of the line ({length:.3} m long)"),
                    ));
                }
                (end, false)
            }
            None => {
                if let Some(s) = &spec.start_m
                    && start >= length
                {
                    return Err(self.err(
                        s.span(),
                        &format!("{field}.start_m"),
                        format!(
                            "{start} m lies at or beyond the end of the line ({length:.3} m long)"
                        ),
                    ));
                }
                (length, line.closed)
            }
        };
        let spacing = spec.spacing_m.get_ref().0;
        let stations = ((end - start) / spacing + 1e-9).floor() + 1.0;
        let count = stations * offset_count as f64;
        if count > MAX_ROW_OBJECTS as f64 {
            return Err(self.err(
                spec.spacing_m.span(),
                &format!("{field}.spacing_m"),
                format!(
                    "{spacing} m over {:.1} m with {} offset(s) makes {count:.0} objects, more than {MAX_ROW_OBJECTS}",
                    end - start,
                    offset_count
                ),
            ));
        }
        Ok(RowStations {
            start,
            end,
            open_end,
            length,
            spacing,
            stations,
            count,
        })
    }

    /// Places a row's objects, station by station and, at each, offset by offset (ids
    /// `<row id>_<n>` from 1), refusing an offset object a sharp turn puts near the line.
    fn place_row(
        &self,
        r: &Spanned<RowSpec>,
        field: &str,
        shape: SolidShape,
        line: &Polyline,
        offsets: &[f64],
        stations: &RowStations,
    ) -> Result<Vec<RowObject>, LocatedError> {
        let spec = r.get_ref();
        let RowStations {
            start,
            end,
            open_end,
            length,
            spacing,
            stations,
            count,
        } = *stations;
        let remission = spec
            .remission
            .map_or_else(|| spec.kind.default_remission(), |r| r.0);
        let prefix = spec.id.get_ref();
        let mut made = Vec::with_capacity(count as usize);
        for k in 0..stations as usize {
            let s_m = start + k as f64 * spacing;
            if s_m > end + 1e-9 || (open_end && s_m >= length - 1e-9) {
                break;
            }
            let (p, heading) = line.at(s_m);
            let normal = Vector2::new(-heading.sin(), heading.cos());
            for &offset_m in offsets {
                let q = p + normal * offset_m;
                // A sharp turn of the line puts an offset object of one segment over another:
                // refuse it rather than place an object where the line runs.
                let d = line.distance(&q);
                if d < 0.9 * offset_m.abs() - 1e-9 {
                    let span = spec
                        .offsets_m
                        .as_ref()
                        .map_or_else(|| r.span(), |o| o.span());
                    return Err(self.err(
                        span,
                        &format!("{field}.offsets_m"),
                        format!(
                            "the object at arc length {s_m:.2} m, offset {offset_m} m, ({:.2}, {:.2}) lies {d:.2} m from the line: it turns too sharply there for this offset (round the corner with more points, or limit the row with start_m/end_m)",
                            q.x, q.y
                        ),
                    ));
                }
                made.push(RowObject {
                    solid: Solid {
                        id: format!("{prefix}_{}", made.len() + 1),
                        kind: spec.kind,
                        shape,
                        x_m: q.x,
                        y_m: q.y,
                        z_min_m: spec.z_min_m.0,
                        yaw_rad: crate::world::wrap_angle(heading + spec.yaw_rad.0),
                        remission,
                        runtime: false,
                    },
                    s_m,
                    offset_m,
                });
            }
        }
        Ok(made)
    }
}

/// An object a row made, with where along its line it stands.
struct RowObject {
    solid: Solid,
    /// Arc length along the row's line, metres.
    s_m: f64,
    /// Lateral offset from the line, metres, left positive.
    offset_m: f64,
}

/// Where along its line a row's stations run (see [`Resolver::row_stations`]).
#[derive(Clone, Copy)]
struct RowStations {
    /// Arc length of the first station, metres.
    start: f64,
    /// Arc length no station goes beyond, metres.
    end: f64,
    /// A closed line without `end_m`: no station at the full length (it would repeat s = 0).
    open_end: bool,
    /// Length of the line, metres.
    length: f64,
    /// Distance between stations, metres.
    spacing: f64,
    /// Number of stations (a whole number).
    stations: f64,
    /// Number of objects: stations times offsets.
    count: f64,
}

/// A row's line: a polyline with arc lengths (closed: back to its first point).
struct Polyline {
    points: Vec<Point2<f64>>,
    s: Vec<f64>,
    closed: bool,
}

impl Polyline {
    fn new(points: &[Point2<f64>], closed: bool) -> Self {
        let mut points = points.to_vec();
        if closed && let Some(first) = points.first().copied() {
            points.push(first);
        }
        let mut s = vec![0.0];
        for w in points.windows(2) {
            s.push(s[s.len() - 1] + (w[1] - w[0]).norm());
        }
        Polyline { points, s, closed }
    }

    fn length_m(&self) -> f64 {
        self.s[self.s.len() - 1]
    }

    /// Point and heading at arc length `s` in [0, length]; on a vertex, the heading of the
    /// segment leaving it (of the last segment at the end).
    fn at(&self, s: f64) -> (Point2<f64>, f64) {
        let i = self
            .s
            .partition_point(|&x| x <= s)
            .saturating_sub(1)
            .min(self.points.len() - 2);
        let (a, b) = (self.points[i], self.points[i + 1]);
        let d = b - a;
        let len = d.norm();
        (a + d * ((s - self.s[i]) / len), d.y.atan2(d.x))
    }

    /// Distance from `p` to the nearest point of the line.
    fn distance(&self, p: &Point2<f64>) -> f64 {
        self.points
            .windows(2)
            .map(|w| {
                let ab = w[1] - w[0];
                let t = ((p - w[0]).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                (p - (w[0] + ab * t)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }
}
