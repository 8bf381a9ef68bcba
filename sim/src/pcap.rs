//! Real Velodyne captures in the simulator's tools (`velodyne` decodes them): a revolution of a
//! pcap as the simulator's LiDAR scan (`taxi-sim scan --pcap`, PLY), and the offline map of a
//! recording (`taxi-sim map SCENARIO --pcap`: the scenario's vehicle gives the levels), written
//! as the mapping drive writes its map; and the other way, the simulator's revolutions written
//! as a capture VeloView opens ([`write_capture`], `taxi-sim scan SCENARIO --out FILE.pcap`).
//!
//! The sensor stands at a pose the user gives (a standing recording; a moving one needs poses,
//! not read yet), at a height the user gives or that the ground says ([`Ground`]: a plane fitted
//! to the returns of the lasers aimed 8 degrees or more down), level or - asked to - with the
//! tilt that plane shows removed (a mount's pitch and roll).

use std::path::Path;

use mapper::{Levels, MapConfig, MultiHeightMap};
use nalgebra::{
    Isometry2, Isometry3, Matrix3, Point2, Point3, Translation3, UnitQuaternion, Vector3,
};
use velodyne::{Calibration, Capture, Frame};

use crate::error::{Error, Result};
use crate::offline_map::MapManifest;
use crate::world::LidarScan;

/// A capture decoded: its calibration and its revolutions (the first and last are partial).
pub struct Recording {
    /// The sensor's lasers.
    pub calibration: Calibration,
    /// The revolutions, VeloView's frame numbering.
    pub frames: Vec<Frame>,
    /// Position packets read.
    pub positions: usize,
    /// The sensor's packets skipped (unreadable whole, or of another length), by why.
    pub skipped: velodyne::Skipped,
}

/// Reads the capture at `path` (its sensor from its packets), with the VeloView calibration
/// file `calibration` or the sensor's built-in table.
pub fn read(path: &Path, calibration: Option<&Path>) -> Result<Recording> {
    let capture = Capture::read(path).map_err(|e| Error::Invalid(e.to_string()))?;
    let built_in = Calibration::built_in(capture.product()).ok_or_else(|| {
        Error::Invalid(format!(
            "{}: the packets do not say which sensor took them (older firmware); only the \
             built-in tables of the HDL-32E and VLP-16 are known",
            path.display()
        ))
    })?;
    let calibration = match calibration {
        Some(file) => Calibration::from_veloview_xml(file, built_in.lasers())
            .map_err(|e| Error::Invalid(e.to_string()))?,
        None => built_in,
    };
    let packets: Vec<_> = capture.data.into_iter().map(|(_, p)| p).collect();
    Ok(Recording {
        frames: velodyne::frames(&packets, &calibration),
        calibration,
        positions: capture.positions.len(),
        skipped: capture.skipped,
    })
}

impl Recording {
    /// A line saying what was skipped, if anything was (for a command to print).
    pub fn skipped_line(&self, path: &Path) -> Option<String> {
        (self.skipped.total() > 0).then(|| {
            format!(
                "{}: skipped {} of the sensor's packets, read on past them as VeloView does: {}",
                path.display(),
                self.skipped.total(),
                self.skipped
            )
        })
    }

    /// The full revolutions (all but the first and last).
    pub fn full(&self) -> &[Frame] {
        let n = self.frames.len();
        if n > 2 { &self.frames[1..n - 1] } else { &[] }
    }

    /// The ground under the sensor ([`Ground::fit`]) from the returns of `frames` of the lasers
    /// aimed 8 degrees or more down.
    pub fn ground(&self, frames: &[Frame]) -> Option<Ground> {
        let low = |laser: u8| {
            self.calibration
                .vertical_deg
                .get(usize::from(laser))
                .is_some_and(|&w| w <= -8.0)
        };
        let points: Vec<Point3<f64>> = frames
            .iter()
            .flat_map(|f| &f.points)
            .filter(|p| low(p.laser))
            .map(|p| {
                // VeloView's frame to the simulator's sensor frame (x forward, y left).
                let [x, y, z] = p.xyz_m.map(f64::from);
                Point3::new(y, -x, z)
            })
            .collect();
        Ground::fit(&points)
    }

