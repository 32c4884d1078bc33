//! The 12-byte cut node: a learned left probability and two slots.

use crate::math::Side;
use bytemuck::{Pod, Zeroable};

/// Flag bit of a slot that ends the cut.
const END: u32 = 1 << 31;

/// One inner node of a guiding cut, plain data (`bytemuck::Pod`), 12 bytes
/// (the paper's code: 20).
///
/// Cut node `i` stands for an inner node of the light tree. Which one is not
/// stored: the cut's root stands for the light tree's root, and a slot that
/// holds a child cut node stands for the light-tree child on that side, so a
/// walk from the root always knows it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct CutNode {
    /// Learned probability of the left side (the right side has
    /// `1 - p_left`).
    p_left: f32,
    /// Per side: a child cut node index, or [`END`] | the light-tree node
    /// where the cut ends.
    slots: [u32; 2],
}

const _: () = assert!(core::mem::size_of::<CutNode>() == 12);

/// What one side of a [`CutNode`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Slot {
    /// The cut continues in this cut node (an index into the cut's nodes).
    Child(u32),
    /// The cut ends here, at this light-tree node: sampling continues below
    /// it by the light tree. The index is recorded in 31 bits for
    /// inspection (exact for any hierarchy below 2^31 nodes); the walks
    /// never read it, they derive the node from the hierarchy.
    End(u32),
}

impl CutNode {
    /// Size of a cut node in bytes.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// A node with left probability `p_left` and the two slots.
    #[inline]
    pub(crate) fn new(p_left: f32, slots: [Slot; 2]) -> Self {
        let enc = |s: Slot| match s {
            Slot::Child(i) => i & !END,
            Slot::End(n) => END | (n & !END),
        };
        Self {
            p_left,
            slots: [enc(slots[0]), enc(slots[1])],
        }
    }

    /// The stored fields (the save format).
    pub(crate) fn raw(&self) -> (f32, [u32; 2]) {
        (self.p_left, self.slots)
    }

    /// A node from [`CutNode::raw`]'s fields (checked by the cut's
    /// `check`).
    pub(crate) fn from_raw(p_left: f32, slots: [u32; 2]) -> Self {
        Self { p_left, slots }
    }

    /// The learned probability of the left side.
    #[inline]
    pub fn p_left(&self) -> f32 {
        self.p_left
    }

    /// The probabilities of left and right in `f64`, as sampling uses them.
    #[inline]
    pub(crate) fn probabilities(&self) -> (f64, f64) {
        let p = self.p_left as f64;
        (p, 1.0 - p)
    }

    /// What the slot on `side` holds.
    #[inline]
    pub fn slot(&self, side: Side) -> Slot {
        let s = self.slots[side.index()];
        if s & END != 0 {
            Slot::End(s & !END)
        } else {
            Slot::Child(s)
        }
    }

    /// The child cut node on `side`, `None` when the cut ends there.
    #[inline]
    pub(crate) fn child(&self, side: Side) -> Option<u32> {
        let s = self.slots[side.index()];
        (s & END == 0).then_some(s)
    }

    #[inline]
    pub(crate) fn set_slot(&mut self, side: Side, slot: Slot) {
        let n = Self::new(self.p_left, [slot, slot]);
        self.slots[side.index()] = n.slots[0];
    }
}
