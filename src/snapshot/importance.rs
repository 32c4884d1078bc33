//! The importance weights of a node's two children at a shading point,
//! over the snapshot's arrays: the GLT's own rule (`src/cut/child_weights.rs`),
//! which this file gathers the records for. A node at even depth weighs
//! each child by its two children's bounds (a leaf child by its own), one
//! at odd depth by the children's own bounds; each bound is a numerator
//! and a squared distance, all `f32`, never dividing a power by a squared
//! distance (a GPU has no `f64` to hold `power / distance^2` for a 1e30 W
//! light a millimetre away), and only the ratio of the two weights is
//! read. A snapshot's [`Bounds`] is the CPU table's record byte for byte,
//! so the lanes are the CPU's exactly. The WGSL kernel
//! (`gpu/src/sample.wgsl`) evaluates the same lanes one at a time.

use super::layout::{Bounds, BoundsPair, LEAF, TreePair};
use crate::cut::{Entry, lanes};
use crate::math::scalar::sqrt;

/// A shading point as the importance reads it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Point {
    pub(super) p: [f32; 3],
    /// The unit normal, or `None` (no normal factor).
    pub(super) n: Option<[f32; 3]>,
}

impl Point {
    /// `p` with `normal` normalised, `None` for a normal that cannot be
    /// (zero, non-finite): as `Vec3::try_normalize`.
    pub(super) fn new(p: [f32; 3], normal: Option<[f32; 3]>) -> Self {
        let n = normal.and_then(|n| {
            let rcp = 1.0 / sqrt(dot(n, n));
            (rcp.is_finite() && rcp > 0.0).then(|| [n[0] * rcp, n[1] * rcp, n[2] * rcp])
        });
        Self { p, n }
    }
}

#[inline(always)]
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The weights at `q` of the two children of the node whose children are
/// pair `k` of `tree`, that node at depth `depth` (the root at 0); `None`
/// for a pair out of range.
#[inline(always)]
pub(super) fn child_weights(
    q: &Point,
    tree: &[TreePair],
    bounds: &[BoundsPair],
    k: u32,
    depth: u32,
) -> Option<(f32, f32)> {
    let pair = bounds.get(k as usize)?;
    let entry = |b: &Bounds| -> Entry { bytemuck::cast(*b) };
    let empty = Entry::EMPTY;
    if depth % 2 == 1 {
        let [l, r] = pair.nodes.map(|b| entry(&b));
        return Some(lanes(q.p, q.n, [&l, &r, &empty, &empty]).side(0));
    }
    let children = tree.get(k as usize)?.nodes;
    let side = |s: usize| -> Option<[Entry; 2]> {
        let link = children[s].link;
        Some(match link & LEAF == 0 {
            true => bounds.get(link as usize)?.nodes.map(|b| entry(&b)),
            false => [entry(&pair.nodes[s]), empty],
        })
    };
    let ([a, b], [c, d]) = (side(0)?, side(1)?);
    Some(lanes(q.p, q.n, [&a, &b, &c, &d]).sides())
}
