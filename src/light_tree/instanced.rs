//! [`InstancedLightTree`]: a light tree over instances of emissive meshes,
//! each instance's leaf continuing into its mesh's one shared tree.

use super::BuildError;
use super::build::BuildHeuristic;
use super::hierarchy::{LightHierarchy, NodeBounds};
use super::shape::same_shape;
use super::tree::LightTree;
use crate::emitter::Emitter;
use crate::math::scalar::{acos, cbrt, cos};
use crate::math::{Aabb, LightCone};
use crate::persist::Fnv;
use alloc::vec::Vec;
use glam::{Affine3A, Vec3, Vec3A};

/// One placement of an emissive mesh: which mesh, where, and how its
/// emitters' powers scale there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// The mesh's index in the list given to [`InstancedLightTree::build`].
    pub mesh: u32,
    /// Mesh space to world space: any invertible affine map. A mirroring
    /// one (negative determinant) turns the emitters' windings, and so the
    /// side a one-sided emitter emits on, as a renderer's triangle normals
    /// computed from the placed corners turn (pbrt's handedness rule). One
    /// that does not keep angles (a non-uniform scale, a shear) bounds its
    /// Lambertian emitters' normals through `M^-T`, the cone's angle
    /// stretched by `M`'s condition number, and other emitters' directions
    /// by the whole sphere.
    pub transform: Affine3A,
    /// The factor the mesh's emitter powers take in this instance: the
    /// transform's area scale (`s^2` for a uniform scale `s`) times any
    /// emission multiplier of the instance. A finite number >= 0.
    pub power_scale: f32,
}

impl Instance {
    /// `mesh` placed by `transform`, its powers scaled by the transform's
    /// area scale, `|det|^(2/3)`: exact for rotations, uniform scales,
    /// mirrors and translations; for a non-uniform scale the mean area
    /// scale, a weight only (sampling stays exact and unbiased whatever the
    /// powers; they steer it).
    pub fn new(mesh: u32, transform: Affine3A) -> Self {
        let side = cbrt(transform.matrix3.determinant().abs());
        Self {
            mesh,
            transform,
            power_scale: side * side,
        }
    }

    /// This instance with its powers scaled by `factor` more (an emission
    /// multiplier).
    pub fn emitting(self, factor: f32) -> Self {
        Self {
            power_scale: self.power_scale * factor,
            ..self
        }
    }
}

/// The angle (radians) a stretched cone is widened by before it is
/// stretched, covering the rounding of its axis and angle.
const STRETCH_SLACK: f32 = 1e-4;

/// Whether every emitter under `cone` lights the half-space in front of
/// it (`theta_e` pi/2): `cos_theta_e` 0 as light-tree nodes decode it,
/// rounded down by at most one code (6.1e-5).
fn lambertian(cone: LightCone) -> bool {
    (-1e-4..=0.0).contains(&cone.cos_theta_e)
}

/// A placed instance as the hierarchy reads it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placed {
    pub(crate) mesh: u32,
    pub(crate) transform: Affine3A,
    /// `|M|`, the absolute linear part: a local box's half extent maps to
    /// at most `|M| * extent`.
    abs_linear: [Vec3A; 3],
    pub(crate) power_scale: f32,
    /// Whether the transform keeps angles (a rotation, mirror and uniform
    /// scale), so a normal cone maps to a cone of the same angle; else
    /// instance nodes are bounded by the whole sphere of directions.
    pub(crate) similar: bool,
    /// The sign of the transform's determinant: a mirror turns a
    /// triangle's winding, and so the side it emits on.
    pub(crate) handedness: f32,
    /// How normals map: `M^-T` times the handedness (a placed triangle's
    /// normal, from its placed corners).
    normal_map: glam::Mat3A,
    /// A bound on how much the transform stretches angles between
    /// directions: its condition number `sigma_max / sigma_min` (1 for a
    /// transform that keeps angles), slightly rounded up.
    distortion: f32,
    /// The instance's first node past its root, and its first emitter.
    node_base: u32,
    pub(crate) emitter_base: u32,
}

