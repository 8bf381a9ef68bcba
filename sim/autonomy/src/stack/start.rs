//! The start-up rule: the vehicle does not move off while part of the ground its circles will
//! sweep lies where its sensors cannot see from where it stands (its [`BlindZone`]), until the
//! crew's walk-around has confirmed that ground ([`Driver::on_walk_around`]).
//!
//! "Unseen is not gone" protects what the sensor once saw; this protects what it never saw. At
//! the start nothing has been seen but what the first revolutions reach, so the ground a level's
//! circles sweep along the first plan that lies in that level's blind zone (the ground where an
//! object of the level's height gets no return: `taxi-sim model coverage`) is ground the stack
//! would drive over blind. The zone is the stack's knowledge of its own sensor layout, given once
//! (as a real stack is given its sensors' calibration), never the world's truth.

use mapper::CollisionModel;
use nalgebra::{Isometry2, Point2};

use super::{Driver, DriverStatus};

/// The ground round the vehicle that its sensors cannot see, per height level, on a grid in the
/// vehicle frame (the vehicle standing still).
#[derive(Clone, Debug, PartialEq)]
pub struct BlindZone {
    /// Lower corner (x, y) of the grid in the vehicle frame, metres.
    pub min_m: [f64; 2],
    /// Cell side, metres.
    pub cell_m: f64,
    /// Cells along x and along y.
    pub cells: [usize; 2],
    /// Per level (the collision model's), per cell (row-major from `min_m`, x fastest): blind.
    pub levels: Vec<Vec<bool>>,
}

impl BlindZone {
    /// The blind ground (any level) that `model`'s circles sweep along `poses` (world from
    /// vehicle) when the vehicle stands at `here` (world from vehicle), square metres: each
    /// level's circles against that level's blind cells (a cell counts once however many poses
    /// and levels reach it). A level the zone does not list has no blind ground.
    pub fn unseen_swept_m2(
        &self,
        model: &CollisionModel,
        here: &Isometry2<f64>,
        poses: &[Isometry2<f64>],
    ) -> f64 {
        let cells = self.unseen_swept_cells(model, here, poses);
        cells.len() as f64 * self.cell_m * self.cell_m
    }

    /// The cells of [`Self::unseen_swept_m2`]: their centres in the world, each `cell_m` square.
    pub fn unseen_swept_cells(
        &self,
        model: &CollisionModel,
        here: &Isometry2<f64>,
        poses: &[Isometry2<f64>],
    ) -> Vec<Point2<f64>> {
        let [nx, ny] = self.cells;
        let mut unseen = vec![false; nx * ny];
        let from_world = here.inverse();
        for pose in poses {
            for c in model.circles() {
                let Some(blind) = self.levels.get(c.level) else {
                    continue;
                };
                let centre = from_world * (pose * Point2::new(c.x_m, c.y_m));
                let r = c.radius_m;
                let index = |v: f64, lo: f64, n: usize| {
                    ((v - lo) / self.cell_m).floor().clamp(0.0, n as f64) as usize
                };
                let (i0, i1) = (
                    index(centre.x - r, self.min_m[0], nx),
                    index(centre.x + r, self.min_m[0], nx.saturating_sub(1)) + 1,
                );
                let (j0, j1) = (
                    index(centre.y - r, self.min_m[1], ny),
                    index(centre.y + r, self.min_m[1], ny.saturating_sub(1)) + 1,
                );
                for j in j0..j1.min(ny) {
                    let y = self.min_m[1] + (j as f64 + 0.5) * self.cell_m;
                    for i in i0..i1.min(nx) {
                        let x = self.min_m[0] + (i as f64 + 0.5) * self.cell_m;
                        let k = j * nx + i;
                        if blind[k] && (x - centre.x).hypot(y - centre.y) <= r {
                            unseen[k] = true;
                        }
                    }
                }
            }
        }
        let centre = |k: usize| {
            let (i, j) = (k % nx, k / nx);
            here * Point2::new(
                self.min_m[0] + (i as f64 + 0.5) * self.cell_m,
                self.min_m[1] + (j as f64 + 0.5) * self.cell_m,
            )
        };
        (0..unseen.len())
            .filter(|&k| unseen[k])
            .map(centre)
            .collect()
    }
}

/// Where the start-up rule stands.
#[derive(Clone, Debug, Default)]
pub(super) enum StartRule {
    /// No rule: the ground round the vehicle was confirmed before the start (or no zone given).
    #[default]
    Done,
    /// The vehicle has not moved off yet and no walk-around has confirmed the ground: each plan
    /// checks its first stretch against the zone.
    Awaiting(BlindZone),
}

impl Driver {
    /// The vehicle's blind zone: until [`Self::on_walk_around`], the driver does not move off
    /// while the ground its first plan sweeps lies partly in it (`WaitingForWalkAround`, and a
    /// pilot call after `pilot_call_after_s`). Without it (the default) the ground round the
    /// vehicle counts as confirmed before the start.
    pub fn await_walk_around(&mut self, zone: BlindZone) {
        self.start = StartRule::Awaiting(zone);
    }

    /// The crew's walk-around has confirmed the ground round the vehicle: it may move off.
    pub fn on_walk_around(&mut self) {
        self.start = StartRule::Done;
        if matches!(self.status, DriverStatus::WaitingForWalkAround { .. }) {
            self.status = DriverStatus::Driving;
        }
    }

    /// The unseen ground the first plan (`poses`, from the estimate `here`) would sweep, while
    /// the rule awaits a walk-around: the status to wait with, or `None` to go (the rule is then
    /// done: everything the vehicle will sweep first is in sight, and once it moves it sees on).
    pub(super) fn walk_around_status(
        &mut self,
        here: &Isometry2<f64>,
        poses: &[Isometry2<f64>],
        now_s: f64,
    ) -> Option<DriverStatus> {
        let StartRule::Awaiting(zone) = &self.start else {
            return None;
        };
        let cells = zone.unseen_swept_cells(&self.vehicle.collision, here, poses);
        let unseen_m2 = cells.len() as f64 * zone.cell_m * zone.cell_m;
        if self.start_unseen_m2.is_none() {
            self.start_unseen_m2 = Some(unseen_m2);
            self.start_unseen_cells = Some((cells, zone.cell_m));
        }
        if unseen_m2 <= 0.0 {
            self.start = StartRule::Done;
            return None;
        }
        let since_s = match self.status {
            DriverStatus::WaitingForWalkAround { since_s, .. } => since_s,
            _ => now_s,
        };
        Some(DriverStatus::WaitingForWalkAround { unseen_m2, since_s })
    }

    /// The unseen ground the first plan checked by the start-up rule would have swept, square
    /// metres (`None`: no rule, or no plan yet).
    pub fn start_unseen_m2(&self) -> Option<f64> {
        self.start_unseen_m2
    }

    /// The cells of [`Self::start_unseen_m2`] (their centres in the world) and their side,
    /// metres: the ground the first plan would have swept blind.
    pub fn start_unseen_cells(&self) -> Option<(&[Point2<f64>], f64)> {
        self.start_unseen_cells
            .as_ref()
            .map(|(c, side)| (c.as_slice(), *side))
    }
}
