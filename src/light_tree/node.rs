//! The 32-byte light-tree node: quantised bounds, an octahedral cone axis,
//! quantised cone angles, the subtree's power and two links.
//!
//! Every quantisation rounds outward (bounds grow, cone angles widen, the
//! axis's encoding error is added to `theta_o`), so a decoded node still
//! bounds its emitters and importance never drops to zero for a light that
//! can contribute.

use super::hierarchy::NodeBounds;
use crate::math::scalar::{ceil, floor};
use crate::math::{Aabb, LightCone, cone_angle_between};
use bytemuck::{Pod, Zeroable};
use core::cmp::Ordering;
use core::f32::consts::PI;
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
    power: u32,
    /// Right child of an inner node, or `LEAF_BIT | emitter` for a leaf.
    link: u32,
    /// Parent index, `u32::MAX` at the root.
    parent: u32,
}

const _: () = assert!(core::mem::size_of::<LightNode>() == 32);

/// Exact (unquantised) data of one node, as the builder computes it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeData {
    /// Bounds of every emitter below.
    pub bounds: Aabb,
    /// Unit axis of the normal cone (ignored for a sphere).
    pub axis: Vec3,
    /// Half-angle of the normal cone in radians; `>= pi` is the sphere.
    pub theta_o: f32,
    /// Cosine of the widest emission angle below.
    pub cos_theta_e: f32,
    /// Whether any emitter below is two-sided.
    pub two_sided: bool,
    /// Total power below.
    pub power: f32,
    /// Right child, or `LEAF_BIT | emitter`.
    pub link: u32,
    /// Parent, or `NO_PARENT`.
    pub parent: u32,
}

impl LightNode {
    /// Encodes exact node data against the scene box `scene`.
    pub(crate) fn encode(scene: &Aabb, d: &NodeData) -> Self {
        let (axis, cos_theta_o) = encode_cone(d.axis, d.theta_o);
        Self {
            bounds: quantize_bounds(scene, &d.bounds),
            cos_theta_o,
            cos_theta_e: encode_cos_e(d.cos_theta_e) | if d.two_sided { TWO_SIDED_BIT } else { 0 },
            axis,
            power: d.power.to_bits(),
            link: d.link,
            parent: d.parent,
        }
    }

    /// Total power below the node.
    #[inline]
    pub fn power(&self) -> f32 {
        f32::from_bits(self.power)
    }

    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.link & LEAF_BIT != 0
    }

    /// The node as eight `u32` words, in an order and packing that do not
    /// depend on the platform (the save format).
    pub(crate) fn words(&self) -> [u32; 8] {
        let b = &self.bounds;
        let pair = |lo: u16, hi: u16| u32::from(lo) | (u32::from(hi) << 16);
        [
            pair(b[0], b[1]),
            pair(b[2], b[3]),
            pair(b[4], b[5]),
            pair(self.cos_theta_o, self.cos_theta_e),
            self.axis,
            self.power,
            self.link,
            self.parent,
        ]
    }

    /// The node from [`LightNode::words`]'s words.
    pub(crate) fn from_words(w: [u32; 8]) -> Self {
        let lo = |x: u32| x as u16;
        let hi = |x: u32| (x >> 16) as u16;
        Self {
            bounds: [lo(w[0]), hi(w[0]), lo(w[1]), hi(w[1]), lo(w[2]), hi(w[2])],
            cos_theta_o: lo(w[3]),
            cos_theta_e: hi(w[3]),
            axis: w[4],
            power: w[5],
            link: w[6],
            parent: w[7],
        }
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
        let b = &self.bounds;
        let (lo, hi) = (scene.min, scene.max);
        let min = Vec3::new(
            dequantize(lo.x, hi.x, b[0]),
            dequantize(lo.y, hi.y, b[1]),
            dequantize(lo.z, hi.z, b[2]),
        );
        let max = Vec3::new(
            dequantize(lo.x, hi.x, b[3]),
            dequantize(lo.y, hi.y, b[4]),
            dequantize(lo.z, hi.z, b[5]),
        );
        NodeBounds {
            bounds: Aabb { min, max },
            cone: LightCone {
                axis: decode_octahedral(self.axis),
                cos_theta_o: decode_cos_o(self.cos_theta_o),
                cos_theta_e: decode_cos_e(self.cos_theta_e & !TWO_SIDED_BIT),
            },
            two_sided: self.cos_theta_e & TWO_SIDED_BIT != 0,
            power: self.power(),
        }
    }
}

