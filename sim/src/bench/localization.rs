//! `taxi-sim bench localization`: the particle filter's cost per revolution on a scenario's real
//! offline map and a real revolution from its start: the measurement update's weighing through
//! the per-window tables against the straightforward per-particle way (one thread each, in
//! alternation), the tables' parallel speed-up, the observation's extraction from the
//! revolution, and one whole update (extraction, diffusion, weighing, resampling).

use autonomy::LidarRevolution;
use autonomy::localizer::{
    LocalizerConfig, Observation, ParticleFilter, UpdateStats, weigh, weigh_parallel,
    weigh_straightforward,
};

use super::timing::{Figure, against, alternating, figure, median_seconds};
use crate::error::Result;

fn ms(name: &str, seconds: f64, target: Option<&'static str>) -> Figure {
    figure(name, seconds, "ms", target)
}

/// The figures on `scenario`'s offline map (built if missing), `samples` rounds each.
pub fn figures_for(
    scenario: &std::path::Path,
    samples: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Figure>> {
    let scenario = crate::scenario::Scenario::from_file(scenario)?;
    let run = crate::scenario::RunConfig::default();
    let dir = crate::offline_map::default_map_dir(&scenario, &run);
    crate::offline_map::ensure(
        &scenario,
        &run,
        &dir,
        &mut || progress("mapping drive"),
        &mut |_, _| {},
    )?;
    progress("a revolution from the start");
    let vehicle = &scenario.vehicle.vehicle;
    let start = scenario.vehicle.world_from_start;
    let world = crate::world::World::with_obstacles(&scenario.full_scene(), vehicle, &start);
    let lidar = crate::world::Lidar::new(run.lidar.clone(), vehicle.vehicle_from_lidar())
        .map_err(|e| crate::error::Error::Invalid(format!("lidar: {e}")))?;
    let scan = lidar
        .scan(&world, &crate::world::SweepPoses::still(start), 0, 1)
        .scan;
    let revolution = LidarRevolution {
        t_s: 0.0,
        scan,
        more_scans: Vec::new(),
        world_from_vehicle_estimate: start,
        estimate_covariance: nalgebra::Matrix3::zeros(),
    };
    let config = LocalizerConfig::default();
    let map_config = run.mapping.map;
    let map = mapper::MultiHeightMap::with_stores(
        map_config,
        crate::offline_map::levels_of(&scenario, &run)?,
        start.translation.vector.into(),
        Some(&dir.join("blocks")),
        None,
    )?;
    let mut pf = ParticleFilter::new(config.clone(), vehicle.spec.motion.wheelbase_m, map, 1);
    pf.initialise(&start)?;
    let self_filter = crate::offline_map::self_filter_model(vehicle)?;
    let margin = run.mapping.map.self_hit_margin_m;
    let obs = Observation::from_revolution(
        &revolution,
        &config,
        Some(&self_filter),
        margin,
        &run.mapping.map,
    );
    figures(
        &mut pf,
        &revolution,
        &obs,
        (&self_filter, margin),
        samples,
        progress,
    )
}

fn figures(
    pf: &mut ParticleFilter,
    revolution: &LidarRevolution,
    obs: &Observation,
    (self_filter, margin): (&mapper::CollisionModel, f64),
    samples: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Figure>> {
    let config = pf.config().clone();
    let n = pf.particles().len();
    let particles = pf.particles().to_vec();
    let lmap = pf
        .localization_map()
        .ok_or_else(|| crate::error::Error::Invalid("no localization map".into()))?
        .clone();
    let remission = pf.map().remission_grid();
    let field = autonomy::localizer::level0_distance(pf.map(), &config);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| crate::error::Error::Invalid(format!("thread pool: {e}")))?;
    progress("weighing: tables vs straightforward, one thread each");
    let (tables, straight) = one.install(|| {
        alternating(
            samples,
            5,
            || {
                std::hint::black_box(weigh(&particles, obs, &lmap, &config));
            },
            || {
                std::hint::black_box(weigh_straightforward(
                    &particles,
                    obs,
                    &remission,
                    field.as_ref(),
                    &config,
                ));
            },
        )
    });
    progress("weighing: all cores vs one");
    let (all, single) = alternating(
        samples,
        5,
        || {
            std::hint::black_box(weigh_parallel(&particles, obs, &lmap, &config));
        },
        || {
            one.install(|| std::hint::black_box(weigh(&particles, obs, &lmap, &config)));
        },
    );
    progress("observation and whole update");
    let extraction = median_seconds(samples, 5, || {
        std::hint::black_box(Observation::from_revolution(
            revolution,
            &config,
            Some(self_filter),
            margin,
            pf.map().config(),
        ));
    });
    let update = median_seconds(samples, 5, || {
        let o = Observation::from_revolution(
            revolution,
            &config,
            Some(self_filter),
            margin,
            pf.map().config(),
        );
        let mut stats = UpdateStats::default();
        pf.measurement_update(&o, &mut stats);
    });
    let straight = ms(
        &format!("weigh {n} particles, straightforward (1 thread)"),
        straight,
        None,
    );
    let tables = against(
        ms(
            &format!("weigh {n} particles, tables (1 thread)"),
            tables,
            None,
        ),
        &straight,
    );
    let single = ms(
        &format!("weigh {n} particles, tables (1 thread)"),
        single,
        None,
    );
    let all = against(
        ms(
            &format!("weigh {n} particles, tables in parallel"),
            all,
            None,
        ),
        &single,
    );
    Ok(vec![
        straight,
        tables,
        all,
        ms(
            &format!(
                "observation from a revolution ({} + {} returns)",
                obs.ground.len(),
                obs.obstacles.len()
            ),
            extraction,
            None,
        ),
        ms(
            &format!("one revolution's filter update ({n} particles)"),
            update,
            Some("<= 2 ms"),
        ),
    ])
}
