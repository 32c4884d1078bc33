//! Why a snapshot cannot be taken, or why arrays are not one.

/// Why a guide cannot be snapshotted, or why arrays handed to
/// [`SnapshotView::new`](super::SnapshotView::new) are not a valid
/// snapshot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SnapshotError {
    /// The guide uses something a snapshot does not carry (named): light
    /// sets, an instanced light tree.
    Unsupported(&'static str),
    /// An index does not fit the 31 bits a snapshot stores it in.
    TooLarge(&'static str),
    /// The header's first word is not [`MAGIC`](super::layout::MAGIC).
    Magic,
    /// The header names another layout [`VERSION`](super::layout::VERSION).
    Version(u32),
    /// The named array's length does not match the header, or an entry in
    /// it points outside its target or backwards (which could loop).
    Invalid(&'static str),
}

impl core::fmt::Display for SnapshotError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Unsupported(what) => write!(f, "a snapshot does not carry {what}"),
            Self::TooLarge(what) => write!(f, "too many {what} for a snapshot's 31-bit indices"),
            Self::Magic => f.write_str("not a guiding snapshot (bad magic)"),
            Self::Version(v) => write!(
                f,
                "snapshot layout version {v}, this crate reads {}",
                super::layout::VERSION
            ),
            Self::Invalid(array) => write!(f, "invalid snapshot: the {array} array is malformed"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SnapshotError {}
