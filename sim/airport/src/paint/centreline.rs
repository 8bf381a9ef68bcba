//! The painted centrelines as the routes follow them: their runs of points and segments, which
//! runs meet end to end, and walks along the paint that go on from one run to the next.

use super::{FOLLOW_DEG, V2, centrelines};
use crate::model::Airport;

/// Paint ends within this of each other are one line going on (m).
const JOIN_M: f64 = 0.5;
/// Most points one walk along the paint visits (a loop of joined runs ends there).
const MAX_WALK: usize = 4096;

/// The centrelines, their segments, and which run ends meet.
pub(super) struct Paint {
    pub(super) runs: Vec<Vec<V2>>,
    /// `(run, i)`: the segment from `runs[run][i]` to `runs[run][i + 1]`.
    pub(super) segments: Vec<(usize, usize)>,
    /// The index of each run's first segment.
    offsets: Vec<usize>,
    /// For each run, at its start and its end: the runs starting (`true`) or ending there.
    joins: Vec<[Vec<(usize, bool)>; 2]>,
}

/// A place on the paint: a point of a run, and which way along it a walk goes.
#[derive(Debug, Clone, Copy)]
pub(super) struct Cursor {
    pub(super) run: usize,
    pub(super) k: usize,
    pub(super) up: bool,
}

impl Paint {
    pub(super) fn of(airport: &Airport) -> Self {
        let runs = centrelines(airport);
        let mut offsets = Vec::with_capacity(runs.len());
        let mut segments = Vec::new();
        for (r, run) in runs.iter().enumerate() {
            offsets.push(segments.len());
            segments.extend((0..run.len() - 1).map(|i| (r, i)));
        }
        let end = |r: usize, start: bool| {
            if start {
                runs[r][0]
            } else {
                runs[r][runs[r].len() - 1]
            }
        };
        let joins = (0..runs.len())
            .map(|r| {
                [true, false].map(|start| {
                    let here = end(r, start);
                    (0..runs.len())
                        .flat_map(|o| [(o, true), (o, false)])
                        .filter(|&(o, s)| {
                            (o, s) != (r, start) && (end(o, s) - here).norm() <= JOIN_M
                        })
                        .collect()
                })
            })
            .collect();
        Self {
            runs,
            segments,
            offsets,
            joins,
        }
    }

    pub(super) fn ends(&self, segment: usize) -> (V2, V2) {
        let (r, i) = self.segments[segment];
        (self.runs[r][i], self.runs[r][i + 1])
    }

    /// The step on from `c`: the cursor at the next point and the segment reaching it. Where a
    /// run ends, on along the run starting or ending there that heads nearest the same way
    /// (within [`FOLLOW_DEG`]).
    fn step(&self, c: Cursor) -> Option<(Cursor, usize)> {
        let run = &self.runs[c.run];
        // Down a run past its first point: `next` wraps past `run.len()`, on into the join.
        let next = if c.up { c.k + 1 } else { c.k.wrapping_sub(1) };
        if next < run.len() {
            let segment = self.offsets[c.run] + c.k.min(next);
            return Some((Cursor { k: next, ..c }, segment));
        }
        let back = if c.up { c.k.checked_sub(1)? } else { c.k + 1 };
        let heading = (run[c.k] - *run.get(back)?).try_normalize(1e-9)?;
        let at_end = usize::from(c.up);
        self.joins[c.run][at_end]
            .iter()
            .filter_map(|&(o, start)| {
                let other = &self.runs[o];
                let cursor = Cursor {
                    run: o,
                    k: if start { 0 } else { other.len() - 1 },
                    up: start,
                };
                let (on, segment) = self.step_within(cursor)?;
                let turn = (other[on.k] - other[cursor.k])
                    .try_normalize(1e-9)?
                    .dot(&heading);
                Some((on, segment, turn))
            })
            .filter(|x| x.2 >= FOLLOW_DEG.to_radians().cos())
            .max_by(|x, y| x.2.total_cmp(&y.2).then(y.1.cmp(&x.1)))
            .map(|(on, segment, _)| (on, segment))
    }

    /// [`Paint::step`] without leaving the run.
    fn step_within(&self, c: Cursor) -> Option<(Cursor, usize)> {
        let next = if c.up { c.k + 1 } else { c.k.checked_sub(1)? };
        (next < self.runs[c.run].len())
            .then(|| (Cursor { k: next, ..c }, self.offsets[c.run] + c.k.min(next)))
    }

    /// The points on from the far end of `segment`, going up its run or down: each point, the
    /// segment reaching it, and the cursor there.
    pub(super) fn walk(
        &self,
        segment: usize,
        up: bool,
    ) -> impl Iterator<Item = (V2, usize, Cursor)> + '_ {
        let (run, i) = self.segments[segment];
        let mut cursor = Some(Cursor {
            run,
            k: if up { i + 1 } else { i },
            up,
        });
        std::iter::from_fn(move || {
            let (next, segment) = self.step(cursor?)?;
            cursor = Some(next);
            Some((self.runs[next.run][next.k], segment, next))
        })
        .take(MAX_WALK)
    }
}
