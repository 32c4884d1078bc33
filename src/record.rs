//! [`RecordOutcome`]: what became of one record, the same answer from
//! every guide.

/// What became of one record (a light sample's, a radiance sample's, a
/// visibility or fraction record): the answer of every `record_*` method
/// of [`LightVertex`](crate::LightVertex) and
/// [`DirectionVertex`](crate::DirectionVertex).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RecordOutcome {
    /// The value was added to what is learned.
    Recorded,
    /// The value was zero (an occluded or black sample): a valid
    /// observation that adds nothing to the sums. It still counts as a
    /// sample for the split and refinement rules.
    Zero,
    /// Bad input, ignored and counted
    /// ([`DroppedRecords`](crate::DroppedRecords)): a non-finite position,
    /// direction, value or pdf, a negative value, a light out of range or
    /// with zero power, an unbounded light beyond the configured count.
    Dropped,
    /// Nothing to learn: the record's kind is switched off in the
    /// configuration (a fraction record without a learned fraction, a
    /// visibility record without learned visibility). The values were
    /// checked; nothing is counted.
    Ignored,
}
