//! The exact variance of the render example's direct-light estimator at a
//! shading point, for any light-selection pmf.
//!
//! The estimator is one next-event sample (light `l` with probability
//! `P(l)`, a point on it with solid-angle pdf `p_l`) plus one BSDF sample
//! (pdf `p_b`), combined by the power heuristic. With `g = f cos Le V`:
//!
//! ```text
//! NEE:  X = g w_l / (P p_l),   w_l = (P p_l)^2 / ((P p_l)^2 + p_b^2)
//!         = g P p_l / ((P p_l)^2 + p_b^2)
//! BSDF: Y = g w_b / p_b,       w_b = p_b^2 / (p_b^2 + (P p_l)^2)
//! Var = E[X^2] - E[X]^2 + E[Y^2] - E[Y]^2
//! ```
//!
//! The two samples are independent, so their variances add. `E[X^2] = sum_l
//! P(l) E[X^2 | l]`; the expectations over the point on a light are the
//! means over the brute-force samples, which are the same for every pmf, so
//! differences between pmfs are exact for those samples (no noise from the
//! sampler under test).
//!
//! The BSDF part is integrated in the light-sample domain: over the
//! directions of light `l`, `E[Y^k] = E_{x ~ p_l}[Y(x)^k p_b(x) / p_l(x)]`,
//! from the same light samples as the NEE part. BSDF samples themselves
//! would almost never hit a millimetre-sized light, and an estimate from a
//! few dozen of them under-reads exactly the pmfs that undersample such
//! lights (by 9-25% on city). Delta lights (`p_b = 0`) have no BSDF part.

use crate::brute_force::PointTerms;

/// The variance of the estimator at `t` when light `t.lights[i]` is chosen
/// with probability `pmf[i]`.
pub fn variance(t: &PointTerms, pmf: &[f64]) -> f64 {
    let (nee, bsdf) = parts(t, pmf);
    nee + bsdf
}

/// The variances of the NEE part and of the BSDF part of [`variance`].
pub fn parts(t: &PointTerms, pmf: &[f64]) -> (f64, f64) {
    let (mut nee_mean, mut nee_m2) = (0.0f64, 0.0f64);
    let (mut b_mean, mut b_m2) = (0.0f64, 0.0f64);
    let m = t.m.max(1) as f64;
    for (term, &p) in t.lights.iter().zip(pmf) {
        let p = if p.is_nan() || p <= 0.0 { 0.0 } else { p };
        let (mut s1, mut s2) = (0.0, 0.0);
        let (mut y1, mut y2) = (0.0, 0.0);
        for x in &term.eval {
            let pl = p * x.pdf_light;
            let pb = x.pdf_bsdf;
            let d = pl * pl + pb * pb;
            if d <= 0.0 {
                continue;
            }
            if p > 0.0 {
                let v = x.g * pl / d;
                s1 += v;
                s2 += v * v;
            }
            if pb > 0.0 {
                // Y = g p_b / d, weighed by p_b / p_l (directions drawn by
                // the light, expectation over the BSDF's).
                let y = x.g * pb / d;
                let w = pb / x.pdf_light;
                y1 += y * w;
                y2 += y * y * w;
            }
        }
        nee_mean += p * s1 / m;
        nee_m2 += p * s2 / m;
        b_mean += y1 / m;
        b_m2 += y2 / m;
    }
    (
        (nee_m2 - nee_mean * nee_mean).max(0.0),
        (b_m2 - b_mean * b_mean).max(0.0),
    )
}

/// The variance as the instrument computed it before: the BSDF part from
/// the `k` BSDF samples themselves (kept to show the difference; a
/// simulation check of both is in `tests`).
pub fn variance_bsdf_sampled(t: &PointTerms, pmf: &[f64]) -> f64 {
    let (nee, bsdf) = parts_bsdf_sampled(t, pmf);
    nee + bsdf
}

/// The two parts of [`variance_bsdf_sampled`].
pub fn parts_bsdf_sampled(t: &PointTerms, pmf: &[f64]) -> (f64, f64) {
    let (mut nee_mean, mut nee_m2) = (0.0f64, 0.0f64);
    let m = t.m.max(1) as f64;
    for (term, &p) in t.lights.iter().zip(pmf) {
        if p.is_nan() || p <= 0.0 {
            continue;
        }
        let (mut s1, mut s2) = (0.0, 0.0);
        for x in &term.eval {
            let pl = p * x.pdf_light;
            let v = x.g * pl / (pl * pl + x.pdf_bsdf * x.pdf_bsdf);
            s1 += v;
            s2 += v * v;
        }
        nee_mean += p * s1 / m;
        nee_m2 += p * s2 / m;
    }
    let (mut b_mean, mut b_m2) = (0.0f64, 0.0f64);
    let k = t.k.max(1) as f64;
    for h in &t.bsdf {
        let pl = pmf[h.term] * h.pdf_light;
        let v = h.g * h.pdf_bsdf / (h.pdf_bsdf * h.pdf_bsdf + pl * pl);
        b_mean += v / k;
        b_m2 += v * v / k;
    }
    (
        (nee_m2 - nee_mean * nee_mean).max(0.0),
        (b_m2 - b_mean * b_mean).max(0.0),
    )
}

