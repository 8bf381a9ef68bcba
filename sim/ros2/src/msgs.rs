//! The standard ROS 2 message types a run is written as: their `ros2msg` schema texts (each
//! type's definition, then every type it uses after a line of 80 `=` and `MSG: pkg/Type`, as
//! rosbag2 embeds them), their RIHS01 type hashes, and their CDR encoders.

use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// A message type: its name, its schema text and its type hash.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MsgType {
    /// `pkg/msg/Type`.
    pub name: &'static str,
    /// RIHS01 hash of its type description (as `ros2 bag` records it in `metadata.yaml`).
    pub hash: &'static str,
    /// The definitions: this type's first, then the types it uses.
    defs: &'static [Def],
}

/// One `.msg` definition (comments stripped).
#[derive(Debug, PartialEq, Eq)]
struct Def {
    name: &'static str,
    text: &'static str,
}

const TIME: Def = Def {
    name: "builtin_interfaces/Time",
    text: "int32 sec\nuint32 nanosec\n",
};
const HEADER: Def = Def {
    name: "std_msgs/Header",
    text: "builtin_interfaces/Time stamp\nstring frame_id\n",
};
const POINT: Def = Def {
    name: "geometry_msgs/Point",
    text: "float64 x\nfloat64 y\nfloat64 z\n",
};
const QUATERNION: Def = Def {
    name: "geometry_msgs/Quaternion",
    text: "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
};
const VECTOR3: Def = Def {
    name: "geometry_msgs/Vector3",
    text: "float64 x\nfloat64 y\nfloat64 z\n",
};
const POSE: Def = Def {
    name: "geometry_msgs/Pose",
    text: "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
};
const POSE_COV: Def = Def {
    name: "geometry_msgs/PoseWithCovariance",
    text: "geometry_msgs/Pose pose\nfloat64[36] covariance\n",
};
const TWIST: Def = Def {
    name: "geometry_msgs/Twist",
    text: "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n",
};
const TWIST_COV: Def = Def {
    name: "geometry_msgs/TwistWithCovariance",
    text: "geometry_msgs/Twist twist\nfloat64[36] covariance\n",
};
const TRANSFORM: Def = Def {
    name: "geometry_msgs/Transform",
    text: "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
};
const TRANSFORM_STAMPED: Def = Def {
    name: "geometry_msgs/TransformStamped",
    text: "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
};
const POSE_STAMPED: Def = Def {
    name: "geometry_msgs/PoseStamped",
    text: "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
};
const POINT_FIELD: Def = Def {
    name: "sensor_msgs/PointField",
    text: "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\n\
           uint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n",
};
const MAP_META: Def = Def {
    name: "nav_msgs/MapMetaData",
    text: "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\nuint32 height\n\
           geometry_msgs/Pose origin\n",
};
const ACKERMANN: Def = Def {
    name: "ackermann_msgs/AckermannDrive",
    text: "float32 steering_angle\nfloat32 steering_angle_velocity\nfloat32 speed\nfloat32 acceleration\n\
           float32 jerk\n",
};

