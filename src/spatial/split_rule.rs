//! Practical Path Guiding's spatial split rule, shared by every structure
//! that refines a [`BinaryTree`] by the number of records its cells took.

use super::{BinaryTree, RefineOutcome};

/// PPG's spatial split threshold after iteration `k` (counted from 0):
/// `c * sqrt(2^k)`, computed in `f64` as `c * 2^(k/2)` (times `sqrt 2` for
/// odd `k`), saturating to infinity. `c` is used as given.
pub fn split_threshold(c: f64, k: u32) -> f64 {
    // sqrt(2^k) = 2^(k/2): halve k, with sqrt(2) for odd k.
    let half = k / 2;
    let even = if half >= 1024 {
        f64::INFINITY
    } else {
        let mut v = 1.0f64;
        for _ in 0..half {
            v *= 2.0;
        }
        v
    };
    let odd = if k % 2 == 1 {
        core::f64::consts::SQRT_2
    } else {
        1.0
    };
    c * even * odd
}

impl<T: Clone> BinaryTree<T> {
    /// PPG's spatial refinement: splits every cell whose `weight` (the
    /// statistical weight it collected) is above `threshold`; the cell is
    /// first given `halve`, then both children hold a copy of it (the upper
    /// one a clone), and both are asked again, so one pass can split a cell
    /// several levels deep. `heap_bytes` and `max_bytes` are those of
    /// [`BinaryTree::refine_with_heap`].
    pub fn split_by_weight(
        &mut self,
        threshold: f64,
        mut weight: impl FnMut(&T) -> f64,
        mut halve: impl FnMut(&mut T),
        heap_bytes: impl FnMut(&T) -> usize,
        max_bytes: Option<usize>,
    ) -> RefineOutcome {
        self.refine_with_heap(
            |cell, _| weight(cell) > threshold,
            |cell| {
                halve(cell);
                cell.clone()
            },
            heap_bytes,
            max_bytes,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threshold_is_c_sqrt_two_to_the_k() {
        assert_eq!(split_threshold(100.0, 0), 100.0);
        assert_eq!(split_threshold(100.0, 2), 200.0);
        assert_eq!(
            split_threshold(3.0, 5),
            3.0 * 4.0 * core::f64::consts::SQRT_2
        );
        assert_eq!(split_threshold(1.0, 4000), f64::INFINITY);
    }
}
