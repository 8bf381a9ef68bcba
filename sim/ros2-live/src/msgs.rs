//! The standard ROS 2 messages the live peer sends and takes, as serde structs in their IDL
//! field order (what `ros2-client` serialises to CDR), built from the simulator's own types. The
//! bags of `run --record` carry the same messages: the tests check byte equality with the `ros2`
//! crate's encoders.

use bytes::Bytes;
use ros2::msgs::{Pose as BagPose, Time as BagTime, VelodynePoint};
use ros2_client::Message;
use serde::de::{SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `builtin_interfaces/Time`.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, 0..1e9.
    pub nanosec: u32,
}

impl From<BagTime> for Time {
    fn from(t: BagTime) -> Self {
        Time {
            sec: t.sec,
            nanosec: t.nanosec,
        }
    }
}

/// `std_msgs/Header`.
#[derive(Serialize, Deserialize, Clone, Debug, Default, PartialEq)]
pub struct Header {
    /// When.
    pub stamp: Time,
    /// In which frame.
    pub frame_id: String,
}

impl Header {
    /// A header stamped `stamp` in `frame`.
    pub fn new(stamp: Time, frame: &str) -> Self {
        Header {
            stamp,
            frame_id: frame.into(),
        }
    }
}

/// `rosgraph_msgs/Clock`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Clock {
    /// The simulated time.
    pub clock: Time,
}

/// `geometry_msgs/Vector3` (also `Point`: the same three doubles).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, Default, PartialEq)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

/// `geometry_msgs/Pose` (also `Transform`: translation and rotation in the same order).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Position (translation).
    pub position: Vector3,
    /// Orientation (rotation).
    pub orientation: Quaternion,
}

impl From<BagPose> for Pose {
    fn from(p: BagPose) -> Self {
        let [x, y, z] = p.position;
        let [qx, qy, qz, qw] = p.orientation;
        Pose {
            position: Vector3 { x, y, z },
            orientation: Quaternion {
                x: qx,
                y: qy,
                z: qz,
                w: qw,
            },
        }
    }
}

impl From<Pose> for BagPose {
    fn from(p: Pose) -> Self {
        let Quaternion { x, y, z, w } = p.orientation;
        BagPose {
            position: [p.position.x, p.position.y, p.position.z],
            orientation: [x, y, z, w],
        }
    }
}

/// A 6x6 covariance, row-major (`float64[36]`: the elements alone in CDR).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Covariance(pub [f64; 36]);

impl Serialize for Covariance {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(36)?;
        for v in &self.0 {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Covariance {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Elements;
        impl<'de> Visitor<'de> for Elements {
            type Value = Covariance;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("36 doubles")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Covariance, A::Error> {
                let mut c = [0.0; 36];
                for (k, v) in c.iter_mut().enumerate() {
                    *v = seq
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(k, &self))?;
                }
                Ok(Covariance(c))
            }
        }
        d.deserialize_tuple(36, Elements)
    }
}

/// `geometry_msgs/TransformStamped`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// The child's pose in the parent.
    pub transform: Pose,
}

/// `tf2_msgs/TFMessage`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

/// `sensor_msgs/PointField`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PointField {
    /// Field name.
    pub name: String,
    /// Byte offset in a point.
    pub offset: u32,
    /// ROS datatype code (7 float32, 4 uint16).
    pub datatype: u8,
    /// Elements.
    pub count: u32,
}

/// `sensor_msgs/PointCloud2`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PointCloud2 {
    /// Stamp and sensor frame.
    pub header: Header,
    /// Rows (1: unorganised).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// The point layout.
    pub fields: Vec<PointField>,
    /// Byte order of `data`.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// The points.
    pub data: Bytes,
    /// No invalid points.
    pub is_dense: bool,
}

