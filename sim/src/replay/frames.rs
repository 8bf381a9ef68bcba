//! What changes over the run, frame by frame: a revolution's LiDAR points (classed as the
//! mapper classes them), the localization's error and particles and the planner's candidates
//! and chosen path; a step's run-time obstacles.

use rerun::datatypes::Rgba32;

use super::shapes::{Placement, log_solid};
use super::style::{
    CLASS_ABOVE, CLASS_GROUND, CLASS_LEVEL0, CLASS_UNMAPPED, CLASS_VEHICLE, strip, yaw_quat,
};
use super::{Replay, Result};
use crate::engine::RevolutionFrame;
use crate::world::Owner;

impl Replay {
    /// The run-time obstacles that appeared, moved or went away since the last logged step:
    /// a shape in its own frame when one appears, its pose when it changes, a clear when it
    /// goes.
    pub(super) fn log_obstacles(&mut self, world: &crate::world::World) -> Result<()> {
        for (k, last) in self.obstacles.iter_mut().enumerate() {
            let i = self.first_obstacle + k;
            let path = &self.obstacle_paths[k];
            let active = world.object_active(i);
            let Some(solid) = world.scene().solids.get(i) else {
                continue;
            };
            match (active, *last) {
                (false, None) => {}
                (false, Some(_)) => {
                    self.rec.log(path.as_str(), &rerun::Clear::flat())?;
                    *last = None;
                }
                (true, prev) => {
                    let now = (solid.x_m, solid.y_m, solid.yaw_rad);
                    if prev.is_none() {
                        log_solid(&self.rec, path, solid, Placement::Own)?;
                    }
                    if prev != Some(now) {
                        self.rec.log(
                            path.as_str(),
                            &rerun::Transform3D::from_translation_rotation(
                                [now.0 as f32, now.1 as f32, 0.0],
                                yaw_quat(now.2),
                            ),
                        )?;
                    }
                    *last = Some(now);
                }
            }
        }
        Ok(())
    }

    /// A revolution at `t_s`: its points (every sensor's, each at its own entity) logged if it
    /// is one of every `scan_every`; whether it was.
    pub(super) fn log_revolution_points(
        &mut self,
        t_s: f64,
        revolution: &autonomy::LidarRevolution,
        owners: &[Option<Owner>],
        more_owners: &[Vec<Option<Owner>>],
    ) -> Result<bool> {
        self.time(t_s);
        let full = self
            .scans_seen
            .is_multiple_of(u64::from(self.options.scan_every));
        self.scans_seen += 1;
        if full {
            self.log_lidar("world/lidar", &revolution.scan, owners)?;
            for (k, scan) in revolution.more_scans.iter().enumerate() {
                let path = self.more_lidar_paths.get(k).cloned().unwrap_or_else(|| {
                    // A stack's revolution names no sensors: numbered.
                    format!("world/lidar/{}", k + 1)
                });
                let owners = more_owners.get(k).map_or(&[][..], Vec::as_slice);
                self.log_lidar(&path, scan, owners)?;
            }
            self.summary.scans_logged += 1;
        }
        Ok(full)
    }

