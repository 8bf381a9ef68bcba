//! `sensor_msgs/msg/PointCloud2` read as any driver writes it: fields found by name, whatever
//! their order, offsets, numeric types, extra fields or byte order; organised (height > 1) or
//! not; rows padded or not. What the mapper needs and a cloud lacks is an error naming the field.

use crate::cdr::CdrReader;
use crate::error::CdrError;

/// A point field's numeric type (`sensor_msgs/PointField` constants 1-8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Datatype {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Datatype {
    fn of(code: u8) -> Option<Self> {
        Some(match code {
            1 => Self::I8,
            2 => Self::U8,
            3 => Self::I16,
            4 => Self::U16,
            5 => Self::I32,
            6 => Self::U32,
            7 => Self::F32,
            8 => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// The value at the start of `b` as f64.
    fn read(self, b: &[u8], big_endian: bool) -> f64 {
        macro_rules! num {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                f64::from(if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                })
            }};
        }
        match self {
            Self::I8 => f64::from(b[0] as i8),
            Self::U8 => f64::from(b[0]),
            Self::I16 => num!(i16, 2),
            Self::U16 => num!(u16, 2),
            Self::I32 => num!(i32, 4),
            Self::U32 => num!(u32, 4),
            Self::F32 => num!(f32, 4),
            Self::F64 => {
                let mut a = [0u8; 8];
                a.copy_from_slice(&b[..8]);
                if big_endian {
                    f64::from_be_bytes(a)
                } else {
                    f64::from_le_bytes(a)
                }
            }
        }
    }
}

/// One field as the cloud declares it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointField {
    /// Its name.
    pub name: String,
    /// Byte offset in a point.
    pub offset: u32,
    /// `sensor_msgs/PointField` datatype (1-8).
    pub datatype: u8,
    /// Elements.
    pub count: u32,
}

/// A cloud's points, the fields the mapper uses taken by name.
#[derive(Debug, Clone, PartialEq)]
pub struct Cloud {
    /// Header stamp, nanoseconds since the epoch.
    pub stamp_ns: u64,
    /// Header frame.
    pub frame_id: String,
    /// Rows (1: unorganised) and points per row.
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// Every field the cloud declares, in its order.
    pub fields: Vec<PointField>,
    /// x, y, z of each point, row by row (NaN where the driver wrote no return).
    pub xyz: Vec<[f64; 3]>,
    /// `intensity`, when the cloud has it.
    pub intensity: Option<Vec<f64>>,
    /// `ring` (the beam), when the cloud has it.
    pub ring: Option<Vec<u16>>,
    /// `time` (seconds after the stamp, or `t` in nanoseconds: as the field says), when present.
    pub time: Option<Vec<f64>>,
}

/// A cloud whose layout does not hold what it says, or lacks what the mapper needs.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CloudError {
    /// The message itself is malformed.
    #[error(transparent)]
    Cdr(#[from] CdrError),
    /// The layout is inconsistent, or a needed field is missing or unusable.
    #[error("field `{field}`: {what}")]
    Field {
        /// The point field (or layout field: `point_step`, `row_step`, `data`).
        field: String,
        /// What is wrong.
        what: String,
    },
}

fn field_error(field: &str, what: impl Into<String>) -> CloudError {
    CloudError::Field {
        field: field.to_string(),
        what: what.into(),
    }
}