    /// Revolution `frame` as the simulator's LiDAR scan, the sensor at `vehicle_from_sensor`
    /// (its height and attitude) on a vehicle at `pose` (azimuth 0 along its heading).
    pub fn scan(
        &self,
        frame: &Frame,
        pose: &Isometry2<f64>,
        vehicle_from_sensor: &Isometry3<f64>,
    ) -> Result<LidarScan> {
        let world_from_sensor = crate::world::planar_to_3d(pose) * vehicle_from_sensor;
        let s = velodyne::to_scan(frame, &self.calibration, &world_from_sensor, pose)
            .map_err(Error::Invalid)?;
        let n = s.scan.returns().len();
        Ok(LidarScan {
            scan: s.scan,
            owners: vec![None; n],
            directions_in_sensor: std::sync::Arc::new(s.directions_in_sensor),
        })
    }
}

/// How `map --pcap` places the sensor.
#[derive(Clone, Debug)]
pub struct Placement {
    /// Where the sensor stands (azimuth 0 along the heading), when `poses` is empty.
    pub pose: Isometry2<f64>,
    /// A moving sensor's poses, `(time, pose)` in time order, time in seconds on the sensor's
    /// clock (its packets' timestamps: seconds past the hour); each revolution is placed at the
    /// pose interpolated at its middle firing ([`revolution_poses`]). Empty: standing at `pose`.
    pub poses: Vec<(f64, Isometry2<f64>)>,
    /// Its height above the ground, metres (`None`: the fitted ground's).
    pub height_m: Option<f64>,
    /// Remove the tilt fitted to the ground (the mount's pitch and roll); else level.
    pub level: bool,
}

/// What `map --pcap` built.
pub struct PcapMapReport {
    /// The map's manifest (also written as `manifest.json`).
    pub manifest: MapManifest,
    /// Revolutions inserted (the full ones).
    pub revolutions: usize,
    /// The ground fitted to the full revolutions.
    pub ground: Ground,
    /// The sensor on the vehicle as mapped: its height and attitude.
    pub vehicle_from_sensor: Isometry3<f64>,
    /// [`Recording::skipped_line`] of the capture.
    pub skipped: Option<String>,
}

/// Builds the offline map of `levels` from the capture at `pcap` (its full revolutions, the
/// sensor placed by `placement`, calibrated by `calibration` or its built-in table) into `out`.
pub fn map_from_pcap(
    pcap: &Path,
    calibration: Option<&Path>,
    placement: &Placement,
    levels: &Levels,
    config: MapConfig,
    out: &Path,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<PcapMapReport> {
    let recording = read(pcap, calibration)?;
    let full = recording.full();
    if full.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no full revolution ({} partial)",
            pcap.display(),
            recording.frames.len()
        )));
    }
    let ground = recording.ground(full).ok_or_else(|| {
        Error::Invalid(format!(
            "{}: too few ground returns to fit the ground under the sensor",
            pcap.display()
        ))
    })?;
    let mut vehicle_from_sensor = if placement.level {
        ground.sensor_above_level_ground()
    } else {
        Isometry3::translation(0.0, 0.0, ground.height_m())
    };
    if let Some(h) = placement.height_m {
        vehicle_from_sensor.translation.vector.z = h;
    }
    let blocks_dir = out.join("blocks");
    crate::offline_map::clear_blocks(&blocks_dir)?;
    let poses = revolution_poses(full, placement)
        .map_err(|e| Error::Invalid(format!("{}: {e}", pcap.display())))?;
    let center = Point2::from(poses[0].translation.vector);
    let mut map =
        MultiHeightMap::with_stores(config, levels.clone(), center, None, Some(&blocks_dir))?;
    for (i, (frame, pose)) in full.iter().zip(&poses).enumerate() {
        let scan = recording.scan(frame, pose, &vehicle_from_sensor)?;
        map.recenter(Point2::from(pose.translation.vector))?;
        map.insert_scan(&scan.scan, None)?;
        progress(i as u64 + 1, full.len() as u64);
    }
    map.flush()?;
    let manifest = crate::offline_map::finish_map(
        &map,
        levels,
        out,
        (
            format!("pcap-{}", pcap.display()),
            format!("pcap {}", pcap.display()),
            full.len(),
            0.0,
        ),
    )?;
    Ok(PcapMapReport {
        manifest,
        revolutions: full.len(),
        ground,
        vehicle_from_sensor,
        skipped: recording.skipped_line(pcap),
    })
}