/// `rosgraph_msgs/msg/Clock`.
pub const CLOCK: MsgType = MsgType {
    name: "rosgraph_msgs/msg/Clock",
    hash: "RIHS01_692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564",
    defs: &[
        Def {
            name: "rosgraph_msgs/Clock",
            text: "builtin_interfaces/Time clock\n",
        },
        TIME,
    ],
};
/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: MsgType = MsgType {
    name: "tf2_msgs/msg/TFMessage",
    hash: "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    defs: &[
        Def {
            name: "tf2_msgs/TFMessage",
            text: "geometry_msgs/TransformStamped[] transforms\n",
        },
        TRANSFORM_STAMPED,
        HEADER,
        TIME,
        TRANSFORM,
        VECTOR3,
        QUATERNION,
    ],
};
/// `sensor_msgs/msg/PointCloud2`.
pub const POINT_CLOUD2: MsgType = MsgType {
    name: "sensor_msgs/msg/PointCloud2",
    hash: "RIHS01_9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5",
    defs: &[
        Def {
            name: "sensor_msgs/PointCloud2",
            text: "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n\
                   bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
        },
        HEADER,
        TIME,
        POINT_FIELD,
    ],
};
/// `nav_msgs/msg/Odometry`.
pub const ODOMETRY: MsgType = MsgType {
    name: "nav_msgs/msg/Odometry",
    hash: "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0",
    defs: &[
        Def {
            name: "nav_msgs/Odometry",
            text: "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n\
                   geometry_msgs/TwistWithCovariance twist\n",
        },
        HEADER,
        TIME,
        POSE_COV,
        POSE,
        POINT,
        QUATERNION,
        TWIST_COV,
        TWIST,
        VECTOR3,
    ],
};
/// `geometry_msgs/msg/PoseWithCovarianceStamped`.
pub const POSE_WITH_COVARIANCE_STAMPED: MsgType = MsgType {
    name: "geometry_msgs/msg/PoseWithCovarianceStamped",
    hash: "RIHS01_26432f9803e43727d3c8f668d1fdb3c630f548af631e2f4e31382371bfea3b6e",
    defs: &[
        Def {
            name: "geometry_msgs/PoseWithCovarianceStamped",
            text: "std_msgs/Header header\ngeometry_msgs/PoseWithCovariance pose\n",
        },
        HEADER,
        TIME,
        POSE_COV,
        POSE,
        POINT,
        QUATERNION,
    ],
};
/// `ackermann_msgs/msg/AckermannDriveStamped`.
pub const ACKERMANN_DRIVE_STAMPED: MsgType = MsgType {
    name: "ackermann_msgs/msg/AckermannDriveStamped",
    hash: "RIHS01_48ca7612a08d3bb72744fd98b71b7cf2ea24c6ad50fa4e1aa0bbad963c90d8cf",
    defs: &[
        Def {
            name: "ackermann_msgs/AckermannDriveStamped",
            text: "std_msgs/Header header\nackermann_msgs/AckermannDrive drive\n",
        },
        HEADER,
        TIME,
        ACKERMANN,
    ],
};
/// `nav_msgs/msg/OccupancyGrid`.
pub const OCCUPANCY_GRID: MsgType = MsgType {
    name: "nav_msgs/msg/OccupancyGrid",
    hash: "RIHS01_8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7",
    defs: &[
        Def {
            name: "nav_msgs/OccupancyGrid",
            text: "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data\n",
        },
        HEADER,
        TIME,
        MAP_META,
        POSE,
        POINT,
        QUATERNION,
    ],
};
/// `nav_msgs/msg/Path`.
pub const PATH: MsgType = MsgType {
    name: "nav_msgs/msg/Path",
    hash: "RIHS01_1957a5bb3cee5da65c4e52e52b65a93df227efce4c20f8458b36e73066ca334b",
    defs: &[
        Def {
            name: "nav_msgs/Path",
            text: "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
        },
        HEADER,
        TIME,
        POSE_STAMPED,
        POSE,
        POINT,
        QUATERNION,
    ],
};
/// `visualization_msgs/msg/MarkerArray` (ROS 2 Jazzy's Marker: with texture, UV and mesh file
/// fields).
pub const MARKER_ARRAY: MsgType = MsgType {
    name: "visualization_msgs/msg/MarkerArray",
    hash: "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
    defs: &[
        Def {
            name: "visualization_msgs/MarkerArray",
            text: "visualization_msgs/Marker[] markers\n",
        },
        Def {
            name: "visualization_msgs/Marker",
            text: "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
                   int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
                   int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n\
                   int32 ARROW_STRIP=12\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\
                   std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
                   geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
                   builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
                   std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\n\
                   visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n\
                   visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n",
        },
        HEADER,
        TIME,
        POSE,
        POINT,
        QUATERNION,
        VECTOR3,
        Def {
            name: "std_msgs/ColorRGBA",
            text: "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
        },
        Def {
            name: "builtin_interfaces/Duration",
            text: "int32 sec\nuint32 nanosec\n",
        },
        Def {
            name: "sensor_msgs/CompressedImage",
            text: "std_msgs/Header header\nstring format\nuint8[] data\n",
        },
        Def {
            name: "visualization_msgs/UVCoordinate",
            text: "float32 u\nfloat32 v\n",
        },
        Def {
            name: "visualization_msgs/MeshFile",
            text: "string filename\nuint8[] data\n",
        },
    ],
};
/// `std_msgs/msg/String` (the run's events, as JSON).
pub const STRING: MsgType = MsgType {
    name: "std_msgs/msg/String",
    hash: "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    defs: &[Def {
        name: "std_msgs/String",
        text: "string data\n",
    }],
};

