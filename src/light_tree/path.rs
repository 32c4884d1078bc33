use crate::math::Side;
use smallvec::SmallVec;

/// An emitter's root-to-leaf path: the inner nodes it passes and the side
/// taken at each, then the leaf. Inline up to 64 levels, heap beyond, so any
/// depth works (the paper's code, pbrt-v4 and Cycles pack paths into 32 or
/// 64 bits and break past that depth).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EmitterPath {
    /// (inner node, side taken) from the root down; built leaf-first and
    /// reversed by `finish`.
    steps: SmallVec<[(u32, Side); 64]>,
    leaf: u32,
}

impl EmitterPath {
    pub(crate) fn new() -> Self {
        Self::default()
    }

    pub(crate) fn push_leaf(&mut self, leaf: u32) {
        self.leaf = leaf;
    }

    pub(crate) fn push_parent(&mut self, node: u32, side: Side) {
        self.steps.push((node, side));
    }

    pub(crate) fn finish(&mut self) {
        self.steps.reverse();
    }

    /// The inner nodes from the root down, each with the side the path takes.
    #[inline]
    pub fn steps(&self) -> &[(u32, Side)] {
        &self.steps
    }

    /// The leaf the path ends at.
    #[inline]
    pub fn leaf(&self) -> u32 {
        self.leaf
    }

    /// Number of inner nodes passed (the leaf's depth).
    #[inline]
    pub fn depth(&self) -> usize {
        self.steps.len()
    }
}