/// The coordinate of grid step `q` between `lo` and `hi`: a convex
/// combination, so it never overflows for finite corners (a difference
/// `hi - lo` could) and is exactly `lo` at 0 and exactly `hi` at `QMAX`.
#[inline]
fn dequantize(lo: f32, hi: f32, q: u16) -> f32 {
    let t = q as f32 * (1.0 / QMAX);
    lo * (1.0 - t) + hi * t
}

#[inline]
fn decode_cos_o(q: u16) -> f32 {
    q as f32 / QMAX * 2.0 - 1.0
}

#[inline]
fn decode_cos_e(q: u16) -> f32 {
    q as f32 / COS_E_MAX * 2.0 - 1.0
}

/// Quantises `b` inside `scene`, rounding outward: from a first guess, each
/// code moves outward until the decoded value (through [`dequantize`]
/// itself, so float rounding cannot shrink the box) contains the corner.
fn quantize_bounds(scene: &Aabb, b: &Aabb) -> [u16; 6] {
    let mut q = [0u16; 6];
    for axis in 0..3 {
        let (lo, hi) = (scene.min[axis], scene.max[axis]);
        if hi.partial_cmp(&lo) != Some(Ordering::Greater) {
            continue;
        }
        // First guesses in f64, where `hi - lo` cannot overflow.
        let scale = QMAX as f64 / (hi as f64 - lo as f64);
        let t = |x: f32| ((x as f64 - lo as f64) * scale).clamp(0.0, QMAX as f64) as f32;
        let (bmin, bmax) = (b.min[axis], b.max[axis]);
        // Truncation floors the non-negative guess.
        let mut qlo = t(bmin) as u16;
        while qlo > 0 && dequantize(lo, hi, qlo) > bmin {
            qlo -= 1;
        }
        let mut qhi = ceil(t(bmax)) as u16;
        while qhi < u16::MAX && dequantize(lo, hi, qhi) < bmax {
            qhi += 1;
        }
        q[axis] = qlo;
        q[axis + 3] = qhi;
    }
    q
}

/// The largest 16-bit code whose decoded cosine is at most `c` (from a
/// guess at or above it).
fn encode_cos_o(c: f64) -> u16 {
    let guess = floor(((c + 1.0) * 0.5 * QMAX as f64) as f32) + 1.0;
    let mut q = guess.clamp(0.0, QMAX) as u16;
    while q > 0 && decode_cos_o(q) as f64 > c {
        q -= 1;
    }
    q
}

/// The largest 15-bit code whose decoded cosine is at most `c` (from a
/// guess at or above it).
fn encode_cos_e(c: f32) -> u16 {
    let c = c.clamp(-1.0, 1.0);
    let guess = floor((c + 1.0) * 0.5 * COS_E_MAX) + 1.0;
    let mut q = guess.clamp(0.0, COS_E_MAX) as u16;
    while q > 0 && decode_cos_e(q) > c {
        q -= 1;
    }
    q
}

