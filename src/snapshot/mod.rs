//! A trained guide's light choice as flat arrays of plain data, for GPU
//! kernels and any other reader that cannot call into the crate.
//!
//! [`Glt::snapshot`](crate::Glt::snapshot) (or
//! [`GuidingField::snapshot`](crate::GuidingField::snapshot)) copies what
//! the GLT's sampling rule reads into a [`Snapshot`]: a [`Header`], the
//! spatial tree's node words, one [`Cell`] per spatial cell, every cell's
//! cut nodes end to end, the cells' unbounded-light fractions and learned
//! visibilities, the light tree as [`TreePair`]s with each pair's
//! first-right leaf position, its nodes' [`Bounds`] and each emitter's leaf
//! position. Every array is `bytemuck::Pod`: upload each with
//! `bytemuck::cast_slice` as one storage buffer. `docs/format.md` gives
//! the layout word by word, and `gpu/` holds a WGSL kernel that samples
//! it, checked against this module on a real GPU API.
//!
//! The sampling rule over the arrays is [`SnapshotView::vertex`], a
//! [`SnapshotVertex`] with the same [`LightChoice`](crate::LightChoice)
//! as the CPU guide's vertex: `no_std`, no allocation, every number in
//! `f32` as a GPU computes it, operation for operation what the WGSL
//! kernel does. Against the guide's own sampler (which keeps its
//! descent and products in `f64`) it chooses the same light for the same
//! number except where the number falls within `f32` rounding of a
//! boundary between two lights, and its pmf agrees to about `1e-6`
//! relative (the tolerances measured on trained scenes are in
//! docs/results.md). Its own `sample` and `pmf` agree bit for bit, and its
//! pmf sums to 1, as every sampler's in the crate.
//!
//! What a snapshot leaves out: light linking (a light tree with light
//! sets, or a query restricted to some unbounded lights) and instanced
//! light trees; [`Glt::snapshot`](crate::Glt::snapshot) refuses those with
//! [`SnapshotError::Unsupported`]. A snapshot is a copy: it does not follow
//! later training; take another after each `refine`.
//!
//! ```
//! use guiding::glam::Vec3;
//! use guiding::{Aabb, BuildHeuristic, Emitter, Glt, GltConfig, LightChoice, LightId, LightTree};
//! use guiding::ShadingContext;
//!
//! let lights = [
//!     Emitter::point(Vec3::new(-1.0, 2.0, 0.0), 1.0),
//!     Emitter::point(Vec3::new(1.0, 2.0, 0.0), 3.0),
//! ];
//! let tree = LightTree::build(&lights[..], BuildHeuristic::default())?;
//! let scene = Aabb::new(Vec3::splat(-3.0), Vec3::splat(3.0));
//! let glt = Glt::new(tree, scene, GltConfig::default())?;
//!
//! let snapshot = glt.snapshot()?;
//! // What a GPU would get: one byte buffer per array.
//! let arrays = snapshot.arrays();
//! let cells: &[u8] = bytemuck::cast_slice(arrays.cells);
//! assert_eq!(cells.len(), 48 * glt.spatial().data_slice().len());
//!
//! // The same rule on the CPU.
//! let view = snapshot.view();
//! let ctx = ShadingContext::on_surface(Vec3::new(0.5, 0.0, 0.0), Vec3::Y);
//! let v = view.vertex(&ctx).expect("a finite point");
//! let s = v.sample(0.7).expect("a light");
//! assert_eq!(s.pmf, v.pmf(s.light));
//! let total: f32 = (0..2).map(|e| v.pmf(LightId::Emitter(e))).sum();
//! assert!((total - 1.0).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod build;
mod error;
mod importance;
pub mod layout;
mod sampling;
mod view;

pub use error::SnapshotError;
pub use layout::{Bounds, BoundsPair, Cell, Header, TreeEntry, TreePair};
pub use sampling::SnapshotVertex;
pub use view::{SnapshotArrays, SnapshotView};

use crate::cut::CutNode;
use alloc::vec::Vec;

/// A trained guide's light choice as owned plain-data arrays (see the
/// [module](self)). Built by [`Glt::snapshot`](crate::Glt::snapshot) and
/// [`GuidingField::snapshot`](crate::GuidingField::snapshot); always
/// valid, so [`Snapshot::view`] cannot fail. `Debug` prints the header
/// and the arrays' lengths.
#[derive(Clone, PartialEq)]
pub struct Snapshot {
    header: Header,
    spatial: Vec<u32>,
    cells: Vec<Cell>,
    cut_nodes: Vec<CutNode>,
    fractions: Vec<f32>,
    visibility: Vec<f32>,
    tree: Vec<TreePair>,
    first_right: Vec<u32>,
    bounds: Vec<BoundsPair>,
    leaf_position: Vec<u32>,
}

impl core::fmt::Debug for Snapshot {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_tuple("Snapshot").field(&self.arrays()).finish()
    }
}

impl Snapshot {
    /// The arrays, borrowed: what to upload, one buffer each.
    pub fn arrays(&self) -> SnapshotArrays<'_> {
        SnapshotArrays {
            header: &self.header,
            spatial: &self.spatial,
            cells: &self.cells,
            cut_nodes: &self.cut_nodes,
            fractions: &self.fractions,
            visibility: &self.visibility,
            tree: &self.tree,
            first_right: &self.first_right,
            bounds: &self.bounds,
            leaf_position: &self.leaf_position,
        }
    }

    /// The arrays ready to sample on the CPU.
    pub fn view(&self) -> SnapshotView<'_> {
        SnapshotView::trusted(self.arrays())
    }

    /// The header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Bytes of all arrays together (what a GPU holds).
    pub fn bytes(&self) -> usize {
        self.arrays().bytes()
    }
}