/// Each revolution's pose: `placement.pose` for a standing sensor; for a moving one the pose
/// of `placement.poses` at the revolution's middle firing, position and heading interpolated
/// linearly (the heading the short way round). Motion within a revolution is not undone: every
/// firing of a revolution is placed at its middle's pose. A revolution outside the poses' time
/// span is an error naming it and its time.
pub fn revolution_poses(
    frames: &[Frame],
    placement: &Placement,
) -> std::result::Result<Vec<Isometry2<f64>>, String> {
    if placement.poses.is_empty() {
        return Ok(vec![placement.pose; frames.len()]);
    }
    let track = &placement.poses;
    frames
        .iter()
        .enumerate()
        .map(|(i, frame)| {
            let mut times: Vec<f64> = frame.points.iter().map(|p| p.time_us * 1e-6).collect();
            times.sort_by(f64::total_cmp);
            let t = *times
                .get(times.len() / 2)
                .ok_or_else(|| format!("full revolution {i} has no return to time it by"))?;
            let (first, last) = (track[0].0, track[track.len() - 1].0);
            if !(first..=last).contains(&t) {
                return Err(format!(
                    "full revolution {i} (at {t:.6} s on the sensor's clock) is outside the poses'                      {first:.6}-{last:.6} s"
                ));
            }
            let k = track.partition_point(|(s, _)| *s <= t).clamp(1, track.len() - 1);
            let ((t0, a), (t1, b)) = (track[k - 1], track[k]);
            let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
            let xy = a.translation.vector.lerp(&b.translation.vector, f);
            let turn = crate::world::wrap_angle(b.rotation.angle() - a.rotation.angle());
            Ok(Isometry2::new(xy, a.rotation.angle() + f * turn))
        })
        .collect()
}

/// Reads a poses file for `map --pcap --poses`: CSV with the header `time_s,x_m,y_m,yaw_deg`
/// (time in seconds on the sensor's clock, position in metres, heading in degrees), at least
/// two rows, times strictly increasing. A wrong line is an error naming the file, the line and
/// the field.
pub fn read_poses_csv(path: &Path) -> Result<Vec<(f64, Isometry2<f64>)>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        what: "reading the poses",
        path: path.to_path_buf(),
        source,
    })?;
    let bad = |line: usize, why: String| {
        Error::Invalid(format!("{}: line {line}: {why}", path.display()))
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    const HEADER: [&str; 4] = ["time_s", "x_m", "y_m", "yaw_deg"];
    match lines.next() {
        Some((_, h)) if h.split(',').map(str::trim).eq(HEADER) => {}
        Some((i, h)) => {
            return Err(bad(
                i + 1,
                format!("the header is `{h}`, want `{}`", HEADER.join(",")),
            ));
        }
        None => return Err(bad(1, "empty: want a header and two poses or more".into())),
    }
    let mut poses: Vec<(f64, Isometry2<f64>)> = Vec::new();
    for (i, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != HEADER.len() {
            return Err(bad(i + 1, format!("{} fields, want 4", fields.len())));
        }
        let mut v = [0.0; 4];
        for (k, (field, name)) in fields.iter().zip(HEADER).enumerate() {
            v[k] = field
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(i + 1, format!("{name}: `{field}` is not a finite number")))?;
        }
        if let Some((t, _)) = poses.last()
            && v[0] <= *t
        {
            return Err(bad(i + 1, format!("time_s: {} is not after {t}", v[0])));
        }
        poses.push((
            v[0],
            Isometry2::new(nalgebra::Vector2::new(v[1], v[2]), v[3].to_radians()),
        ));
    }
    if poses.len() < 2 {
        return Err(bad(
            text.lines().count().max(1),
            format!("{} poses, want two or more", poses.len()),
        ));
    }
    Ok(poses)
}