impl PointCloud2 {
    /// A revolution as the ROS Velodyne driver publishes it (`ros2::msgs::velodyne_cloud`'s
    /// layout: x, y, z, intensity, ring, time).
    pub fn velodyne(stamp: Time, frame: &str, points: &[VelodynePoint]) -> Self {
        let n = u32::try_from(points.len()).unwrap_or(u32::MAX);
        let step = ros2::msgs::VELODYNE_POINT_STEP;
        PointCloud2 {
            header: Header::new(stamp, frame),
            height: 1,
            width: n,
            fields: ros2::msgs::VELODYNE_FIELDS
                .iter()
                .map(|&(name, offset, datatype)| PointField {
                    name: name.into(),
                    offset,
                    datatype,
                    count: 1,
                })
                .collect(),
            is_bigendian: false,
            point_step: step,
            row_step: step.saturating_mul(n),
            data: Bytes::from(ros2::msgs::velodyne_data(points)),
            is_dense: true,
        }
    }
}

/// `geometry_msgs/PoseWithCovariance`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Its covariance over x, y, z, roll, pitch, yaw.
    pub covariance: Covariance,
}

/// `geometry_msgs/PoseWithCovarianceStamped`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PoseWithCovarianceStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose and its covariance.
    pub pose: PoseWithCovariance,
}

/// `geometry_msgs/Twist`.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, Default, PartialEq)]
pub struct Twist {
    /// m/s.
    pub linear: Vector3,
    /// rad/s.
    pub angular: Vector3,
}

/// `geometry_msgs/TwistWithCovariance`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Its covariance.
    pub covariance: Covariance,
}

/// `nav_msgs/Odometry`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Odometry {
    /// Stamp and the odometry frame.
    pub header: Header,
    /// The vehicle's frame.
    pub child_frame_id: String,
    /// The pose in the odometry frame.
    pub pose: PoseWithCovariance,
    /// The velocity in the vehicle's frame.
    pub twist: TwistWithCovariance,
}

/// `geometry_msgs/PoseStamped`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PoseStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose.
    pub pose: Pose,
}

/// `nav_msgs/Path`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Path {
    /// Stamp and frame.
    pub header: Header,
    /// The poses.
    pub poses: Vec<PoseStamped>,
}

/// `geometry_msgs/TwistStamped`: the command, as Nav2 publishes it.
#[derive(Serialize, Deserialize, Clone, Debug, Default, PartialEq)]
pub struct TwistStamped {
    /// The stamp of the step it answers.
    pub header: Header,
    /// The velocity asked for.
    pub twist: Twist,
}

/// A message the `ros2` crate already encodes for the bags (its CDR payload, the encapsulation
/// header dropped), sent as it is: its bytes go out one by one as a fixed-size array, which CDR
/// writes with neither a length nor padding, so the wire holds the bag's message byte for byte.
#[derive(Clone, Debug, PartialEq)]
pub struct RawCdr(pub Vec<u8>);

impl RawCdr {
    /// From a whole encoded message (with its 4-byte encapsulation header, as the bags hold it).
    pub fn from_message(message: &[u8]) -> Self {
        RawCdr(message.get(4..).unwrap_or_default().to_vec())
    }
}

impl Serialize for RawCdr {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeTuple;
        let mut t = s.serialize_tuple(self.0.len())?;
        for b in &self.0 {
            t.serialize_element(b)?;
        }
        t.end()
    }
}

impl Message for Clock {}
impl Message for TfMessage {}
impl Message for PointCloud2 {}
impl Message for PoseWithCovarianceStamped {}
impl Message for Odometry {}
impl Message for Path {}
impl Message for TwistStamped {}

#[cfg(test)]
mod tests {
    use super::*;
    use byteorder::LittleEndian;

    /// CDR as the transport writes it, with the 4-byte encapsulation header the bags carry.
    fn cdr<T: Serialize>(m: &T) -> Vec<u8> {
        let mut out = vec![0, 1, 0, 0];
        out.extend(cdr_encoding::to_vec::<T, LittleEndian>(m).unwrap());
        out
    }

    fn stamp() -> BagTime {
        BagTime::from_ns(1_704_067_212_300_000_000)
    }

