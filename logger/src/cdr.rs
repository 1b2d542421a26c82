//! CDR, as ROS 2 puts messages on the wire and in MCAP (`cdr` message
//! encoding): little-endian plain CDR (XCDR1) after the 4-byte
//! encapsulation header `00 01 00 00`; every primitive aligned to its own
//! size (at most 8) counted from the end of that header; a string is a u32
//! length (the terminating NUL included), its bytes and the NUL; a sequence
//! is a u32 count and its elements.
//!
//! Written here rather than taken from a crate: the `cdr` and
//! `cdr-encoding` crates serialise through serde, which would need a serde
//! struct per message beside the field list the wire already declares
//! ([`wire::data_message!`]), and the per-joint arrays trimmed to `dof`
//! would have to be copied into `Vec`s first. Walking the field list
//! straight into a reused buffer is a copy per field, and the whole codec
//! is these two small types.

use crate::decode_error::DecodeError;

/// The encapsulation header of little-endian plain CDR (`CDR_LE`).
pub const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Appends one CDR message to a buffer.
pub struct CdrWriter<'a> {
    out: &'a mut Vec<u8>,
    start: usize,
}

impl<'a> CdrWriter<'a> {
    /// Starts a message at the end of `out` (its encapsulation header).
    pub fn new(out: &'a mut Vec<u8>) -> Self {
        out.extend_from_slice(&CDR_LE);
        let start = out.len();
        Self { out, start }
    }

    #[inline]
    fn align(&mut self, n: usize) {
        let pad = (n - (self.out.len() - self.start) % n) % n;
        self.out.extend_from_slice(&[0u8; 8][..pad]);
    }

    /// A bool or a byte.
    pub fn u8(&mut self, x: u8) {
        self.out.push(x);
    }

    /// A uint32.
    #[inline]
    pub fn u32(&mut self, x: u32) {
        self.align(4);
        self.out.extend_from_slice(&x.to_le_bytes());
    }

    /// An int32.
    #[inline]
    pub fn i32(&mut self, x: i32) {
        self.align(4);
        self.out.extend_from_slice(&x.to_le_bytes());
    }

    /// A uint64.
    #[inline]
    pub fn u64(&mut self, x: u64) {
        self.align(8);
        self.out.extend_from_slice(&x.to_le_bytes());
    }

    /// An int64.
    #[inline]
    pub fn i64(&mut self, x: i64) {
        self.align(8);
        self.out.extend_from_slice(&x.to_le_bytes());
    }

    /// A float64.
    #[inline]
    pub fn f64(&mut self, x: f64) {
        self.align(8);
        self.out.extend_from_slice(&x.to_le_bytes());
    }

    /// A float32.
    #[inline]
    pub fn f32(&mut self, x: f32) {
        self.align(4);
        self.out.extend_from_slice(&x.to_le_bytes());
    }

    /// A string.
    pub fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.out.extend_from_slice(s.as_bytes());
        self.out.push(0);
    }

    /// A sequence's element count (the elements follow).
    pub fn len(&mut self, n: usize) {
        self.u32(n as u32);
    }

    /// A `float64[]`.
    pub fn f64s(&mut self, xs: &[f64]) {
        self.len(xs.len());
        if !xs.is_empty() {
            self.out.reserve(4 + 8 * xs.len());
            self.align(8);
            for x in xs {
                self.out.extend_from_slice(&x.to_le_bytes());
            }
        }
    }

    /// A `builtin_interfaces/Time` (or `Duration`) of `ns` nanoseconds.
    pub fn time(&mut self, ns: u64) {
        self.i32((ns / 1_000_000_000) as i32);
        self.u32((ns % 1_000_000_000) as u32);
    }

    /// A `std_msgs/Header` stamped `ns` in `frame_id`.
    pub fn header(&mut self, ns: u64, frame_id: &str) {
        self.time(ns);
        self.string(frame_id);
    }
}

/// Reads one CDR message, every length checked against what is left.
pub struct CdrReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

fn short(what: &str) -> DecodeError {
    DecodeError::Truncated {
        field: what.to_string(),
    }
}

