//! `std::io` adapters: one saved structure read from a stream without
//! trusting its length, and written to one.

use super::bytes::{HEADER_BYTES, MAGIC};
use std::io::{self, Read, Write};
use std::vec::Vec;

/// What [`read_from`] allocates for a payload before any of it arrives.
const FIRST_CHUNK: usize = 64 * 1024;

/// Reads one saved structure (header and payload) from `reader`: exactly
/// its bytes, so several can follow each other in one stream. A payload
/// longer than `max_bytes` is refused before anything is allocated for it
/// (`InvalidData`), as is a stream that does not start with the magic;
/// below that, the buffer grows with the bytes that arrive, not with the
/// length the stream claims (at most 64 KiB before the first payload
/// byte). Load the result with the structure's `from_bytes`, which checks
/// the rest.
pub fn read_from<R: Read + ?Sized>(reader: &mut R, max_bytes: usize) -> io::Result<Vec<u8>> {
    let mut header = [0u8; HEADER_BYTES];
    reader.read_exact(&mut header)?;
    if header[..8] != MAGIC {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            "not guiding data",
        ));
    }
    let mut len = [0u8; 8];
    len.copy_from_slice(&header[HEADER_BYTES - 16..HEADER_BYTES - 8]);
    let len = u64::from_le_bytes(len);
    if len > max_bytes as u64 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            "saved structure larger than allowed",
        ));
    }
    let mut out = buffer_for(len);
    out.extend_from_slice(&header);
    reader.take(len).read_to_end(&mut out)?;
    if out.len() != HEADER_BYTES + len as usize {
        return Err(io::ErrorKind::UnexpectedEof.into());
    }
    Ok(out)
}

/// The buffer a payload of claimed length `len` is read into: room for the
/// header and at most [`FIRST_CHUNK`] of it. The claimed length is only an
/// upper bound until the bytes arrive; the buffer grows with what is read
/// (a short stream claiming 256 MiB costs what it holds), never with what
/// it claims.
fn buffer_for(len: u64) -> Vec<u8> {
    let first = usize::try_from(len).unwrap_or(usize::MAX).min(FIRST_CHUNK);
    Vec::with_capacity(HEADER_BYTES + first)
}

/// Writes saved bytes (from any `to_bytes`) to `writer`.
pub fn write_to<W: Write + ?Sized>(writer: &mut W, bytes: &[u8]) -> io::Result<()> {
    writer.write_all(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::LightTree;
    use crate::emitter::Emitter;
    use glam::Vec3;

    #[test]
    fn streams_hold_several_structures() {
        let a =
            LightTree::build(&[Emitter::point(Vec3::ONE, 1.0)][..], Default::default()).unwrap();
        let b = LightTree::build(
            &[Emitter::point(Vec3::X, 2.0), Emitter::point(Vec3::Y, 1.0)][..],
            Default::default(),
        )
        .unwrap();
        let mut stream = Vec::new();
        write_to(&mut stream, &a.to_bytes()).unwrap();
        write_to(&mut stream, &b.to_bytes()).unwrap();
        let mut r = &stream[..];
        let first = read_from(&mut r, 1 << 20).unwrap();
        let second = read_from(&mut r, 1 << 20).unwrap();
        assert_eq!(LightTree::from_bytes(&first).unwrap().nodes(), a.nodes());
        assert_eq!(LightTree::from_bytes(&second).unwrap().nodes(), b.nodes());
        assert!(r.is_empty());
        // A length over the limit is refused before reading the payload;
        // one exactly at it is read.
        let first_len = a.to_bytes().len() - HEADER_BYTES;
        assert_eq!(
            read_from(&mut &stream[..], first_len - 1)
                .unwrap_err()
                .kind(),
            io::ErrorKind::InvalidData
        );
        assert_eq!(read_from(&mut &stream[..], first_len).unwrap(), first);
        // Truncated.
        let cut = &stream[..HEADER_BYTES + 3];
        assert_eq!(
            read_from(&mut &cut[..], 1 << 20).unwrap_err().kind(),
            io::ErrorKind::UnexpectedEof
        );
        assert_eq!(
            read_from(&mut &b"nonsense, clearly not guiding data....."[..], 100)
                .unwrap_err()
                .kind(),
            io::ErrorKind::InvalidData
        );
    }

    /// A short stream that claims a huge payload is refused as truncated,
    /// and the room made for it before the bytes arrive is bounded (the
    /// control: a buffer sized by the claim holds 256 MiB).
    #[test]
    fn a_claimed_length_is_not_allocated() {
        let tree =
            LightTree::build(&[Emitter::point(Vec3::ONE, 1.0)][..], Default::default()).unwrap();
        let mut bytes = tree.to_bytes();
        let claimed = 256u64 << 20;
        let at = HEADER_BYTES - 16;
        bytes[at..at + 8].copy_from_slice(&claimed.to_le_bytes());
        let err = read_from(&mut &bytes[..], 1 << 30).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::UnexpectedEof);
        assert!(buffer_for(claimed).capacity() <= HEADER_BYTES + FIRST_CHUNK);
        assert!(buffer_for(u64::MAX).capacity() <= HEADER_BYTES + FIRST_CHUNK);
        assert!(buffer_for(10).capacity() >= HEADER_BYTES + 10);
    }
}
