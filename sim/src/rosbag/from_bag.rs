//! The offline map built from a bag (`taxi-sim map SCENARIO --from-bag BAG`): the point clouds of
//! one topic, each organised into a scan ([`mapper::organise`]: columns by azimuth, beams by
//! ring) at the pose the bag gives for its stamp - by the transform tree (`/tf`, `/tf_static`:
//! the fixed frame to the cloud's frame, and to the base frame for the vehicle) or by an
//! odometry topic (the base frame's pose, the sensor's mount from `/tf_static`) - and inserted
//! as the mapping drive inserts its revolutions; written as the mapping drive writes its map.
//!
//! Two passes over the bag, each streamed from disk: the poses (small), then the clouds, each
//! decoded and organised beside the insertion of the one before. A cloud with no pose at its
//! stamp is skipped and counted; a bag where none has one is an error, as is a cloud topic
//! missing or of another type, and a cloud that lacks `ring` or `intensity` (named with its
//! topic and index).

use std::path::{Path, PathBuf};

use mapper::{CollisionModel, ColumnLayout, Levels, MapConfig, MultiHeightMap, Scan, SensorPoint};
use nalgebra::{Isometry2, Isometry3, Point2, Vector2};
use ros2::{BagError, BagMessage, BagReader};

use super::bag_error;
use super::tf::{TfBuffer, isometry, sample_at};
use crate::error::{Error, Result};
use crate::offline_map::MapManifest;

/// Where a cloud's pose comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PoseSource {
    /// The transform tree: `fixed_frame` -> the cloud's frame, and -> `base_frame`.
    Tf,
    /// `nav_msgs/msg/Odometry` on this topic: its child frame's pose in its header's frame.
    Odom(String),
}

/// What to read from a bag.
#[derive(Debug, Clone)]
pub struct BagMapOptions {
    /// The point cloud topic.
    pub cloud_topic: String,
    /// Where poses come from.
    pub pose_source: PoseSource,
    /// The map's frame (with [`PoseSource::Tf`]).
    pub fixed_frame: String,
    /// The vehicle's frame (its rear axle, as the vehicle file's origin).
    pub base_frame: String,
    /// Firings a revolution (default: found in each cloud).
    pub columns: Option<usize>,
}

impl Default for BagMapOptions {
    fn default() -> Self {
        Self {
            cloud_topic: "/velodyne_points".into(),
            pose_source: PoseSource::Tf,
            fixed_frame: "map".into(),
            base_frame: "base_link".into(),
            columns: None,
        }
    }
}

/// What [`map_from_bag`] did.
#[derive(Debug, Clone)]
pub struct BagMapReport {
    /// The map's manifest (also written as `manifest.json`).
    pub manifest: MapManifest,
    /// Clouds on the topic.
    pub clouds: u64,
    /// Clouds skipped: no pose at their stamp, or too few points to organise.
    pub skipped: u64,
    /// Why the first was skipped.
    pub first_skipped: Option<String>,
    /// The layout of the last cloud inserted.
    pub layout: Option<ColumnLayout>,
}

const POINT_CLOUD2: &str = "sensor_msgs/msg/PointCloud2";
const ODOMETRY: &str = "nav_msgs/msg/Odometry";

fn message_error(m: &BagMessage<'_>, what: impl Into<String>) -> Error {
    bag_error(BagError::Message {
        path: m.file.to_path_buf(),
        topic: m.topic.to_string(),
        index: m.index,
        what: what.into(),
    })
}

/// The bag's poses.
struct Poses {
    tf: TfBuffer,
    /// With [`PoseSource::Odom`]: the samples of the odometry's child frame.
    odom: Vec<(u64, Isometry3<f64>)>,
    /// The odometry's child frame (the first message's).
    odom_child: String,
}