impl MsgType {
    /// The schema text (`ros2msg`) rosbag2 embeds for this type.
    #[must_use]
    pub fn schema(&self) -> String {
        let mut text = String::new();
        for (i, def) in self.defs.iter().enumerate() {
            if i > 0 {
                text.push_str(&"=".repeat(80));
                text.push_str("\nMSG: ");
                text.push_str(def.name);
                text.push('\n');
            }
            text.push_str(def.text);
        }
        text
    }
}

/// A ROS time: seconds and nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, 0..1e9.
    pub nanosec: u32,
}

impl Time {
    /// From nanoseconds since the epoch.
    #[must_use]
    pub fn from_ns(ns: u64) -> Self {
        Self {
            sec: i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX),
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    /// Nanoseconds since the epoch.
    #[must_use]
    pub fn ns(&self) -> u64 {
        u64::try_from(self.sec).unwrap_or(0) * 1_000_000_000 + u64::from(self.nanosec)
    }
}

fn header(w: &mut CdrWriter, stamp: Time, frame_id: &str) {
    w.i32(stamp.sec);
    w.u32(stamp.nanosec);
    w.string(frame_id);
}

/// A pose: position and orientation (quaternion x, y, z, w).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Metres.
    pub position: [f64; 3],
    /// Unit quaternion, x y z w.
    pub orientation: [f64; 4],
}

impl Pose {
    /// A planar pose: `x`, `y`, heading `yaw` (radians) about z.
    #[must_use]
    pub fn planar(x: f64, y: f64, z: f64, yaw: f64) -> Self {
        let (s, c) = (yaw / 2.0).sin_cos();
        Self {
            position: [x, y, z],
            orientation: [0.0, 0.0, s, c],
        }
    }

    fn write(&self, w: &mut CdrWriter) {
        for v in self.position.iter().chain(&self.orientation) {
            w.f64(*v);
        }
    }
}

/// One transform of a `TFMessage`: `child` in `parent`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transform {
    /// Its stamp.
    pub stamp: Time,
    /// The parent frame.
    pub parent: String,
    /// The child frame.
    pub child: String,
    /// The child's pose in the parent.
    pub pose: Pose,
}

/// `tf2_msgs/msg/TFMessage`.
#[must_use]
pub fn tf_message(transforms: &[Transform]) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(96 * transforms.len());
    w.count(transforms.len());
    for t in transforms {
        header(&mut w, t.stamp, &t.parent);
        w.string(&t.child);
        t.pose.write(&mut w);
    }
    w.finish()
}

/// `rosgraph_msgs/msg/Clock`.
#[must_use]
pub fn clock(t: Time) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.i32(t.sec);
    w.u32(t.nanosec);
    w.finish()
}

/// A point as the ROS Velodyne driver publishes it (`velodyne_pointcloud`'s XYZIRT): x, y, z,
/// intensity (float32), ring (uint16), time (float32, seconds after the cloud's stamp), packed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelodynePoint {
    /// Metres, in the sensor frame.
    pub xyz: [f32; 3],
    /// The driver's intensity (0-255 for a Velodyne; here the calibrated remission 0..1 times 255).
    pub intensity: f32,
    /// Beam, 0 lowest.
    pub ring: u16,
    /// Seconds after the stamp.
    pub time: f32,
}

