//! Every message type's CDR decoded by its own schema - field by field from the `ros2msg` text
//! a bag embeds, as rosbags or Foxglove decode it - and compared with what was encoded: each
//! encoder writes exactly the fields its schema names, in its order, widths and alignment, and
//! nothing after them (frame ids of every length shift the alignment); the crate's own readers
//! give back what was written.

use std::collections::HashMap;

use ros2::CdrError;
use ros2::cdr::CdrReader;
use ros2::msgs::{self, Marker, MarkerShape, MsgType, Pose, Time, Transform, VelodynePoint};

use crate::common::T0;

/// Every message type the crate writes.
const ALL: [MsgType; 10] = [
    msgs::CLOCK,
    msgs::TF_MESSAGE,
    msgs::POINT_CLOUD2,
    msgs::ODOMETRY,
    msgs::POSE_WITH_COVARIANCE_STAMPED,
    msgs::ACKERMANN_DRIVE_STAMPED,
    msgs::OCCUPANCY_GRID,
    msgs::PATH,
    msgs::MARKER_ARRAY,
    msgs::STRING,
];

/// Frame ids of 0 to 12 bytes: whatever follows starts at every alignment.
const FRAMES: [&str; 7] = ["", "m", "map", "odom", "lidar", "base_link", "velodyne_top"];

const PRIMITIVES: [&str; 13] = [
    "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "float32", "float64",
];

/// A value decoded by a schema.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Bool(bool),
    Int(i64),
    Float(f64),
    Text(String),
    List(Vec<Value>),
    Msg(Vec<(String, Value)>),
}

/// A schema's definitions: each type's fields as `(type, name)`, the message's own under "".
type Defs = HashMap<String, Vec<(String, String)>>;

/// The definitions in `msg`'s schema text (constants left out).
fn parse_schema(msg: &MsgType) -> Defs {
    let text = msg.schema();
    let mut defs = Defs::new();
    let mut current = String::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if !line.is_empty() && line.chars().all(|c| c == '=') {
            let next = lines.next().unwrap_or_default();
            let Some(name) = next.strip_prefix("MSG: ") else {
                panic!("{}: {next:?} after a separator", msg.name);
            };
            current = name.to_string();
            continue;
        }
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.contains('=') {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let &[ty, name] = words.as_slice() else {
            panic!("{}: {line:?} is not `type name`", msg.name);
        };
        let fields = defs.entry(current.clone()).or_default();
        fields.push((ty.to_string(), name.to_string()));
    }
    defs
}

/// `ty` without its array suffix (`float64[36]`, `uint8[]`).
fn element(ty: &str) -> &str {
    ty.split_once('[').map_or(ty, |(e, _)| e)
}

/// Reads one value of type `ty` (the field `name`) as the schema says.
fn decode(r: &mut CdrReader<'_>, defs: &Defs, ty: &str, name: &str) -> Result<Value, String> {
    let err = |e: CdrError| format!("{name} ({ty}): {e}");
    if let Some((item, len)) = ty.strip_suffix(']').and_then(|t| t.split_once('[')) {
        let n = if len.is_empty() {
            r.count("sequence", 1).map_err(err)?
        } else {
            len.parse().map_err(|_| format!("{name}: {ty}"))?
        };
        let items: Result<Vec<Value>, String> =
            (0..n).map(|_| decode(r, defs, item, name)).collect();
        return items.map(Value::List);
    }
    Ok(match ty {
        "bool" => Value::Bool(r.bool("bool").map_err(err)?),
        "int8" => Value::Int(i64::from(r.u8("int8").map_err(err)? as i8)),
        "uint8" | "byte" | "char" => Value::Int(i64::from(r.u8("uint8").map_err(err)?)),
        "int16" => Value::Int(i64::from(r.u16("int16").map_err(err)? as i16)),
        "uint16" => Value::Int(i64::from(r.u16("uint16").map_err(err)?)),
        "int32" => Value::Int(i64::from(r.i32("int32").map_err(err)?)),
        "uint32" => Value::Int(i64::from(r.u32("uint32").map_err(err)?)),
        "int64" | "uint64" => Value::Int(r.u64("int64").map_err(err)? as i64),
        "float32" => Value::Float(f64::from(r.f32("float32").map_err(err)?)),
        "float64" => Value::Float(r.f64("float64").map_err(err)?),
        "string" => Value::Text(r.string("string").map_err(err)?),
        nested => {
            let fields = defs
                .get(nested)
                .ok_or_else(|| format!("{name}: type {nested} is not in the schema"))?;
            let mut out = Vec::with_capacity(fields.len());
            for (t, n) in fields {
                out.push((n.clone(), decode(r, defs, t, n)?));
            }
            Value::Msg(out)
        }
    })
}

