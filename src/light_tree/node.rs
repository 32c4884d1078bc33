//! The 32-byte light-tree node: quantised bounds, an octahedral cone axis,
//! quantised cone angles, the subtree's power and two links.
//!
//! Every quantisation rounds outward (bounds grow, cone angles widen, the
//! axis's encoding error is added to `theta_o`), so a decoded node still
//! bounds its emitters and importance never drops to zero for a light that
//! can contribute.

use super::hierarchy::NodeBounds;
use crate::math::scalar::{ceil, floor};
use crate::math::{Aabb, LightCone};
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

/// Link bit marking a leaf; the other 31 bits hold the emitter.
pub(crate) const LEAF_BIT: u32 = 1 << 31;
/// `parent` of the root.
pub(crate) const NO_PARENT: u32 = u32::MAX;
/// Bit of `cos_theta_e` marking a two-sided subtree.
const TWO_SIDED_BIT: u16 = 1 << 15;
const COS_E_MAX: f32 = 32767.0;
const QMAX: f32 = 65535.0;

/// One node of a [`super::LightTree`], plain data (`bytemuck::Pod`), 32 bytes.
///
/// Inner nodes are laid out depth-first: the left child directly follows its
/// parent, `link` holds the right child. Leaves hold their emitter.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct LightNode {
    /// Bounds quantised to 16 bits per coordinate inside the scene box: lower
    /// xyz then upper xyz.
    bounds: [u16; 6],
    /// `cos(theta_o)` mapped from `[-1, 1]` to 16 bits, rounded down.
    cos_theta_o: u16,
    /// `cos(theta_e)` in 15 bits, rounded down; top bit = two-sided.
    cos_theta_e: u16,
    /// Octahedral encoding of the cone axis, 2 x 16 bits.
    axis: u32,
    /// Total power below, as `f32` bits (kept as bits so the node is `Eq`).
    energy: u32,
    /// Right child of an inner node, or `LEAF_BIT | emitter` for a leaf.
    link: u32,
    /// Parent index, `u32::MAX` at the root.
    parent: u32,
}

const _: () = assert!(core::mem::size_of::<LightNode>() == 32);

impl LightNode {
    /// Encodes exact node data against the scene box `scene`.
    pub(crate) fn encode(
        scene: &Aabb,
        bounds: &Aabb,
        cone: &LightCone,
        two_sided: bool,
        energy: f32,
        link: u32,
        parent: u32,
    ) -> Self {
        let (axis, cone) = encode_cone(cone);
        Self {
            bounds: quantize_bounds(scene, bounds),
            cos_theta_o: (floor((cone.cos_theta_o.clamp(-1.0, 1.0) + 1.0) * 0.5 * QMAX)) as u16,
            cos_theta_e: (floor((cone.cos_theta_e.clamp(-1.0, 1.0) + 1.0) * 0.5 * COS_E_MAX))
                as u16
                | if two_sided { TWO_SIDED_BIT } else { 0 },
            axis,
            energy: energy.to_bits(),
            link,
            parent,
        }
    }

    /// Total power below the node.
    #[inline]
    pub fn energy(&self) -> f32 {
        f32::from_bits(self.energy)
    }

    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.link & LEAF_BIT != 0
    }

    #[inline]
    pub(crate) fn link(&self) -> u32 {
        self.link
    }

    #[inline]
    pub(crate) fn parent(&self) -> u32 {
        self.parent
    }

    /// Decodes the node's (conservative) bounds against the scene box.
    #[inline]
    pub(crate) fn decode(&self, scene: &Aabb) -> NodeBounds {
        let ext = scene.diagonal() / QMAX;
        let q = |i: usize| self.bounds[i] as f32;
        let min = scene.min + Vec3::new(q(0), q(1), q(2)) * ext;
        let max = scene.min + Vec3::new(q(3), q(4), q(5)) * ext;
        NodeBounds {
            bounds: Aabb { min, max },
            cone: LightCone {
                axis: decode_octahedral(self.axis),
                cos_theta_o: self.cos_theta_o as f32 / QMAX * 2.0 - 1.0,
                cos_theta_e: (self.cos_theta_e & !TWO_SIDED_BIT) as f32 / COS_E_MAX * 2.0 - 1.0,
            },
            two_sided: self.cos_theta_e & TWO_SIDED_BIT != 0,
            energy: self.energy(),
        }
    }
}

/// Quantises `b` inside `scene`, rounding outward and checking the decoded
/// value so float rounding can never shrink the box.
fn quantize_bounds(scene: &Aabb, b: &Aabb) -> [u16; 6] {
    let ext = scene.diagonal();
    let step = ext / QMAX;
    let mut q = [0u16; 6];
    for axis in 0..3 {
        if !(ext[axis] > 0.0) {
            q[axis] = 0;
            q[axis + 3] = 0;
            continue;
        }
        let t = |x: f32| (x - scene.min[axis]) / ext[axis] * QMAX;
        let mut lo = floor(t(b.min[axis])).clamp(0.0, QMAX) as u16;
        while lo > 0 && scene.min[axis] + lo as f32 * step[axis] > b.min[axis] {
            lo -= 1;
        }
        let mut hi = ceil(t(b.max[axis])).clamp(0.0, QMAX) as u16;
        while hi < u16::MAX && scene.min[axis] + hi as f32 * step[axis] < b.max[axis] {
            hi += 1;
        }
        q[axis] = lo;
        q[axis + 3] = hi;
    }
    q
}

