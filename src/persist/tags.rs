//! Enumerations and configuration errors in the save format.

use super::{LoadError, Reader};
use crate::math::Accumulation;
use crate::spatial::SpatialFilter;

/// A field's `ConfigError` as a load error at `offset`.
pub(crate) fn config_error(e: crate::ConfigError, offset: usize) -> LoadError {
    Reader::invalid(e.field, offset)
}

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

pub(crate) const ACCUMULATION: [Accumulation; 2] =
    [Accumulation::Fast, Accumulation::Deterministic];
pub(crate) const FILTERS: [SpatialFilter; 3] = [
    SpatialFilter::Nearest,
    SpatialFilter::StochasticBox,
    SpatialFilter::Box,
];
