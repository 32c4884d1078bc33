//! A snapshot's arrays, borrowed ([`SnapshotArrays`]), and the same
//! arrays checked so they can be sampled ([`SnapshotView`]).

use super::SnapshotError;
use super::layout::{BoundsPair, Cell, Header, LEAF, MAGIC, NO_EMITTER, TreePair, VERSION};
use crate::cut::{CutNode, Slot};
use crate::math::Side;

/// A snapshot's arrays as slices: what to upload to a GPU, one buffer
/// each, or what a reader that got them elsewhere (a file, a mapped
/// buffer) hands to [`SnapshotView::new`]. `docs/format.md` describes each.
/// `Debug` prints the header and each array's length, not the arrays (a
/// city's are megabytes of text).
#[derive(Clone, Copy, PartialEq)]
pub struct SnapshotArrays<'a> {
    /// Counts and shared rules.
    pub header: &'a Header,
    /// The spatial tree's node words, root first: [`LEAF`] | cell, or an
    /// inner node's first child (the second follows it); children split
    /// their parent's box at its midpoint, on x, y, z in turn.
    pub spatial: &'a [u32],
    /// One record per cell.
    pub cells: &'a [Cell],
    /// Every cell's cut nodes, each cell's in pre-order from its root.
    pub cut_nodes: &'a [CutNode],
    /// Each cell's learned fraction of every unbounded light (`unbounded`
    /// per cell, in cell order).
    pub fractions: &'a [f32],
    /// Each cell's learned visibilities (empty when none are learned).
    pub visibility: &'a [f32],
    /// The light tree, as sibling pairs.
    pub tree: &'a [TreePair],
    /// Per pair, where the right child of the node whose children it holds
    /// starts in depth-first leaf order.
    pub first_right: &'a [u32],
    /// Per pair, both nodes' bounds (empty when no rule reads importance).
    pub bounds: &'a [BoundsPair],
    /// Per emitter, its leaf's position in depth-first leaf order
    /// (`u32::MAX` for an emitter with no leaf).
    pub leaf_position: &'a [u32],
}

impl core::fmt::Debug for SnapshotArrays<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SnapshotArrays")
            .field("header", self.header)
            .field("spatial", &self.spatial.len())
            .field("cells", &self.cells.len())
            .field("cut_nodes", &self.cut_nodes.len())
            .field("fractions", &self.fractions.len())
            .field("visibility", &self.visibility.len())
            .field("tree", &self.tree.len())
            .field("first_right", &self.first_right.len())
            .field("bounds", &self.bounds.len())
            .field("leaf_position", &self.leaf_position.len())
            .finish()
    }
}

impl SnapshotArrays<'_> {
    /// Bytes of all arrays together.
    pub fn bytes(&self) -> usize {
        use core::mem::size_of_val;
        size_of_val(self.header)
            + size_of_val(self.spatial)
            + size_of_val(self.cells)
            + size_of_val(self.cut_nodes)
            + size_of_val(self.fractions)
            + size_of_val(self.visibility)
            + size_of_val(self.tree)
            + size_of_val(self.first_right)
            + size_of_val(self.bounds)
            + size_of_val(self.leaf_position)
    }
}

/// Snapshot arrays known to be valid: every walk over them stays in
/// bounds and ends (links only point forward). [`SnapshotView::vertex`]
/// gives the GLT's sampling rule over them
/// (`src/snapshot/sampling.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SnapshotView<'a> {
    pub(super) a: SnapshotArrays<'a>,
}

impl<'a> SnapshotView<'a> {
    /// Checks `arrays` (O(total length)): the header's magic, version and
    /// counts, and that every index points inside its array and every link
    /// forward. The sampler never panics and never loops on a view this
    /// accepts.
    pub fn new(arrays: SnapshotArrays<'a>) -> Result<Self, SnapshotError> {
        check(&arrays)?;
        Ok(Self { a: arrays })
    }

    /// Arrays built by this crate, which are valid by construction.
    pub(super) fn trusted(arrays: SnapshotArrays<'a>) -> Self {
        debug_assert_eq!(check(&arrays), Ok(()));
        Self { a: arrays }
    }

    /// The arrays.
    pub fn arrays(&self) -> SnapshotArrays<'a> {
        self.a
    }
}

/// `Ok` when `cond`, else [`SnapshotError::Invalid`] naming `array`.
fn ensure(cond: bool, array: &'static str) -> Result<(), SnapshotError> {
    if cond {
        Ok(())
    } else {
        Err(SnapshotError::Invalid(array))
    }
}

