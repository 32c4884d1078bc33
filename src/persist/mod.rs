//! Saving and loading what was learned, and the light tree it refers to:
//! `to_bytes` / `from_bytes` on [`LightTree`](crate::LightTree),
//! [`SdTree`](crate::SdTree), [`Glt`](crate::Glt) and
//! [`GuidingField`](crate::GuidingField), over byte slices (no
//! `std` needed); with `std`, `read_from` and `write_to` move them through
//! `std::io` streams without trusting a length in the stream.
//!
//! Every buffer starts with a header: the magic `GUIDING\0`, the format
//! version (a `u32`, [`FORMAT_VERSION`]), the crate version that wrote it
//! (three `u16`), the [`Kind`] of structure (`u32`), the payload's length
//! (`u64`) and an FNV-1a 64 checksum (`u64`) of the header before it and
//! the payload; then the payload. Every
//! number is little-endian on every platform; `f32` and `f64` are stored
//! as their bits. The layout of each payload is in `docs/format.md`.
//!
//! Loading checks everything the in-memory code relies on (indices in
//! range, each tree a tree, cuts covering each light once, probabilities
//! and sums finite and non-negative, configurations valid), so a buffer
//! that loads samples and evaluates exactly like the structure that was
//! saved, and a corrupted or hostile one is a [`LoadError`] naming the
//! field and offset. No length in a buffer is trusted beyond the bytes
//! that follow it. Counts of what was recorded are data, not lengths, and
//! are taken as they are: a buffer claiming 2^60 records in a cell makes the
//! next `refine` split that cell as 2^60 records would, so load buffers from
//! untrusted sources into a structure whose refinement is bounded
//! (`max_bytes`), or do not refine them.
//!
//! Learned state refers to the light hierarchy it was trained with by node
//! index: the file holds the hierarchy's
//! [`shape_fingerprint`](crate::light_tree::shape_fingerprint) (its nodes'
//! links and each leaf's emitter), and loading against a hierarchy of
//! another shape (other lights, another order, another build) is
//! [`LoadError::LightTreeMismatch`]. A refit of the tree
//! ([`LightTree::refit`](crate::LightTree::refit): the lights moved or
//! changed power) has the same shape, so state saved at one frame of an
//! animation loads over the tree refitted to any other. Between runs a
//! renderer may change the camera, the resolution and the sample counts,
//! and move its lights through refits; it may not add, remove or reorder
//! lights or rebuild the tree (save the tree with the state, or build it
//! the same way from the same lights). Files before format version 4 hold
//! the whole tree's [`fingerprint`](crate::light_tree::fingerprint) and
//! load only over the very tree they were saved with.

mod bytes;
mod error;
#[cfg(feature = "std")]
mod io;
mod tags;

pub(crate) use bytes::{Fnv, Reader, Writer};
pub use error::LoadError;
#[cfg(feature = "std")]
pub use io::{read_from, write_to};
pub(crate) use tags::{tag, untag};

/// The format version this build writes (and the newest it reads). It
/// changes whenever any payload's layout changes; a build reads every
/// version up to its own.
pub const FORMAT_VERSION: u32 = bytes::FORMAT_VERSION;

/// Which structure a buffer holds (the header's `kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum Kind {
    /// A [`LightTree`](crate::LightTree).
    LightTree = 1,
    /// An [`SdTree`](crate::SdTree).
    SdTree = 2,
    /// A [`Glt`](crate::Glt).
    Glt = 3,
    /// A [`GuidingField`](crate::GuidingField).
    Field = 4,
}