    /// A revolution's returns, every `point_stride` columns, classed as the mapper classes
    /// them: ground, vehicle (self), beyond mapping range, obstacle at level k, above every
    /// level.
    pub(super) fn log_lidar(
        &mut self,
        path: &str,
        scan: &mapper::Scan,
        owners: &[Option<Owner>],
    ) -> Result<()> {
        let Some(levels) = &self.levels else {
            return Ok(());
        };
        let beams = scan.beams();
        let params = self.obstacle_test;
        let (mut positions, mut classes) = (Vec::new(), Vec::new());
        for (c, column) in scan
            .columns()
            .iter()
            .enumerate()
            .step_by(self.options.point_stride)
        {
            let sensor = nalgebra::Point3::from(column.world_from_sensor.translation.vector);
            let returns = &scan.returns()[c * beams..(c + 1) * beams];
            for (b, r) in returns.iter().enumerate() {
                let Some(r) = r else { continue };
                let p = r.point_in_world;
                positions.push([p.x as f32, p.y as f32, p.z as f32]);
                let owner = owners.get(c * beams + b).copied().flatten();
                let range_xy = (p.x - sensor.x).hypot(p.y - sensor.y);
                let class = if matches!(owner, Some(Owner::VehiclePart(_))) {
                    CLASS_VEHICLE
                } else if range_xy > params.max_range_m {
                    CLASS_UNMAPPED
                } else {
                    // The mapper's obstacle test: this return against the one below it.
                    let height = p.z - params.ground_height_m;
                    let obstacle = match b.checked_sub(1).and_then(|lb| returns[lb]) {
                        Some(lower) => mapper::occupancy::obstacle_probability(
                            &sensor,
                            &lower.point_in_world,
                            &p,
                            &params,
                        )
                        .is_some_and(|pr| pr > 0.5),
                        None => params
                            .unsafe_height_above_ground_m
                            .is_some_and(|h| height >= h),
                    };
                    if !obstacle {
                        CLASS_GROUND
                    } else {
                        (0..levels.count())
                            .rev()
                            .find(|&k| levels.classify(k, height) == mapper::HeightClass::Inside)
                            .map_or(CLASS_ABOVE, |k| CLASS_LEVEL0 + k as u16)
                    }
                };
                classes.push(class);
            }
        }
        self.rec.log(
            path,
            &rerun::Points3D::new(positions)
                .with_class_ids(classes)
                .with_radii([0.04]),
        )?;
        Ok(())
    }