/// Reads a `PointCloud2` message (its CDR bytes).
///
/// # Errors
/// The message is malformed, its sizes disagree, or it has no usable x, y or z.
pub fn read_cloud(cdr: &[u8]) -> Result<Cloud, CloudError> {
    let mut r = CdrReader::new(cdr)?;
    let sec = r.i32("header.stamp.sec")?;
    let nanosec = r.u32("header.stamp.nanosec")?;
    let frame_id = r.string("header.frame_id")?;
    let height = r.u32("height")?;
    let width = r.u32("width")?;
    let n = r.count("fields", 13)?;
    let mut fields = Vec::with_capacity(n);
    for _ in 0..n {
        fields.push(PointField {
            name: r.string("fields.name")?,
            offset: r.u32("fields.offset")?,
            datatype: r.u8("fields.datatype")?,
            count: r.u32("fields.count")?,
        });
    }
    let big_endian = r.bool("is_bigendian")?;
    let point_step = r.u32("point_step")? as usize;
    let row_step = r.u32("row_step")? as usize;
    let data = r.bytes("data")?;
    let (rows, per_row) = (height as usize, width as usize);
    if per_row.checked_mul(point_step).is_none_or(|w| w > row_step) {
        return Err(field_error(
            "row_step",
            format!("{row_step} bytes cannot hold {per_row} points of {point_step} bytes"),
        ));
    }
    if rows.checked_mul(row_step) != Some(data.len()) {
        return Err(field_error(
            "data",
            format!(
                "{} bytes, not height {rows} x row_step {row_step}",
                data.len()
            ),
        ));
    }
    let column = |name: &str, needed: bool| -> Result<Option<Vec<f64>>, CloudError> {
        let Some(f) = fields.iter().find(|f| f.name == name) else {
            return if needed {
                let names: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
                Err(field_error(
                    name,
                    format!("missing (the cloud has {names:?})"),
                ))
            } else {
                Ok(None)
            };
        };
        let t = Datatype::of(f.datatype)
            .ok_or_else(|| field_error(name, format!("datatype {} is none of 1-8", f.datatype)))?;
        let (offset, size) = (f.offset as usize, t.size());
        if f.count == 0 || offset + size > point_step {
            return Err(field_error(
                name,
                format!(
                    "offset {offset} + {size} bytes, count {}, in a point of {point_step} bytes",
                    f.count
                ),
            ));
        }
        let mut out = Vec::with_capacity(rows * per_row);
        for row in 0..rows {
            for p in 0..per_row {
                let at = row * row_step + p * point_step + offset;
                out.push(t.read(&data[at..at + size], big_endian));
            }
        }
        Ok(Some(out))
    };
    let (Some(x), Some(y), Some(z)) = (column("x", true)?, column("y", true)?, column("z", true)?)
    else {
        unreachable!("needed fields are Some or an error");
    };
    let xyz = x
        .iter()
        .zip(&y)
        .zip(&z)
        .map(|((x, y), z)| [*x, *y, *z])
        .collect();
    let intensity = column("intensity", false)?;
    let ring = column("ring", false)?.map(|v| {
        v.into_iter()
            .map(|b| b.clamp(0.0, f64::from(u16::MAX)) as u16)
            .collect()
    });
    let time = match column("time", false)? {
        Some(t) => Some(t),
        None => column("t", false)?,
    };
    let stamp_ns = u64::try_from(sec).unwrap_or(0) * 1_000_000_000 + u64::from(nanosec);
    Ok(Cloud {
        stamp_ns,
        frame_id,
        height,
        width,
        fields,
        xyz,
        intensity,
        ring,
        time,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::CdrWriter;
    use crate::msgs::{Time, VelodynePoint, velodyne_cloud};

    /// A cloud laid out as another driver might: `fields` (name, offset, datatype), `step`,
    /// two rows of `per_row` points padded to `row_step`, each point's bytes from `point`.
    fn foreign(
        fields: &[(&str, u32, u8)],
        step: u32,
        per_row: u32,
        row_step: u32,
        big_endian: bool,
        point: impl Fn(u32) -> Vec<u8>,
    ) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.i32(7);
        w.u32(5);
        w.string("lidar_top");
        w.u32(2);
        w.u32(per_row);
        w.count(fields.len());
        for (name, offset, datatype) in fields {
            w.string(name);
            w.u32(*offset);
            w.u8(*datatype);
            w.u32(1);
        }
        w.bool(big_endian);
        w.u32(step);
        w.u32(row_step);
        let mut data = Vec::new();
        for row in 0..2 {
            for p in 0..per_row {
                let mut b = point(row * per_row + p);
                b.resize(step as usize, 0);
                data.extend(b);
            }
            data.resize(((row + 1) * row_step) as usize, 0xAA);
        }
        w.bytes(&data);
        w.bool(false);
        w.finish()
    }

    #[test]
    fn the_simulators_own_clouds_read_back() {
        let points: Vec<VelodynePoint> = (0..5)
            .map(|i| VelodynePoint {
                xyz: [i as f32, -(i as f32), 0.5],
                intensity: 10.0 * i as f32,
                ring: i as u16,
                time: 0.01 * i as f32,
            })
            .collect();
        let c = read_cloud(&velodyne_cloud(
            Time::from_ns(3_000_000_007),
            "velodyne",
            &points,
        ))
        .unwrap();
        assert_eq!(
            (c.stamp_ns, c.frame_id.as_str(), c.width, c.height),
            (3_000_000_007, "velodyne", 5, 1)
        );
        assert_eq!(c.xyz[3], [3.0, -3.0, 0.5]);
        assert_eq!(c.ring.unwrap(), [0, 1, 2, 3, 4]);
        assert_eq!(c.intensity.unwrap()[4], 40.0);
        assert!((c.time.unwrap()[2] - 0.02).abs() < 1e-7);
    }

    /// float64 coordinates after an extra field, z first, an organised cloud with padded rows,
    /// big-endian, no ring: read by name all the same.
    #[test]
    fn other_drivers_layouts_are_read_by_field_name() {
        let fields = [("z", 4, 8), ("x", 12, 8), ("y", 20, 8), ("label", 0, 6)];
        let bytes = foreign(&fields, 32, 3, 100, true, |i| {
            let mut b = vec![0u8; 32];
            b[0..4].copy_from_slice(&9u32.to_be_bytes());
            b[4..12].copy_from_slice(&(0.25 * f64::from(i)).to_be_bytes());
            b[12..20].copy_from_slice(&f64::from(i).to_be_bytes());
            b[20..28].copy_from_slice(&(-f64::from(i)).to_be_bytes());
            b
        });
        let c = read_cloud(&bytes).unwrap();
        assert_eq!((c.height, c.width, c.xyz.len()), (2, 3, 6));
        assert_eq!(c.xyz[4], [4.0, -4.0, 1.0]);
        assert!(c.ring.is_none() && c.intensity.is_none());
    }

    #[test]
    fn a_bad_cloud_is_an_error_naming_the_field() {
        let point = |_| vec![0u8; 12];
        let xyz = [("x", 0, 7), ("y", 4, 7), ("z", 8, 7)];
        let no_z = [("x", 0, 7), ("y", 4, 7)];
        let cases: [(Vec<u8>, &str); 4] = [
            (
                foreign(&no_z, 12, 2, 24, false, point),
                "field `z`: missing (the cloud has [\"x\", \"y\"])",
            ),
            (
                foreign(&xyz, 8, 2, 16, false, point),
                "field `z`: offset 8 + 4 bytes, count 1, in a point of 8 bytes",
            ),
            (
                foreign(&xyz, 12, 2, 20, false, point),
                "field `row_step`: 20 bytes cannot hold 2 points of 12 bytes",
            ),
            (
                foreign(
                    &[("x", 0, 9), ("y", 4, 7), ("z", 8, 7)],
                    12,
                    2,
                    24,
                    false,
                    point,
                ),
                "field `x`: datatype 9 is none of 1-8",
            ),
        ];
        for (bytes, says) in cases {
            assert_eq!(read_cloud(&bytes).unwrap_err().to_string(), says);
        }
        // Cut short: the CDR reader names where it ran out.
        let whole = foreign(&xyz, 12, 2, 24, false, point);
        let e = read_cloud(&whole[..whole.len() - 10])
            .unwrap_err()
            .to_string();
        assert!(e.contains("field `data`"), "{e}");
    }
}
