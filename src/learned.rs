//! What a guide learned, to read: its spatial tree and cells, each cell's
//! guiding cut and directional quadtree, the tables every cut shares, the
//! light tree's nodes, and the bytes all of it takes. A renderer needs none
//! of it to render; a debug view, a statistics overlay or a test does.
//!
//! Each guide hands these out by `&` and nothing here changes what it
//! learned: [`Glt::spatial`](crate::Glt::spatial) (and
//! [`SdTree::spatial`](crate::SdTree::spatial),
//! [`GuidingField::spatial`](crate::GuidingField::spatial)) give the
//! [`BinaryTree`] of cells (read through [`SpatialTree`]), [`Glt::locate`](crate::Glt::locate) a point's
//! [`CellId`], [`GltCell::cut`] a cell's [`GuidingCut`] with its
//! [`CutNode`]s, [`Glt::memory`](crate::Glt::memory) a [`GltMemory`].
//!
//! ```
//! use guiding::glam::Vec3;
//! use guiding::learned::{GltCell, GltMemory, SpatialTree};
//! use guiding::{Aabb, Emitter, Glt, GltConfig, LightTree};
//!
//! let lights = [Emitter::point(Vec3::X, 1.0), Emitter::point(Vec3::Y, 2.0)];
//! let tree = LightTree::build(&lights[..], Default::default())?;
//! let glt = Glt::new(tree, Aabb::new(Vec3::splat(-2.0), Vec3::splat(2.0)), GltConfig::default())?;
//! let cell = glt.locate(Vec3::ZERO).expect("a finite point");
//! let data: &GltCell = glt.spatial().data(cell);
//! assert_eq!(data.cut().nodes().len(), 1); // a new cut: the root's split
//! let memory: GltMemory = glt.memory();
//! assert_eq!(memory.cells, 1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use crate::cut::{CutError, CutMemory, CutNode, CutRules, GuidingCut, Slot};
pub use crate::field::{FieldCell, FieldMemory};
pub use crate::glt::{GltCell, GltMemory};
pub use crate::light_tree::LightNode;
pub use crate::quadtree::{DirectionalTree, QuadLeaf, UNIFORM_PDF};
pub use crate::sd_tree::{SdCell, SdTreeMemory};
pub use crate::spatial::{BinaryTree, CellId, SpatialTree};
