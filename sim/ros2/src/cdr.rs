//! CDR (OMG XCDR1, little endian) as ROS 2 serialises messages: a 4-byte encapsulation header
//! `00 01 00 00`, then each field aligned to its own size counted from the byte after the
//! header; strings as a u32 length that counts a closing NUL, then the bytes and the NUL;
//! sequences as a u32 count, then the elements; fixed arrays as the elements alone; nested
//! messages as their fields, with no alignment of their own.

use crate::error::CdrError;

/// The encapsulation header of little-endian XCDR1.
pub const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Builds one message's bytes.
#[derive(Debug, Clone)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self::new()
    }
}

macro_rules! put {
    ($($name:ident: $t:ty),*) => {$(
        #[doc = concat!("Appends a `", stringify!($t), "`, aligned to its size.")]
        pub fn $name(&mut self, v: $t) {
            self.align(std::mem::size_of::<$t>());
            self.buf.extend_from_slice(&v.to_le_bytes());
        }
    )*};
}

impl CdrWriter {
    /// An empty message (its encapsulation header only).
    #[must_use]
    pub fn new() -> Self {
        Self::with_capacity(64)
    }

    /// An empty message with room for `bytes` bytes.
    #[must_use]
    pub fn with_capacity(bytes: usize) -> Self {
        let mut buf = Vec::with_capacity(bytes + 4);
        buf.extend_from_slice(&CDR_LE);
        Self { buf }
    }

    /// Pads with zeros to a multiple of `n` bytes after the header.
    pub fn align(&mut self, n: usize) {
        while !(self.buf.len() - 4).is_multiple_of(n) {
            self.buf.push(0);
        }
    }

    put!(u16: u16, u32: u32, i32: i32, u64: u64, f32: f32, f64: f64);

    /// Appends a byte.
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// Appends a signed byte.
    pub fn i8(&mut self, v: i8) {
        self.buf.push(v.to_le_bytes()[0]);
    }

    /// Appends a bool (one byte).
    pub fn bool(&mut self, v: bool) {
        self.buf.push(u8::from(v));
    }

    /// Appends a string: its length with the NUL, the bytes, the NUL.
    pub fn string(&mut self, s: &str) {
        self.u32(len_u32(s.len() + 1));
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// Appends a sequence's count (its elements follow).
    pub fn count(&mut self, n: usize) {
        self.u32(len_u32(n));
    }

    /// Appends a `uint8[]` or `int8[]`: its count and the bytes.
    pub fn bytes(&mut self, b: &[u8]) {
        self.count(b.len());
        self.buf.extend_from_slice(b);
    }

    /// Appends bytes as they are (a sequence's elements after its [`CdrWriter::count`]).
    pub fn raw(&mut self, b: &[u8]) {
        self.buf.extend_from_slice(b);
    }

    /// The message's bytes, header included.
    #[must_use]
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}

/// A length as CDR's u32 (a message over 4 GiB is not one this program writes).
fn len_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// Reads one message's fields in order, every read bounds-checked; errors name the field and
/// the offset.
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    at: usize,
}

macro_rules! get {
    ($($name:ident: $t:ty),*) => {$(
        #[doc = concat!("Reads a `", stringify!($t), "` named `field`, aligned to its size.")]
        ///
        /// # Errors
        /// The message ends first.
        pub fn $name(&mut self, field: &'static str) -> Result<$t, CdrError> {
            const N: usize = std::mem::size_of::<$t>();
            self.align(N);
            let b = self.take(N, field)?;
            let mut a = [0u8; N];
            a.copy_from_slice(b);
            Ok(<$t>::from_le_bytes(a))
        }
    )*};
}

impl<'a> CdrReader<'a> {
    /// A reader of `buf`, a whole message: its encapsulation must be little-endian XCDR1.
    ///
    /// # Errors
    /// Shorter than the header, or another encapsulation (big endian, XCDR2).
    pub fn new(buf: &'a [u8]) -> Result<Self, CdrError> {
        if buf.len() < 4 {
            return Err(CdrError::new(
                "encapsulation",
                0,
                "the message is shorter than its 4-byte header",
            ));
        }
        if buf[..2] != CDR_LE[..2] {
            return Err(CdrError::new(
                "encapsulation",
                0,
                format!(
                    "{:02x} {:02x} is not little-endian CDR (00 01)",
                    buf[0], buf[1]
                ),
            ));
        }
        Ok(Self { buf, at: 4 })
    }

    fn align(&mut self, n: usize) {
        let rel = self.at - 4;
        self.at += (n - rel % n) % n;
    }

