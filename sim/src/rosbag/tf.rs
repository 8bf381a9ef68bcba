//! A transform tree read from a bag's `/tf` and `/tf_static` (tf2's rules, as a mapping node
//! sees them): every frame has one parent; a static transform holds at all times, a dynamic one
//! is interpolated between the two samples around the time asked (position linearly, rotation by
//! slerp) and held for at most [`TfBuffer::tolerance_ns`] beyond its first or last sample - tf2
//! would not extrapolate at all; a revolution stamped a little after the last pose is common.

use std::collections::HashMap;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use ros2::msgs::{Pose, Transform};

/// One frame's link to its parent.
#[derive(Debug, Clone)]
struct Link {
    parent: String,
    /// Static: holds at all times.
    fixed: Option<Isometry3<f64>>,
    /// Dynamic samples: stamp (ns), the frame's pose in its parent; sorted by [`TfBuffer::sort`].
    samples: Vec<(u64, Isometry3<f64>)>,
}

/// The transforms of a bag.
#[derive(Debug, Clone, Default)]
pub struct TfBuffer {
    links: HashMap<String, Link>,
    sorted: bool,
}

/// A pose as an isometry.
#[must_use]
pub fn isometry(p: &Pose) -> Isometry3<f64> {
    let [x, y, z, w] = p.orientation;
    Isometry3::from_parts(
        Translation3::new(p.position[0], p.position[1], p.position[2]),
        UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
    )
}

/// Interpolates between two poses, `f` in 0..1.
#[must_use]
pub fn interpolate(a: &Isometry3<f64>, b: &Isometry3<f64>, f: f64) -> Isometry3<f64> {
    let t = a.translation.vector.lerp(&b.translation.vector, f);
    let r = a
        .rotation
        .try_slerp(&b.rotation, f, 1e-9)
        .unwrap_or(if f < 0.5 { a.rotation } else { b.rotation });
    Isometry3::from_parts(Translation3::from(t), r)
}

/// The sample of a sorted series at `t_ns`: interpolated inside, held within `tolerance_ns`
/// outside; `Err((first, last))` beyond.
pub fn sample_at(
    samples: &[(u64, Isometry3<f64>)],
    t_ns: u64,
    tolerance_ns: u64,
) -> Result<Isometry3<f64>, (u64, u64)> {
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
        return Err((0, 0));
    };
    if t_ns <= first.0 {
        return if first.0 - t_ns <= tolerance_ns {
            Ok(first.1)
        } else {
            Err((first.0, last.0))
        };
    }
    if t_ns >= last.0 {
        return if t_ns - last.0 <= tolerance_ns {
            Ok(last.1)
        } else {
            Err((first.0, last.0))
        };
    }
    let after = samples.partition_point(|s| s.0 <= t_ns);
    let (a, b) = (&samples[after - 1], &samples[after]);
    if a.0 == t_ns {
        return Ok(a.1);
    }
    let f = (t_ns - a.0) as f64 / (b.0 - a.0) as f64;
    Ok(interpolate(&a.1, &b.1, f))
}

impl TfBuffer {
    /// How long a dynamic transform is held beyond its first or last sample: 0.1 s.
    pub const fn tolerance_ns() -> u64 {
        100_000_000
    }

    /// Adds a transform (static from `/tf_static`).
    ///
    /// # Errors
    /// The frame already has another parent (the tree would not be a tree).
    pub fn add(&mut self, t: &Transform, is_static: bool) -> Result<(), String> {
        let pose = isometry(&t.pose);
        let link = self.links.entry(t.child.clone()).or_insert_with(|| Link {
            parent: t.parent.clone(),
            fixed: None,
            samples: Vec::new(),
        });
        if link.parent != t.parent {
            return Err(format!(
                "frame `{}` has two parents, `{}` and `{}`",
                t.child, link.parent, t.parent
            ));
        }
        if is_static {
            link.fixed = Some(pose);
        } else {
            link.samples.push((t.stamp.ns(), pose));
            self.sorted = false;
        }
        Ok(())
    }

    /// Sorts the samples by stamp (once all are added).
    pub fn sort(&mut self) {
        for link in self.links.values_mut() {
            link.samples.sort_by_key(|s| s.0);
        }
        self.sorted = true;
    }

