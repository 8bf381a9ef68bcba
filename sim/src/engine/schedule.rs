//! The schedule of a revolution: when it is mapped and planned from. Sequential: mapped and
//! planned the instant it is taken. Overlapped (as on the vehicle): mapped by a rayon task while
//! the next physics steps run; the next revolution is taken while the plan is made from it.

use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::Instant;

use autonomy::{Driver, OnlineMap, PlanTimes};

use crate::error::{Error, Result};
use crate::scenario::Schedule;
use crate::world::Captured;

/// A plan made from a mapped revolution.
pub struct Planned {
    /// The revolution planned from.
    pub captured: Captured,
    /// Wall time of its mapping, seconds.
    pub mapping_s: f64,
    /// Wall time of the distance maps and the plan, seconds.
    pub times: PlanTimes,
}

/// A revolution mapped by a task: the map back, the revolution, the wall time it took.
type Mapped = Result<(Box<OnlineMap>, Captured, f64)>;

/// Where the online map is.
enum Slot {
    /// Here, up to date with every revolution taken (sequential) or but the last (overlapped).
    Ready(Box<OnlineMap>),
    /// With a task mapping a revolution.
    InFlight(Receiver<Mapped>),
    /// Between the two, inside a call (never seen outside one).
    Moving,
}

/// Owns the online map and runs a revolution's stages in the configured order.
pub struct Scheduler {
    schedule: Schedule,
    slot: Slot,
    /// Overlapped: the revolution taken at the last call, to be mapped.
    taken: Option<Captured>,
}

impl Scheduler {
    /// A scheduler of `map`.
    pub fn new(schedule: Schedule, map: OnlineMap) -> Self {
        Scheduler {
            schedule,
            slot: Slot::Ready(Box::new(map)),
            taken: None,
        }
    }

    /// Takes a revolution (`capture`) and plans: sequential, from it; overlapped, from the last
    /// one (mapped meanwhile), while `capture` runs beside. Returns the wall time of the casts
    /// and the plan: `None` until a revolution has been mapped (the vehicle waits).
    pub fn revolution(
        &mut self,
        capture: impl FnOnce() -> Result<Captured> + Send,
        driver: &mut Driver,
    ) -> Result<(f64, Option<Planned>)> {
        match self.schedule {
            Schedule::Sequential => {
                let Slot::Ready(map) = &mut self.slot else {
                    return Err(Error::Invalid("the online map is not ready".into()));
                };
                let captured = capture()?;
                let lidar_s = captured.lidar_s;
                let mapping_s = map_one(map, &captured)?;
                let times = driver.plan(map)?;
                let planned = Planned {
                    captured,
                    mapping_s,
                    times,
                };
                Ok((lidar_s, Some(planned)))
            }
            Schedule::Overlapped => {
                // The last revolution's mapping is awaited here, on the loop's thread, before
                // the join - not inside it. A closure of a join can be stolen by a worker that
                // is itself inside the mapping task, waiting in one of the mapping's own joins:
                // that worker would then wait for the mapping below it on its own stack, for
                // ever (it hung with 3 or more threads).
                let (mut map, last) = match std::mem::replace(&mut self.slot, Slot::Moving) {
                    Slot::Ready(map) => (map, None),
                    Slot::InFlight(rx) => {
                        let (map, captured, mapping_s) = wait_for(&rx)?;
                        (map, Some((captured, mapping_s)))
                    }
                    Slot::Moving => {
                        return Err(Error::Invalid("the online map was lost".into()));
                    }
                };
                // The next revolution is cast beside the plan from the last one.
                let (fresh, planned) = rayon::join(capture, || {
                    last.map(|(captured, mapping_s)| {
                        driver.plan(&mut map).map(|times| Planned {
                            captured,
                            mapping_s,
                            times,
                        })
                    })
                    .transpose()
                });
                self.slot = Slot::Ready(map);
                let planned = planned?;
                let fresh = fresh?;
                let lidar_s = fresh.lidar_s;
                self.taken = Some(fresh);
                Ok((lidar_s, planned))
            }
        }
    }

    /// The online map, when no task holds it (between [`Scheduler::revolution`] and
    /// [`Scheduler::dispatch`]).
    pub fn map(&self) -> Option<&OnlineMap> {
        match &self.slot {
            Slot::Ready(map) => Some(map),
            _ => None,
        }
    }

    /// Overlapped: starts mapping the revolution just taken, as a task of `tasks` that runs
    /// beside the physics steps (nothing before the next plan needs it). Sequential: nothing.
    pub fn dispatch<'s>(&mut self, tasks: &rayon::Scope<'s>) {
        let Some(captured) = self.taken.take() else {
            return;
        };
        let Slot::Ready(mut map) = std::mem::replace(&mut self.slot, Slot::Moving) else {
            return;
        };
        let (tx, rx) = channel();
        tasks.spawn(move |_| {
            let mapped = map_one(&mut map, &captured).map(|s| (map, captured, s));
            // The receiver is gone only if the loop has ended: nothing waits for this.
            let _ = tx.send(mapped);
        });
        self.slot = Slot::InFlight(rx);
    }
}

/// Maps one revolution; returns the wall time it took.
fn map_one(map: &mut OnlineMap, captured: &Captured) -> Result<f64> {
    let t = Instant::now();
    map.update(&captured.revolution)?;
    Ok(t.elapsed().as_secs_f64())
}

/// Waits for a mapping task's answer, running other pending rayon work meanwhile (the task's
/// own parallel pieces, typically) instead of blocking a worker. Only the loop's own thread
/// waits here, outside any job another worker could steal.
fn wait_for(rx: &Receiver<Mapped>) -> Mapped {
    loop {
        match rx.try_recv() {
            Ok(answer) => return answer,
            Err(TryRecvError::Empty) => {
                if rayon::yield_now() != Some(rayon::Yield::Executed) {
                    std::thread::yield_now();
                }
            }
            Err(TryRecvError::Disconnected) => {
                return Err(Error::Invalid(
                    "the mapping task ended without an answer".into(),
                ));
            }
        }
    }
}