/// `cdr` decoded as `msg`'s schema says, every byte of it used.
fn decoded(msg: &MsgType, cdr: &[u8]) -> Value {
    let defs = parse_schema(msg);
    let mut r = CdrReader::new(cdr).unwrap();
    let v = decode(&mut r, &defs, "", msg.name).unwrap_or_else(|e| panic!("{}: {e}", msg.name));
    assert_eq!(
        r.offset(),
        cdr.len(),
        "{}: bytes after the last field",
        msg.name
    );
    v
}

/// The value at `path` (`markers.1.pose.position.x`: fields by name, list items by index).
fn at<'a>(v: &'a Value, path: &str) -> &'a Value {
    path.split('.').fold(v, |v, key| match v {
        Value::Msg(fields) => fields
            .iter()
            .find(|(n, _)| n == key)
            .map(|(_, v)| v)
            .unwrap_or_else(|| panic!("{path}: no field {key}")),
        Value::List(items) => &items[key.parse::<usize>().unwrap()],
        other => panic!("{path}: {key} of {other:?}"),
    })
}

fn float(v: &Value, path: &str) -> f64 {
    match at(v, path) {
        Value::Float(x) => *x,
        other => panic!("{path}: {other:?}"),
    }
}

fn int(v: &Value, path: &str) -> i64 {
    match at(v, path) {
        Value::Int(x) => *x,
        other => panic!("{path}: {other:?}"),
    }
}

fn text<'a>(v: &'a Value, path: &str) -> &'a str {
    match at(v, path) {
        Value::Text(x) => x,
        other => panic!("{path}: {other:?}"),
    }
}

fn list<'a>(v: &'a Value, path: &str) -> &'a [Value] {
    match at(v, path) {
        Value::List(x) => x,
        other => panic!("{path}: {other:?}"),
    }
}

fn boolean(v: &Value, path: &str) -> bool {
    match at(v, path) {
        Value::Bool(x) => *x,
        other => panic!("{path}: {other:?}"),
    }
}

fn floats(v: &Value, path: &str) -> Vec<f64> {
    (0..list(v, path).len())
        .map(|i| float(v, &format!("{path}.{i}")))
        .collect()
}

/// A `builtin_interfaces/Time` at `path`.
fn stamp_of(v: &Value, path: &str) -> Time {
    let sec = i32::try_from(int(v, &format!("{path}.sec"))).unwrap();
    let nanosec = u32::try_from(int(v, &format!("{path}.nanosec"))).unwrap();
    Time { sec, nanosec }
}

/// A header's stamp and frame at `path`.
fn header_of<'a>(v: &'a Value, path: &str) -> (Time, &'a str) {
    (
        stamp_of(v, &format!("{path}.stamp")),
        text(v, &format!("{path}.frame_id")),
    )
}

/// Position and quaternion (x y z, then x y z w) at `path`, named as `geometry_msgs/Pose`
/// (`position`, `orientation`) or `geometry_msgs/Transform` (`translation`, `rotation`).
fn pose_of(v: &Value, path: &str, (position, orientation): (&str, &str)) -> [f64; 7] {
    let p = |axis: &str| float(v, &format!("{path}.{position}.{axis}"));
    let q = |axis: &str| float(v, &format!("{path}.{orientation}.{axis}"));
    [p("x"), p("y"), p("z"), q("x"), q("y"), q("z"), q("w")]
}

const POSE: (&str, &str) = ("position", "orientation");

fn seven(p: &Pose) -> [f64; 7] {
    let [x, y, z] = p.position;
    let [qx, qy, qz, qw] = p.orientation;
    [x, y, z, qx, qy, qz, qw]
}

fn close(a: &Pose, b: &Pose) -> bool {
    seven(a)
        .iter()
        .zip(seven(b))
        .all(|(a, b)| (a - b).abs() < 1e-12)
}

/// The `i`th test pose: a full 3-D orientation.
fn pose(i: usize) -> Pose {
    let q = [0.1 * i as f64, -0.2, 0.3, 0.9];
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    Pose {
        position: [i as f64 + 0.5, -1.5 * i as f64, 0.25],
        orientation: q.map(|x| x / n),
    }
}

fn stamp(k: usize) -> Time {
    Time::from_ns(T0 + k as u64 * 7_777_777)
}

