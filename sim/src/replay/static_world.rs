//! The static world, logged once when the run starts: the axes' convention, the ground and
//! its painted patches, the static objects, the route, the vehicle (parts and circles), the
//! LiDAR's point classes and the names and colours of the time series.

use rerun::RecordingStream;
use rerun::components::FillMode;
use rerun::datatypes::Rgba32;

use super::shapes::{Placement, circle_strip, log_part, log_solid};
use super::style::{
    CLASS_ABOVE, CLASS_GROUND, CLASS_LEVEL0, CLASS_UNMAPPED, CLASS_VEHICLE, level_color, path_part,
    yaw_quat,
};
use super::{Replay, Result};
use crate::engine::RunStart;

/// The ground slab and the painted patches (grey by remission).
fn log_ground(rec: &RecordingStream, scene: &crate::world::Scene) -> Result<()> {
    let (min, max) = (scene.min_m, scene.max_m);
    rec.log_static(
        "world/ground",
        &rerun::Boxes3D::from_centers_and_half_sizes(
            [[
                (0.5 * (min[0] + max[0])) as f32,
                (0.5 * (min[1] + max[1])) as f32,
                -0.03,
            ]],
            [[
                (0.5 * (max[0] - min[0])) as f32,
                (0.5 * (max[1] - min[1])) as f32,
                0.02,
            ]],
        )
        .with_fill_mode(FillMode::Solid)
        .with_colors([Rgba32::from_rgb(70, 72, 78)]),
    )?;
    let grey = |r: f32| {
        let v = (90.0 + 160.0 * r.clamp(0.0, 1.0)) as u8;
        Rgba32::from_rgb(v, v, v)
    };
    if !scene.patches.is_empty() {
        rec.log_static(
            "world/patches",
            &rerun::Boxes3D::from_centers_and_half_sizes(
                scene
                    .patches
                    .iter()
                    .map(|p| [p.x_m as f32, p.y_m as f32, -0.005]),
                scene
                    .patches
                    .iter()
                    .map(|p| [0.5 * p.length_m as f32, 0.5 * p.width_m as f32, 0.004]),
            )
            .with_quaternions(scene.patches.iter().map(|p| yaw_quat(p.yaw_rad)))
            .with_fill_mode(FillMode::Solid)
            .with_colors(scene.patches.iter().map(|p| grey(p.remission))),
        )?;
    }
    if !scene.areas.is_empty() {
        // Paved areas (an airport's pavement and runways): their outlines and holes, closed,
        // grey by remission, just above the ground.
        let rings: Vec<(Vec<[f32; 3]>, f32)> = scene
            .areas
            .iter()
            .flat_map(|a| {
                std::iter::once(&a.outline)
                    .chain(&a.holes)
                    .map(move |ring| (ring, a.remission))
            })
            .map(|(ring, remission)| {
                let mut strip: Vec<[f32; 3]> = ring
                    .iter()
                    .map(|p| [p[0] as f32, p[1] as f32, -0.008])
                    .collect();
                strip.extend(strip.first().copied());
                (strip, remission)
            })
            .collect();
        rec.log_static(
            "world/areas",
            &rerun::LineStrips3D::new(rings.iter().map(|(s, _)| s.clone()))
                .with_colors(rings.iter().map(|(_, r)| grey(*r))),
        )?;
    }
    Ok(())
}

/// The route as a line strip just above the ground, closed back to its first point when the
/// route is closed.
fn log_route(rec: &RecordingStream, scenario: &crate::scenario::Scenario) -> Result<()> {
    let mut route: Vec<[f32; 3]> = scenario
        .route
        .waypoints_m
        .iter()
        .map(|p| [p.x as f32, p.y as f32, 0.02])
        .collect();
    if scenario.route.closed
        && let Some(first) = route.first().copied()
    {
        route.push(first);
    }
    rec.log_static(
        "world/route",
        &rerun::LineStrips3D::new([route])
            .with_radii([0.08])
            .with_colors([Rgba32::from_rgb(250, 250, 250)]),
    )?;
    Ok(())
}

