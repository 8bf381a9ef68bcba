//! URDF at the crate's edge: reads a description with urdf-rs and places every `<collision>`
//! primitive in the vehicle frame by composing the joint origins from the root link.
//!
//! Conventions (URDF): box `size` is the full extent; cylinders and capsules run along their z;
//! `rpy` is roll, pitch, yaw about the fixed X, Y, Z axes, i.e. `R = Rz(yaw) Ry(pitch) Rx(roll)`
//! (nalgebra's `from_euler_angles(roll, pitch, yaw)`). A joint's origin is the child frame in the
//! parent frame at joint position zero; movable joints are taken at zero.

use std::collections::{BTreeMap, VecDeque};
use std::path::Path;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::error::{Error, Result};
use crate::shapes::{Part, Shape};

/// Reads a URDF file into vehicle-frame parts (a thin wrapper over [`parts_from_str`]).
pub fn parts_from_file(path: &Path) -> Result<Vec<Part>> {
    let text = std::fs::read_to_string(path).map_err(|error| Error::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parts_from_str(&text, &path.display().to_string())
}

/// Parses URDF text into vehicle-frame parts; `file` names the source in errors.
pub fn parts_from_str(urdf: &str, file: &str) -> Result<Vec<Part>> {
    let robot = urdf_rs::read_from_string(urdf).map_err(|e| Error::Urdf {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    parts_from_robot(&robot, file)
}

fn check_finite(file: &str, link: &str, what: String, values: &[f64]) -> Result<()> {
    for (i, v) in values.iter().enumerate() {
        if !v.is_finite() {
            return Err(Error::BadNumber {
                file: file.to_string(),
                link: link.to_string(),
                what: format!("{what}[{i}]"),
                value: *v,
                must_be_positive: false,
            });
        }
    }
    Ok(())
}

fn check_positive(file: &str, link: &str, what: String, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::BadNumber {
            file: file.to_string(),
            link: link.to_string(),
            what,
            value,
            must_be_positive: true,
        })
    }
}

fn isometry(pose: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = pose.xyz.0;
    let [roll, pitch, yaw] = pose.rpy.0;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}

/// Places every collision primitive of a parsed robot in the frame of its root link.
pub fn parts_from_robot(robot: &urdf_rs::Robot, file: &str) -> Result<Vec<Part>> {
    let (children, parent_of) = joint_tree(robot, file)?;
    let root = root_link(robot, file, &parent_of)?;
    let vehicle_from_link = vehicle_from_links(robot, &children, root);
    let mut parts = Vec::new();
    for (i, link) in robot.links.iter().enumerate() {
        let Some(vehicle_from_link) = vehicle_from_link[i] else {
            return Err(tree_err(
                file,
                &link.name,
                "is not reachable from the root link (the joints form a cycle)".into(),
            ));
        };
        for (k, collision) in link.collision.iter().enumerate() {
            let name = &link.name;
            check_finite(
                file,
                name,
                format!("collision {k} origin xyz"),
                &collision.origin.xyz.0,
            )?;
            check_finite(
                file,
                name,
                format!("collision {k} origin rpy"),
                &collision.origin.rpy.0,
            )?;
            let shape = collision_shape(file, name, k, &collision.geometry)?;
            parts.push(Part {
                link: name.clone(),
                collision_index: k,
                shape,
                vehicle_from_part: vehicle_from_link * isometry(&collision.origin),
            });
        }
    }
    if parts.is_empty() {
        return Err(Error::NoCollisionGeometry {
            file: file.to_string(),
        });
    }
    Ok(parts)
}

/// A [`Error::Tree`]: `link` of `file` is wrongly placed in the link tree.
fn tree_err(file: &str, link: &str, message: String) -> Error {
    Error::Tree {
        file: file.to_string(),
        link: link.to_string(),
        message,
    }
}

/// The links' tree as the joints make it, indexed like `robot.links`: `children[parent]` lists
/// `(joint, child)` in joint order, `parent_of[child]` is the joint above the link. Refuses a link
/// defined twice, a joint naming an unknown link, a link with two parent joints and a joint
/// origin that is not finite (in that order, joint by joint).
#[allow(clippy::type_complexity)]
fn joint_tree(
    robot: &urdf_rs::Robot,
    file: &str,
) -> Result<(Vec<Vec<(usize, usize)>>, Vec<Option<usize>>)> {
    let mut index: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, link) in robot.links.iter().enumerate() {
        if index.insert(link.name.as_str(), i).is_some() {
            return Err(tree_err(file, &link.name, "defined twice".into()));
        }
    }
    // children[parent] = (joint, child); parent_of[child] = joint.
    let mut children: Vec<Vec<(usize, usize)>> = vec![Vec::new(); robot.links.len()];
    let mut parent_of: Vec<Option<usize>> = vec![None; robot.links.len()];
    for (j, joint) in robot.joints.iter().enumerate() {
        let find = |name: &str, role: &'static str| {
            index.get(name).copied().ok_or_else(|| Error::MissingLink {
                file: file.to_string(),
                joint: joint.name.clone(),
                role,
                link: name.to_string(),
            })
        };
        let parent = find(&joint.parent.link, "parent")?;
        let child = find(&joint.child.link, "child")?;
        if let Some(other) = parent_of[child] {
            return Err(tree_err(
                file,
                &joint.child.link,
                format!(
                    "is the child of two joints (`{}` and `{}`)",
                    robot.joints[other].name, joint.name
                ),
            ));
        }
        check_finite(
            file,
            &joint.child.link,
            format!("origin of joint `{}` xyz", joint.name),
            &joint.origin.xyz.0,
        )?;
        check_finite(
            file,
            &joint.child.link,
            format!("origin of joint `{}` rpy", joint.name),
            &joint.origin.rpy.0,
        )?;
        parent_of[child] = Some(j);
        children[parent].push((j, child));
    }
    Ok((children, parent_of))
}