/// Bytes of one [`VelodynePoint`] in the cloud.
pub const VELODYNE_POINT_STEP: u32 = 22;

/// The Velodyne point's fields: name, byte offset, ROS datatype (7 float32, 4 uint16).
pub const VELODYNE_FIELDS: [(&str, u32, u8); 6] = [
    ("x", 0, 7),
    ("y", 4, 7),
    ("z", 8, 7),
    ("intensity", 12, 7),
    ("ring", 16, 4),
    ("time", 18, 7),
];

fn velodyne_point(p: &VelodynePoint) -> [u8; VELODYNE_POINT_STEP as usize] {
    let mut b = [0u8; VELODYNE_POINT_STEP as usize];
    for (k, v) in p.xyz.iter().enumerate() {
        b[4 * k..4 * k + 4].copy_from_slice(&v.to_le_bytes());
    }
    b[12..16].copy_from_slice(&p.intensity.to_le_bytes());
    b[16..18].copy_from_slice(&p.ring.to_le_bytes());
    b[18..22].copy_from_slice(&p.time.to_le_bytes());
    b
}

/// The points packed as a cloud's `data` (little-endian, [`VELODYNE_FIELDS`]).
#[must_use]
pub fn velodyne_data(points: &[VelodynePoint]) -> Vec<u8> {
    let mut data = Vec::with_capacity(VELODYNE_POINT_STEP as usize * points.len());
    for p in points {
        data.extend_from_slice(&velodyne_point(p));
    }
    data
}

/// `sensor_msgs/msg/PointCloud2` of Velodyne points, unorganised (height 1), dense.
#[must_use]
pub fn velodyne_cloud(stamp: Time, frame_id: &str, points: &[VelodynePoint]) -> Vec<u8> {
    let step = VELODYNE_POINT_STEP as usize;
    let mut w = CdrWriter::with_capacity(200 + step * points.len());
    header(&mut w, stamp, frame_id);
    w.u32(1);
    w.u32(u32::try_from(points.len()).unwrap_or(u32::MAX));
    w.count(VELODYNE_FIELDS.len());
    for (name, offset, datatype) in VELODYNE_FIELDS {
        w.string(name);
        w.u32(offset);
        w.u8(datatype);
        w.u32(1);
    }
    w.bool(false);
    w.u32(VELODYNE_POINT_STEP);
    w.u32(u32::try_from(step * points.len()).unwrap_or(u32::MAX));
    // The points straight into the message (no second copy of 1.5 MB a revolution).
    w.count(step * points.len());
    for p in points {
        w.raw(&velodyne_point(p));
    }
    w.bool(true);
    w.finish()
}

/// `nav_msgs/msg/Odometry`.
#[must_use]
pub fn odometry(
    stamp: Time,
    frame_id: &str,
    child: &str,
    pose: &Pose,
    pose_covariance: &[f64; 36],
    twist: [[f64; 3]; 2],
) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(740);
    header(&mut w, stamp, frame_id);
    w.string(child);
    pose.write(&mut w);
    pose_covariance.iter().for_each(|&v| w.f64(v));
    twist.iter().flatten().for_each(|&v| w.f64(v));
    (0..36).for_each(|_| w.f64(0.0));
    w.finish()
}

/// `geometry_msgs/msg/PoseWithCovarianceStamped`.
#[must_use]
pub fn pose_with_covariance(
    stamp: Time,
    frame_id: &str,
    pose: &Pose,
    covariance: &[f64; 36],
) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(380);
    header(&mut w, stamp, frame_id);
    pose.write(&mut w);
    covariance.iter().for_each(|&v| w.f64(v));
    w.finish()
}

/// `ackermann_msgs/msg/AckermannDriveStamped`: steering angle (rad) and speed (m/s).
#[must_use]
pub fn ackermann(stamp: Time, frame_id: &str, steering_angle: f32, speed: f32) -> Vec<u8> {
    let mut w = CdrWriter::new();
    header(&mut w, stamp, frame_id);
    for v in [steering_angle, 0.0, speed, 0.0, 0.0] {
        w.f32(v);
    }
    w.finish()
}

