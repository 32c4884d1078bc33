//! Enumerations in the save format: a variant as one byte.

use super::{LoadError, Reader};

/// `x` as one byte by its position in `all`.
pub(crate) fn tag<T: PartialEq + Copy>(all: &[T], x: T) -> u8 {
    all.iter().position(|&a| a == x).unwrap_or(0) as u8
}

/// The variant at position `byte` of `all`.
pub(crate) fn untag<T: Copy>(
    r: &mut Reader<'_>,
    field: &'static str,
    all: &[T],
) -> Result<T, LoadError> {
    let at = r.offset();
    let b = r.u8(field)?;
    all.get(usize::from(b))
        .copied()
        .ok_or_else(|| Reader::invalid(field, at))
}