/// Every type a schema's fields name is a primitive or is defined in the schema - the element
/// types of sequences an encoder leaves empty too, which no decode below reaches - and every
/// type has its RIHS01 hash.
#[test]
fn every_schema_defines_every_type_it_uses() {
    for msg in ALL {
        let defs = parse_schema(&msg);
        assert!(defs.contains_key(""), "{}", msg.name);
        for (owner, fields) in &defs {
            for (ty, name) in fields {
                let e = element(ty);
                assert!(
                    PRIMITIVES.contains(&e) || e == "string" || defs.contains_key(e),
                    "{}: {owner}.{name}: {ty} is not defined",
                    msg.name
                );
            }
        }
        let hash = msg.hash.strip_prefix("RIHS01_").unwrap_or_default();
        assert!(
            hash.len() == 64 && hash.bytes().all(|b| b.is_ascii_hexdigit()),
            "{}: {}",
            msg.name,
            msg.hash
        );
        assert_eq!(msg.name.split('/').nth(1), Some("msg"), "{}", msg.name);
    }
}

/// `Clock` and `String` by their schemas.
#[test]
fn clock_and_string_decode_by_their_schemas() {
    for ns in [0, 1, 999_999_999, T0 + 123_456_789] {
        let v = decoded(&msgs::CLOCK, &msgs::clock(Time::from_ns(ns)));
        assert_eq!(stamp_of(&v, "clock").ns(), ns);
    }
    for s in ["", "a", "{\"stop\":1}", "Zürich ✈ KSYR"] {
        let v = decoded(&msgs::STRING, &msgs::string(s));
        assert_eq!(text(&v, "data"), s);
    }
}

/// `TFMessage` of one to seven transforms by its schema, and read back by `read_tf_message`.
#[test]
fn transforms_decode_by_their_schema_and_read_back() {
    for (k, frame) in FRAMES.iter().enumerate() {
        let transforms: Vec<Transform> = (0..=k)
            .map(|i| Transform {
                stamp: stamp(k + i),
                parent: FRAMES[i].to_string(),
                child: (*frame).to_string(),
                pose: pose(i),
            })
            .collect();
        let cdr = msgs::tf_message(&transforms);
        let v = decoded(&msgs::TF_MESSAGE, &cdr);
        assert_eq!(list(&v, "transforms").len(), transforms.len());
        for (i, t) in transforms.iter().enumerate() {
            let p = format!("transforms.{i}");
            assert_eq!(
                header_of(&v, &format!("{p}.header")),
                (t.stamp, t.parent.as_str())
            );
            assert_eq!(text(&v, &format!("{p}.child_frame_id")), t.child);
            let got = pose_of(&v, &format!("{p}.transform"), ("translation", "rotation"));
            assert_eq!(got, seven(&t.pose), "{p}");
        }
        let back = msgs::read_tf_message(&cdr).unwrap();
        assert_eq!(back.len(), transforms.len());
        for (a, b) in back.iter().zip(&transforms) {
            assert_eq!(
                (a.stamp, &a.parent, &a.child),
                (b.stamp, &b.parent, &b.child)
            );
            assert!(close(&a.pose, &b.pose), "{a:?} {b:?}");
        }
    }
}

/// `Odometry` and `PoseWithCovarianceStamped` by their schemas (covariances and twist where
/// the schema puts them), odometry read back by `read_odometry`.
#[test]
fn odometry_and_poses_with_covariance_decode_by_their_schemas() {
    let covariance: [f64; 36] = std::array::from_fn(|i| i as f64 - 17.5);
    let twist = [[1.0, 2.0, 3.0], [-0.1, -0.2, -0.3]];
    for (k, frame) in FRAMES.iter().enumerate() {
        let cdr = msgs::odometry(stamp(k), frame, "base_link", &pose(k), &covariance, twist);
        let v = decoded(&msgs::ODOMETRY, &cdr);
        assert_eq!(header_of(&v, "header"), (stamp(k), *frame));
        assert_eq!(text(&v, "child_frame_id"), "base_link");
        assert_eq!(pose_of(&v, "pose.pose", POSE), seven(&pose(k)));
        assert_eq!(floats(&v, "pose.covariance"), covariance);
        let linear = ["x", "y", "z"].map(|a| float(&v, &format!("twist.twist.linear.{a}")));
        let angular = ["x", "y", "z"].map(|a| float(&v, &format!("twist.twist.angular.{a}")));
        assert_eq!([linear, angular], twist);
        assert_eq!(floats(&v, "twist.covariance"), [0.0; 36]);
        let o = msgs::read_odometry(&cdr).unwrap();
        assert_eq!(
            (o.stamp, o.parent.as_str(), o.child.as_str()),
            (stamp(k), *frame, "base_link")
        );
        assert!(close(&o.pose, &pose(k)), "{o:?}");

        let cdr = msgs::pose_with_covariance(stamp(k), frame, &pose(k), &covariance);
        let v = decoded(&msgs::POSE_WITH_COVARIANCE_STAMPED, &cdr);
        assert_eq!(header_of(&v, "header"), (stamp(k), *frame));
        assert_eq!(pose_of(&v, "pose.pose", POSE), seven(&pose(k)));
        assert_eq!(floats(&v, "pose.covariance"), covariance);
    }
}

