//! [`InstancedTables`]: the GLT's tables over an
//! [`InstancedLightTree`], one set per mesh shared by all its instances.
//!
//! Inside an instance the walk reads its mesh's tables with the shading
//! point moved into mesh space. For a transform that keeps angles
//! (rotations, mirrors, uniform scales) every importance inside the
//! instance is the mesh-space one times the same factor, so the split
//! probabilities are those of the world-space bounds up to rounding (and
//! the mesh-space boxes are tighter: a turned box's world box is not).
//! Power splits are the mesh's, the instance's power scale cancelling.
//! A mirror turns one-sided emitters (`Instance::transform`), so mirrored
//! instances read a view of the table with the cone axes turned; a
//! transform that does not keep angles reads one without cones (every
//! direction possible, as the world-space bounds have it), which keeps
//! the bound conservative: the distance it divides by is the mesh-space
//! one, a weight only, and the tangent-plane test is exact under any
//! affine map. (For triangles the mesh-space cones would be exact there
//! too, a front/back test being a half-space test; reading them instead
//! was measured on stretched lamp panels, `examples/instancing.rs` row 3:
//! the typical point's variance 0.99x the flat tree's without cones,
//! 1.03x with them, so not kept; and a spot's cone stretched is no
//! cone.)

use super::child_weights::Lanes;
use super::config::ImportanceBound;
use super::importance_table::{FastQuery, ImportanceTable};
use super::tables::{Segment, TreeTables};
use super::walk::WalkTable;
use crate::light_tree::{InstancedLightTree, LightHierarchy, LightTree, NodeBounds};
use crate::math::LightCone;
use alloc::vec::Vec;
use glam::{Mat3A, Vec3A};

/// How an instance sees its mesh's emission cones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum View {
    /// As they are (a transform that keeps angles and handedness).
    Direct = 0,
    /// Turned around (a mirror that keeps angles).
    Mirrored = 1,
    /// Not at all: every direction (a transform that does not keep
    /// angles).
    Unoriented = 2,
}

impl View {
    const ALL: [View; 3] = [View::Direct, View::Mirrored, View::Unoriented];

    /// A mesh node's bounds as this view's table holds them.
    fn bounds(self, b: NodeBounds) -> NodeBounds {
        let cone = match self {
            View::Direct => b.cone,
            View::Mirrored => LightCone {
                axis: -b.cone.axis,
                ..b.cone
            },
            View::Unoriented => LightCone {
                cos_theta_o: -1.0,
                ..b.cone
            },
        };
        NodeBounds { cone, ..b }
    }
}

/// One mesh's tables: its split and walk tables, and an importance table
/// for each view some instance of it reads (none when no rule uses
/// importance).
#[derive(Clone, Debug)]
struct MeshTables {
    tables: TreeTables,
    views: [Option<ImportanceTable>; 3],
}

/// What the walk needs of one instance: how to move a point into its mesh
/// space, which tables it reads and its first emitter id.
#[derive(Clone, Copy, Debug)]
struct InstanceView {
    /// The inverse of the instance's linear part.
    to_mesh: Mat3A,
    /// The transpose of its linear part (normals are covectors).
    normal_to_mesh: Mat3A,
    /// Its translation.
    origin: Vec3A,
    /// The instance's power scale.
    power_scale: f32,
    /// What squared distances grow by from mesh to world space:
    /// `|det|^(2/3)`, exactly the square of the scale for a transform that
    /// keeps angles (for one that does not, a weight only, as the
    /// unoriented view's distances are).
    distance2_scale: f32,
    mesh: u32,
    view: View,
    emitter_base: u32,
}

/// The GLT's tables over an [`InstancedLightTree`] below its top tree:
/// per mesh, shared by its instances; per instance, its placement.
#[derive(Clone, Debug)]
pub(crate) struct InstancedTables {
    meshes: Vec<MeshTables>,
    instances: Vec<InstanceView>,
}