/// A light tree over instances of emissive meshes: one [`LightTree`] per
/// mesh, built once in mesh space and shared by every instance of it, and
/// a top tree over the instances whose leaf for instance `i` continues
/// into its mesh's tree, seen through the instance's transform. A scene of
/// 8,000 instances of a 5,000-triangle mesh stores one 5,000-leaf tree and
/// an 8,000-leaf one, not 40 million leaves (docs/benchmarks.md).
///
/// As a [`LightHierarchy`] it is the flat tree it stands for: emitter
/// `emitter_base(i) + t` is triangle (emitter) `t` of instance `i`'s mesh
/// ([`InstancedLightTree::emitter_id`], [`InstancedLightTree::locate`]), with
/// world-space bounds, cones and powers computed on the fly from the
/// mesh's; so every sampler over a hierarchy samples it exactly (sample ==
/// pmf, normalised) and the GLT's cuts descend into the instances. Nodes
/// `0..top` are the top tree's (instance `i`'s leaf is its mesh's root);
/// instance `i`'s other nodes follow, in instance order. Queries inside an
/// instance find it through an index over the node ids (a step or two).
///
/// The GLT over it ([`crate::Glt`], [`crate::GuidingField`]) keeps its
/// tables per mesh, shared by the mesh's instances
/// ([`LightHierarchy::as_instanced`]): its walk enters an instance's mesh
/// tree with the shading point moved into mesh space, so its memory grows
/// with the meshes and instances, not with the triangles placed.
///
/// ```
/// use guiding::glam::{Affine3A, Vec3};
/// use guiding::{Aabb, BuildHeuristic, Emitter, Glt, GltConfig, Instance, InstancedLightTree};
/// use guiding::{LightChoice, LightHierarchy, LightTree, ShadingContext};
/// // A lamp shade of two triangles, built once in its own space.
/// let shade = [
///     Emitter::triangle([Vec3::ZERO, Vec3::X, Vec3::Y], 1.0, false),
///     Emitter::triangle([Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y], 1.0, false),
/// ];
/// let mesh = LightTree::build(&shade[..], BuildHeuristic::default())?;
/// // Three lamps along a street, the last one twice as bright.
/// let lamps: Vec<Instance> = (0..3)
///     .map(|i| Instance::new(0, Affine3A::from_translation(Vec3::X * 10.0 * i as f32)))
///     .collect();
/// let lamps = [lamps[0], lamps[1], lamps[2].emitting(2.0)];
/// let tree = InstancedLightTree::build(vec![mesh], &lamps, BuildHeuristic::default())?;
/// assert_eq!(tree.emitter_count(), 6);
/// // Emitter ids name (instance, triangle) pairs.
/// let id = tree.emitter_id(2, 1).unwrap();
/// assert_eq!(tree.locate(id), Some((2, 1)));
/// // The GLT guides over it as over any hierarchy.
/// let street = Aabb::new(Vec3::splat(-5.0), Vec3::new(30.0, 5.0, 5.0));
/// let glt = Glt::new(&tree, street, GltConfig::default()).unwrap();
/// let ctx = ShadingContext::on_surface(Vec3::new(20.5, 0.5, 3.0), -Vec3::Z);
/// let vertex = glt.vertex(&ctx).unwrap();
/// let s = vertex.sample(0.3).unwrap();
/// assert_eq!(s.pmf, vertex.pmf(s.light));
/// # Ok::<(), guiding::BuildError>(())
/// ```
#[derive(Clone, Debug)]
pub struct InstancedLightTree {
    meshes: Vec<LightTree>,
    instances: Vec<Placed>,
    top: LightTree,
    node_count: u32,
    emitter_count: u32,
    /// The instance holding the first node of each run of `1 << shift`
    /// nodes past the top tree: a node's instance is found from there in
    /// a step or two instead of a binary search.
    buckets: Vec<u32>,
    shift: u32,
}

