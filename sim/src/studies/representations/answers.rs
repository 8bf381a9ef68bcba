//! Each representation's collision answer at a pose, timed, and its wrong answers against the
//! exact one, split by what was near.

use std::collections::BTreeMap;
use std::time::Instant;

use mapper::{CollisionModel, DistanceMaps};
use nalgebra::Isometry2;
use serde::{Deserialize, Serialize};

use super::spans::{SpanCircle, placed};
use super::truth::{Near, TruthPose};
use crate::error::Result;

/// Wrong answers of one representation on one kind of neighbour.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// Poses judged.
    pub poses: usize,
    /// Poses where the vehicle truly touches something.
    pub colliding: usize,
    /// Said colliding where nothing touches.
    pub false_alarms: usize,
    /// Said clear where something touches.
    pub misses: usize,
}

impl Errors {
    /// Adds one pose: (the exact answer, the representation's).
    pub fn add(&mut self, (truth, said): (bool, bool)) {
        self.poses += 1;
        self.colliding += usize::from(truth);
        self.false_alarms += usize::from(said && !truth);
        self.misses += usize::from(truth && !said);
    }

    /// Wrong answers over poses, percent.
    pub fn wrong_percent(&self) -> f64 {
        100.0 * (self.false_alarms + self.misses) as f64 / self.poses.max(1) as f64
    }
}

/// A representation's answers over the poses: per kind of neighbour and in all, the time of one
/// pose check, and the answers themselves (for comparing representations pose by pose).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Judged {
    /// In all.
    pub all: Errors,
    /// Per kind of neighbour.
    pub by_near: BTreeMap<Near, Errors>,
    /// Mean time of one pose check, ns (one thread).
    pub pose_check_ns: f64,
    /// The answer at each pose, in pose order.
    #[serde(skip, default)]
    pub answers: Vec<bool>,
}

/// Judges `check` over `poses`: the answers against the truth, then the checks timed over
/// repeated passes (at least 20 ms; `pose_check_ns` NaN without poses).
pub fn judge(poses: &[TruthPose], mut check: impl FnMut(&Isometry2<f64>) -> bool) -> Judged {
    let mut out = judge_untimed(poses, &mut check);
    if poses.is_empty() {
        return out;
    }
    let (mut reps, mut sink) = (0u64, 0usize);
    let t = Instant::now();
    while reps == 0 || t.elapsed().as_millis() < 20 {
        for p in poses {
            sink += usize::from(check(std::hint::black_box(&p.pose)));
        }
        reps += 1;
    }
    std::hint::black_box(sink);
    out.pose_check_ns = t.elapsed().as_nanos() as f64 / (reps as f64 * poses.len() as f64);
    out
}

/// [`judge`] without the timing (`pose_check_ns` NaN): for answers timed elsewhere.
pub fn judge_untimed(
    poses: &[TruthPose],
    mut check: impl FnMut(&Isometry2<f64>) -> bool,
) -> Judged {
    let mut out = Judged {
        pose_check_ns: f64::NAN,
        ..Judged::default()
    };
    for p in poses {
        let said = check(&p.pose);
        out.answers.push(said);
        out.all.add((p.colliding, said));
        out.by_near
            .entry(p.near)
            .or_default()
            .add((p.colliding, said));
    }
    out
}

/// The thesis' check: each circle against its level's distance map (the loop's `check_pose`).
pub fn cumulative<'a>(
    model: &'a CollisionModel,
    maps: &'a DistanceMaps,
) -> Result<impl Fn(&Isometry2<f64>) -> bool + 'a> {
    let checker = model.checker(maps)?;
    Ok(move |pose: &Isometry2<f64>| checker.check_pose(pose, 0.0).colliding)
}

/// Banded maps: each circle against its own band and every band above it that starts below the
/// top of the parts it covers (a band wholly above a part cannot touch it).
pub fn banded<'a>(
    circles: &'a [SpanCircle],
    maps: &'a DistanceMaps,
    heights_m: &'a [f64],
) -> impl Fn(&Isometry2<f64>) -> bool + 'a {
    move |pose: &Isometry2<f64>| {
        circles.iter().any(|c| {
            let (centre, r, _, hi) = placed(c, pose);
            (c.level..heights_m.len())
                .take_while(|&j| heights_m[j] < hi)
                .any(|j| maps.levels()[j].distance_at(&centre) < r as f32)
        })
    }
}

/// A representation that answers per circle with its height span.
pub fn spans<'a>(
    circles: &'a [SpanCircle],
    collides: impl Fn(nalgebra::Point2<f64>, f64, f64, f64) -> bool + 'a,
) -> impl Fn(&Isometry2<f64>) -> bool + 'a {
    move |pose: &Isometry2<f64>| {
        circles.iter().any(|c| {
            let (centre, r, lo, hi) = placed(c, pose);
            collides(centre, r, lo, hi)
        })
    }
}
