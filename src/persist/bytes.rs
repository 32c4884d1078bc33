//! The byte layer: a little-endian writer, a bounds-checked reader, the
//! header and its checksum.

use super::{Kind, LoadError};
use alloc::vec::Vec;

/// The first eight bytes of every saved structure.
pub(crate) const MAGIC: [u8; 8] = *b"GUIDING\0";

/// The format version this build writes, and the newest it reads.
pub(crate) const FORMAT_VERSION: u32 = 6;

/// Bytes of the header: magic, format version, crate version (three
/// `u16`), kind, payload length, checksum.
pub(crate) const HEADER_BYTES: usize = 8 + 4 + 6 + 4 + 8 + 8;

/// FNV-1a, 64 bits: the payload checksum and the light-tree fingerprint.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fnv(u64);

impl Fnv {
    pub(crate) fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    pub(crate) fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }

    pub(crate) fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }

    pub(crate) fn u64(&mut self, x: u64) {
        self.bytes(&x.to_le_bytes());
    }

    pub(crate) fn finish(&self) -> u64 {
        self.0
    }
}

/// Appends little-endian values.
#[derive(Debug, Default)]
pub(crate) struct Writer {
    buf: Vec<u8>,
}

impl Writer {
    pub(crate) fn u8(&mut self, x: u8) {
        self.buf.push(x);
    }

    pub(crate) fn bool(&mut self, x: bool) {
        self.u8(u8::from(x));
    }

    pub(crate) fn u32(&mut self, x: u32) {
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    pub(crate) fn u64(&mut self, x: u64) {
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    pub(crate) fn f32(&mut self, x: f32) {
        self.u32(x.to_bits());
    }

    pub(crate) fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }

    /// A vector: three `f32`.
    pub(crate) fn vec3(&mut self, v: glam::Vec3) {
        for x in v.to_array() {
            self.f32(x);
        }
    }

    /// A count, as `u64`.
    pub(crate) fn len(&mut self, n: usize) {
        self.u64(n as u64);
    }

    pub(crate) fn bytes(&mut self, b: &[u8]) {
        self.buf.extend_from_slice(b);
    }

    /// The payload behind a header for `kind`.
    pub(crate) fn finish(self, kind: Kind) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_BYTES + self.buf.len());
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        for part in crate_version() {
            out.extend_from_slice(&part.to_le_bytes());
        }
        out.extend_from_slice(&(kind as u32).to_le_bytes());
        out.extend_from_slice(&(self.buf.len() as u64).to_le_bytes());
        // The checksum covers the header before it and the payload.
        let mut sum = Fnv::new();
        sum.bytes(&out);
        sum.bytes(&self.buf);
        out.extend_from_slice(&sum.finish().to_le_bytes());
        out.extend_from_slice(&self.buf);
        out
    }
}

/// The crate's version, as written in every header.
pub(crate) fn crate_version() -> [u16; 3] {
    let part = |s: &str| s.parse::<u16>().unwrap_or(0);
    [
        part(env!("CARGO_PKG_VERSION_MAJOR")),
        part(env!("CARGO_PKG_VERSION_MINOR")),
        part(env!("CARGO_PKG_VERSION_PATCH")),
    ]
}

/// Reads little-endian values, checking every length against the bytes
/// that are left.
#[derive(Debug)]
pub(crate) struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
    /// The format version of the buffer (older layouts keep their
    /// reading paths).
    version: u32,
}