impl InstancedLightTree {
    /// Builds the top tree over `instances` of `meshes` (trees built in
    /// mesh space, any number of instances each) with `heuristic`.
    ///
    /// Errors: an instance naming no mesh, with a non-finite or singular
    /// transform, or a power scale that is not a finite number >= 0
    /// ([`BuildError::InvalidInstance`]); more nodes or emitters than `u32`
    /// ids can name ([`BuildError::TooManyEmitters`]); and the top tree's
    /// own errors.
    pub fn build(
        meshes: Vec<LightTree>,
        instances: &[Instance],
        heuristic: BuildHeuristic,
    ) -> Result<Self, BuildError> {
        let top_emitters = instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let invalid = BuildError::InvalidInstance { instance: i };
                let mesh = meshes.get(inst.mesh as usize).ok_or(invalid)?;
                let m = inst.transform.matrix3;
                let det = m.determinant();
                let fine = inst.transform.translation.is_finite()
                    && m.is_finite()
                    && det != 0.0
                    && det.is_finite()
                    && inst.power_scale.is_finite()
                    && inst.power_scale >= 0.0;
                if !fine {
                    return Err(invalid);
                }
                Ok(Emitter {
                    area: 0.0,
                    delta: false,
                    ..root_emitter(mesh, &place(inst, 0, 0))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let top = LightTree::build(top_emitters.as_slice(), heuristic)?;
        let too_many = |count| BuildError::TooManyEmitters { count };
        let mut node_base = top.node_count() as u64;
        let mut emitter_base = 0u64;
        let mut placed = Vec::with_capacity(instances.len());
        for inst in instances {
            let mesh = &meshes[inst.mesh as usize];
            let p = place(inst, node_base as u32, emitter_base as u32);
            node_base += mesh.node_count().saturating_sub(1) as u64;
            emitter_base += mesh.emitter_count() as u64;
            if node_base > u64::from(u32::MAX) || emitter_base >= u64::from(u32::MAX) {
                return Err(too_many(emitter_base as usize));
            }
            placed.push(p);
        }
        let first = top.node_count() as u32;
        let (buckets, shift) = buckets(&placed, first, node_base as u32);
        Ok(Self {
            meshes,
            instances: placed,
            top,
            node_count: node_base as u32,
            emitter_count: emitter_base as u32,
            buckets,
            shift,
        })
    }

    /// The meshes' trees.
    pub fn meshes(&self) -> &[LightTree] {
        &self.meshes
    }

    /// The tree over the instances (its emitter `i` is instance `i`).
    pub fn top(&self) -> &LightTree {
        &self.top
    }

    /// The emitter id of emitter `t` of instance `instance`'s mesh; `None`
    /// out of range.
    pub fn emitter_id(&self, instance: u32, t: u32) -> Option<u32> {
        let p = self.instances.get(instance as usize)?;
        let mesh = &self.meshes[p.mesh as usize];
        ((t as usize) < mesh.emitter_count()).then(|| p.emitter_base + t)
    }

    /// The instance and mesh emitter of emitter id `emitter`; `None` out
    /// of range.
    pub fn locate(&self, emitter: u32) -> Option<(u32, u32)> {
        if emitter >= self.emitter_count {
            return None;
        }
        // The last instance starting at or before it (instances of empty
        // meshes start where the next one does: the last of them is taken,
        // and that is the one holding it).
        let i = self
            .instances
            .partition_point(|p| p.emitter_base <= emitter)
            - 1;
        Some((i as u32, emitter - self.instances[i].emitter_base))
    }

    /// Bytes held: the meshes' trees, the top tree and the instances.
    pub fn bytes(&self) -> usize {
        self.meshes.iter().map(LightTree::bytes).sum::<usize>()
            + self.top.bytes()
            + self.instances.len() * core::mem::size_of::<Placed>()
            + self.buckets.len() * core::mem::size_of::<u32>()
    }

    /// The placements, in instance order.
    pub(crate) fn placements(&self) -> &[Placed] {
        &self.instances
    }

    /// FNV-1a 64 over what the flat tree it stands for is made of: its
    /// node and emitter counts, `tree(top)`, the meshes' `tree(mesh)`, and
    /// per instance what `instance` adds. O(top nodes + mesh nodes +
    /// instances), where hashing the flat tree node by node is O(placed
    /// triangles): seconds at 40 million.
    pub(crate) fn hash_parts(
        &self,
        tree: impl Fn(&LightTree) -> u64,
        instance: impl Fn(&mut Fnv, &Placed),
    ) -> u64 {
        let mut h = Fnv::new();
        // Tells these apart from the node-by-node hashes of flat trees.
        h.bytes(b"instanced");
        h.u32(self.node_count);
        h.u32(self.emitter_count);
        h.u64(tree(&self.top));
        h.u32(self.meshes.len() as u32);
        for mesh in &self.meshes {
            h.u64(tree(mesh));
        }
        h.u32(self.instances.len() as u32);
        for p in &self.instances {
            h.u32(p.mesh);
            instance(&mut h, p);
        }
        h.finish()
    }

    /// Whether `other` stands for a flat tree of the same shape: the same
    /// top tree and mesh shapes, the same mesh in every instance.
    pub(crate) fn same_shape_as(&self, other: &Self) -> bool {
        same_shape(&self.top, &other.top)
            && self.meshes.len() == other.meshes.len()
            && self
                .meshes
                .iter()
                .zip(&other.meshes)
                .all(|(a, b)| same_shape(a, b))
            && self.instances.len() == other.instances.len()
            && self
                .instances
                .iter()
                .zip(&other.instances)
                .all(|(a, b)| a.mesh == b.mesh)
    }

    /// The instance (index and placement) and mesh node of node `node`
    /// past the top tree.
    #[inline]
    fn inside(&self, node: u32) -> Option<(u32, &Placed, u32)> {
        if node < self.top.node_count() as u32 || node >= self.node_count {
            return None;
        }
        // The last instance starting at or before it (one whose mesh has
        // no node past its root starts where the next one does), walked to
        // from its bucket's first.
        let offset = node - self.top.node_count() as u32;
        let mut i = self.buckets[(offset >> self.shift) as usize] as usize;
        while self
            .instances
            .get(i + 1)
            .is_some_and(|p| p.node_base <= node)
        {
            i += 1;
        }
        let p = &self.instances[i];
        Some((i as u32, p, node - p.node_base + 1))
    }

    /// The id of mesh node `local` of instance `i` (`p` its placement).
    #[inline]
    fn id(&self, i: u32, p: &Placed, local: u32) -> Option<u32> {
        match local {
            0 => self.top.leaf(i),
            _ => Some(p.node_base + local - 1),
        }
    }
}

/// The bucket index over the nodes `first..end` of `placed`: runs of
/// `1 << shift` nodes, about one instance's worth each, and for each run
/// the instance holding its first node.
fn buckets(placed: &[Placed], first: u32, end: u32) -> (Vec<u32>, u32) {
    let nodes = end - first;
    let per_instance = nodes / (placed.len() as u32).max(1);
    let shift = per_instance.max(1).ilog2();
    let mut out = Vec::with_capacity((nodes >> shift) as usize + 1);
    let mut i = 0usize;
    for b in 0..=(nodes >> shift) {
        let node = first + (b << shift);
        while placed.get(i + 1).is_some_and(|p| p.node_base <= node) {
            i += 1;
        }
        out.push(i as u32);
    }
    (out, shift)
}

/// `inst` as the hierarchy reads it, its nodes from `node_base`, its
/// emitters from `emitter_base`.
fn place(inst: &Instance, node_base: u32, emitter_base: u32) -> Placed {
    let m = inst.transform.matrix3;
    let abs_linear = [m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs()];
    let gram = m.transpose() * m;
    let s2 = (gram.x_axis.x + gram.y_axis.y + gram.z_axis.z) / 3.0;
    let tolerance = 1e-4 * s2;
    let off = |a: f32, b: f32| (a - b).abs() <= tolerance;
    let similar = off(gram.x_axis.x, s2)
        && off(gram.y_axis.y, s2)
        && off(gram.z_axis.z, s2)
        && off(gram.x_axis.y, 0.0)
        && off(gram.x_axis.z, 0.0)
        && off(gram.y_axis.z, 0.0);
    let handedness = m.determinant().signum();
    Placed {
        mesh: inst.mesh,
        transform: inst.transform,
        abs_linear,
        power_scale: inst.power_scale,
        similar,
        handedness,
        normal_map: m.inverse().transpose() * handedness,
        distortion: condition_number(glam::Mat3::from(m)),
        node_base,
        emitter_base,
    }
}

/// The condition number of `m`: `sqrt(lambda_max / lambda_min)` of its
/// Gram matrix `m^T m`, formed and solved in closed form (Smith's method)
/// in `f64`, rounded up by 1e-4 of itself (more than the eigenvalues'
/// rounding wherever it matters: a cone stretched by more than 3e4 is the
/// whole sphere anyway); infinite when `m` is singular or not finite.
fn condition_number(m: glam::Mat3) -> f32 {
    let cols = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.to_array().map(f64::from));
    // The Gram matrix's entry (r, c): column r dotted with column c.
    let a = |r: usize, c: usize| (0..3).map(|k| cols[r][k] * cols[c][k]).sum::<f64>();
    let off = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
    let diag = [a(0, 0), a(1, 1), a(2, 2)];
    let (lo, hi) = if off == 0.0 {
        let lo = diag.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = diag.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    } else {
        let q = (diag[0] + diag[1] + diag[2]) / 3.0;
        let p2 = diag.iter().map(|d| (d - q) * (d - q)).sum::<f64>() + 2.0 * off;
        let p = libm::sqrt(p2 / 6.0);
        let b = |r: usize, c: usize| (a(r, c) - if r == c { q } else { 0.0 }) / p;
        let det = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(2, 1))
            - b(0, 1) * (b(1, 0) * b(2, 2) - b(1, 2) * b(2, 0))
            + b(0, 2) * (b(1, 0) * b(2, 1) - b(1, 1) * b(2, 0));
        let phi = libm::acos((det / 2.0).clamp(-1.0, 1.0)) / 3.0;
        let third = 2.0 * core::f64::consts::PI / 3.0;
        (
            q + 2.0 * p * libm::cos(phi + third),
            q + 2.0 * p * libm::cos(phi),
        )
    };
    let k = libm::sqrt(hi / lo);
    if lo > 0.0 && k.is_finite() {
        (k * (1.0 + 1e-4)) as f32
    } else {
        f32::INFINITY
    }
}

