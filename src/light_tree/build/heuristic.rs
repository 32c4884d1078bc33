//! The build heuristics: which one to use ([`BuildHeuristic`]) and how each
//! prices one side of a split.

use super::bucket::Bucket;
use crate::math::scalar::{cos, safe_acos, sin_cos};
use core::f32::consts::PI;
use glam::Vec3;

/// How the builder chooses where to split a set of emitters.
///
/// The three of the paper weight the classic surface-area cost
/// `SA(left) * W(left) + SA(right) * W(right)` differently; SAOH is pbrt-v4's
/// orientation-aware cost. All binned ones evaluate 12 buckets per axis.
/// Where a weight sums to zero (point lights under SAH, dark lights under
/// SARH) the split falls back to counting emitters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildHeuristic {
    /// Median split by count along the widest axis: equal weight per
    /// emitter, depth `ceil(log2 n)`.
    Balanced,
    /// Surface-area heuristic weighted by emitter surface area.
    Sah,
    /// Surface-area-radiance heuristic: SAH weighted by area x radiosity
    /// (= power). The paper's choice: a few percent lower RMSE and memory.
    #[default]
    Sarh,
    /// pbrt-v4's surface-area-orientation heuristic: power x M_omega(cone)
    /// x surface area x the box's aspect factor.
    Saoh,
}

/// What a bucket's cost weighs: area (SAH), power (SARH, SAOH) or, where
/// those sum to zero, the emitter count.
pub(super) struct Weights {
    heuristic: BuildHeuristic,
    total_area: f64,
    total_power: f64,
}

impl Weights {
    pub(super) fn new(heuristic: BuildHeuristic, total_area: f64, total_power: f64) -> Self {
        Self {
            heuristic,
            total_area,
            total_power,
        }
    }

    #[inline]
    fn weight(&self, b: &Bucket) -> f64 {
        match self.heuristic {
            BuildHeuristic::Sah if self.total_area > 0.0 => b.area,
            BuildHeuristic::Sarh | BuildHeuristic::Saoh if self.total_power > 0.0 => b.power,
            _ => b.count as f64,
        }
    }

    /// The cost of one side: weight x surface area (x `M_omega` x the
    /// aspect factor `kr` under SAOH).
    #[inline]
    pub(super) fn cost<const SAOH: bool>(
        &self,
        b: &Bucket,
        kr: f64,
        memo: &mut OrientationMemo,
    ) -> f64 {
        let sa = b.bounds.surface_area() as f64;
        if SAOH {
            let m = memo.get(b.theta_o, b.cone.cos_theta_e) as f64;
            self.weight(b) * m * sa * kr
        } else {
            self.weight(b) * sa
        }
    }
}

/// SAOH's `Kr`: the box's longest extent over its extent along `axis`.
#[inline]
pub(super) fn aspect<const SAOH: bool>(diag: &Vec3, axis: usize) -> f64 {
    if SAOH && diag[axis] > 0.0 {
        (diag.max_element() / diag[axis]) as f64
    } else {
        1.0
    }
}

/// The last few values of [`m_omega`]: most buckets' cones are the whole
/// sphere or one shared emitter cone, so a handful of entries saves nearly
/// every evaluation (three transcendental functions each).
#[derive(Default)]
pub(super) struct OrientationMemo {
    keys: [Option<(u32, u32)>; 4],
    values: [f32; 4],
    next: usize,
}

impl OrientationMemo {
    #[inline]
    pub(super) fn get(&mut self, theta_o: f32, cos_theta_e: f32) -> f32 {
        let key = Some((theta_o.to_bits(), cos_theta_e.to_bits()));
        if let Some(i) = self.keys.iter().position(|&k| k == key) {
            return self.values[i];
        }
        let v = m_omega(theta_o, cos_theta_e);
        self.keys[self.next] = key;
        self.values[self.next] = v;
        self.next = (self.next + 1) % self.keys.len();
        v
    }
}

/// pbrt-v4's orientation measure (`M_omega`) of a cone with half-angle
/// `theta_o` (as `safe_acos` of its cosine) and emission cosine
/// `cos_theta_e`.
pub(super) fn m_omega(theta_o: f32, cos_theta_e: f32) -> f32 {
    let theta_e = safe_acos(cos_theta_e);
    let theta_w = (theta_o + theta_e).min(PI);
    let (sin_o, cos_o) = sin_cos(theta_o);
    2.0 * PI * (1.0 - cos_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - cos(theta_o - 2.0 * theta_w) - 2.0 * theta_o * sin_o + cos_o)
}