fn check(a: &SnapshotArrays) -> Result<(), SnapshotError> {
    let h = a.header;
    if h.magic != MAGIC {
        return Err(SnapshotError::Magic);
    }
    if h.version != VERSION {
        return Err(SnapshotError::Version(h.version));
    }
    let len = |n: u32| n as usize;
    ensure(
        h.root_min.iter().chain(&h.root_max).all(|x| x.is_finite())
            && (0..3).all(|i| h.root_min[i] <= h.root_max[i]),
        "header",
    )?;
    ensure(a.spatial.len() == len(h.spatial_nodes), "spatial")?;
    ensure(
        a.cells.len() == len(h.cells) && !a.cells.is_empty(),
        "cells",
    )?;
    ensure(a.cut_nodes.len() == len(h.cut_nodes), "cut nodes")?;
    ensure(a.tree.len() == len(h.tree_pairs), "tree")?;
    ensure(a.first_right.len() == a.tree.len(), "first right")?;
    ensure(
        a.bounds.is_empty() || a.bounds.len() == a.tree.len(),
        "bounds",
    )?;
    ensure(a.leaf_position.len() == len(h.emitters), "leaf positions")?;
    ensure(a.visibility.len() == len(h.visibilities), "visibility")?;
    let k = len(h.unbounded);
    ensure(
        a.fractions.len()
            == a.cells
                .len()
                .checked_mul(k)
                .ok_or(SnapshotError::Invalid("fractions"))?,
        "fractions",
    )?;
    // Values: probabilities and weights in [0, 1], bounds finite, so
    // every answer is a finite pmf in [0, 1].
    let unit = |x: f32| (0.0..=1.0).contains(&x);
    ensure(
        a.cells.iter().all(|c| {
            [c.unbounded, c.learned, c.floor, c.cut, c.prior]
                .into_iter()
                .all(unit)
        }),
        "cells",
    )?;
    ensure(a.cut_nodes.iter().all(|n| unit(n.p_left())), "cut nodes")?;
    ensure(a.fractions.iter().all(|&f| unit(f)), "fractions")?;
    ensure(a.visibility.iter().all(|&v| unit(v)), "visibility")?;
    ensure(
        a.tree
            .iter()
            .flat_map(|p| &p.nodes)
            .all(|e| e.split.is_nan() || e.split.abs() <= 0.5),
        "tree",
    )?;
    ensure(
        a.bounds.iter().flat_map(|p| &p.nodes).all(|b| {
            b.center.iter().all(|x| x.is_finite())
                && b.radius2 >= 0.0
                && b.radius2.is_finite()
                && b.power >= 0.0
                && b.power.is_finite()
        }),
        "bounds",
    )?;
    // Spatial nodes: a leaf names a cell, an inner node's two children lie
    // after it.
    for (i, &w) in a.spatial.iter().enumerate() {
        let ok = match w & LEAF {
            0 => (w as usize) > i && (w as usize) + 1 < a.spatial.len(),
            _ => ((w & !LEAF) as usize) < a.cells.len(),
        };
        ensure(ok, "spatial")?;
    }
    ensure(!a.spatial.is_empty(), "spatial")?;
    // Cells: cuts inside the node array, in pre-order (children after
    // their node, inside the cell's range); visibilities inside theirs.
    for c in a.cells {
        let (first, n) = (c.first_node as usize, c.nodes as usize);
        let end = first
            .checked_add(n)
            .ok_or(SnapshotError::Invalid("cells"))?;
        ensure(end <= a.cut_nodes.len(), "cells")?;
        for (i, node) in a.cut_nodes[first..end].iter().enumerate() {
            for side in [Side::Left, Side::Right] {
                if let Slot::Child(j) = node.slot(side) {
                    ensure((j as usize) > i && (j as usize) < n, "cut nodes")?;
                }
            }
        }
        if !a.visibility.is_empty() {
            let slots = (2 * n).max(1) + k;
            let v = (c.first_visibility as usize).checked_add(slots);
            ensure(v.is_some_and(|v| v <= a.visibility.len()), "cells")?;
        }
    }
    // Light tree: inner entries point to later pairs; leaves name an
    // emitter (or none, as the root pair's unused second entry does).
    for (k, pair) in a.tree.iter().enumerate() {
        for e in &pair.nodes {
            let ok = match e.link & LEAF {
                0 => (e.link as usize) > k && (e.link as usize) < a.tree.len(),
                _ => e.link == NO_EMITTER || ((e.link & !LEAF) as usize) < a.leaf_position.len(),
            };
            ensure(ok, "tree")?;
        }
    }
    Ok(())
}