/// Encodes the axis, then `theta_o` widened by the axis encoding's angular
/// error (and a margin for float error), as a cosine rounded down.
fn encode_cone(axis: Vec3, theta_o: f32) -> (u32, u16) {
    if theta_o.partial_cmp(&PI) != Some(Ordering::Less) {
        return (encode_octahedral(Vec3::Z), 0);
    }
    let code = encode_octahedral(axis);
    let err = cone_angle_between(axis, decode_octahedral(code));
    let theta = theta_o.max(0.0) as f64 + err as f64 + 1e-5;
    if theta >= core::f64::consts::PI {
        return (code, 0);
    }
    (code, encode_cos_o(libm::cos(theta)))
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

    fn data(bounds: Aabb, cone: &LightCone, two_sided: bool, power: f32) -> NodeData {
        NodeData {
            bounds,
            axis: cone.axis,
            theta_o: if cone.is_sphere() { PI } else { cone.theta_o() },
            cos_theta_e: cone.cos_theta_e,
            two_sided,
            power,
            link: 0,
            parent: 0,
        }
    }

    fn encode(scene: &Aabb, b: &Aabb, cone: &LightCone, two_sided: bool) -> NodeBounds {
        LightNode::encode(scene, &data(*b, cone, two_sided, 2.0)).decode(scene)
    }

    #[test]
    fn bounds_round_outward() {
        let scene = Aabb::new(Vec3::new(-3.7, 0.1, 2.0), Vec3::new(11.3, 0.1, 9.9));
        for i in 0..200 {
            let f = i as f32 / 199.0;
            let lo = scene.min + scene.diagonal() * f * 0.7;
            let b = Aabb::new(lo, lo + scene.diagonal() * 0.123 * (1.0 - f));
            let d = encode(&scene, &b, &LightCone::SPHERE, false).bounds;
            assert!(
                d.min.cmple(b.min).all() && d.max.cmpge(b.max).all(),
                "{b:?} -> {d:?}"
            );
            // Never more than two steps loose.
            assert!((b.min - d.min).max_element() <= 2.0 * scene.diagonal().max_element() / QMAX);
        }
    }

    #[test]
    fn scene_box_decodes_exactly() {
        // The root's box must decode to itself: the top code is exactly the
        // scene's upper corner, whatever the rounding of `hi - lo`.
        for scene in [
            Aabb::new(
                Vec3::new(-51.948204, -52.036892, -52.17461),
                Vec3::new(52.057804, 51.75599, 52.51436),
            ),
            Aabb::new(Vec3::splat(-3e38), Vec3::splat(3.4e38)),
            Aabb::new(Vec3::splat(1e-40), Vec3::splat(3e-40)),
        ] {
            let d = encode(&scene, &scene, &LightCone::SPHERE, false).bounds;
            assert_eq!(d, scene);
        }
    }

    #[test]
    fn huge_scenes_never_decode_to_nan() {
        let scene = Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
        for i in 0..100 {
            let x = f32::MAX * (i as f32 / 50.0 - 1.0);
            let b = Aabb::new(Vec3::splat(x), Vec3::splat(x * 0.5));
            let d = encode(&scene, &b, &LightCone::SPHERE, false).bounds;
            assert!(!d.min.is_nan() && !d.max.is_nan());
            assert!(
                d.min.cmple(b.min).all() && d.max.cmpge(b.max).all(),
                "{b:?} -> {d:?}"
            );
        }
    }

    #[test]
    fn cone_widens_by_axis_error() {
        let scene = Aabb::new(Vec3::ZERO, Vec3::ONE);
        for i in 0..500 {
            let t = i as f32 * 0.731;
            let axis = Vec3::new(t.cos(), (t * 1.7).sin(), (t * 0.3).cos() - 0.5).normalize();
            let cone = LightCone::new(axis, 0.01 * (i % 7) as f32, 1.2);
            let d = encode(&scene, &scene, &cone, i % 2 == 0);
            assert_eq!(d.two_sided, i % 2 == 0);
            assert!(d.cone.cos_theta_o <= cone.cos_theta_o);
            assert!(d.cone.cos_theta_e <= cone.cos_theta_e);
            // The true axis lies inside the decoded cone, even for a cone of
            // angle 0 (whose cosine 1 has no room to round down in f32).
            let need = cone_angle_between(axis, d.cone.axis) as f64 + cone.theta_o() as f64;
            assert!(
                need <= libm::acos(d.cone.cos_theta_o as f64),
                "{cone:?} -> {d:?}"
            );
            assert_eq!(d.power, 2.0);
        }
    }

    #[test]
    fn sphere_stays_sphere() {
        let scene = Aabb::new(Vec3::ZERO, Vec3::ONE);
        assert!(
            encode(&scene, &scene, &LightCone::SPHERE, false)
                .cone
                .is_sphere()
        );
        let wide = LightCone::new(Vec3::X, PI - 1e-6, 1.0);
        assert!(encode(&scene, &scene, &wide, false).cone.is_sphere());
    }

    #[test]
    fn flat_scene_axis_decodes_to_scene() {
        let scene = Aabb::new(Vec3::new(0.0, 5.0, 0.0), Vec3::new(1.0, 5.0, 1.0));
        let b = Aabb::from_point(Vec3::new(0.5, 5.0, 0.5));
        let d = encode(&scene, &b, &LightCone::SPHERE, false);
        assert_eq!(d.bounds.min.y, 5.0);
        assert_eq!(d.bounds.max.y, 5.0);
    }
}