/// The one link without a parent joint; none (a cycle) or several (a forest) is an error.
fn root_link(robot: &urdf_rs::Robot, file: &str, parent_of: &[Option<usize>]) -> Result<usize> {
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&i| parent_of[i].is_none())
        .collect();
    match roots.as_slice() {
        [root] => Ok(*root),
        [] => {
            let name = robot.links.first().map_or("", |l| l.name.as_str());
            Err(tree_err(
                file,
                name,
                "no root link: the joints form a cycle".into(),
            ))
        }
        [first, second, ..] => Err(tree_err(
            file,
            &robot.links[*second].name,
            format!(
                "is not connected to the root link `{}` (a description has one tree)",
                robot.links[*first].name
            ),
        )),
    }
}

/// Each link's pose in the vehicle (root link) frame, composing the joint origins breadth first
/// from `root`; `None` for a link the root does not reach.
fn vehicle_from_links(
    robot: &urdf_rs::Robot,
    children: &[Vec<(usize, usize)>],
    root: usize,
) -> Vec<Option<Isometry3<f64>>> {
    let mut vehicle_from_link: Vec<Option<Isometry3<f64>>> = vec![None; robot.links.len()];
    vehicle_from_link[root] = Some(Isometry3::identity());
    let mut queue = VecDeque::from([root]);
    while let Some(l) = queue.pop_front() {
        let Some(vehicle_from_parent) = vehicle_from_link[l] else {
            continue;
        };
        for &(j, child) in &children[l] {
            if vehicle_from_link[child].is_none() {
                vehicle_from_link[child] =
                    Some(vehicle_from_parent * isometry(&robot.joints[j].origin));
                queue.push_back(child);
            }
        }
    }
    vehicle_from_link
}

/// The shape of collision `k` of link `name`, its dimensions checked positive (box sizes are
/// full extents, cylinder and capsule lengths full lengths); a mesh is refused.
fn collision_shape(
    file: &str,
    name: &str,
    k: usize,
    geometry: &urdf_rs::Geometry,
) -> Result<Shape> {
    Ok(match geometry {
        urdf_rs::Geometry::Box { size } => {
            let mut half = Vector3::zeros();
            for (axis, (v, label)) in size.0.iter().zip(["x", "y", "z"]).enumerate() {
                half[axis] = 0.5
                    * check_positive(file, name, format!("collision {k} box size {label}"), *v)?;
            }
            Shape::Box {
                half_extents_m: half,
            }
        }
        urdf_rs::Geometry::Cylinder { radius, length } => Shape::Cylinder {
            radius_m: check_positive(
                file,
                name,
                format!("collision {k} cylinder radius"),
                *radius,
            )?,
            half_length_m: 0.5
                * check_positive(
                    file,
                    name,
                    format!("collision {k} cylinder length"),
                    *length,
                )?,
        },
        urdf_rs::Geometry::Capsule { radius, length } => Shape::Capsule {
            radius_m: check_positive(file, name, format!("collision {k} capsule radius"), *radius)?,
            half_length_m: 0.5
                * check_positive(file, name, format!("collision {k} capsule length"), *length)?,
        },
        urdf_rs::Geometry::Sphere { radius } => Shape::Sphere {
            radius_m: check_positive(file, name, format!("collision {k} sphere radius"), *radius)?,
        },
        urdf_rs::Geometry::Mesh { filename, .. } => {
            return Err(Error::UnsupportedGeometry {
                file: file.to_string(),
                link: name.to_string(),
                index: k,
                geometry: format!("mesh (`{filename}`)"),
            });
        }
    })
}