/// Mesh-space bounds `b` seen through placement `p`: the box around the
/// transformed box, the cone turned with it, the power scaled. Where the
/// transform does not keep angles, a Lambertian cone (`theta_e` pi/2:
/// each emitter lights the half-space in front of it, which any affine
/// map keeps) takes its axis through the normal map and its angle
/// stretched by the transform's condition number (a normalised linear map
/// moves directions on the sphere by at most that factor); other cones
/// become the whole sphere.
fn world(p: &Placed, b: NodeBounds) -> NodeBounds {
    let c = Vec3A::from(b.bounds.center());
    let h = Vec3A::from(b.bounds.diagonal()) * 0.5;
    let [x, y, z] = p.abs_linear;
    let extent = Vec3::from(x * h.x + y * h.y + z * h.z);
    let center = Vec3::from(p.transform.transform_point3a(c));
    let cone = if b.cone.cos_theta_o <= -1.0 {
        b.cone
    } else if p.similar {
        let axis = p.transform.matrix3.mul_vec3a(Vec3A::from(b.cone.axis)) * p.handedness;
        match Vec3::from(axis).try_normalize() {
            Some(axis) => LightCone { axis, ..b.cone },
            None => LightCone {
                cos_theta_o: -1.0,
                ..b.cone
            },
        }
    } else {
        let theta = (acos(b.cone.cos_theta_o.clamp(-1.0, 1.0)) + STRETCH_SLACK) * p.distortion;
        let axis = Vec3::from(p.normal_map.mul_vec3a(Vec3A::from(b.cone.axis))).try_normalize();
        match axis {
            Some(axis) if lambertian(b.cone) && theta < core::f32::consts::PI => LightCone {
                axis,
                cos_theta_o: cos(theta),
                ..b.cone
            },
            _ => LightCone {
                cos_theta_o: -1.0,
                ..b.cone
            },
        }
    };
    NodeBounds {
        bounds: Aabb::new(center - extent, center + extent),
        cone,
        two_sided: b.two_sided,
        power: b.power * p.power_scale,
    }
}

