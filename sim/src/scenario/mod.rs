//! What a run is asked to do: scenario files (TOML: the ground, the vehicle, the route, static
//! objects and rows of them, painted patches, run-time obstacles with expectations, laps, seed)
//! read, checked and resolved into a [`Scenario`], and run configurations ([`RunConfig`]: rates,
//! schedule, LiDAR, map, pose source, collision model, faults) that a scenario may carry in its
//! `[config]` table. Every mistake is a [`LocatedError`](crate::toml_file::LocatedError) naming the
//! file, the line, the column and the field.
//!
//! The pipeline, by stage:
//! - `spec`: the file as written ([`ScenarioFile`] and the `*Spec` structs, serde);
//! - `numbers`: the validating numbers the file is read with ([`Finite`], [`Positive`]...);
//! - `resolve`: the resolver, the file turned into the model with the cross-field checks (the
//!   route and the vehicle, objects, patches and obstacles, rows), and the entries that read a
//!   file ([`Scenario::from_file`], [`Scenario::from_str`]);
//! - `overlap`: the start overlap of a solid and the vehicle ([`start_overlap`]);
//! - `model`: the resolved scenario ([`Scenario`], [`Route`], [`Obstacle`]...) and its scenes;
//! - `run_config`: the run configuration ([`RunConfig`]).

mod model;
mod numbers;
pub(crate) mod overlap;
mod resolve;
mod run_config;
mod spec;

pub use model::{
    Ground, KnownProblem, MotionStop, MoverState, Obstacle, ObstacleMotion,
    REACTIVE_ACCELERATION_M_S2, Route, Scenario, ScenarioVehicle, Survey, TrainLink, WalkAround,
};
pub use numbers::{Count, Finite, Laps, NonNegative, Positive, Remission};
pub use overlap::start_overlap;
pub use run_config::{
    CollisionModelConfig, MappingConfig, NoisyTruthConfig, OBSTACLE_HEIGHT_M, PoseSourceConfig,
    RunConfig, SAFE_HEIGHT_FROM_GROUND_M, Schedule,
};
pub use spec::{
    Expectation, ExpectationsSpec, ExpectedEnd, MAX_ROW_OBJECTS, MAX_TRAIN_CARS, ObjectSpec,
    ObstacleSpec, PatchSpec, RegressSpec, RouteSpec, RowLine, RowSpec, ScenarioFile, StartPose,
    StopSpec, SurveyedStands, TodayEnd, TodaySpec, TrainSpec, VehicleEntry, WalkAroundSpec,
    WorldSpec,
};