impl Replay {
    /// Logs what stays the same all run (static): the axes' convention, the ground and its
    /// patches, the static objects, the route, the vehicle, the LiDAR's classes and the names
    /// and colours of the time series, in that order.
    pub(super) fn log_static_world(&mut self, run: &RunStart<'_>) -> Result<()> {
        let rec = &self.rec;
        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        let scene = run.scene;
        log_ground(rec, scene)?;
        for solid in &scene.solids[..run.first_obstacle] {
            log_solid(
                rec,
                &format!("world/objects/{}", path_part(&solid.id)),
                solid,
                Placement::World,
            )?;
        }
        log_route(rec, run.scenario)?;
        self.log_vehicle(run)?;
        self.log_lidar_classes()?;
        self.log_series_names()?;
        Ok(())
    }

    /// The vehicle: its parts, coloured by level, and its circles at each level's height.
    fn log_vehicle(&self, run: &RunStart<'_>) -> Result<()> {
        let rec = &self.rec;
        let vehicle = &run.scenario.vehicle.vehicle;
        for (i, part) in vehicle.parts.iter().enumerate() {
            let level = run.part_levels.get(i).copied().unwrap_or(0);
            log_part(
                rec,
                &format!(
                    "world/vehicle/parts/{}/{}",
                    path_part(&part.link),
                    part.collision_index
                ),
                part,
                level_color(level),
            )?;
        }
        for (k, h) in self.level_heights_m.iter().enumerate() {
            let strips: Vec<Vec<[f32; 3]>> = run
                .model
                .circles()
                .iter()
                .filter(|c| c.level == k)
                .map(|c| circle_strip(c.x_m, c.y_m, c.radius_m, h.max(0.05)))
                .collect();
            rec.log_static(
                format!("world/vehicle/circles/level_{k}"),
                &rerun::LineStrips3D::new(strips)
                    .with_radii([0.03])
                    .with_colors([level_color(k)]),
            )?;
        }
        Ok(())
    }

    /// The LiDAR's classes (ground, vehicle, unmapped, above every level, one per level) as the
    /// annotation context of `world/lidar`.
    fn log_lidar_classes(&self) -> Result<()> {
        let mut classes: Vec<(u16, String, Rgba32)> = vec![
            (
                CLASS_GROUND,
                "ground (free)".into(),
                Rgba32::from_rgb(150, 150, 150),
            ),
            (
                CLASS_VEHICLE,
                "vehicle (self)".into(),
                Rgba32::from_rgb(90, 60, 120),
            ),
            (
                CLASS_UNMAPPED,
                "beyond mapping range".into(),
                Rgba32::from_rgb(80, 80, 80),
            ),
            (
                CLASS_ABOVE,
                "above every level".into(),
                Rgba32::from_rgb(200, 200, 255),
            ),
        ];
        for k in 0..self.level_heights_m.len() {
            classes.push((
                CLASS_LEVEL0 + k as u16,
                format!("obstacle, level {k}"),
                level_color(k),
            ));
        }
        self.rec.log_static(
            "world/lidar",
            &rerun::AnnotationContext::new(
                classes
                    .iter()
                    .map(|(id, label, color)| (*id, label.as_str(), *color)),
            ),
        )?;
        Ok(())
    }

    /// Names and colours of the time series.
    fn log_series_names(&self) -> Result<()> {
        let rec = &self.rec;
        for (k, _) in self.level_heights_m.iter().enumerate() {
            rec.log_static(
                format!("plots/clearance_m/level_{k}"),
                &rerun::SeriesLines::new()
                    .with_names([format!("clearance level {k} (m)")])
                    .with_colors([level_color(k)]),
            )?;
        }
        for (path, name) in [
            ("plots/speed_m_s", "speed (m/s)"),
            ("plots/steering_rad", "steering (rad)"),
            ("plots/real_time_factor", "real-time factor"),
            ("plots/speed_scale", "avoider speed scale"),
        ] {
            rec.log_static(path, &rerun::SeriesLines::new().with_names([name]))?;
        }
        Ok(())
    }
}