/// The top tree's emitter for an instance: its mesh's root, placed.
fn root_emitter(mesh: &LightTree, p: &Placed) -> Emitter {
    let Some(root) = mesh.root() else {
        // An empty mesh: nothing to choose, a point where it stands.
        let at = Vec3::from(p.transform.translation);
        return Emitter::point(at, 0.0);
    };
    let b = world(p, mesh.node_bounds(root));
    Emitter {
        bounds: b.bounds,
        power: b.power,
        area: 0.0,
        cone: (b.cone.cos_theta_o > -1.0).then_some(b.cone),
        two_sided: b.two_sided,
        delta: false,
        weight: 1.0,
        light_sets: u64::MAX,
    }
}

impl LightHierarchy for InstancedLightTree {
    #[inline]
    fn root(&self) -> Option<u32> {
        self.top.root()
    }

    fn children(&self, node: u32) -> Option<[u32; 2]> {
        if let Some((i, p, local)) = self.inside(node) {
            let [a, b] = self.meshes[p.mesh as usize].children(local)?;
            return Some([self.id(i, p, a)?, self.id(i, p, b)?]);
        }
        match self.top.children(node) {
            Some(c) => Some(c),
            None => {
                let i = self.top.emitter(node)?;
                let p = &self.instances[i as usize];
                let [a, b] = self.meshes[p.mesh as usize].children(0)?;
                Some([self.id(i, p, a)?, self.id(i, p, b)?])
            }
        }
    }

