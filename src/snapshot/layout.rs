//! The snapshot's plain-data records: what each array of a [`Snapshot`]
//! holds, word by word, so a GPU kernel (or any other reader) can declare
//! the same structs. Every record is `#[repr(C)]`, `bytemuck::Pod`, made
//! of 32-bit words (two 16-bit halves at most), little-endian as uploaded
//! from the usual hosts, and free of `vec3` alignment traps (no field is
//! wider than 4 bytes).
//!
//! [`Snapshot`]: super::Snapshot

use bytemuck::{Pod, Zeroable};

/// `"GLTS"` read as a little-endian `u32`: the first word of every
/// snapshot header.
pub const MAGIC: u32 = u32::from_le_bytes(*b"GLTS");

/// The layout version this crate writes and reads. A change of any record
/// below, or of what a field means, bumps it (docs/format.md).
pub const VERSION: u32 = 2;

/// The top bit of a link word: set, the low 31 bits name a cell
/// ([`Header`]'s spatial nodes) or an emitter ([`TreeEntry::link`]).
pub const LEAF: u32 = 1 << 31;

/// A [`TreeEntry::link`] of a leaf that names no usable emitter: never
/// chosen.
pub const NO_EMITTER: u32 = u32::MAX;

/// [`Header::flags`]: below the cut, children are chosen by their
/// importance at the shading point (else by power).
pub const BELOW_IMPORTANCE: u32 = 1;
/// [`Header::flags`]: the prior component is the light tree by importance
/// at the shading point (else by power).
pub const PRIOR_IMPORTANCE: u32 = 2;
/// [`Header::flags`]: importance weighs a node's children by their
/// children's bounds at even depths (`ImportanceBound::Grandchildren`,
/// new in version 2; else by their own bounds at every depth).
pub const GRANDCHILDREN: u32 = 4;

/// [`Cell::flags`]: the cut's probabilities follow the importance at the
/// shading point (a learned ratio times the children's importances).
pub const MODULATED: u32 = 1;
/// [`Cell::flags`]: the prior component has weight and its product is
/// tracked along the walk.
pub const PRIOR: u32 = 2;

/// [`Bounds::flags`]: the cone covers every direction.
pub const OMNI: u16 = 1;
/// [`Bounds::flags`]: an emitter below is two-sided.
pub const TWO_SIDED: u16 = 2;

/// The first 64 bytes: what the arrays hold and the rules shared by every
/// cell.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Header {
    /// [`MAGIC`].
    pub magic: u32,
    /// [`VERSION`].
    pub version: u32,
    /// [`BELOW_IMPORTANCE`] | [`PRIOR_IMPORTANCE`] | [`GRANDCHILDREN`].
    pub flags: u32,
    /// Unbounded lights `k` (each cell has `k` learned fractions).
    pub unbounded: u32,
    /// The spatial tree's root cube: `min` x, y, z.
    pub root_min: [f32; 3],
    /// Number of spatial-tree node words.
    pub spatial_nodes: u32,
    /// The root cube's `max` x, y, z.
    pub root_max: [f32; 3],
    /// Number of [`Cell`]s.
    pub cells: u32,
    /// Number of [`CutNode`](crate::learned::CutNode)-layout records (12
    /// bytes: `p_left: f32`, two slot words), all cells' cuts end to end.
    pub cut_nodes: u32,
    /// Number of [`TreePair`]s (pair 0 holds the light tree's root; an
    /// empty tree has none).
    pub tree_pairs: u32,
    /// Number of emitters (the length of the leaf-position array).
    pub emitters: u32,
    /// Number of learned visibilities (all cells' end to end; 0 when the
    /// guide learns none).
    pub visibilities: u32,
}

const _: () = assert!(core::mem::size_of::<Header>() == 64);

/// One spatial cell's learned light choice: where its cut and visibilities
/// start and the weights of its mixture, precomputed from its confidence
/// and the guide's configuration. 48 bytes.
///
/// An emitter is chosen with `cut * P_cut + prior * P_prior`, unbounded
/// light `i` with `learned * f_i + floor` (`f_i` the cell's fraction `i`),
/// and the walk first picks the unbounded lights with probability
/// `unbounded`, then the cut over the prior with `cut / (cut + prior)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Cell {
    /// Index of the cell's first cut node (its cut's root); its slots' child
    /// indices count from here.
    pub first_node: u32,
    /// Number of cut nodes (0: the light tree's root ends the cut).
    pub nodes: u32,
    /// Index of the cell's first learned visibility (one per slot, one for
    /// the root when the cut has no node, then one per unbounded light);
    /// unused when the header has no visibilities.
    pub first_visibility: u32,
    /// [`MODULATED`] | [`PRIOR`].
    pub flags: u32,
    /// Probability of the unbounded lights together.
    pub unbounded: f32,
    /// Weight of the cell's learned fractions in an unbounded light's pmf.
    pub learned: f32,
    /// Each unbounded light's floor (the prior's share).
    pub floor: f32,
    /// Weight of the learned (cut) component.
    pub cut: f32,
    /// Weight of the prior component.
    pub prior: f32,
    /// Unused, zero (keeps the record 16-byte aligned).
    pub pad: [u32; 3],
}

const _: () = assert!(core::mem::size_of::<Cell>() == 48);

/// One light-tree node as the walk reads it: 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct TreeEntry {
    /// An inner node's power split: the smaller side's probability, negative
    /// when the right side is the smaller (the larger side has `1 - |s|`);
    /// NaN when both children are dark, and for leaves.
    pub split: f32,
    /// An inner node's children [`TreePair`] index (always greater than the
    /// index of the pair holding the node), or [`LEAF`] | its emitter for a
    /// leaf ([`NO_EMITTER`] for one that cannot be chosen).
    pub link: u32,
}

/// Two siblings, left then right (pair 0: the root, then an unused entry).
/// Pairs are laid out depth-first, left subtree first. 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct TreePair {
    /// Left, right.
    pub nodes: [TreeEntry; 2],
}

const _: () = assert!(core::mem::size_of::<TreePair>() == 16);

/// One light-tree node's bounds, as the importance reads them: 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Bounds {
    /// Centre of the node's box.
    pub center: [f32; 3],
    /// Squared radius of the box's bounding sphere.
    pub radius2: f32,
    /// The cone axis, signed-normalised (`code / 32767`).
    pub axis: [i16; 3],
    /// [`OMNI`] | [`TWO_SIDED`].
    pub flags: u16,
    /// `1 - cos theta_o` of the widened normal cone, as the high 16 bits
    /// of an `f32` (bfloat16, rounded up).
    pub one_minus_cos_o: u16,
    /// `1 - cos theta_e` (the emission spread), bfloat16 rounded up.
    pub one_minus_cos_e: u16,
    /// Total power, finite (the importance is formed as a numerator and a
    /// squared distance, never their quotient, so a 1e30 W node stays
    /// finite in `f32`); 0 for a node that cannot contribute.
    pub power: f32,
}

const _: () = assert!(core::mem::size_of::<Bounds>() == 32);

/// The bounds of a [`TreePair`]'s two nodes, at the same index: 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BoundsPair {
    /// Left, right.
    pub nodes: [Bounds; 2],
}