impl<'a> CdrReader<'a> {
    /// The message in `data`: an error unless it starts with the
    /// little-endian CDR header (the only one testbed writes).
    pub fn new(data: &'a [u8]) -> Result<Self, DecodeError> {
        match data.get(..4) {
            Some(h) if h[..2] == CDR_LE[..2] => Ok(Self {
                buf: &data[4..],
                pos: 0,
            }),
            Some(h) => Err(DecodeError::NotLittleEndianCdr {
                encapsulation: [h[0], h[1]],
            }),
            None => Err(DecodeError::ShorterThanHeader),
        }
    }

    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], DecodeError> {
        let at = self.pos.next_multiple_of(N.min(8));
        let bytes = self
            .buf
            .get(at..at + N)
            .ok_or_else(|| short(what))?
            .try_into()
            .map_err(|_| short(what))?;
        self.pos = at + N;
        Ok(bytes)
    }

    /// A bool or a byte.
    pub fn u8(&mut self, what: &str) -> Result<u8, DecodeError> {
        Ok(self.take::<1>(what)?[0])
    }

    /// A uint32.
    pub fn u32(&mut self, what: &str) -> Result<u32, DecodeError> {
        self.take(what).map(u32::from_le_bytes)
    }

    /// An int32.
    pub fn i32(&mut self, what: &str) -> Result<i32, DecodeError> {
        self.take(what).map(i32::from_le_bytes)
    }

    /// A uint64.
    pub fn u64(&mut self, what: &str) -> Result<u64, DecodeError> {
        self.take(what).map(u64::from_le_bytes)
    }

    /// An int64.
    pub fn i64(&mut self, what: &str) -> Result<i64, DecodeError> {
        self.take(what).map(i64::from_le_bytes)
    }

    /// A float64.
    pub fn f64(&mut self, what: &str) -> Result<f64, DecodeError> {
        self.take(what).map(f64::from_le_bytes)
    }

    /// A float32.
    pub fn f32(&mut self, what: &str) -> Result<f32, DecodeError> {
        self.take(what).map(f32::from_le_bytes)
    }

    /// A sequence's element count, checked against the bytes left at
    /// `min_size` bytes an element.
    pub fn len(&mut self, what: &str, min_size: usize) -> Result<usize, DecodeError> {
        let n = self.u32(what)? as usize;
        if n.saturating_mul(min_size) > self.buf.len() - self.pos {
            return Err(DecodeError::LengthPastEnd {
                field: what.to_string(),
                entries: n,
            });
        }
        Ok(n)
    }

    /// A string.
    pub fn string(&mut self, what: &str) -> Result<&'a str, DecodeError> {
        let n = self.len(what, 1)?;
        let bytes = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        let text = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        std::str::from_utf8(text).map_err(|_| DecodeError::NotUtf8 {
            field: what.to_string(),
        })
    }

    /// A `float64[]` into `out` (cleared first).
    pub fn f64s(&mut self, what: &str, out: &mut Vec<f64>) -> Result<(), DecodeError> {
        let n = self.len(what, 8)?;
        out.clear();
        for _ in 0..n {
            out.push(self.f64(what)?);
        }
        Ok(())
    }

    /// A `builtin_interfaces/Time` in nanoseconds (an error if negative).
    pub fn time(&mut self, what: &str) -> Result<u64, DecodeError> {
        let sec = self.i32(what)?;
        let nsec = self.u32(what)?;
        if sec < 0 || nsec >= 1_000_000_000 {
            return Err(DecodeError::NotATime {
                field: what.to_string(),
                sec,
                nsec,
            });
        }
        Ok(sec as u64 * 1_000_000_000 + nsec as u64)
    }

    /// Whether every byte was read (up to the final padding).
    pub fn at_end(&self) -> bool {
        self.buf.len() - self.pos < 8 && self.buf[self.pos..].iter().all(|b| *b == 0)
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// The bytes ROS 2 writes for `std_msgs/Header{stamp: 1.5 s, frame_id:
    /// "ab"}` then `float64[] {0.5}`: alignment counts from after the header.
    #[test]
    fn layout_follows_plain_cdr() {
        let mut out = Vec::new();
        let mut w = CdrWriter::new(&mut out);
        w.header(1_500_000_000, "ab");
        w.f64s(&[0.5]);
        let mut want = vec![0, 1, 0, 0];
        want.extend(1i32.to_le_bytes());
        want.extend(500_000_000u32.to_le_bytes());
        want.extend(3u32.to_le_bytes());
        want.extend(b"ab\0");
        want.push(0); // pad to 4 for the count
        want.extend(1u32.to_le_bytes());
        want.extend([0; 4]); // pad to 8 for the float64
        want.extend(0.5f64.to_le_bytes());
        assert_eq!(out, want);
        let mut r = CdrReader::new(&out).unwrap();
        assert_eq!(r.time("stamp").unwrap(), 1_500_000_000);
        assert_eq!(r.string("frame_id").unwrap(), "ab");
        let mut xs = Vec::new();
        r.f64s("x", &mut xs).unwrap();
        assert_eq!(xs, [0.5]);
        assert!(r.at_end());
        assert!(r.u8("more").is_err());
    }

    #[test]
    fn damaged_messages_are_errors_not_panics() {
        assert!(CdrReader::new(&[0, 1]).is_err());
        assert!(CdrReader::new(&[0, 0, 0, 0]).is_err());
        let mut r = CdrReader::new(&[0, 1, 0, 0, 255, 255, 255, 255]).unwrap();
        assert_eq!(
            r.f64s("q", &mut Vec::new()).unwrap_err(),
            DecodeError::LengthPastEnd {
                field: "q".into(),
                entries: u32::MAX as usize
            }
        );
        let mut r = CdrReader::new(&[0, 1, 0, 0, 1, 0, 0]).unwrap();
        assert!(r.u32("dof").is_err());
    }
}
