//! [`LoadError`]: why a saved structure could not be loaded.

/// Why bytes could not be loaded as a guiding structure. Every variant
/// says where: the byte offset into the buffer and the field being read.
/// Loading never panics and never trusts a length in the file beyond the
/// bytes that follow it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LoadError {
    /// The buffer ends before `field` (at `offset`) is complete.
    Truncated {
        /// What was being read.
        field: &'static str,
        /// Where it starts.
        offset: usize,
    },
    /// The buffer does not start with the crate's magic bytes.
    NotGuidingData,
    /// Written in a format version this build does not read.
    UnsupportedVersion {
        /// The version in the header.
        found: u32,
        /// The newest version this build reads.
        supported: u32,
    },
    /// Holds another kind of structure than the one asked for.
    WrongKind {
        /// The kind asked for (`Kind` as a number).
        expected: u32,
        /// The kind in the header.
        found: u32,
    },
    /// The payload's checksum does not match the header's: the bytes were
    /// changed after they were written.
    Checksum,
    /// `field` (at `offset`) holds a value the structure cannot have: out
    /// of range, not finite, an index outside its table, a broken tree.
    Invalid {
        /// The field.
        field: &'static str,
        /// Where it was read.
        offset: usize,
    },
    /// The learned state was trained with another light hierarchy than the
    /// one given (other lights, another order, another build): loading it
    /// would give wrong probabilities.
    LightTreeMismatch {
        /// The fingerprint of the hierarchy it was trained with.
        saved: u64,
        /// The fingerprint of the hierarchy given.
        given: u64,
    },
    /// Bytes remain after the structure's end (at `offset`).
    TrailingBytes {
        /// Where the structure ended.
        offset: usize,
    },
}

impl core::fmt::Display for LoadError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Truncated { field, offset } => {
                write!(f, "truncated: {field} at byte {offset} is incomplete")
            }
            Self::NotGuidingData => write!(f, "not guiding data (bad magic)"),
            Self::UnsupportedVersion { found, supported } => write!(
                f,
                "format version {found} is not supported (this build reads up to {supported})"
            ),
            Self::WrongKind { expected, found } => {
                write!(f, "holds structure kind {found}, expected {expected}")
            }
            Self::Checksum => write!(f, "checksum mismatch: the data was altered"),
            Self::Invalid { field, offset } => write!(f, "invalid {field} at byte {offset}"),
            Self::LightTreeMismatch { saved, given } => write!(
                f,
                "trained with light tree {saved:016x}, given {given:016x}"
            ),
            Self::TrailingBytes { offset } => write!(f, "trailing bytes after byte {offset}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for LoadError {}
