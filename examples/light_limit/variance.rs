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
//! P(l) E[X^2 | l]`; the expectations over the point on a light and over
//! the BSDF direction are the means over the brute-force samples, which are
//! the same for every pmf, so differences between pmfs are exact for those
//! samples (no noise from the sampler under test).

use crate::brute_force::PointTerms;

/// The variance of the estimator at `t` when light `t.lights[i]` is chosen
/// with probability `pmf[i]`.
pub fn variance(t: &PointTerms, pmf: &[f64]) -> f64 {
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
    (nee_m2 - nee_mean * nee_mean).max(0.0) + (b_m2 - b_mean * b_mean).max(0.0)
}

/// The clairvoyant pmf at `t`: proportional to the square root of each
/// light's second moment, estimated from the held-out samples only.
pub fn clairvoyant(t: &PointTerms) -> Vec<f64> {
    let w: Vec<f64> = t.lights.iter().map(|l| l.held_out_m2.sqrt()).collect();
    let total: f64 = w.iter().sum();
    if total > 0.0 {
        w.iter().map(|x| x / total).collect()
    } else {
        w
    }
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