/// `AckermannDriveStamped`, `OccupancyGrid` and `Path` by their schemas.
#[test]
fn drive_commands_grids_and_paths_decode_by_their_schemas() {
    for (k, frame) in FRAMES.iter().enumerate() {
        let (steer, speed) = (0.05f32 * k as f32 - 0.2, 2.5f32 - k as f32);
        let v = decoded(
            &msgs::ACKERMANN_DRIVE_STAMPED,
            &msgs::ackermann(stamp(k), frame, steer, speed),
        );
        assert_eq!(header_of(&v, "header"), (stamp(k), *frame));
        let drive = [
            "steering_angle",
            "steering_angle_velocity",
            "speed",
            "acceleration",
            "jerk",
        ]
        .map(|f| float(&v, &format!("drive.{f}")));
        assert_eq!(drive, [f64::from(steer), 0.0, f64::from(speed), 0.0, 0.0]);

        let (width, height) = (k as u32 + 1, 2);
        let cells: Vec<i8> = (0..width * height)
            .map(|i| [-1, 0, 100, 37][i as usize % 4])
            .collect();
        let cdr = msgs::occupancy_grid(stamp(k), frame, 0.2, (width, height), &pose(k), &cells);
        let v = decoded(&msgs::OCCUPANCY_GRID, &cdr);
        assert_eq!(header_of(&v, "header"), (stamp(k), *frame));
        assert_eq!(stamp_of(&v, "info.map_load_time"), stamp(k));
        assert_eq!(float(&v, "info.resolution"), f64::from(0.2f32));
        assert_eq!(
            (int(&v, "info.width"), int(&v, "info.height")),
            (i64::from(width), 2)
        );
        assert_eq!(pose_of(&v, "info.origin", POSE), seven(&pose(k)));
        let data: Vec<i64> = (0..cells.len())
            .map(|i| int(&v, &format!("data.{i}")))
            .collect();
        assert_eq!(
            data,
            cells.iter().map(|&c| i64::from(c)).collect::<Vec<_>>()
        );

        let poses: Vec<(f64, f64, f64)> = (0..k)
            .map(|i| (i as f64, -(i as f64), 0.1 * i as f64))
            .collect();
        let v = decoded(&msgs::PATH, &msgs::path(stamp(k), frame, &poses));
        assert_eq!(header_of(&v, "header"), (stamp(k), *frame));
        assert_eq!(list(&v, "poses").len(), k);
        for (i, &(x, y, yaw)) in poses.iter().enumerate() {
            let p = format!("poses.{i}");
            assert_eq!(header_of(&v, &format!("{p}.header")), (stamp(k), *frame));
            let want = seven(&Pose::planar(x, y, 0.0, yaw));
            assert_eq!(pose_of(&v, &format!("{p}.pose"), POSE), want, "{p}");
        }
    }
}

