//! The viewer's layout (the blueprint): the 3D world large on the left; the distance maps, the
//! time series and the events on the right; the 3D camera behind the vehicle, following it.

use nalgebra::{Isometry2, Point2};
use rerun::blueprint::{
    Blueprint, ContainerLike, Grid, Horizontal, Spatial2DView, Spatial3DView, TextLogView,
    TimePanel, TimeSeriesView, Vertical,
};

use super::{Replay, Result, TIMELINE};

impl Replay {
    /// The layout: the 3D world large on the left; the distance maps, the time series and the
    /// events on the right. Sent as the active blueprint (a user's own layout is one click away:
    /// "reset to default blueprint" brings this one back).
    fn blueprint(levels: usize) -> (Blueprint, Option<String>) {
        let maps: Vec<rerun::blueprint::ContainerLike> = (0..levels)
            .map(|k| {
                Spatial2DView::new(format!("level {k} distance map (m)"))
                    .with_origin(format!("/maps/level_{k}"))
                    .into()
            })
            .collect();
        let series = |name: &str, origin: &str, contents: &[&str]| -> ContainerLike {
            TimeSeriesView::new(name)
                .with_origin(origin)
                .with_contents(contents.iter().map(|c| c.to_string()))
                .into()
        };
        let plots = Grid::new([
            series(
                "speed (m/s), avoider scale",
                "/plots",
                &["/plots/speed_m_s", "/plots/speed_scale"],
            ),
            series("steering (rad)", "/plots", &["/plots/steering_rad"]),
            series(
                "clearance per level (m)",
                "/plots/clearance_m",
                &["/plots/clearance_m/**"],
            ),
            series("real-time factor", "/plots", &["/plots/real_time_factor"]),
        ])
        .with_grid_columns(2);
        let world: ContainerLike = Spatial3DView::new("world").with_origin("/world").into();
        let world_path = match &world {
            ContainerLike::View(v) => Some(v.blueprint_path().to_string()),
            _ => None,
        };
        let blueprint = Blueprint::new(
            Horizontal::new([
                world,
                Vertical::new([
                    Horizontal::new(maps).into(),
                    plots.into(),
                    TextLogView::new("events").with_origin("/events").into(),
                ])
                .with_row_shares([1.0, 1.4, 0.7])
                .into(),
            ])
            .with_column_shares([1.8, 1.0]),
        )
        .with_time_panel(TimePanel::new().with_timeline(TIMELINE));
        (blueprint, world_path)
    }

    /// Sends the layout as the active blueprint, with the 3D view's camera behind the vehicle
    /// and following it. The Rust blueprint API cannot set a view's camera yet, so its messages
    /// are rendered into memory first and the camera is added to the same blueprint store.
    pub(super) fn send_blueprint(&self, levels: usize, start: &Isometry2<f64>) -> Result<()> {
        use rerun::external::re_sdk_types::blueprint::archetypes::EyeControls3D;
        let (blueprint, world_path) = Self::blueprint(levels);
        let activation = rerun::blueprint::BlueprintActivation {
            make_active: true,
            make_default: true,
        };
        let (memory, storage) = rerun::RecordingStreamBuilder::new("taxi-sim").memory()?;
        blueprint.send(&memory, activation)?;
        memory.flush_blocking()?;
        let mut messages = storage.take();
        let Some(command) = messages.iter().find_map(|m| match m {
            rerun::log::LogMsg::BlueprintActivationCommand(c) => Some(c.clone()),
            _ => None,
        }) else {
            // Nothing to add the camera to: send the layout as it is.
            return Ok(blueprint.send(&self.rec, activation)?);
        };
        messages.retain(|m| {
            m.store_id() == &command.blueprint_id
                && !matches!(m, rerun::log::LogMsg::BlueprintActivationCommand(_))
        });
        if let Some(world_path) = world_path {
            let (eye, eye_storage) =
                rerun::RecordingStreamBuilder::from_store_id(&command.blueprint_id).memory()?;
            eye.set_time_sequence("blueprint", 0);
            let at = |x: f64, y: f64, z: f64| -> [f32; 3] {
                let p = start * Point2::new(x, y);
                [p.x as f32, p.y as f32, z as f32]
            };
            eye.log(
                format!("{world_path}/EyeControls3D"),
                &EyeControls3D::new()
                    .with_position(at(-18.0, 12.0, 14.0))
                    .with_look_target(at(6.0, 0.0, 0.0))
                    .with_eye_up([0.0, 0.0, 1.0])
                    .with_tracking_entity("/world/vehicle"),
            )?;
            eye.flush_blocking()?;
            messages.extend(
                eye_storage
                    .take()
                    .into_iter()
                    .filter(|m| matches!(m, rerun::log::LogMsg::ArrowMsg(..))),
            );
        }
        self.rec.send_blueprint(messages, command);
        Ok(())
    }
}