impl Poses {
    /// The vehicle's planar pose and the sensor's pose in the map at `t_ns`.
    fn at(
        &self,
        options: &BagMapOptions,
        frame_id: &str,
        t_ns: u64,
    ) -> std::result::Result<(Isometry2<f64>, Isometry3<f64>), String> {
        let base = &options.base_frame;
        let world_from_base = match options.pose_source {
            PoseSource::Tf => self.tf.lookup(&options.fixed_frame, base, t_ns)?,
            PoseSource::Odom(_) => {
                let world_from_child = sample_at(&self.odom, t_ns, TfBuffer::tolerance_ns())
                    .map_err(|(first, last)| {
                        format!(
                            "{:.3} s is outside the odometry, {:.3} to {:.3} s",
                            t_ns as f64 * 1e-9,
                            first as f64 * 1e-9,
                            last as f64 * 1e-9
                        )
                    })?;
                // The odometry's child is the base frame, or linked to it in the tree (a
                // base_footprint); a frame the tree does not know is taken as the base frame
                // under another name (`ground_truth/base_link`).
                match self.tf.lookup(&self.odom_child, base, t_ns) {
                    Ok(child_from_base) => world_from_child * child_from_base,
                    Err(_) if !self.tf.knows(&self.odom_child) => world_from_child,
                    Err(e) => return Err(e),
                }
            }
        };
        let world_from_sensor = match options.pose_source {
            PoseSource::Tf => self.tf.lookup(&options.fixed_frame, frame_id, t_ns)?,
            PoseSource::Odom(_) => world_from_base * self.tf.lookup(base, frame_id, t_ns)?,
        };
        let (_, _, yaw) = world_from_base.rotation.euler_angles();
        let t = world_from_base.translation.vector;
        Ok((
            Isometry2::new(Vector2::new(t.x, t.y), yaw),
            world_from_sensor,
        ))
    }
}