    /// The estimate's error against the truth of the same revolution and its own standard
    /// deviation (plots); with `particles`, a hundred of the particles and the 2-sigma ellipse
    /// of the estimate's position.
    pub(super) fn log_localization(
        &mut self,
        frame: &RevolutionFrame<'_>,
        particles: bool,
    ) -> Result<()> {
        let Some(estimate) = frame.pose_estimate else {
            return Ok(());
        };
        let d = frame.estimate.translation.vector - frame.truth.translation.vector;
        let left = frame.truth.rotation * nalgebra::Vector2::y();
        self.rec.log(
            "plots/localization/cross_track_error_m",
            &rerun::Scalars::single(d.dot(&left)),
        )?;
        self.rec.log(
            "plots/localization/cross_track_sigma_m",
            &rerun::Scalars::single(estimate.cross_track_sigma_m()),
        )?;
        let Some(ps) = frame.particles.filter(|_| particles) else {
            return Ok(());
        };
        let every = ps.len().div_ceil(100).max(1);
        self.rec.log(
            "world/localization/particles",
            &rerun::Points3D::new(
                ps.iter()
                    .step_by(every)
                    .map(|p| [p.x as f32, p.y as f32, 0.08]),
            )
            .with_radii([0.05])
            .with_colors([Rgba32::from_rgb(255, 120, 0)]),
        )?;
        let c = estimate.covariance.fixed_view::<2, 2>(0, 0).into_owned();
        let eig = c.symmetric_eigen();
        let centre = estimate.world_from_vehicle.translation.vector;
        let ellipse: Vec<[f32; 3]> = (0..=32)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 32.0;
                let u = nalgebra::Vector2::new(
                    2.0 * eig.eigenvalues[0].max(0.0).sqrt() * a.cos(),
                    2.0 * eig.eigenvalues[1].max(0.0).sqrt() * a.sin(),
                );
                let p = centre + eig.eigenvectors * u;
                [p.x as f32, p.y as f32, 0.08]
            })
            .collect();
        self.rec.log(
            "world/localization/covariance_2sigma",
            &rerun::LineStrips3D::new([ellipse]).with_colors([Rgba32::from_rgb(255, 120, 0)]),
        )?;
        Ok(())
    }

    /// The planner's chosen path (red when blocked) and, with `candidates`, every candidate
    /// (red: colliding).
    pub(super) fn log_plan(&mut self, frame: &RevolutionFrame<'_>, candidates: bool) -> Result<()> {
        let plan = frame.plan;
        if candidates {
            let colors: Vec<Rgba32> = plan
                .candidates
                .iter()
                .map(|c| {
                    if c.collision_at_m.is_some() {
                        Rgba32::from_unmultiplied_rgba(255, 60, 60, 160)
                    } else {
                        Rgba32::from_unmultiplied_rgba(120, 230, 120, 120)
                    }
                })
                .collect();
            self.rec.log(
                "world/planner/candidates",
                &rerun::LineStrips3D::new(plan.candidates.iter().map(|c| strip(&c.poses, 4)))
                    .with_radii([0.025])
                    .with_colors(colors),
            )?;
        }
        let chosen = plan.chosen();
        let color = if plan.blocked {
            Rgba32::from_rgb(255, 40, 40)
        } else {
            Rgba32::from_rgb(40, 120, 255)
        };
        self.rec.log(
            "world/planner/chosen",
            &rerun::LineStrips3D::new([strip(&chosen.poses, 2)])
                .with_radii([0.07])
                .with_colors([color]),
        )?;
        Ok(())
    }

    /// Each predicted mover's footprints over the horizon (capsules, from green now to red at
    /// the horizon) and the conflict the vehicle slowed or stopped for (a red ring where the
    /// mover would be).
    pub(super) fn log_traffic(&mut self, frame: &RevolutionFrame<'_>) -> Result<()> {
        let mut strips = Vec::new();
        let mut colors = Vec::new();
        for p in frame.predictions {
            let horizon = p.discs.last().map_or(1.0, |d| d.dt_s.max(1e-9));
            for d in &p.discs {
                strips.push(capsule(d));
                let u = (d.dt_s / horizon).clamp(0.0, 1.0);
                colors.push(Rgba32::from_unmultiplied_rgba(
                    (60.0 + 195.0 * u) as u8,
                    (220.0 * (1.0 - u)) as u8,
                    60,
                    200,
                ));
            }
        }
        self.rec.log(
            "world/traffic/predicted",
            &rerun::LineStrips3D::new(strips)
                .with_radii([0.03])
                .with_colors(colors),
        )?;
        let ring: Vec<Vec<[f32; 3]>> = frame
            .conflict
            .iter()
            .map(|c| {
                (0..=24)
                    .map(|k| {
                        let a = k as f64 * std::f64::consts::TAU / 24.0;
                        let q = c.mover_at + nalgebra::Vector2::new(a.cos(), a.sin()) * 1.5;
                        [q.x as f32, q.y as f32, 0.1]
                    })
                    .collect()
            })
            .collect();
        self.rec.log(
            "world/traffic/conflict",
            &rerun::LineStrips3D::new(ring)
                .with_radii([0.08])
                .with_colors([Rgba32::from_rgb(255, 30, 30)]),
        )?;
        Ok(())
    }
}

/// The outline of a predicted footprint: a capsule along the mover's heading.
fn capsule(d: &autonomy::traffic::PredictedDisc) -> Vec<[f32; 3]> {
    let (r, h) = (d.radius_m, d.half_length_m);
    let u = nalgebra::Vector2::new(d.heading_rad.cos(), d.heading_rad.sin());
    let n = nalgebra::Vector2::new(-u.y, u.x);
    let mut out = Vec::with_capacity(26);
    for (end, sign) in [(h, 1.0), (-h, -1.0)] {
        for k in 0..=12 {
            let a = -std::f64::consts::FRAC_PI_2 + k as f64 * std::f64::consts::PI / 12.0;
            let q = d.center + u * end + (u * a.cos() + n * a.sin()) * (r * sign);
            out.push([q.x as f32, q.y as f32, 0.08]);
        }
    }
    out.push(out[0]);
    out
}
