//! The offline map's settings, shared by the mapping drive, the closed loop and the replay: the
//! map configuration of a run configuration, the levels of a scenario's vehicle, the self-hit
//! filter's circles.

use mapper::{Levels, MapConfig};

use crate::error::Result;
use crate::scenario::{RunConfig, Scenario};

/// The map settings of a configuration's mapping drive (its mapping settings as they are).
pub fn map_config(config: &RunConfig) -> MapConfig {
    config.mapping.map
}

/// The circles the LiDAR self-hit filter uses: every part at its own level (the banded fit keeps
/// the parts a cumulative fit drops because they lie over a lower level's parts, such as a wing
/// root over the fuselage), so returns off the vehicle's own wing are dropped while a cone under
/// the wing is not.
pub fn self_filter_model(vehicle: &aircraft::Vehicle) -> Result<mapper::CollisionModel> {
    let options = aircraft::FitOptions {
        banded_maps: true,
        ..vehicle.spec.fit.clone()
    };
    Ok(vehicle
        .fit_with(&vehicle.spec.heights_of_interest_m, &options)?
        .model)
}

/// The levels a scenario's vehicle asks for under `config`: its heights of interest (or the
/// configuration's), cumulative, under its ceiling (`aircraft::Vehicle::ceiling_m`: its top plus
/// its overhead clearance).
pub fn levels_of(scenario: &Scenario, config: &RunConfig) -> Result<Levels> {
    levels_of_vehicle(&scenario.vehicle.vehicle, config)
}

/// [`levels_of`] for a vehicle without a scenario (a map from a bag or a capture).
pub fn levels_of_vehicle(vehicle: &aircraft::Vehicle, config: &RunConfig) -> Result<Levels> {
    Ok(Levels::new(
        config.heights_of_interest_m(vehicle).to_vec(),
        mapper::LevelMode::Cumulative,
        Some(vehicle.ceiling_m()),
    )?)
}

/// The LiDAR seed of a surveyed map's drive (`[airport] surveyed_stands`): one survey, whatever
/// the seed of the run that uses it.
pub const SURVEY_SEED: u64 = 1;

/// The speed of a surveyed map's drive, m/s (a revolution every 0.5 m): one survey, whatever the
/// run's speed.
pub const SURVEY_SPEED_M_S: f64 = 5.0;

/// The seed and speed of a scenario's mapping drive: the survey's when its map is surveyed apart
/// from the run ([`Scenario::survey_scene`]), else the run's own.
pub fn drive_seed_and_speed(scenario: &Scenario) -> (u64, f64) {
    if scenario.survey.is_some() {
        (SURVEY_SEED, SURVEY_SPEED_M_S)
    } else {
        (scenario.seed, scenario.route.speed_m_s)
    }
}