/// Pass 1: the transforms (and odometry), the cloud topic checked; returns the poses and the
/// number of clouds.
fn read_poses(reader: &BagReader, options: &BagMapOptions) -> Result<(Poses, u64)> {
    let mut poses = Poses {
        tf: TfBuffer::default(),
        odom: Vec::new(),
        odom_child: String::new(),
    };
    let mut clouds = 0u64;
    let mut types: Vec<(String, String)> = Vec::new();
    let odom_topic = match &options.pose_source {
        PoseSource::Odom(topic) => Some(topic.as_str()),
        PoseSource::Tf => None,
    };
    reader
        .read(&|_| true, &mut |m| {
            if !types.iter().any(|(t, _)| t == m.topic) {
                types.push((m.topic.to_string(), m.type_name.to_string()));
            }
            let tf_static = m.topic == "/tf_static";
            if m.topic == options.cloud_topic {
                clouds += 1;
            } else if tf_static || m.topic == "/tf" {
                let transforms =
                    ros2::msgs::read_tf_message(m.data).map_err(|e| BagError::Message {
                        path: m.file.to_path_buf(),
                        topic: m.topic.into(),
                        index: m.index,
                        what: e.to_string(),
                    })?;
                for t in &transforms {
                    poses
                        .tf
                        .add(t, tf_static)
                        .map_err(|what| BagError::Message {
                            path: m.file.to_path_buf(),
                            topic: m.topic.into(),
                            index: m.index,
                            what,
                        })?;
                }
            } else if Some(m.topic) == odom_topic && m.type_name == ODOMETRY {
                let o = ros2::msgs::read_odometry(m.data).map_err(|e| BagError::Message {
                    path: m.file.to_path_buf(),
                    topic: m.topic.into(),
                    index: m.index,
                    what: e.to_string(),
                })?;
                if poses.odom.is_empty() {
                    poses.odom_child.clone_from(&o.child);
                }
                poses.odom.push((o.stamp.ns(), isometry(&o.pose)));
            }
            Ok(())
        })
        .map_err(bag_error)?;
    poses.tf.sort();
    poses.odom.sort_by_key(|s| s.0);
    let file = reader.files()[0].display().to_string();
    let listing = || {
        types
            .iter()
            .map(|(t, ty)| format!("{t} ({ty})"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    check_topic(&types, &options.cloud_topic, POINT_CLOUD2, &file, listing)?;
    if let Some(topic) = odom_topic {
        check_topic(&types, topic, ODOMETRY, &file, listing)?;
    }
    if options.pose_source == PoseSource::Tf && poses.tf.is_empty() {
        return Err(Error::Invalid(format!(
            "{file}: no poses: the bag has no /tf or /tf_static (its topics: {}); give \
             --pose-source odom --odom-topic TOPIC if it has odometry",
            listing()
        )));
    }
    Ok((poses, clouds))
}

fn check_topic(
    types: &[(String, String)],
    topic: &str,
    expected: &str,
    file: &str,
    listing: impl Fn() -> String,
) -> Result<()> {
    match types.iter().find(|(t, _)| t == topic) {
        None => Err(Error::Invalid(format!(
            "{file}: no topic {topic} (the bag has: {})",
            listing()
        ))),
        Some((_, ty)) if ty != expected => Err(Error::Invalid(format!(
            "{file}: topic {topic} is of type `{ty}`, not {expected}"
        ))),
        Some(_) => Ok(()),
    }
}

/// A cloud organised: the vehicle's pose, the scan, its firings' layout.
type Organised = (Isometry2<f64>, Scan, ColumnLayout);

/// One cloud decoded and organised at its pose; `Ok(Err(why))` when it has no pose.
fn scan_of(
    m: &BagMessage<'_>,
    options: &BagMapOptions,
    poses: &Poses,
) -> Result<std::result::Result<Organised, String>> {
    if m.encoding != "cdr" {
        return Err(message_error(
            m,
            format!("encoded as `{}`, not cdr", m.encoding),
        ));
    }
    let cloud = ros2::read_cloud(m.data).map_err(|e| message_error(m, e.to_string()))?;
    let missing = |field: &str| {
        message_error(
            m,
            format!(
                "field `{field}`: missing (the mapper needs it; the cloud has {:?})",
                cloud.fields.iter().map(|f| &f.name).collect::<Vec<_>>()
            ),
        )
    };
    let rings = cloud.ring.as_ref().ok_or_else(|| missing("ring"))?;
    let intensity = cloud
        .intensity
        .as_ref()
        .ok_or_else(|| missing("intensity"))?;
    let (vehicle, sensor) = match poses.at(options, &cloud.frame_id, cloud.stamp_ns) {
        Ok(p) => p,
        Err(why) => return Ok(Err(why)),
    };
    // The ROS Velodyne driver's intensity is 0-255; the mapper takes 0..1.
    let points: Vec<SensorPoint> = cloud
        .xyz
        .iter()
        .zip(rings)
        .zip(intensity)
        .filter(|((p, _), _)| p.iter().all(|v| v.is_finite()))
        .map(|((p, &ring), &i)| SensorPoint {
            xyz: *p,
            ring,
            intensity: ((i / 255.0) as f32).clamp(0.0, 1.0),
        })
        .collect();
    let beams = points.iter().map(|p| usize::from(p.ring) + 1).max();
    let (Some(beams), Some(layout)) = (beams, ColumnLayout::estimate(&points, options.columns))
    else {
        return Ok(Err(format!("{} points: too few to organise", points.len())));
    };
    let scan = mapper::organise(&points, beams, &layout, &sensor, &vehicle)
        .map_err(|e| message_error(m, e.to_string()))?;
    Ok(Ok((vehicle, scan, layout)))
}

/// Builds the offline map of `levels` from the bag at `bag` into `out` (blocks, the levels'
/// ROS maps and pictures, `manifest.json`). `progress(done, total)` after each cloud.
#[allow(clippy::too_many_arguments)]
pub fn map_from_bag(
    bag: &Path,
    options: &BagMapOptions,
    levels: &Levels,
    config: MapConfig,
    self_filter: Option<&CollisionModel>,
    out: &Path,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<BagMapReport> {
    if let Some(c) = options.columns
        && !(1..=mapper::organise::MAX_COLUMNS).contains(&c)
    {
        return Err(Error::Invalid(format!(
            "--columns {c}: firings a revolution are 1 to {}",
            mapper::organise::MAX_COLUMNS
        )));
    }
    let reader = BagReader::open(bag).map_err(bag_error)?;
    let (poses, clouds) = read_poses(&reader, options)?;
    let blocks_dir = out.join("blocks");
    crate::offline_map::clear_blocks(&blocks_dir)?;
    let mut map: Option<MultiHeightMap> = None;
    let mut report = BagMapReport {
        manifest: empty_manifest(bag, levels),
        clouds,
        skipped: 0,
        first_skipped: None,
        layout: None,
    };
    let (mut inserted, mut route_m, mut last) = (0usize, 0.0, None::<Point2<f64>>);
    let mut pending: Option<(Isometry2<f64>, Scan)> = None;
    let mut insert = |map: &mut Option<MultiHeightMap>, (vehicle, scan): (Isometry2<f64>, Scan)| {
        let p = Point2::from(vehicle.translation.vector);
        let map = match map {
            Some(map) => map,
            None => map.insert(MultiHeightMap::with_stores(
                config,
                levels.clone(),
                p,
                None,
                Some(&blocks_dir),
            )?),
        };
        map.recenter(p)?;
        map.insert_scan(&scan, self_filter)?;
        route_m += last.map_or(0.0, |q: Point2<f64>| (p - q).norm());
        last = Some(p);
        inserted += 1;
        Result::<()>::Ok(())
    };
    let mut failure: Option<Error> = None;
    let mut done = 0u64;
    let read = reader.read(&|t| t == options.cloud_topic, &mut |m| {
        // This cloud organised beside the insertion of the one before.
        let (scan, result) = rayon::join(
            || scan_of(m, options, &poses),
            || pending.take().map_or(Ok(()), |p| insert(&mut map, p)),
        );
        let outcome = result.and(scan);
        match outcome {
            Ok(Ok((vehicle, scan, layout))) => {
                report.layout = Some(layout);
                pending = Some((vehicle, scan));
            }
            Ok(Err(why)) => {
                report.skipped += 1;
                report
                    .first_skipped
                    .get_or_insert(format!("{} message {}: {why}", m.topic, m.index));
            }
            Err(e) => {
                failure = Some(e);
                return Err(BagError::Read {
                    path: m.file.to_path_buf(),
                    at: String::new(),
                    what: "stopped".into(),
                });
            }
        }
        done += 1;
        progress(done, clouds);
        Ok(())
    });
    if let Some(e) = failure {
        return Err(e);
    }
    read.map_err(bag_error)?;
    if let Some(p) = pending.take() {
        insert(&mut map, p)?;
    }
    let Some(map) = map else {
        return Err(Error::Invalid(format!(
            "{}: none of the {clouds} clouds of {} could be mapped (no pose at its stamp, or too few points){}",
            bag.display(),
            options.cloud_topic,
            report
                .first_skipped
                .as_ref()
                .map_or(String::new(), |w| format!(" (the first: {w})"))
        )));
    };
    map.flush()?;
    report.manifest =
        crate::offline_map::finish_map(&map, levels, out, bag_manifest(bag, inserted, route_m))?;
    Ok(report)
}

fn empty_manifest(bag: &Path, levels: &Levels) -> MapManifest {
    MapManifest {
        fingerprint: String::new(),
        scenario: format!("bag {}", bag.display()),
        scans: 0,
        route_m: 0.0,
        blocks: 0,
        level_heights_m: levels.heights_m().to_vec(),
        occupied_cells: Vec::new(),
    }
}

/// The manifest's fields that are the bag's: a fingerprint that no scenario's matches (`bag-`
/// and a digest of the bag's files' names and sizes), revolutions, distance.
fn bag_manifest(bag: &Path, scans: usize, route_m: f64) -> (String, String, usize, f64) {
    let mut h = crc32fast::Hasher::new();
    let files: Vec<PathBuf> = BagReader::open(bag)
        .map(|r| r.files().to_vec())
        .unwrap_or_default();
    for f in &files {
        h.update(f.display().to_string().as_bytes());
        h.update(&std::fs::metadata(f).map_or(0, |m| m.len()).to_le_bytes());
    }
    (
        format!("bag-{:08x}", h.finalize()),
        format!("bag {}", bag.display()),
        scans,
        route_m,
    )
}
