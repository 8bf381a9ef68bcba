//! The drive every representation is fed: the scenario's route inside a fixed window, one
//! revolution every 0.1 s at the route's speed (as the mapping drive casts them), the vehicle's
//! own returns removed once, and each revolution inserted into every representation in turn,
//! each insertion timed on one thread.

use std::time::Instant;

use autonomy::RoutePath;
use mapper::elevation::ElevationMap;
use mapper::voxel::VoxelGrid;
use mapper::{CollisionModel, Levels, MultiHeightMap, Scan};
use nalgebra::{Isometry2, Point2, Point3};

use crate::error::{Error, Result};
use crate::scenario::{RunConfig, Scenario};
use crate::world::{Lidar, SweepPoses, World};

/// Where along the route the window and the drive are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stretch {
    /// Arc length of the window's centre along the route, metres (`None`: the route's middle).
    pub at_m: Option<f64>,
    /// Length of route driven, centred on `at_m`, metres (clipped to the route and the window).
    pub length_m: f64,
    /// Distance between revolutions, metres (`None`: one every 0.1 s at the route's speed, as the
    /// mapping drive).
    pub spacing_m: Option<f64>,
}

/// Every representation under comparison, fed the same revolutions.
pub struct Representations {
    /// The thesis' map: one grid per height of interest, each holding everything above it.
    pub cumulative: MultiHeightMap,
    /// The same levels as bands: each grid holds its band only.
    pub banded: MultiHeightMap,
    /// A dense 3D grid of the same resolution up to the vehicle's ceiling.
    pub voxels: VoxelGrid,
    /// Per cell the lowest and highest obstacle height seen.
    pub elevation: ElevationMap,
    /// A diagnostic: the dense 3D grid with free space all but uncounted (`l_free` -1e-6), which
    /// tells misses from what was never seen apart from misses from what beams carved away.
    pub voxels_hits_only: Option<VoxelGrid>,
}

/// Seconds each representation spent, summed over the drive, and per revolution.
#[derive(Clone, Debug, Default)]
pub struct InsertTimes {
    /// Per revolution: cumulative, banded, voxels, elevation (seconds).
    pub per_revolution: Vec<[f64; 4]>,
    /// Per revolution: the distance maps brought up to date, cumulative and banded (seconds).
    pub distance_update: Vec<[f64; 2]>,
}

/// One revolution as OctoMap is given it: the sensor's origin and every return.
pub struct Cloud {
    /// The sensor's origin, world frame.
    pub origin: Point3<f64>,
    /// Every return kept (the vehicle's own removed), world frame.
    pub points: Vec<[f32; 3]>,
}

/// The floor of the 3D representations: returns below it are the ground (the mapper's safe
/// height, as the simulator sets it).
pub const FLOOR_M: f64 = 0.05;

impl Representations {
    /// Empty representations over the map window centred on `centre`.
    pub fn new(
        scenario: &Scenario,
        config: &RunConfig,
        centre: Point2<f64>,
        carving_diagnostic: bool,
    ) -> Result<Self> {
        let levels = crate::offline_map::levels_of(scenario, config)?;
        let banded = Levels::new(
            levels.heights_m().to_vec(),
            mapper::LevelMode::Banded,
            levels.ceiling_m(),
        )?;
        let map_config = config.mapping.map;
        let cumulative = MultiHeightMap::new(map_config, levels, centre)?;
        let banded = MultiHeightMap::new(map_config, banded, centre)?;
        let geometry = *cumulative.geometry();
        let top = scenario.vehicle.vehicle.ceiling_m();
        let hits_only = mapper::OccupancyParams {
            l_free: -1e-6,
            ..map_config.occupancy
        };
        Ok(Representations {
            voxels_hits_only: carving_diagnostic
                .then(|| VoxelGrid::new(geometry, FLOOR_M, top, hits_only))
                .transpose()?,
            voxels: VoxelGrid::new(geometry, FLOOR_M, top, map_config.occupancy)?,
            elevation: ElevationMap::new(geometry, FLOOR_M, top)?,
            cumulative,
            banded,
        })
    }