/// `nav_msgs/msg/OccupancyGrid`: `data` row-major from the origin's row, ROS values (0 free,
/// 100 occupied, -1 unknown).
#[must_use]
pub fn occupancy_grid(
    stamp: Time,
    frame_id: &str,
    resolution_m: f32,
    (width, height): (u32, u32),
    origin: &Pose,
    data: &[i8],
) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(120 + data.len());
    header(&mut w, stamp, frame_id);
    w.i32(stamp.sec);
    w.u32(stamp.nanosec);
    w.f32(resolution_m);
    w.u32(width);
    w.u32(height);
    origin.write(&mut w);
    w.count(data.len());
    data.iter().for_each(|&v| w.i8(v));
    w.finish()
}

/// `nav_msgs/msg/Path` of planar poses (x, y, yaw).
#[must_use]
pub fn path(stamp: Time, frame_id: &str, poses: &[(f64, f64, f64)]) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(96 * poses.len() + 32);
    header(&mut w, stamp, frame_id);
    w.count(poses.len());
    for &(x, y, yaw) in poses {
        header(&mut w, stamp, frame_id);
        Pose::planar(x, y, 0.0, yaw).write(&mut w);
    }
    w.finish()
}

/// `std_msgs/msg/String`.
#[must_use]
pub fn string(data: &str) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.string(data);
    w.finish()
}

/// One shape of a `visualization_msgs/Marker` (the types taxi-sim draws).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkerShape {
    /// `CUBE`: scale is the full size.
    Cube = 1,
    /// `CYLINDER`: scale x, y the diameters, z the height.
    Cylinder = 3,
}

/// A marker: a shape added (or replaced: the same `ns` and `id`) with no lifetime limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// Shape.
    pub shape: MarkerShape,
    /// Pose of its centre in the array's frame.
    pub pose: Pose,
    /// Size, metres.
    pub scale: [f64; 3],
    /// Colour r, g, b, a in 0..1.
    pub color: [f32; 4],
    /// Whether it follows its frame's later transforms (a vehicle's own circles).
    pub frame_locked: bool,
}

fn marker(w: &mut CdrWriter, stamp: Time, frame_id: &str, m: &Marker, action: i32) {
    header(w, stamp, frame_id);
    w.string(&m.ns);
    w.i32(m.id);
    w.i32(m.shape as i32);
    w.i32(action);
    m.pose.write(w);
    m.scale.iter().for_each(|&v| w.f64(v));
    m.color.iter().for_each(|&v| w.f32(v));
    w.i32(0); // lifetime: forever
    w.u32(0);
    w.bool(m.frame_locked);
    w.count(0); // points
    w.count(0); // colors
    w.string(""); // texture_resource
    header(w, stamp, frame_id); // texture: none
    w.string("");
    w.count(0);
    w.count(0); // uv_coordinates
    w.string(""); // text
    w.string(""); // mesh_resource
    w.string(""); // mesh_file
    w.count(0);
    w.bool(false);
}

/// `visualization_msgs/msg/MarkerArray`: with `clear`, a `DELETEALL` first (what was drawn
/// before goes), then `markers` added.
#[must_use]
pub fn marker_array(stamp: Time, frame_id: &str, clear: bool, markers: &[Marker]) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(256 * (markers.len() + 1));
    w.count(markers.len() + usize::from(clear));
    if clear {
        let none = Marker {
            ns: String::new(),
            id: 0,
            shape: MarkerShape::Cube,
            pose: Pose::planar(0.0, 0.0, 0.0, 0.0),
            scale: [1.0; 3],
            color: [0.0; 4],
            frame_locked: false,
        };
        marker(&mut w, stamp, frame_id, &none, 3);
    }
    for m in markers {
        marker(&mut w, stamp, frame_id, m, 0);
    }
    w.finish()
}