/// The ground under a sensor: the plane `z = a x + b y + c` in the sensor's frame fitted to
/// returns of the ground, and their spread about it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// The plane's slope along x.
    pub a: f64,
    /// The plane's slope along y.
    pub b: f64,
    /// The plane's height at the sensor, metres (minus the sensor's height).
    pub c: f64,
    /// Standard deviation of the fitted returns about the plane, metres.
    pub spread_m: f64,
}

impl Ground {
    /// The ground fitted to `points` (in the sensor frame; those 4-30 m away horizontally
    /// count): a least-squares plane through those within 0.25 m of their most common height
    /// (5-cm bins), refitted to those within 0.15 m of the first. `None` below 50 points.
    pub fn fit(points: &[Point3<f64>]) -> Option<Ground> {
        let near: Vec<Point3<f64>> = points
            .iter()
            .copied()
            .filter(|p| (4.0..30.0).contains(&p.coords.xy().norm()))
            .collect();
        let mut bins = std::collections::HashMap::<i64, usize>::new();
        for p in &near {
            *bins.entry((p.z / 0.05).floor() as i64).or_default() += 1;
        }
        let (mode, _) = bins.into_iter().max_by_key(|&(b, c)| (c, -b))?;
        let mode_z = (mode as f64 + 0.5) * 0.05;
        let band: Vec<Point3<f64>> = near
            .into_iter()
            .filter(|p| (p.z - mode_z).abs() < 0.25)
            .collect();
        let first = fit_plane(&band)?;
        let inliers: Vec<Point3<f64>> = band
            .into_iter()
            .filter(|p| (p.z - first.z_at(p)).abs() < 0.15)
            .collect();
        let plane = fit_plane(&inliers)?;
        let spread = (inliers
            .iter()
            .map(|p| (p.z - plane.z_at(p)).powi(2))
            .sum::<f64>()
            / inliers.len() as f64)
            .sqrt();
        Some(Ground {
            spread_m: spread,
            ..plane
        })
    }

    /// The plane's height at `p`'s x, y.
    pub fn z_at(&self, p: &Point3<f64>) -> f64 {
        self.a * p.x + self.b * p.y + self.c
    }

    /// The sensor's height above the ground under it, metres.
    pub fn height_m(&self) -> f64 {
        -self.c
    }

    /// The sensor's pitch (nose up positive) and roll (right side down positive), degrees.
    pub fn pitch_roll_deg(&self) -> [f64; 2] {
        [-self.a.atan().to_degrees(), -self.b.atan().to_degrees()]
    }

    /// The sensor's pose over this ground made level at z = 0: its height, and the tilt that
    /// turns the ground's normal up.
    pub fn sensor_above_level_ground(&self) -> Isometry3<f64> {
        let normal = Vector3::new(-self.a, -self.b, 1.0).normalize();
        let rotation = UnitQuaternion::rotation_between(&normal, &Vector3::z()).unwrap_or_default();
        Isometry3::from_parts(Translation3::new(0.0, 0.0, self.height_m()), rotation)
    }
}

