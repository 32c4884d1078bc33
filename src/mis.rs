//! Multiple importance sampling for direct light: the heuristics, and the
//! two conventions renderers combine next-event estimation with BSDF (or
//! guided) sampling by, each with what its samples contribute and what they
//! record for the GLT ([`Convention`], [`DirectLight`]).
//!
//! The heuristics take the pdfs of the two techniques for the same sample,
//! in the same measure (solid angle).

use crate::math::luminance;
use glam::Vec3;

/// Veach's power heuristic (beta = 2), the weight of technique `a` against
/// `b`: `a^2 / (a^2 + b^2)`, squared in `f64` so that neither tiny nor huge
/// pdfs underflow or overflow. An infinite `a` (a delta technique) gets 1,
/// two zero pdfs get 0, NaN gives 0.
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    if a.is_infinite() && a > 0.0 {
        return 1.0;
    }
    let (a, b) = (f64::from(a), f64::from(b));
    let (a2, b2) = (a * a, b * b);
    let w = a2 / (a2 + b2);
    if w.is_finite() { w as f32 } else { 0.0 }
}

/// Veach's balance heuristic, the weight of technique `a` against `b`:
/// `a / (a + b)`, with the same edges as [`power_heuristic`].
#[inline]
pub fn balance_heuristic(a: f32, b: f32) -> f32 {
    if a.is_infinite() && a > 0.0 {
        return 1.0;
    }
    let (a, b) = (f64::from(a), f64::from(b));
    let w = a / (a + b);
    if w.is_finite() { w as f32 } else { 0.0 }
}

/// How a renderer combines its light sample with its BSDF sample. Both are
/// unbiased; they differ in which BSDF samples compete with which light,
/// and so in the MIS weights, the contributions and the light records.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Convention {
    /// pbrt-v4 (and the render example): one light sample per vertex from
    /// the light sampler, and the path's own BSDF sample, which counts any
    /// emitter it hits. The light's pdf in both weights includes its
    /// selection pmf, evaluated for the light the BSDF sample hit.
    PbrtV4,
    /// pbrt-v3 (`UniformSampleOneLight` / `EstimateDirect`): one light is
    /// chosen, then one light sample and one BSDF sample are both
    /// estimates of that light only; a BSDF sample that hits another light
    /// counts nothing here, and the sum is divided by the chosen light's
    /// pmf. The weights use the light's pdf without the pmf.
    PbrtV3,
}

/// The MIS weight of one direct-light sample and the factor that turns
/// radiance into its contribution and its light record, under a
/// [`Convention`]:
///
/// - contribution to the pixel (or to the path's radiance at the vertex):
///   `f_cos * le * factor` (`f_cos` the BSDF value times the cosine; for a
///   BSDF sample whose `f_cos / pdf` the path throughput already holds,
///   that is `le * weight` added through the throughput);
/// - value to record for the light
///   ([`LightVertex::record_light`](crate::LightVertex::record_light)):
///   `luminance(le) * factor` (or any
///   fixed scalar of `le`), whatever its visibility: an occluded sample
///   records 0 (a zero is a valid record: it adds nothing to what is
///   learned and counts as a sample for the split and refinement rules).
///
/// Over the light choice and both samples, the values recorded for light
/// `l` have as expectation the radiance it sends to the vertex (visibility
/// included, BSDF and cosine not) integrated over the directions it
/// covers, in both conventions; the contributions, the direct light
/// (`tests/mis_conventions.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectLight {
    /// The MIS weight, in `[0, 1]`.
    pub weight: f32,
    /// `weight / pdf` of the whole technique (see above); 0 when the
    /// sample cannot count (zero, NaN or infinite pdfs).
    pub factor: f32,
}

