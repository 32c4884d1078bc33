//! Node layouts: the 8-byte link both copies share and the 24-byte sampling
//! node.
//!
//! Children of a node are contiguous, in quadrant order, starting at
//! `first_child`; the mask says which quadrants have one, so the child of
//! quadrant `q` is `first_child + popcount(mask & ((1 << q) - 1))`. Indices
//! are `u32`: no 65,535-node limit.

/// Which quadrants of a node have a child node, and where the children are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Link {
    first_child: u32,
    mask: u32,
}

impl Link {
    /// A node whose four quadrants are leaves.
    pub(crate) const LEAF: Self = Self {
        first_child: 0,
        mask: 0,
    };

    /// Children at `first_child..` for the quadrants set in the low four bits
    /// of `mask`.
    #[inline]
    pub(crate) fn new(first_child: u32, mask: u32) -> Self {
        debug_assert!(mask < 16);
        Self { first_child, mask }
    }

    /// The stored fields (the save format): first child and mask.
    pub(crate) fn raw(self) -> (u32, u32) {
        (self.first_child, self.mask)
    }

    /// The child node of quadrant `q`, if the quadrant is not a leaf.
    #[inline]
    pub(crate) fn child(self, q: usize) -> Option<usize> {
        if (self.mask >> q) & 1 == 0 {
            return None;
        }
        let before = self.mask & ((1u32 << q) - 1);
        Some(self.first_child as usize + before.count_ones() as usize)
    }
}

/// A node of the sampling copy: the probability of each quadrant (its share
/// of the node's total, as learned) and the link to its children.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Node {
    /// Quadrant shares; they sum to 1 up to `f32` rounding (queries divide
    /// by their sum, so the density stays normalised).
    pub(crate) probs: [f32; 4],
    pub(crate) link: Link,
}

impl Node {
    /// A node that splits its square evenly.
    pub(crate) const UNIFORM_LEAF: Self = Self {
        probs: [0.25; 4],
        link: Link::LEAF,
    };
}

/// Bytes of one sampling-copy node.
pub const NODE_BYTES: usize = core::mem::size_of::<Node>();

const _: () = assert!(NODE_BYTES <= 24);
const _: () = assert!(core::mem::size_of::<Link>() == 8);

/// The probability of quadrant `q` of a node: the same expression for
/// sampling, evaluation and inspection, so they agree bit for bit.
#[inline]
pub(crate) fn quadrant_probability(probs: &[f32; 4], q: usize) -> f64 {
    let p = probs.map(f64::from);
    let total = (p[0] + p[1]) + (p[2] + p[3]);
    if total > 0.0 { p[q] / total } else { 0.25 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_fits_24_bytes() {
        assert_eq!(NODE_BYTES, 24);
    }

    #[test]
    fn children_are_ranked_by_mask() {
        let l = Link::new(100, 0b1010);
        assert_eq!(l.child(0), None);
        assert_eq!(l.child(1), Some(100));
        assert_eq!(l.child(2), None);
        assert_eq!(l.child(3), Some(101));
        let full = Link::new(u32::MAX - 3, 0b1111);
        assert_eq!(full.child(3), Some(u32::MAX as usize));
        assert_eq!(Link::LEAF.child(0), None);
    }

    #[test]
    fn probabilities_normalise() {
        let p = [1.0, 1.0, 2.0, 0.0];
        assert_eq!(quadrant_probability(&p, 2), 0.5);
        assert_eq!(quadrant_probability(&p, 3), 0.0);
        assert_eq!(quadrant_probability(&[0.0; 4], 1), 0.25);
    }
}
