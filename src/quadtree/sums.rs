//! Reading the building copy's sums as per-quadrant subtree totals.

use super::node::Link;
use crate::math::SumBuffer;
use alloc::vec::Vec;

/// The building copy's sums in `f64`, four per node, made consistent: mass a
/// box record left on an inner quadrant is spread evenly over the leaves below
/// it (a quarter per level), then every inner quadrant holds the total of its
/// child node. Leaf quadrants hold what landed in them. The same inputs give
/// the same bits (fixed order of operations).
pub(crate) fn subtree_sums(links: &[Link], sums: &SumBuffer) -> Vec<f64> {
    let mut s: Vec<f64> = (0..4 * links.len()).map(|i| sums.get(i)).collect();
    // Parents precede children (breadth-first), so one forward pass pushes
    // deposits all the way down.
    for (n, link) in links.iter().enumerate() {
        for q in 0..4 {
            if let Some(c) = link.child(q) {
                let d = s[4 * n + q];
                if d != 0.0 {
                    s[4 * n + q] = 0.0;
                    for j in 0..4 {
                        s[4 * c + j] += 0.25 * d;
                    }
                }
            }
        }
    }
    for (n, link) in links.iter().enumerate().rev() {
        for q in 0..4 {
            if let Some(c) = link.child(q) {
                s[4 * n + q] = node_total(&s, c);
            }
        }
    }
    s
}

/// The sum of node `n`'s four quadrants, in a fixed order.
#[inline]
pub(crate) fn node_total(s: &[f64], n: usize) -> f64 {
    (s[4 * n] + s[4 * n + 1]) + (s[4 * n + 2] + s[4 * n + 3])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Accumulation;

    #[test]
    fn deposits_spread_and_totals_add_up() {
        // Root with a child under quadrant 2, which has a child under 0.
        let links = [Link::new(1, 0b0100), Link::new(2, 0b0001), Link::LEAF];
        let b = SumBuffer::new(12, Accumulation::Deterministic);
        b.add(4, 3.0); // deposit on node 1's quadrant 0 (inner)
        b.add(4 * 2 + 3, 1.0); // a leaf of node 2
        b.add(5, 2.0); // a leaf of node 1
        b.add(0, 5.0); // a leaf of the root
        let s = subtree_sums(&links, &b);
        for j in 0..4 {
            let expect = 0.75 + if j == 3 { 1.0 } else { 0.0 };
            assert_eq!(s[8 + j], expect);
        }
        assert_eq!(s[4], 4.0);
        assert_eq!(s[5], 2.0);
        assert_eq!(s[2], 6.0);
        assert_eq!(node_total(&s, 0), 11.0);
    }
}