/// What one direct-light sample adds to the path and what it records
/// for the light it reached ([`DirectLight::estimate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectEstimate {
    /// Added to the path's radiance at the vertex (before the path's
    /// throughput): `f_cos * le * factor`, 0 when occluded.
    pub contribution: Vec3,
    /// The value to record for the light (`record_light`):
    /// `luminance(le) * factor`, 0 when occluded (record it: a zero adds
    /// nothing to what is learned and counts as a sample for the split
    /// and refinement rules; [`RecordOutcome::Zero`](crate::RecordOutcome::Zero)).
    pub record: f32,
}

impl DirectLight {
    /// Nothing: a sample that cannot count.
    pub const NONE: Self = Self {
        weight: 0.0,
        factor: 0.0,
    };

    /// The sample's contribution and record in one call, from the light's
    /// arriving radiance `le` (linear Rec. 709 RGB), `f_cos` (the BSDF
    /// value times the cosine, RGB) and whether the shadow ray found the
    /// light unoccluded. A renderer whose estimator returns only the
    /// weighted contribution (pbrt-v3's `EstimateDirect`) calls this for
    /// its light sample and its BSDF sample and sums the contributions.
    /// A non-finite result counts as nothing (both 0).
    ///
    /// ```
    /// use guiding::glam::Vec3;
    /// use guiding::Convention;
    /// // A light chosen with pmf 0.25, its point sampled with solid-angle
    /// // pdf 2, the BSDF sampling that direction with pdf 0.5.
    /// let d = Convention::PbrtV4.light_sample(0.25, 2.0, 0.5);
    /// let e = d.estimate(Vec3::splat(3.0), Vec3::splat(0.1), true);
    /// assert_eq!(e.contribution, Vec3::splat(0.1 * 3.0) * d.factor);
    /// assert_eq!(e.record, 3.0 * d.factor);
    /// assert_eq!(d.estimate(Vec3::splat(3.0), Vec3::splat(0.1), false).record, 0.0);
    /// ```
    #[inline]
    pub fn estimate(self, le: Vec3, f_cos: Vec3, visible: bool) -> DirectEstimate {
        let contribution = f_cos * le * self.factor;
        let record = luminance(le) * self.factor;
        if visible && contribution.is_finite() && record.is_finite() {
            DirectEstimate {
                contribution,
                record,
            }
        } else {
            DirectEstimate {
                contribution: Vec3::ZERO,
                record: 0.0,
            }
        }
    }

    /// `weight / (a * b)` in `f64`, 0 when not finite or not positive.
    #[inline]
    fn new(weight: f32, a: f32, b: f32) -> Self {
        let f = f64::from(weight) / (f64::from(a) * f64::from(b));
        if f > 0.0 && f.is_finite() {
            Self {
                weight,
                factor: f as f32,
            }
        } else {
            Self::NONE
        }
    }
}

impl Convention {
    /// The light sample of a light chosen with probability `pmf`: its
    /// direction has solid-angle pdf `pdf_light` from the light and
    /// `pdf_bsdf` from the vertex's direction sampling (BSDF or guided
    /// mixture). For a delta light (a point or a sun) pass `pdf_light` 1
    /// and `pdf_bsdf` 0: no BSDF sample competes with it, the weight is 1.
    #[inline]
    pub fn light_sample(self, pmf: f32, pdf_light: f32, pdf_bsdf: f32) -> DirectLight {
        let competing = match self {
            Self::PbrtV4 => pmf * pdf_light,
            Self::PbrtV3 => pdf_light,
        };
        DirectLight::new(power_heuristic(competing, pdf_bsdf), pmf, pdf_light)
    }

    /// The BSDF sample of direction pdf `pdf_bsdf` that hit a light whose
    /// light sampling pdf for that direction is `pdf_light`, `pmf` the
    /// light's selection probability at the vertex (pbrt-v4: the pmf of
    /// the light it hit, from the light sampler's `pmf`; pbrt-v3: the pmf
    /// the chosen light was chosen with, and the sample counts only if it
    /// hit that light).
    #[inline]
    pub fn bsdf_sample(self, pmf: f32, pdf_light: f32, pdf_bsdf: f32) -> DirectLight {
        match self {
            Self::PbrtV4 => {
                let w = power_heuristic(pdf_bsdf, pmf * pdf_light);
                DirectLight::new(w, pdf_bsdf, 1.0)
            }
            Self::PbrtV3 => {
                let w = power_heuristic(pdf_bsdf, pdf_light);
                DirectLight::new(w, pdf_bsdf, pmf)
            }
        }
    }
}

