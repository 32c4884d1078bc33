//! Practical Path Guiding's spatial split rule, shared by every structure
//! that refines a [`BinaryTree`](super::BinaryTree) by the number of
//! records its cells took.

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