    /// Inserts one revolution into each, in turn, timing each (and the 2D maps' distance
    /// updates, as the loop brings them up to date every revolution).
    pub fn insert(&mut self, scan: &Scan, times: &mut InsertTimes) -> Result<()> {
        let mut t = [0.0; 4];
        let start = Instant::now();
        self.cumulative.insert_scan(scan, None)?;
        t[0] = start.elapsed().as_secs_f64();
        let start = Instant::now();
        self.banded.insert_scan(scan, None)?;
        t[1] = start.elapsed().as_secs_f64();
        let start = Instant::now();
        self.voxels.insert_scan(scan);
        t[2] = start.elapsed().as_secs_f64();
        let start = Instant::now();
        self.elevation.insert_scan(scan);
        t[3] = start.elapsed().as_secs_f64();
        if let Some(v) = &mut self.voxels_hits_only {
            v.insert_scan(scan);
        }
        times.per_revolution.push(t);
        let start = Instant::now();
        self.cumulative.update_distance_maps();
        let c = start.elapsed().as_secs_f64();
        let start = Instant::now();
        self.banded.update_distance_maps();
        times
            .distance_update
            .push([c, start.elapsed().as_secs_f64()]);
        Ok(())
    }
}

/// The vehicle poses of the drive: along `route` every `spacing_m`, over the stretch, inside the
/// window (`lo`, `hi`) less `margin_m`.
pub fn drive_poses(
    route: &RoutePath,
    stretch: &Stretch,
    spacing_m: f64,
    (lo, hi, margin_m): (Point2<f64>, Point2<f64>, f64),
) -> Vec<Isometry2<f64>> {
    let at = stretch.at_m.unwrap_or(0.5 * route.length_m());
    let (s0, s1) = (
        (at - 0.5 * stretch.length_m).max(0.0),
        (at + 0.5 * stretch.length_m).min(route.length_m()),
    );
    let n = ((s1 - s0) / spacing_m).floor() as usize;
    (0..=n)
        .map(|k| {
            let (p, heading) = route.at(s0 + k as f64 * spacing_m);
            Isometry2::new(p.coords, heading)
        })
        .filter(|pose| {
            let p = pose.translation.vector;
            p.x > lo.x + margin_m
                && p.y > lo.y + margin_m
                && p.x < hi.x - margin_m
                && p.y < hi.y - margin_m
        })
        .collect()
}

impl Cloud {
    /// Every return of `scan`, from its first column's sensor origin (a still sweep: every
    /// column's).
    pub fn of(scan: &Scan) -> Result<Cloud> {
        let origin = scan
            .columns()
            .first()
            .map(|c| Point3::from(c.world_from_sensor.translation.vector))
            .ok_or_else(|| Error::Invalid("a revolution with no column".into()))?;
        let points = scan
            .returns()
            .iter()
            .flatten()
            .map(|r| {
                let p = r.point_in_world;
                [p.x as f32, p.y as f32, p.z as f32]
            })
            .collect();
        Ok(Cloud { origin, points })
    }
}

/// `scan` without the returns on the vehicle itself (its circles, with the map's margin).
pub fn without_self_hits(scan: &Scan, vehicle: &CollisionModel, margin_m: f64) -> Result<Scan> {
    let beams = scan.beams();
    let mut returns = scan.returns().to_vec();
    for (c, col) in scan.columns().iter().enumerate() {
        let from_world = col.world_from_vehicle.inverse();
        for r in &mut returns[c * beams..(c + 1) * beams] {
            if let Some(ret) = r {
                let p = ret.point_in_world;
                if vehicle.is_self_hit(&(from_world * Point2::new(p.x, p.y)), p.z, margin_m) {
                    *r = None;
                }
            }
        }
    }
    Ok(Scan::new(beams, scan.columns().to_vec(), returns)?)
}

/// Casts the revolution at `pose` (index `k`) in `world`.
pub fn cast(lidar: &Lidar, world: &mut World, pose: &Isometry2<f64>, k: usize, seed: u64) -> Scan {
    world.set_vehicle_pose(pose, k as f64 * 0.1);
    lidar
        .scan(world, &SweepPoses::still(*pose), k as u64, seed)
        .scan
}