/// The light sample of a resampled light choice
/// ([`crate::resampling::resample`]) whose BSDF sample is kept apart (not
/// resampled as a candidate: then there is no MIS weight), under pbrt-v4's
/// convention: the MIS
/// weight against the BSDF sample takes the candidate density
/// `pmf * pdf_light` as the light strategy's (proxy) density, as the BSDF
/// sample's weight [`Convention::bsdf_sample`] does with the pmf of the
/// light it hit, so the two weights sum to one and the combination is
/// unbiased; the factor is `weight_mis * weight / pdf_light` (`weight` the
/// resampled choice's, in place of `1 / pmf`). A delta light: `pdf_light`
/// 1 and `pdf_bsdf` 0.
///
/// pbrt-v3's convention is not offered: its BSDF sample counts only for the
/// chosen light, weighed by the same `1 / pmf`, which resampling keeps
/// unbiased only where the renderer's unshadowed estimate is positive
/// everywhere a light's own sampling can land.
#[inline]
pub fn resampled_light_sample(pmf: f32, weight: f32, pdf_light: f32, pdf_bsdf: f32) -> DirectLight {
    let w = power_heuristic(pmf * pdf_light, pdf_bsdf);
    let f = f64::from(w) * f64::from(weight) / f64::from(pdf_light);
    if f > 0.0 && f.is_finite() && pmf > 0.0 && pmf.is_finite() {
        DirectLight {
            weight: w,
            factor: f as f32,
        }
    } else {
        DirectLight::NONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The contribution is `f_cos le factor` per channel, the record the
    /// luminance of `le` times the factor; occluded or non-finite, both 0.
    #[test]
    fn an_estimate_is_its_contribution_and_its_record() {
        let d = Convention::PbrtV3.bsdf_sample(0.5, 1.0, 2.0);
        let (le, f) = (Vec3::new(1.0, 2.0, 4.0), Vec3::new(0.5, 0.25, 0.125));
        let e = d.estimate(le, f, true);
        assert_eq!(e.contribution, Vec3::splat(0.5 * d.factor));
        assert_eq!(e.record, luminance(le) * d.factor);
        assert!(e.record > 0.0);
        let nothing = DirectEstimate {
            contribution: Vec3::ZERO,
            record: 0.0,
        };
        assert_eq!(d.estimate(le, f, false), nothing);
        assert_eq!(d.estimate(Vec3::splat(f32::NAN), f, true), nothing);
        assert_eq!(d.estimate(le, Vec3::splat(f32::INFINITY), true), nothing);
        assert_eq!(DirectLight::NONE.estimate(le, f, true), nothing);
    }

    #[test]
    fn weights_sum_to_one_and_edges_are_defined() {
        for (a, b) in [(1.0, 1.0), (0.3, 7.0), (1e-30, 1e-30), (1e20, 3.0)] {
            for h in [power_heuristic, balance_heuristic] {
                let s = h(a, b) + h(b, a);
                assert!((s - 1.0).abs() < 1e-6, "{a} {b}: {s}");
            }
        }
        assert_eq!(power_heuristic(2.0, 1.0), 0.8);
        assert_eq!(balance_heuristic(3.0, 1.0), 0.75);
        for h in [power_heuristic, balance_heuristic] {
            assert_eq!(h(f32::INFINITY, 1.0), 1.0);
            assert_eq!(h(1.0, f32::INFINITY), 0.0);
            assert_eq!(h(0.0, 0.0), 0.0);
            assert_eq!(h(f32::NAN, 1.0), 0.0);
            assert_eq!(h(0.0, 1.0), 0.0);
        }
    }
}
