//! Walking a light hierarchy with one uniform number: the sampling walk and
//! the pmf replay share these two functions, so they multiply exactly the
//! same probabilities in the same order.

use super::LightHierarchy;
use crate::math::{Descent, Side};

/// Descends from `node` to a leaf. At each inner node with children `l`, `r`
/// it chooses by `weights(l, r)` (any non-negative pair; both zero or
/// invalid ends the walk with `None`). Returns the leaf.
#[inline]
pub(crate) fn descend<H: LightHierarchy + ?Sized>(
    tree: &H,
    mut node: u32,
    d: &mut Descent,
    weights: impl Fn(u32, u32) -> (f64, f64),
) -> Option<u32> {
    while let Some([l, r]) = tree.children(node) {
        let (wl, wr) = weights(l, r);
        node = match d.choose(wl, wr)? {
            Side::Left => l,
            Side::Right => r,
        };
    }
    Some(node)
}

/// Replays `steps` (inner nodes with the side taken, as in
/// [`super::EmitterPath::steps`]) with the same `weights` as [`descend`].
/// Returns false as soon as a step has probability 0.
#[inline]
pub(crate) fn follow<H: LightHierarchy + ?Sized>(
    tree: &H,
    steps: &[(u32, Side)],
    d: &mut Descent,
    weights: impl Fn(u32, u32) -> (f64, f64),
) -> bool {
    for &(node, side) in steps {
        let Some([l, r]) = tree.children(node) else {
            return false;
        };
        let (wl, wr) = weights(l, r);
        if !d.follow(wl, wr, side) {
            return false;
        }
    }
    true
}

/// Subtree powers as descent weights.
#[inline]
pub(crate) fn power_weights<H: LightHierarchy + ?Sized>(
    tree: &H,
) -> impl Fn(u32, u32) -> (f64, f64) {
    move |l, r| (tree.power(l) as f64, tree.power(r) as f64)
}