impl InstancedTables {
    /// The tables of `tree`'s meshes, with importance tables weighing
    /// children by `importance`'s bound when there is one. O(mesh nodes +
    /// instances).
    pub(crate) fn new(tree: &InstancedLightTree, importance: Option<ImportanceBound>) -> Self {
        let instances: Vec<InstanceView> = tree
            .placements()
            .iter()
            .map(|p| InstanceView {
                to_mesh: p.transform.matrix3.inverse(),
                normal_to_mesh: p.transform.matrix3.transpose(),
                origin: p.transform.translation,
                power_scale: p.power_scale,
                distance2_scale: {
                    let s = libm::cbrtf(p.transform.matrix3.determinant().abs());
                    s * s
                },
                mesh: p.mesh,
                view: match (p.similar, p.handedness < 0.0) {
                    (false, _) => View::Unoriented,
                    (true, true) => View::Mirrored,
                    (true, false) => View::Direct,
                },
                emitter_base: p.emitter_base,
            })
            .collect();
        // Which views of each mesh some instance reads.
        let mut used = alloc::vec![[false; 3]; tree.meshes().len()];
        for v in &instances {
            used[v.mesh as usize][v.view as usize] = true;
        }
        let meshes = tree
            .meshes()
            .iter()
            .zip(&used)
            .map(|(mesh, used)| {
                let pairs = WalkTable::pair_nodes(mesh);
                MeshTables {
                    tables: TreeTables::new(mesh, None),
                    views: View::ALL.map(|v| {
                        importance.filter(|_| used[v as usize]).map(|bound| {
                            ImportanceTable::from_bounds(
                                pairs.iter().copied(),
                                |n| v.bounds(mesh.node_bounds(n)),
                                bound,
                            )
                        })
                    }),
                }
            })
            .collect();
        Self { meshes, instances }
    }

    /// The walk inside instance `i`: its mesh's tables, the point `fast`
    /// (in world space) moved into mesh space. `None` for an instance out
    /// of range.
    #[inline]
    pub(crate) fn segment(&self, i: u32, fast: &FastQuery) -> Option<Segment<'_>> {
        let v = self.instances.get(i as usize)?;
        let mesh = self.meshes.get(v.mesh as usize)?;
        let importance = mesh.views[v.view as usize].as_ref();
        let fast = match importance {
            Some(_) => fast.moved(&v.to_mesh, v.origin, &v.normal_to_mesh),
            None => *fast,
        };
        Some(mesh.tables.segment(importance, fast, Some(i)))
    }

    /// The raw lanes at `fast` (in world space) of the two children of
    /// instance `i`'s mesh root, in lanes 0 and 1, brought to world space
    /// by the instance's power and distance scales (`Lanes::with_side`
    /// applies them): what the top tree weighs the instance's leaf by where
    /// the flattened tree would weigh the mesh root by its children
    /// (`ImportanceBound::Grandchildren`). `None` where the mesh root is a
    /// leaf (the leaf's own bound stands), out of range and without an
    /// importance table.
    #[inline]
    pub(crate) fn root_lanes(&self, i: u32, fast: &FastQuery) -> Option<(Lanes, f32, f32)> {
        let seg = self.segment(i, fast)?;
        let k = seg.walk.root()?.children()?;
        let v = self.instances.get(i as usize)?;
        let lanes = seg.importance?.child_lanes(&seg.fast, k)?;
        Some((lanes, v.power_scale, v.distance2_scale))
    }

    /// The emitter id of emitter `t` of instance `i`'s mesh.
    #[inline(always)]
    pub(crate) fn emitter_id(&self, i: u32, t: u32) -> Option<u32> {
        self.instances.get(i as usize)?.emitter_base.checked_add(t)
    }

    /// Heap bytes.
    pub(crate) fn bytes(&self) -> usize {
        let views = |m: &MeshTables| {
            m.views
                .iter()
                .flatten()
                .map(ImportanceTable::bytes)
                .sum::<usize>()
        };
        self.meshes
            .iter()
            .map(|m| m.tables.bytes() + views(m))
            .sum::<usize>()
            + self.meshes.len() * core::mem::size_of::<MeshTables>()
            + self.instances.len() * core::mem::size_of::<InstanceView>()
    }
}

/// The mesh `tree`'s instance `i` places; for the pmf's path inside it.
pub(crate) fn mesh_of(tree: &InstancedLightTree, i: u32) -> Option<&LightTree> {
    let p = tree.placements().get(i as usize)?;
    tree.meshes().get(p.mesh as usize)
}