/// `MarkerArray` (ROS 2 Jazzy's `Marker`, texture and mesh fields included) by its schema,
/// with and without the `DELETEALL` that clears what was drawn before.
#[test]
fn marker_arrays_decode_by_their_schema() {
    for (k, frame) in FRAMES.iter().enumerate() {
        let markers: Vec<Marker> = (0..k.min(3))
            .map(|i| Marker {
                ns: FRAMES[k - i].to_string(),
                id: i as i32 - 1,
                shape: if i % 2 == 0 {
                    MarkerShape::Cube
                } else {
                    MarkerShape::Cylinder
                },
                pose: pose(i),
                scale: [1.0 + i as f64, 2.0, 0.5],
                color: [0.1, 0.2 * i as f32, 0.3, 1.0],
                frame_locked: i == 1,
            })
            .collect();
        for clear in [false, true] {
            let cdr = msgs::marker_array(stamp(k), frame, clear, &markers);
            let v = decoded(&msgs::MARKER_ARRAY, &cdr);
            let first = usize::from(clear);
            assert_eq!(list(&v, "markers").len(), markers.len() + first);
            if clear {
                assert_eq!(int(&v, "markers.0.action"), 3, "DELETEALL");
            }
            for (i, m) in markers.iter().enumerate() {
                let p = format!("markers.{}", i + first);
                let f = |field: &str| format!("{p}.{field}");
                assert_eq!(header_of(&v, &f("header")), (stamp(k), *frame));
                assert_eq!(
                    (text(&v, &f("ns")), int(&v, &f("id"))),
                    (m.ns.as_str(), i64::from(m.id))
                );
                assert_eq!(
                    (int(&v, &f("type")), int(&v, &f("action"))),
                    (m.shape as i64, 0)
                );
                assert_eq!(pose_of(&v, &f("pose"), POSE), seven(&m.pose));
                let scale = ["x", "y", "z"].map(|a| float(&v, &f(&format!("scale.{a}"))));
                assert_eq!(scale, m.scale);
                let color = ["r", "g", "b", "a"].map(|a| float(&v, &f(&format!("color.{a}"))));
                assert_eq!(color, m.color.map(f64::from));
                assert_eq!(stamp_of(&v, &f("lifetime")), Time { sec: 0, nanosec: 0 });
                assert_eq!(boolean(&v, &f("frame_locked")), m.frame_locked);
                for empty in [
                    "points",
                    "colors",
                    "uv_coordinates",
                    "texture.data",
                    "mesh_file.data",
                ] {
                    assert!(list(&v, &f(empty)).is_empty(), "{p}.{empty}");
                }
                for empty in [
                    "texture_resource",
                    "text",
                    "mesh_resource",
                    "mesh_file.filename",
                ] {
                    assert_eq!(text(&v, &f(empty)), "", "{p}.{empty}");
                }
                assert!(!boolean(&v, &f("mesh_use_embedded_materials")));
            }
        }
    }
}

/// A Velodyne `PointCloud2` by its schema: its fields declared as the ROS driver declares them
/// (XYZIRT, packed in 22 bytes) and each point's bytes where its fields say.
#[test]
fn velodyne_clouds_decode_by_their_schema() {
    let declared = [
        ("x", 0, 7),
        ("y", 4, 7),
        ("z", 8, 7),
        ("intensity", 12, 7),
        ("ring", 16, 4),
        ("time", 18, 7),
    ];
    for (k, frame) in FRAMES.iter().enumerate() {
        let points: Vec<VelodynePoint> = (0..k * 3)
            .map(|i| VelodynePoint {
                xyz: [i as f32, -0.5 * i as f32, 1.25],
                intensity: 3.0 * i as f32,
                ring: (31 - i % 32) as u16,
                time: 1e-3 * i as f32,
            })
            .collect();
        let v = decoded(
            &msgs::POINT_CLOUD2,
            &msgs::velodyne_cloud(stamp(k), frame, &points),
        );
        assert_eq!(header_of(&v, "header"), (stamp(k), *frame));
        let n = points.len() as i64;
        let step = i64::from(msgs::VELODYNE_POINT_STEP);
        assert_eq!((int(&v, "height"), int(&v, "width")), (1, n));
        assert_eq!(
            (int(&v, "point_step"), int(&v, "row_step")),
            (step, step * n)
        );
        assert!(!boolean(&v, "is_bigendian") && boolean(&v, "is_dense"));
        assert_eq!(list(&v, "fields").len(), declared.len());
        for (i, (name, offset, datatype)) in declared.into_iter().enumerate() {
            let p = format!("fields.{i}");
            assert_eq!(text(&v, &format!("{p}.name")), name);
            let layout = ["offset", "datatype", "count"].map(|f| int(&v, &format!("{p}.{f}")));
            assert_eq!(layout, [offset, datatype, 1], "{name}");
        }
        let data: Vec<u8> = list(&v, "data")
            .iter()
            .map(|b| match b {
                Value::Int(b) => u8::try_from(*b).unwrap(),
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(data.len() as i64, step * n);
        for (p, b) in points.iter().zip(data.chunks(22)) {
            let f32_at = |at: usize| f32::from_le_bytes(b[at..at + 4].try_into().unwrap());
            assert_eq!([f32_at(0), f32_at(4), f32_at(8)], p.xyz);
            assert_eq!(f32_at(12), p.intensity);
            assert_eq!(u16::from_le_bytes([b[16], b[17]]), p.ring);
            assert_eq!(f32_at(18), p.time);
        }
    }
}