    #[test]
    fn a_raw_message_goes_out_as_the_bags_bytes() {
        // A marker array: strings, arrays and doubles after odd lengths, so padding matters.
        let circle = |x_m, y_m, radius_m, level| mapper::Circle {
            x_m,
            y_m,
            radius_m,
            level,
        };
        let model = mapper::CollisionModel::new(
            vec![circle(0.5, 0.0, 1.25, 0), circle(-3.0, 2.0, 0.75, 1)],
            vec![0.0, 1.1],
        )
        .unwrap();
        let bag = sim::rosbag::collision_model_message(&model, &[0.0, 1.1], 1.5);
        assert!(bag.len() > 200);
        assert_eq!(cdr(&RawCdr::from_message(&bag)), bag);
    }

    #[test]
    fn a_cloud_is_the_bags_cloud_byte_for_byte() {
        let points = [
            VelodynePoint {
                xyz: [1.0, -2.0, 0.5],
                intensity: 40.0,
                ring: 3,
                time: 0.0,
            },
            VelodynePoint {
                xyz: [10.25, 0.0, -1.5],
                intensity: 255.0,
                ring: 31,
                time: 0.01,
            },
        ];
        let live = PointCloud2::velodyne(stamp().into(), "velodyne", &points);
        let bag = ros2::msgs::velodyne_cloud(stamp(), "velodyne", &points);
        assert_eq!(cdr(&live), bag);
    }

    #[test]
    fn clock_tf_and_pose_are_the_bags_byte_for_byte() {
        assert_eq!(
            cdr(&Clock {
                clock: stamp().into()
            }),
            ros2::msgs::clock(stamp())
        );
        let pose = BagPose::planar(3.0, -4.0, 0.0, 0.7);
        let tf = TfMessage {
            transforms: vec![TransformStamped {
                header: Header::new(stamp().into(), "odom"),
                child_frame_id: "base_link".into(),
                transform: pose.into(),
            }],
        };
        let bag = ros2::msgs::tf_message(&[ros2::msgs::Transform {
            stamp: stamp(),
            parent: "odom".into(),
            child: "base_link".into(),
            pose,
        }]);
        assert_eq!(cdr(&tf), bag);
        let mut c = [0.0; 36];
        c[0] = 0.04;
        c[35] = 0.001;
        let live = PoseWithCovarianceStamped {
            header: Header::new(stamp().into(), "map"),
            pose: PoseWithCovariance {
                pose: pose.into(),
                covariance: Covariance(c),
            },
        };
        let bag = ros2::msgs::pose_with_covariance(stamp(), "map", &pose, &c);
        assert_eq!(cdr(&live), bag);
    }

    #[test]
    fn odometry_is_the_bags_byte_for_byte() {
        let pose = BagPose::planar(1.0, 2.0, 0.0, -0.3);
        let mut c = [0.0; 36];
        c[7] = 0.5;
        let live = Odometry {
            header: Header::new(stamp().into(), "odom"),
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: pose.into(),
                covariance: Covariance(c),
            },
            twist: TwistWithCovariance {
                twist: Twist {
                    linear: Vector3 {
                        x: 2.5,
                        ..Vector3::default()
                    },
                    angular: Vector3 {
                        z: 0.1,
                        ..Vector3::default()
                    },
                },
                covariance: Covariance([0.0; 36]),
            },
        };
        let bag = ros2::msgs::odometry(
            stamp(),
            "odom",
            "base_link",
            &pose,
            &c,
            [[2.5, 0.0, 0.0], [0.0, 0.0, 0.1]],
        );
        assert_eq!(cdr(&live), bag);
    }

    #[test]
    fn a_command_reads_back_as_written() {
        let m = TwistStamped {
            header: Header::new(stamp().into(), "base_link"),
            twist: Twist {
                linear: Vector3 {
                    x: 3.0,
                    ..Vector3::default()
                },
                angular: Vector3 {
                    z: -0.2,
                    ..Vector3::default()
                },
            },
        };
        let bytes = cdr_encoding::to_vec::<_, LittleEndian>(&m).unwrap();
        let (back, _) = cdr_encoding::from_bytes::<TwistStamped, LittleEndian>(&bytes).unwrap();
        assert_eq!(back, m);
    }
}