impl<'a> Reader<'a> {
    /// The payload of `bytes` after checking its header for `kind`.
    pub(crate) fn open(bytes: &'a [u8], kind: Kind) -> Result<Self, LoadError> {
        let mut r = Reader {
            buf: bytes,
            pos: 0,
            version: 0,
        };
        let magic = r.take(8, "magic")?;
        if magic != MAGIC {
            return Err(LoadError::NotGuidingData);
        }
        let version = r.u32("format version")?;
        if version == 0 || version > FORMAT_VERSION {
            return Err(LoadError::UnsupportedVersion {
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        r.version = version;
        for _ in 0..3 {
            r.u16("crate version")?;
        }
        let found = r.u32("kind")?;
        if found != kind as u32 {
            return Err(LoadError::WrongKind {
                expected: kind as u32,
                found,
            });
        }
        let len = r.u64("payload length")?;
        let checksum = r.u64("checksum")?;
        let rest = r.buf.len() - r.pos;
        if len > rest as u64 {
            return Err(LoadError::Truncated {
                field: "payload",
                offset: r.pos,
            });
        }
        if len < rest as u64 {
            return Err(LoadError::TrailingBytes {
                offset: r.pos + len as usize,
            });
        }
        let mut sum = Fnv::new();
        sum.bytes(&r.buf[..HEADER_BYTES - 8]);
        sum.bytes(&r.buf[r.pos..]);
        if sum.finish() != checksum {
            return Err(LoadError::Checksum);
        }
        Ok(r)
    }

    /// Bytes left to read.
    pub(crate) fn left(&self) -> usize {
        self.buf.len() - self.pos
    }

    /// The format version the buffer was written with.
    pub(crate) fn version(&self) -> u32 {
        self.version
    }

    /// The error for `field` read at `offset`.
    pub(crate) fn invalid(field: &'static str, offset: usize) -> LoadError {
        LoadError::Invalid { field, offset }
    }

    /// Where the next read starts.
    pub(crate) fn offset(&self) -> usize {
        self.pos
    }

    /// Succeeds when every byte was read.
    pub(crate) fn end(&self) -> Result<(), LoadError> {
        if self.pos == self.buf.len() {
            Ok(())
        } else {
            Err(LoadError::TrailingBytes { offset: self.pos })
        }
    }

    fn take(&mut self, n: usize, field: &'static str) -> Result<&'a [u8], LoadError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.buf.len());
        let Some(end) = end else {
            return Err(LoadError::Truncated {
                field,
                offset: self.pos,
            });
        };
        let s = &self.buf[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], LoadError> {
        let s = self.take(N, field)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    pub(crate) fn u8(&mut self, field: &'static str) -> Result<u8, LoadError> {
        Ok(self.array::<1>(field)?[0])
    }

    pub(crate) fn bool(&mut self, field: &'static str) -> Result<bool, LoadError> {
        let at = self.pos;
        match self.u8(field)? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(Self::invalid(field, at)),
        }
    }

    pub(crate) fn u16(&mut self, field: &'static str) -> Result<u16, LoadError> {
        Ok(u16::from_le_bytes(self.array(field)?))
    }

    pub(crate) fn u32(&mut self, field: &'static str) -> Result<u32, LoadError> {
        Ok(u32::from_le_bytes(self.array(field)?))
    }

    pub(crate) fn u64(&mut self, field: &'static str) -> Result<u64, LoadError> {
        Ok(u64::from_le_bytes(self.array(field)?))
    }

    pub(crate) fn f32(&mut self, field: &'static str) -> Result<f32, LoadError> {
        Ok(f32::from_bits(self.u32(field)?))
    }

    pub(crate) fn f64(&mut self, field: &'static str) -> Result<f64, LoadError> {
        Ok(f64::from_bits(self.u64(field)?))
    }

    /// A vector written by [`Writer::vec3`] (not checked).
    pub(crate) fn vec3(&mut self, field: &'static str) -> Result<glam::Vec3, LoadError> {
        Ok(glam::Vec3::new(
            self.f32(field)?,
            self.f32(field)?,
            self.f32(field)?,
        ))
    }

    /// A value that `ok` accepts, else [`LoadError::Invalid`].
    pub(crate) fn check<T>(
        &mut self,
        field: &'static str,
        read: impl FnOnce(&mut Self, &'static str) -> Result<T, LoadError>,
        ok: impl FnOnce(&T) -> bool,
    ) -> Result<T, LoadError> {
        let at = self.pos;
        let v = read(self, field)?;
        if ok(&v) {
            Ok(v)
        } else {
            Err(Self::invalid(field, at))
        }
    }

    /// A count of items of at least `item_bytes` bytes each: never more
    /// than the bytes left could hold, so no length in the file can make
    /// the reader allocate more than the file's size.
    pub(crate) fn len(
        &mut self,
        field: &'static str,
        item_bytes: usize,
    ) -> Result<usize, LoadError> {
        let at = self.pos;
        let n = self.u64(field)?;
        let left = (self.buf.len() - self.pos) as u64;
        if n.saturating_mul(item_bytes.max(1) as u64) > left {
            return Err(LoadError::Truncated { field, offset: at });
        }
        Ok(n as usize)
    }

    pub(crate) fn bytes(&mut self, n: usize, field: &'static str) -> Result<&'a [u8], LoadError> {
        self.take(n, field)
    }
}