/// Encodes the axis and widens `theta_o` by the encoding's angular error.
fn encode_cone(cone: &LightCone) -> (u32, LightCone) {
    if cone.is_sphere() {
        return (encode_octahedral(Vec3::Z), *cone);
    }
    let code = encode_octahedral(cone.axis);
    let err = crate::math::cone_angle_between(cone.axis, decode_octahedral(code));
    // A small margin for the decode's own float error.
    let theta_o = cone.theta_o() + err + 1e-5;
    let widened = if theta_o >= core::f32::consts::PI {
        LightCone {
            cos_theta_e: cone.cos_theta_e,
            ..LightCone::SPHERE
        }
    } else {
        LightCone {
            cos_theta_o: crate::math::scalar::cos(theta_o),
            ..*cone
        }
    };
    (code, widened)
}

fn encode_octahedral(v: Vec3) -> u32 {
    let v = v / (v.x.abs() + v.y.abs() + v.z.abs());
    let mut p = Vec2::new(v.x, v.y);
    if v.z < 0.0 {
        p = (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign_not_zero(p);
    }
    let q = |x: f32| ((x.clamp(-1.0, 1.0) + 1.0) * 0.5 * QMAX + 0.5) as u32;
    q(p.x) | (q(p.y) << 16)
}

#[inline]
fn decode_octahedral(code: u32) -> Vec3 {
    let x = (code & 0xffff) as f32 / QMAX * 2.0 - 1.0;
    let y = (code >> 16) as f32 / QMAX * 2.0 - 1.0;
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z < 0.0 {
        let s = sign_not_zero(Vec2::new(x, y));
        ((1.0 - y.abs()) * s.x, (1.0 - x.abs()) * s.y)
    } else {
        (x, y)
    };
    Vec3::new(x, y, z).normalize_or(Vec3::Z)
}

#[inline]
fn sign_not_zero(p: Vec2) -> Vec2 {
    Vec2::new(
        if p.x >= 0.0 { 1.0 } else { -1.0 },
        if p.y >= 0.0 { 1.0 } else { -1.0 },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::cone_angle_between;

    #[test]
    fn bounds_round_outward() {
        let scene = Aabb::new(Vec3::new(-3.7, 0.1, 2.0), Vec3::new(11.3, 0.1, 9.9));
        for i in 0..200 {
            let f = i as f32 / 199.0;
            let lo = scene.min + scene.diagonal() * f * 0.7;
            let b = Aabb::new(lo, lo + scene.diagonal() * 0.123 * (1.0 - f));
            let n = LightNode::encode(&scene, &b, &LightCone::SPHERE, false, 1.0, 0, 0);
            let d = n.decode(&scene).bounds;
            assert!(
                d.min.cmple(b.min).all() && d.max.cmpge(b.max).all(),
                "{b:?} -> {d:?}"
            );
            // Never more than two steps loose.
            assert!((b.min - d.min).max_element() <= 2.0 * scene.diagonal().max_element() / QMAX);
        }
    }

    #[test]
    fn cone_widens_by_axis_error() {
        let scene = Aabb::new(Vec3::ZERO, Vec3::ONE);
        for i in 0..500 {
            let t = i as f32 * 0.731;
            let axis = Vec3::new(t.cos(), (t * 1.7).sin(), (t * 0.3).cos() - 0.5).normalize();
            let cone = LightCone::new(axis, 0.01 * (i % 7) as f32, 1.2);
            let n = LightNode::encode(&scene, &scene, &cone, i % 2 == 0, 2.0, 0, 0);
            let d = n.decode(&scene);
            assert_eq!(d.two_sided, i % 2 == 0);
            assert!(d.cone.cos_theta_o <= cone.cos_theta_o);
            assert!(d.cone.cos_theta_e <= cone.cos_theta_e);
            // The true axis lies inside the decoded cone.
            assert!(cone_angle_between(axis, d.cone.axis) <= d.cone.theta_o());
            assert_eq!(d.energy, 2.0);
        }
    }

    #[test]
    fn sphere_stays_sphere() {
        let scene = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let n = LightNode::encode(&scene, &scene, &LightCone::SPHERE, false, 1.0, 0, 0);
        assert!(n.decode(&scene).cone.is_sphere());
    }

    #[test]
    fn flat_scene_axis_decodes_to_scene() {
        let scene = Aabb::new(Vec3::new(0.0, 5.0, 0.0), Vec3::new(1.0, 5.0, 1.0));
        let b = Aabb::from_point(Vec3::new(0.5, 5.0, 0.5));
        let d = LightNode::encode(&scene, &b, &LightCone::SPHERE, false, 1.0, 0, 0).decode(&scene);
        assert_eq!(d.bounds.min.y, 5.0);
        assert_eq!(d.bounds.max.y, 5.0);
    }
}
