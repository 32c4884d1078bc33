//! How many passes each training iteration renders.

/// One planned training iteration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Iteration {
    /// Iteration number `k`, from 0.
    pub index: u32,
    /// Passes to render: `2^k`, or everything left for the last iteration.
    pub passes: u64,
    /// True for the final iteration (its image is the one kept; the
    /// guiding structures need no refinement after it).
    pub is_last: bool,
}

/// `2^index`, saturating.
#[inline]
fn planned_passes(index: u32) -> u64 {
    1u64.checked_shl(index).unwrap_or(u64::MAX)
}

/// The iteration `index` given `remaining_passes` of the budget; `None` when
/// nothing is left.
///
/// It renders `2^index` passes, unless what would remain afterwards is less
/// than the `2^(index+1)` the next iteration needs: then it is the last and
/// renders all `remaining_passes`. Started from iteration 0 with the whole
/// budget `B`, the last iteration `k` gets `R >= 2^k` passes while the ones
/// before took `2^k - 1`, so it renders at least half of `B`.
pub fn next_iteration(index: u32, remaining_passes: u64) -> Option<Iteration> {
    if remaining_passes == 0 {
        return None;
    }
    let planned = planned_passes(index);
    let after = remaining_passes.saturating_sub(planned);
    if remaining_passes <= planned || after < planned.saturating_mul(2) {
        Some(Iteration {
            index,
            passes: remaining_passes,
            is_last: true,
        })
    } else {
        Some(Iteration {
            index,
            passes: planned,
            is_last: false,
        })
    }
}

/// The iteration `index` given `remaining_seconds` of a time budget and the
/// measured `seconds_per_pass` (take it from the latest iteration: guided
/// passes cost more than unguided ones).
///
/// The passes the remaining time affords decide as in [`next_iteration`].
/// With no usable measurement (`seconds_per_pass` not positive and finite,
/// e.g. before the first pass) it plans `2^index` passes, not last. `None`
/// when the time left does not pay for one pass.
///
/// The measurement comes from a training iteration, which also records
/// records; the last iteration only renders and is usually cheaper per
/// pass, so it affords more passes than planned here. A renderer with a
/// hard deadline should render the last iteration until the time is up
/// (as the `render` example does) rather than a fixed pass count.
pub fn next_iteration_by_time(
    index: u32,
    remaining_seconds: f64,
    seconds_per_pass: f64,
) -> Option<Iteration> {
    if remaining_seconds.is_nan() || remaining_seconds <= 0.0 {
        return None;
    }
    if !(seconds_per_pass > 0.0 && seconds_per_pass.is_finite()) {
        return Some(Iteration {
            index,
            passes: planned_passes(index),
            is_last: false,
        });
    }
    let affordable = remaining_seconds / seconds_per_pass;
    // `as` saturates for large values; floor by truncation (positive).
    next_iteration(index, affordable as u64)
}

/// The iterations of a budget of passes, in order (an iterator of
/// `Iteration`).
#[derive(Clone, Debug)]
pub struct Iterations {
    remaining: u64,
    index: u32,
}

impl Iterations {
    /// The plan for `total_passes` passes in all.
    pub fn new(total_passes: u64) -> Self {
        Self {
            remaining: total_passes,
            index: 0,
        }
    }

    /// Passes not yet handed out.
    pub fn remaining(&self) -> u64 {
        self.remaining
    }
}

impl Iterator for Iterations {
    type Item = Iteration;

    fn next(&mut self) -> Option<Iteration> {
        let it = next_iteration(self.index, self.remaining)?;
        self.remaining -= it.passes;
        if it.is_last {
            self.remaining = 0;
        }
        self.index = self.index.saturating_add(1);
        Some(it)
    }
}