/// The clairvoyant pmf at `t`: proportional to the square root of each
/// light's second moment, estimated from the held-out samples only, mixed
/// with 1% of the same rule on the *unshadowed* second moments. The floor
/// matters where lights are partly hidden (ring's slats): a light whose 16
/// held-out samples were all occluded but whose evaluation samples are not
/// would get pmf 0, and its whole contribution would fall on BSDF samples
/// that almost never hit it (ring's clairvoyant read 2.18 without the floor,
/// above the GLT's 3.45 / 1.6). The floor costs at most 1/0.99 in variance.
pub fn clairvoyant(t: &PointTerms) -> Vec<f64> {
    let normalised = |w: Vec<f64>| {
        let total: f64 = w.iter().sum();
        if total > 0.0 {
            w.iter().map(|x| x / total).collect()
        } else {
            w
        }
    };
    let seen = normalised(t.lights.iter().map(|l| l.held_out_m2.sqrt()).collect());
    let blind = normalised(
        t.lights
            .iter()
            .map(|l| l.held_out_unshadowed_m2.sqrt())
            .collect(),
    );
    let has = |w: &[f64]| w.iter().any(|&x| x > 0.0);
    let share = match (has(&seen), has(&blind)) {
        (true, true) => 0.99,
        (true, false) => 1.0,
        _ => 0.0,
    };
    seen.iter()
        .zip(&blind)
        .map(|(a, b)| share * a + (1.0 - share) * b)
        .collect()
}

/// The relative variance over many points, in the render example's relMSE
/// normalisation: the mean over points of `Var_i / (I_i^2 + 0.01 mean(I)^2)`
/// with `I_i` the direct light at point `i`.
pub fn relative(points: &[PointTerms], variances: &[f64]) -> f64 {
    let n = points.len().max(1) as f64;
    let mean_i = points.iter().map(|t| t.direct).sum::<f64>() / n;
    let floor = 0.01 * mean_i * mean_i;
    points
        .iter()
        .zip(variances)
        .map(|(t, v)| {
            let d = t.direct * t.direct + floor;
            if d > 0.0 { v / d } else { 0.0 }
        })
        .sum::<f64>()
        / n
}

/// The variance of the estimator when its next-event sample is resampled:
/// `m` candidates `x_j = (l_j, y_j)` drawn with the light pmf `pmf` and each
/// light's own sampling (density `q = P p_l`), one kept in proportion to
/// `w_j = target(x_j) / q(x_j)`, the estimate `f(x) W` with
/// `W = (sum_j w_j / m) / target(x)`. The target is the unshadowed
/// contribution `g` at the sampled point times `visibility[i]`, a per-light
/// factor (1: visibility-blind; the held-out visibility at the point: the
/// best a learned visibility could give). MIS weights use the candidate
/// density `P p_l` as the NEE strategy's proxy density, for both
/// strategies, so the BSDF part is the same as [`parts`]'.
///
/// For i.i.d. candidates the second moment has a closed form:
///
/// ```text
/// E[Y^2] = (1/m) int f^2/q + (1 - 1/m) (int target) (int f^2/target)
/// ```
///
/// (condition on the candidates: the kept one's term is
/// `(sum w)^2 / m^2 * sum_s (w_s / sum w) f_s^2 / target_s^2`; the pairs
/// `k == s` give the first term, the others the product of two
/// expectations). At `m = 1` it is plain sampling by `pmf`. Every integral
/// is over the same light samples as [`parts`].
pub fn resampled_parts(t: &PointTerms, pmf: &[f64], visibility: &[f64], m: usize) -> (f64, f64) {
    let n = t.m.max(1) as f64;
    let m = m.max(1) as f64;
    let (mut a, mut b, mut c, mut mean) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for ((term, &p), &v) in t.lights.iter().zip(pmf).zip(visibility) {
        if p.is_nan() || p <= 0.0 {
            continue;
        }
        b += v * term.unshadowed;
        for x in &term.eval {
            let pl = p * x.pdf_light;
            let w = pl * pl / (pl * pl + x.pdf_bsdf * x.pdf_bsdf);
            let f = x.g * w; // visible samples only
            a += f * f / (p * x.pdf_light * x.pdf_light) / n;
            c += f * f / (x.g * v * x.pdf_light) / n;
            mean += f / x.pdf_light / n;
        }
    }
    let nee = (a / m + (1.0 - 1.0 / m) * b * c - mean * mean).max(0.0);
    (nee, parts(t, pmf).1)
}

/// The per-light visibilities of [`resampled_parts`]: all 1, or the
/// held-out visibility at the point (floored at `floor`, as a learned
/// visibility's prior would be).
pub fn visibilities(t: &PointTerms, oracle: bool, floor: f64) -> Vec<f64> {
    t.lights
        .iter()
        .map(|l| {
            if oracle {
                l.held_out_visibility.max(floor)
            } else {
                1.0
            }
        })
        .collect()
}