    /// Whether the frame is in the tree (as a child or a parent).
    #[must_use]
    pub fn knows(&self, frame: &str) -> bool {
        self.links.contains_key(frame) || self.links.values().any(|l| l.parent == frame)
    }

    /// Whether the tree has any transform.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.links.is_empty()
    }

    /// The frame's pose in its tree's root at `t_ns`, and the root's name.
    fn in_root(&self, frame: &str, t_ns: u64) -> Result<(String, Isometry3<f64>), String> {
        debug_assert!(self.sorted || self.links.values().all(|l| l.samples.len() < 2));
        let mut pose = Isometry3::identity();
        let mut at = frame.to_string();
        for _ in 0..64 {
            let Some(link) = self.links.get(&at) else {
                return Ok((at, pose));
            };
            let step = match (&link.fixed, link.samples.is_empty()) {
                (Some(fixed), true) => *fixed,
                _ => sample_at(&link.samples, t_ns, Self::tolerance_ns()).map_err(
                    |(first, last)| {
                        format!(
                            "`{}` -> `{at}` at {:.3} s is outside its transforms, {:.3} to {:.3} s",
                            link.parent,
                            t_ns as f64 * 1e-9,
                            first as f64 * 1e-9,
                            last as f64 * 1e-9
                        )
                    },
                )?,
            };
            pose = step * pose;
            at.clone_from(&link.parent);
        }
        Err(format!("the frames above `{frame}` form a loop"))
    }

    /// The pose of frame `source` in frame `target` at `t_ns`.
    ///
    /// # Errors
    /// The frames are in two trees, or a link has no transform near `t_ns`.
    pub fn lookup(&self, target: &str, source: &str, t_ns: u64) -> Result<Isometry3<f64>, String> {
        let (root_s, root_from_source) = self.in_root(source, t_ns)?;
        let (root_t, root_from_target) = self.in_root(target, t_ns)?;
        if root_s != root_t {
            return Err(format!(
                "no transform from `{target}` to `{source}`: `{source}` is under `{root_s}`, \
                 `{target}` under `{root_t}`"
            ));
        }
        Ok(root_from_target.inverse() * root_from_source)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ros2::msgs::Time;

    fn tf(parent: &str, child: &str, t_s: f64, x: f64, yaw: f64) -> Transform {
        Transform {
            stamp: Time::from_ns((t_s * 1e9) as u64),
            parent: parent.into(),
            child: child.into(),
            pose: Pose::planar(x, 0.0, 0.0, yaw),
        }
    }

    /// map -> odom (static) -> base_link (moving) -> velodyne (static): the chain composed,
    /// interpolated between samples, held 0.1 s beyond them and refused further.
    #[test]
    fn a_chain_is_composed_and_interpolated() {
        let mut b = TfBuffer::default();
        b.add(&tf("map", "odom", 0.0, 10.0, 0.0), true).unwrap();
        b.add(&tf("base_link", "velodyne", 0.0, 1.0, 0.0), true)
            .unwrap();
        b.add(&tf("odom", "base_link", 2.0, 4.0, 0.2), false)
            .unwrap();
        b.add(&tf("odom", "base_link", 1.0, 2.0, 0.0), false)
            .unwrap();
        b.sort();
        let at = |t: f64| b.lookup("map", "velodyne", (t * 1e9) as u64);
        let p = at(1.5).unwrap();
        let yaw = 0.1f64;
        assert!((p.translation.x - (10.0 + 3.0 + yaw.cos())).abs() < 1e-9);
        assert!((p.translation.y - yaw.sin()).abs() < 1e-9);
        assert!((p.rotation.euler_angles().2 - yaw).abs() < 1e-9);
        assert!(at(2.05).is_ok());
        let e = at(2.5).unwrap_err();
        assert!(e.contains("outside its transforms"), "{e}");
        let back = b.lookup("velodyne", "map", 1_500_000_000).unwrap();
        assert!((back * p).translation.vector.norm() < 1e-9);
        assert!(
            b.lookup("map", "elsewhere", 0)
                .unwrap_err()
                .contains("no transform")
        );
        assert!(b.add(&tf("earth", "odom", 0.0, 0.0, 0.0), true).is_err());
    }
}