/// The least-squares plane through `points` (at least 50).
fn fit_plane(points: &[Point3<f64>]) -> Option<Ground> {
    if points.len() < 50 {
        return None;
    }
    let mut m = Matrix3::zeros();
    let mut v = Vector3::zeros();
    for p in points {
        let row = Vector3::new(p.x, p.y, 1.0);
        m += row * row.transpose();
        v += row * p.z;
    }
    let s = m.lu().solve(&v)?;
    Some(Ground {
        a: s.x,
        b: s.y,
        c: s.z,
        spread_m: 0.0,
    })
}

/// The Velodyne product whose packets carry `scan`'s beams: a 16-beam scan the VLP-16's, a
/// 32-beam one the HDL-32E's; `None` for another beam count.
pub fn product_of(scan: &LidarScan) -> Option<velodyne::Product> {
    match scan.scan.beams() {
        16 => Some(velodyne::Product::Vlp16),
        32 => Some(velodyne::Product::Hdl32e),
        _ => None,
    }
}

/// `scans` (consecutive revolutions of one sensor turning at `rotation_hz`, the first starting
/// at `start_s` past the hour) as the data packets the sensor would send, written atomically as
/// a pcap (Ethernet, UDP port 2368). Each column is a firing at the azimuth of its beams
/// (VeloView's: clockwise from ahead), its returns' ranges and intensities (0-1 scaled to
/// 0-255). The simulator's head turns anticlockwise and a Velodyne's clockwise: a revolution's
/// columns are written in the sensor's order, from the one straight ahead (column 0) clockwise
/// (the last column next) - for a standing sensor the same revolution. Returns the packets
/// written.
///
/// # Errors
/// A scan of neither sensor's beam count, a range a packet cannot carry, or the file.
pub fn write_capture(
    scans: &[LidarScan],
    rotation_hz: f64,
    start_s: f64,
    path: &Path,
) -> Result<usize> {
    let Some(first) = scans.first() else {
        return Err(Error::Invalid("no revolution to write".into()));
    };
    let product = product_of(first).ok_or_else(|| {
        Error::Invalid(format!(
            "{} beams: a capture holds an HDL-32E's 32 or a VLP-16's 16",
            first.scan.beams()
        ))
    })?;
    let mut firings = Vec::new();
    for (r, scan) in scans.iter().enumerate() {
        let (beams, columns) = (scan.scan.beams(), scan.scan.columns().len());
        for k in 0..columns {
            let c = (columns - k) % columns;
            // The column's heading in the sensor frame (x ahead, y left), from any beam.
            let d = scan.directions_in_sensor[c * beams];
            let azimuth_deg = f64::from(-d[1]).atan2(f64::from(d[0])).to_degrees();
            let by_beam = scan.scan.returns()[c * beams..(c + 1) * beams]
                .iter()
                .map(|ret| {
                    ret.map(|ret| {
                        let intensity = (f64::from(ret.intensity).clamp(0.0, 1.0) * 255.0).round();
                        (f64::from(ret.range_m), intensity as u8)
                    })
                })
                .collect();
            let t_s = start_s + (r as f64 + k as f64 / columns as f64) / rotation_hz;
            firings.push(velodyne::encode::Firing {
                azimuth_deg,
                time_us: t_s * 1e6,
                by_beam,
            });
        }
    }
    let packets = velodyne::encode::data_packets(product, &firings).map_err(Error::Invalid)?;
    let datagrams: Vec<(f64, u16, Vec<u8>)> = packets
        .iter()
        .map(|p| {
            let t_s = f64::from(p.timestamp_us) * 1e-6;
            (t_s, velodyne::packet::DATA_PORT, p.encode())
        })
        .collect();
    mapper::write_atomically(path, &velodyne::pcap_bytes(&datagrams))
        .map_err(|e| Error::Invalid(format!("writing {}: {e}", path.display())))?;
    Ok(packets.len())
}