    fn parent(&self, node: u32) -> Option<u32> {
        match self.inside(node) {
            Some((i, p, local)) => {
                let parent = self.meshes[p.mesh as usize].parent(local)?;
                self.id(i, p, parent)
            }
            None => self.top.parent(node),
        }
    }

    fn power(&self, node: u32) -> f32 {
        match self.inside(node) {
            Some((_, p, local)) => self.meshes[p.mesh as usize].power(local) * p.power_scale,
            None => self.top.power(node),
        }
    }

    fn node_bounds(&self, node: u32) -> NodeBounds {
        match self.inside(node) {
            Some((_, p, local)) => world(p, self.meshes[p.mesh as usize].node_bounds(local)),
            None => self.top.node_bounds(node),
        }
    }

    fn emitter(&self, node: u32) -> Option<u32> {
        let (p, local) = match self.inside(node) {
            Some((_, p, local)) => (p, local),
            None if self.top.children(node).is_some() => return None,
            None => (&self.instances[self.top.emitter(node)? as usize], 0),
        };
        let t = self.meshes[p.mesh as usize].emitter(local)?;
        Some(p.emitter_base + t)
    }

    fn leaf(&self, emitter: u32) -> Option<u32> {
        let (i, t) = self.locate(emitter)?;
        let p = &self.instances[i as usize];
        let local = self.meshes[p.mesh as usize].leaf(t)?;
        self.id(i, p, local)
    }

    fn node_count(&self) -> usize {
        self.node_count as usize
    }

    fn emitter_count(&self) -> usize {
        self.emitter_count as usize
    }

    #[inline(always)]
    fn as_instanced(&self) -> Option<&InstancedLightTree> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat3, Quat};

    /// The condition number from the closed-form eigenvalues: 1 (rounded
    /// up by 1e-4) for angle-keeping maps, the ratio of the scales for a
    /// turned stretch (up to 1,000), never below the largest ratio of
    /// lengths seen over 20,000 directions and within 1% of it; infinite
    /// for a singular map.
    #[test]
    fn condition_number_bounds_the_stretch_of_directions() {
        let k = condition_number;
        let turn = Mat3::from_quat(Quat::from_axis_angle(
            Vec3::new(1.0, 2.0, 3.0).normalize(),
            0.7,
        ));
        assert!((k(Mat3::IDENTITY) - 1.0001).abs() < 1e-6);
        assert!((k(turn * 3.0) - 1.0001).abs() < 1e-5);
        let mut state = 0x2545_f491_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        for scale in [
            Vec3::new(4.0, 1.0, 0.5),
            Vec3::new(-2.0, 2.0, 1.0),
            Vec3::new(1.0, 1.0, 1e-3),
        ] {
            let m = turn * Mat3::from_diagonal(scale) * turn.transpose();
            let want = scale.abs().max_element() / scale.abs().min_element();
            assert!(
                (k(m) / want - 1.0).abs() < 1e-3,
                "{scale}: {} vs {want}",
                k(m)
            );
            if want > 10.0 {
                // Random directions do not find the extremes of a thin map.
                continue;
            }
            let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
            for _ in 0..20_000 {
                let Some(u) = Vec3::new(next(), next(), next()).try_normalize() else {
                    continue;
                };
                let l = (m * u).length();
                (lo, hi) = (lo.min(l), hi.max(l));
            }
            assert!(
                hi / lo <= k(m) && hi / lo >= 0.99 * k(m),
                "{scale}: seen {}",
                hi / lo
            );
        }
        assert_eq!(
            k(Mat3::from_diagonal(Vec3::new(1.0, 0.0, 1.0))),
            f32::INFINITY
        );
    }
}
