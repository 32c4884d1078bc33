//! The light tree's nodes decoded once for fast importance evaluation: the
//! Estevez-Kulla importance of [`super::importance`] computed in `f32` from
//! precomputed bounding spheres and cone sines, without decoding the
//! quantised nodes on every visit.

use super::importance::BACK_FACTOR;
use crate::emitter::ShadingContext;
use crate::light_tree::LightHierarchy;
use alloc::vec::Vec;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// Slack on the emission-angle test: `f32` rounding must never decide that
/// a cluster cannot reach a point that the exact bound says it reaches
/// (the importance is then 0 and, with an importance prior, so is the pmf).
const COS_SLACK: f32 = 1e-4;

/// One node, as the importance needs it: 48 bytes.
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
#[repr(C)]
struct Entry {
    center: [f32; 3],
    /// Squared radius of the box's bounding sphere.
    radius2: f32,
    /// Unit cone axis (zero when the cone covers every direction).
    axis: [f32; 3],
    cos_o: f32,
    sin_o: f32,
    cos_e: f32,
    /// Total power; 0 for a node that cannot contribute (no power, empty
    /// or non-finite box).
    energy: f32,
    /// 1 when an emitter below is two-sided.
    two_sided: u32,
}

/// Every node of a light tree decoded for [`ImportanceTable::importance`].
#[derive(Clone, Debug, Default)]
pub(crate) struct ImportanceTable {
    entries: Vec<Entry>,
}

/// A shading point prepared for many evaluations.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FastQuery {
    p: Vec3,
    n: Option<Vec3>,
    finite: bool,
}

impl FastQuery {
    /// Prepares `ctx` (its normal normalised once).
    #[inline]
    pub(crate) fn new(ctx: &ShadingContext) -> Self {
        Self {
            p: ctx.position,
            n: ctx.normal.and_then(Vec3::try_normalize),
            finite: ctx.position.is_finite(),
        }
    }
}

#[inline(always)]
fn sin_of(cos: f32) -> f32 {
    (1.0 - cos * cos).max(0.0).sqrt()
}

/// `cos(max(0, a - b))` from the sines and cosines of `a` and `b`.
#[inline(always)]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// `sin(max(0, a - b))` from the sines and cosines of `a` and `b`.
#[inline(always)]
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

impl ImportanceTable {
    /// Decodes every node of `tree`.
    pub(crate) fn new<H: LightHierarchy + ?Sized>(tree: &H) -> Self {
        let entries = (0..tree.node_count() as u32)
            .map(|n| {
                let b = tree.node_bounds(n);
                let (lo, hi) = (b.bounds.min, b.bounds.max);
                let valid = b.energy > 0.0
                    && b.energy.is_finite()
                    && lo.is_finite()
                    && hi.is_finite()
                    && !b.bounds.is_empty();
                if !valid {
                    return Entry::default();
                }
                let cos_o = b.cone.cos_theta_o.clamp(-1.0, 1.0);
                let axis = b.cone.axis.try_normalize().unwrap_or(Vec3::ZERO);
                Entry {
                    center: (lo * 0.5 + hi * 0.5).to_array(),
                    radius2: (0.5 * (hi - lo)).length_squared(),
                    axis: axis.to_array(),
                    cos_o,
                    sin_o: sin_of(cos_o),
                    cos_e: b.cone.cos_theta_e.clamp(-1.0, 1.0),
                    energy: b.energy,
                    two_sided: u32::from(b.two_sided),
                }
            })
            .collect();
        Self { entries }
    }

    /// Bytes of the table.
    pub(crate) fn bytes(&self) -> usize {
        self.entries.len() * core::mem::size_of::<Entry>()
    }

    /// The importance of `node` at `q`: the bound of
    /// [`super::importance`] (power x conservative emission cosine /
    /// squared distance clamped to the bounding sphere, x the conservative
    /// `|cos|` to the normal), evaluated in `f32` up to the final quotient.
    /// Finite, never negative, 0 for nodes out of range.
    #[inline]
    pub(crate) fn importance(&self, q: &FastQuery, node: u32) -> f64 {
        let Some(e) = self.entries.get(node as usize) else {
            return 0.0;
        };
        if !(e.energy > 0.0 && q.finite) {
            return 0.0;
        }
        let to_p = q.p - Vec3::from_array(e.center);
        let dist2 = to_p.length_squared();
        let r2 = e.radius2;
        let phi = f64::from(e.energy);
        if dist2 <= r2 {
            // Inside the bounding sphere every direction is possible.
            return phi / f64::from(r2).max(1e-200);
        }
        let wi = to_p * (1.0 / dist2.sqrt());
        let sin2_b = r2 / dist2;
        let (sin_b, cos_b) = (sin2_b.sqrt(), (1.0 - sin2_b).max(0.0).sqrt());
        let axis = Vec3::from_array(e.axis);
        let cos_thetap = if e.cos_o > -1.0 && axis != Vec3::ZERO {
            let mut cos_w = axis.dot(wi).clamp(-1.0, 1.0);
            if e.two_sided != 0 {
                cos_w = cos_w.abs();
            }
            let sin_w = sin_of(cos_w);
            let cos_x = cos_sub_clamped(sin_w, cos_w, e.sin_o, e.cos_o);
            let sin_x = sin_sub_clamped(sin_w, cos_w, e.sin_o, e.cos_o);
            cos_sub_clamped(sin_x, cos_x, sin_b, cos_b)
        } else {
            1.0
        };
        // Written so that a NaN also gives 0.
        let reaches = cos_thetap >= e.cos_e - COS_SLACK;
        if !reaches {
            return 0.0;
        }
        let mut imp = f64::from(cos_thetap.max(BACK_FACTOR as f32)) / f64::from(dist2);
        if let Some(n) = q.n {
            let cos_i = wi.dot(n).abs().min(1.0);
            imp *= f64::from(cos_sub_clamped(sin_of(cos_i), cos_i, sin_b, cos_b).max(0.0));
        }
        let imp = phi * imp;
        if imp >= 0.0 && imp.is_finite() {
            imp
        } else {
            0.0
        }
    }

    /// The centre and squared bounding radius of `node` (zero for nodes
    /// out of range or that cannot contribute).
    #[inline]
    pub(crate) fn sphere(&self, node: u32) -> (Vec3, f32) {
        self.entries
            .get(node as usize)
            .map_or((Vec3::ZERO, 0.0), |e| {
                (Vec3::from_array(e.center), e.radius2)
            })
    }
}