    fn take(&mut self, n: usize, field: &'static str) -> Result<&'a [u8], CdrError> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.buf.len())
            .ok_or_else(|| {
                CdrError::new(
                    field,
                    self.at,
                    format!(
                        "needs {n} bytes, the message has {} left",
                        self.buf.len().saturating_sub(self.at)
                    ),
                )
            })?;
        let b = &self.buf[self.at..end];
        self.at = end;
        Ok(b)
    }

    get!(u16: u16, u32: u32, i32: i32, u64: u64, f32: f32, f64: f64);

    /// Reads a byte.
    ///
    /// # Errors
    /// The message ends first.
    pub fn u8(&mut self, field: &'static str) -> Result<u8, CdrError> {
        Ok(self.take(1, field)?[0])
    }

    /// Reads a bool.
    ///
    /// # Errors
    /// The message ends first.
    pub fn bool(&mut self, field: &'static str) -> Result<bool, CdrError> {
        Ok(self.u8(field)? != 0)
    }

    /// Reads a string (its NUL dropped).
    ///
    /// # Errors
    /// The message ends first, no NUL closes it, or it is not UTF-8.
    pub fn string(&mut self, field: &'static str) -> Result<String, CdrError> {
        let n = self.u32(field)? as usize;
        let at = self.at;
        let b = self.take(n, field)?;
        let text = match b.split_last() {
            Some((0, text)) => text,
            _ => {
                return Err(CdrError::new(
                    field,
                    at,
                    "the string does not end with a NUL",
                ));
            }
        };
        String::from_utf8(text.to_vec())
            .map_err(|_| CdrError::new(field, at, "the string is not UTF-8"))
    }

    /// Reads a sequence's count, checked against what is left (each element at least
    /// `min_element_bytes` long).
    ///
    /// # Errors
    /// The message ends first, or cannot hold that many elements.
    pub fn count(
        &mut self,
        field: &'static str,
        min_element_bytes: usize,
    ) -> Result<usize, CdrError> {
        let at = self.at;
        let n = self.u32(field)? as usize;
        let left = self.buf.len() - self.at;
        if n.saturating_mul(min_element_bytes.max(1)) > left && min_element_bytes > 0 {
            return Err(CdrError::new(
                field,
                at,
                format!("a count of {n} does not fit in the {left} bytes left"),
            ));
        }
        Ok(n)
    }

    /// Reads a `uint8[]`.
    ///
    /// # Errors
    /// The message ends first.
    pub fn bytes(&mut self, field: &'static str) -> Result<&'a [u8], CdrError> {
        let n = self.count(field, 1)?;
        self.take(n, field)
    }

    /// Where the next read starts (bytes from the message's start).
    #[must_use]
    pub fn offset(&self) -> usize {
        self.at
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layout the ROS 2 tooling writes (checked byte for byte against rosbags'
    /// `serialize_cdr`): a stamp, a frame id padded to the next u32, a one-point cloud.
    #[test]
    fn a_point_cloud_is_laid_out_as_ros_writes_it() {
        let mut w = CdrWriter::new();
        w.i32(1);
        w.u32(2);
        w.string("velodyne");
        w.u32(1); // height
        w.u32(1); // width
        w.count(1);
        w.string("x");
        w.u32(0);
        w.u8(7);
        w.u32(1);
        w.bool(false);
        w.u32(4);
        w.u32(4);
        w.bytes(&1.0f32.to_le_bytes());
        w.bool(true);
        let b = w.finish();
        assert_eq!(b.len(), 81);
        assert_eq!(&b[..4], &CDR_LE);
        assert_eq!(&b[12..16], &9u32.to_le_bytes());
        assert_eq!(&b[16..25], b"velodyne\0");
        assert_eq!(&b[25..28], &[0, 0, 0]);
        assert_eq!(&b[28..32], &1u32.to_le_bytes());
        assert_eq!(&b[76..80], &1.0f32.to_le_bytes());
        assert_eq!(b[80], 1);
    }

    /// Doubles align to 8 counted from after the header: a transform's translation after two
    /// frame ids starts at byte 36.
    #[test]
    fn doubles_align_after_the_header() {
        let mut w = CdrWriter::new();
        w.count(1);
        w.i32(1);
        w.u32(2);
        w.string("map");
        w.string("odom");
        w.f64(1.0);
        let b = w.finish();
        assert_eq!(&b[36..44], &1.0f64.to_le_bytes());
        let mut r = CdrReader::new(&b).unwrap();
        assert_eq!(r.count("transforms", 1).unwrap(), 1);
        assert_eq!((r.i32("sec").unwrap(), r.u32("nanosec").unwrap()), (1, 2));
        assert_eq!(r.string("frame_id").unwrap(), "map");
        assert_eq!(r.string("child_frame_id").unwrap(), "odom");
        assert_eq!(r.f64("x").unwrap(), 1.0);
        let e = r.f64("y").unwrap_err();
        assert_eq!((e.field, e.offset), ("y", 44));
    }

    #[test]
    fn bad_messages_are_errors_naming_the_field() {
        assert!(CdrReader::new(&[0, 1]).is_err());
        let e = CdrReader::new(&[0, 0, 0, 0]).unwrap_err();
        assert!(e.to_string().contains("not little-endian"), "{e}");
        // A string without its NUL, a count beyond the message.
        let mut w = CdrWriter::new();
        w.u32(3);
        w.u8(b'a');
        w.u8(b'b');
        w.u8(b'c');
        let b = w.finish();
        let e = CdrReader::new(&b).unwrap().string("frame_id").unwrap_err();
        assert!(
            e.to_string().contains("frame_id") && e.to_string().contains("NUL"),
            "{e}"
        );
        let mut w = CdrWriter::new();
        w.u32(1_000_000);
        let b = w.finish();
        let e = CdrReader::new(&b).unwrap().bytes("data").unwrap_err();
        assert!(e.to_string().contains("does not fit"), "{e}");
    }
}
