//! The capture of a revolution: cast from the true pose, degraded by the faults, its points
//! re-expressed where a mapper at the pose estimate would put them ([`Sensor::capture`]), and the
//! result with what only the simulator knows of it ([`Captured`]).

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use autonomy::{LidarRevolution, PoseEstimate};
use nalgebra::Isometry2;

use super::faults::{FaultCounts, FaultsConfig, degrade};
use super::lidar::{Lidar, SweepPoses};
use super::physics::{Owner, World, planar_to_3d};
use crate::error::Result;

/// A revolution as taken: the stack's message and what only the simulator knows of it.
pub struct Captured {
    /// What the stack receives.
    pub revolution: LidarRevolution,
    /// What each return hit (ground truth, for pictures).
    pub owners: Vec<Option<Owner>>,
    /// The same for each of the other LiDARs' scans (`revolution.more_scans`).
    pub more_owners: Vec<Vec<Option<Owner>>>,
    /// The true pose it was taken at.
    pub truth: Isometry2<f64>,
    /// Wall time of the casts, seconds.
    pub lidar_s: f64,
}

/// One of a vehicle's other LiDARs (the sidecar's `extra_lidars`): its name (its frame) and
/// the sensor.
pub struct NamedLidar {
    /// Its frame and topic name.
    pub name: String,
    /// The sensor (its mount, beams and noise).
    pub lidar: Lidar,
}

/// A scan's points moved from the true pose to the estimated one: where a mapper with a wrong
/// pose would put them.
fn reexpress(
    scan: mapper::Scan,
    truth: &Isometry2<f64>,
    estimate: &Isometry2<f64>,
) -> Result<mapper::Scan> {
    let lift = planar_to_3d;
    let correction = lift(estimate) * lift(truth).inverse();
    Ok(scan.moved(&correction, estimate)?)
}

/// What a revolution is cast with: the world, the LiDAR, and the faults between them.
pub struct Sensor<'r> {
    /// The world cast into.
    pub world: &'r World,
    /// The LiDAR (its mount, beams and noise).
    pub lidar: &'r Lidar,
    /// The vehicle's other LiDARs, cast in the same world at the same time.
    pub more: &'r [NamedLidar],
    /// The faults between the sensor and the stack.
    pub faults: &'r FaultsConfig,
    /// The run's seed (the casts' noise and the faults are drawn from it and the index).
    pub seed: u64,
    /// Returns the faults dropped, counted (the casts may run on another thread).
    pub dropped: &'r AtomicU64,
    /// Spurious returns the faults added, counted.
    pub spurious: &'r AtomicU64,
}

impl Sensor<'_> {
    /// Revolution `index`, taken at `t_s` from the true pose, degraded by the faults, its points
    /// where a mapper at `estimate` would put them.
    pub fn capture(
        &self,
        truth: &Isometry2<f64>,
        estimate: &PoseEstimate,
        index: u64,
        t_s: f64,
    ) -> Result<Captured> {
        let t0 = Instant::now();
        let (scan, owners) = self.take(self.lidar, self.seed, truth, estimate, index)?;
        let (mut more_scans, mut more_owners) = (Vec::new(), Vec::new());
        for (k, NamedLidar { lidar, .. }) in self.more.iter().enumerate() {
            // Each sensor its own noise and faults, reproducible from the run's seed.
            let seed = self.seed ^ (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let (scan, owners) = self.take(lidar, seed, truth, estimate, index)?;
            more_scans.push(scan);
            more_owners.push(owners);
        }
        let (covariance, estimate) = (estimate.covariance, &estimate.world_from_vehicle);
        Ok(Captured {
            revolution: LidarRevolution {
                t_s,
                scan,
                more_scans,
                world_from_vehicle_estimate: *estimate,
                estimate_covariance: covariance,
            },
            owners,
            more_owners,
            truth: *truth,
            lidar_s: t0.elapsed().as_secs_f64(),
        })
    }

    /// One sensor's scan of revolution `index`, degraded by the faults, where a mapper at
    /// `estimate` would put it; what each return hit.
    fn take(
        &self,
        lidar: &Lidar,
        seed: u64,
        truth: &Isometry2<f64>,
        estimate: &PoseEstimate,
        index: u64,
    ) -> Result<(mapper::Scan, Vec<Option<Owner>>)> {
        let mut taken = lidar.scan(self.world, &SweepPoses::still(*truth), index, seed);
        if self.faults.any() {
            let mut counts = FaultCounts::default();
            taken.scan = degrade(&taken.scan, self.faults, seed, index, &mut counts)?;
            taken.owners.truncate(0);
            self.dropped
                .fetch_add(counts.dropped_returns, Ordering::Relaxed);
            self.spurious
                .fetch_add(counts.spurious_returns, Ordering::Relaxed);
        }
        let estimate = &estimate.world_from_vehicle;
        let scan = if estimate == truth {
            taken.scan
        } else {
            reexpress(taken.scan, truth, estimate)?
        };
        Ok((scan, taken.owners))
    }
}