fn read_time(r: &mut CdrReader<'_>) -> Result<Time, CdrError> {
    let at = r.offset();
    let sec = r.i32("header.stamp.sec")?;
    let nanosec = r.u32("header.stamp.nanosec")?;
    if sec < 0 || nanosec >= 1_000_000_000 {
        return Err(CdrError::new(
            "header.stamp",
            at,
            format!("{sec} s {nanosec} ns is not a time after the epoch"),
        ));
    }
    Ok(Time { sec, nanosec })
}

fn read_pose(r: &mut CdrReader<'_>, field: &'static str) -> Result<Pose, CdrError> {
    let at = r.offset();
    let mut v = [0.0; 7];
    for x in &mut v {
        *x = r.f64(field)?;
    }
    let q = [v[3], v[4], v[5], v[6]];
    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !v.iter().all(|x| x.is_finite()) || (norm - 1.0).abs() > 1e-3 {
        return Err(CdrError::new(
            field,
            at,
            format!("{v:?} is not a finite position and a unit quaternion"),
        ));
    }
    Ok(Pose {
        position: [v[0], v[1], v[2]],
        orientation: q.map(|x| x / norm),
    })
}

/// Reads a `tf2_msgs/msg/TFMessage`.
///
/// # Errors
/// The message is malformed, a pose is not finite or its quaternion not of unit length.
pub fn read_tf_message(cdr: &[u8]) -> Result<Vec<Transform>, CdrError> {
    let mut r = CdrReader::new(cdr)?;
    let n = r.count("transforms", 60)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let stamp = read_time(&mut r)?;
        let parent = r.string("header.frame_id")?;
        let child = r.string("child_frame_id")?;
        let pose = read_pose(&mut r, "transform")?;
        out.push(Transform {
            stamp,
            parent,
            child,
            pose,
        });
    }
    Ok(out)
}

/// Reads a `nav_msgs/msg/Odometry`'s stamp and pose: the child frame's pose in the header's frame.
///
/// # Errors
/// The message is malformed, or its pose is not finite or its quaternion not of unit length.
pub fn read_odometry(cdr: &[u8]) -> Result<Transform, CdrError> {
    let mut r = CdrReader::new(cdr)?;
    let stamp = read_time(&mut r)?;
    let parent = r.string("header.frame_id")?;
    let child = r.string("child_frame_id")?;
    let pose = read_pose(&mut r, "pose.pose")?;
    Ok(Transform {
        stamp,
        parent,
        child,
        pose,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schemas_put_the_type_first_and_its_dependencies_after_separators() {
        let text = POINT_CLOUD2.schema();
        assert!(text.starts_with("std_msgs/Header header\nuint32 height\n"));
        let sep = format!("{}\nMSG: std_msgs/Header\n", "=".repeat(80));
        assert!(text.contains(&sep), "{text}");
        assert_eq!(text.matches("\nMSG: ").count(), 3);
        assert_eq!(STRING.schema(), "string data\n");
    }

    /// Sizes the notes measured with rosbags: PoseWithCovarianceStamped in "map" 364 bytes,
    /// Odometry "odom"/"base_link" 724.
    #[test]
    fn fixed_size_messages_have_the_sizes_ros_gives_them() {
        let pose = Pose::planar(1.0, 2.0, 0.0, 0.5);
        assert_eq!(
            pose_with_covariance(Time::from_ns(1), "map", &pose, &[0.0; 36]).len(),
            364
        );
        assert_eq!(
            odometry(
                Time::from_ns(1),
                "odom",
                "base_link",
                &pose,
                &[0.0; 36],
                [[0.0; 3]; 2]
            )
            .len(),
            724
        );
        let cloud = velodyne_cloud(
            Time::from_ns(1),
            "velodyne",
            &[VelodynePoint {
                xyz: [1.0, 2.0, 3.0],
                intensity: 4.0,
                ring: 5,
                time: 0.01,
            }; 3],
        );
        assert_eq!(&cloud[cloud.len() - 1..], &[1]);
        assert_eq!(
            Time::from_ns(1_704_067_200_123_456_789).ns(),
            1_704_067_200_123_456_789
        );
    }
}
