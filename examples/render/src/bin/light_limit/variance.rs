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
    shares(points, variances).iter().sum()
}

/// Each point's share of [`relative`]: its variance over the point's
/// normalisation, divided by the number of points.
pub fn shares(points: &[PointTerms], variances: &[f64]) -> Vec<f64> {
    let n = points.len().max(1) as f64;
    let mean_i = points.iter().map(|t| t.direct).sum::<f64>() / n;
    let floor = 0.01 * mean_i * mean_i;
    points
        .iter()
        .zip(variances)
        .map(|(t, v)| {
            let d = t.direct * t.direct + floor;
            if d > 0.0 { v / d / n } else { 0.0 }
        })
        .collect()
}

/// The density both strategies' MIS weights take for a resampled
/// next-event sample (its true density is not known in closed form; any
/// density that is a function of the sample alone keeps the combination
/// unbiased).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Proxy {
    /// The candidates' density `q = P p_l` (what the crate's `resample`
    /// returns as the pmf).
    Candidate,
    /// The resampled density's usual approximation,
    /// `m t q / (t + (m - 1) Z q)` (`t` the target, `Z` its integral at the
    /// point): `q` at one candidate, `t / Z` at infinitely many. `None`
    /// takes the exact `Z` at the point (the bound for any estimate of it).
    Resampled(Option<f64>),
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
#[allow(dead_code)] // the closed form by name; the instrument calls `resampled_parts_with`
pub fn resampled_parts(t: &PointTerms, pmf: &[f64], visibility: &[f64], m: usize) -> (f64, f64) {
    resampled_parts_with(t, pmf, visibility, m, Proxy::Candidate)
}

/// [`resampled_parts`] with both strategies' MIS weights taken from
/// `proxy`: `f = g w_l` in the closed form, and the BSDF part integrated
/// as [`parts`] does, with the proxy in place of `P p_l`.
pub fn resampled_parts_with(
    t: &PointTerms,
    pmf: &[f64],
    visibility: &[f64],
    m: usize,
    proxy: Proxy,
) -> (f64, f64) {
    let n = t.m.max(1) as f64;
    let mf = m.max(1) as f64;
    let valid = |p: f64| !p.is_nan() && p > 0.0;
    // The target's integral at the point.
    let z: f64 = t
        .lights
        .iter()
        .zip(pmf)
        .zip(visibility)
        .filter(|((_, p), _)| valid(**p))
        .map(|((term, _), &v)| v * term.unshadowed)
        .sum();
    let density = |p: f64, x: &crate::brute_force::NeeSample, v: f64| {
        let q = p * x.pdf_light;
        match proxy {
            Proxy::Candidate => q,
            Proxy::Resampled(estimate) => {
                let z = estimate.unwrap_or(z);
                let target = x.g * v;
                let d = target + (mf - 1.0) * z * q;
                if d > 0.0 { mf * target * q / d } else { q }
            }
        }
    };
    let (mut a, mut c, mut mean) = (0.0f64, 0.0f64, 0.0f64);
    let (mut b_mean, mut b_m2) = (0.0f64, 0.0f64);
    for ((term, &p), &v) in t.lights.iter().zip(pmf).zip(visibility) {
        let p = if valid(p) { p } else { 0.0 };
        for x in &term.eval {
            let pp = if p > 0.0 { density(p, x, v) } else { 0.0 };
            let pb = x.pdf_bsdf;
            let d = pp * pp + pb * pb;
            if d <= 0.0 {
                continue;
            }
            if p > 0.0 {
                let f = x.g * pp * pp / d; // visible samples only
                a += f * f / (p * x.pdf_light * x.pdf_light) / n;
                c += f * f / (x.g * v * x.pdf_light) / n;
                mean += f / x.pdf_light / n;
            }
            if pb > 0.0 {
                let y = x.g * pb / d;
                let w = pb / x.pdf_light;
                b_mean += y * w / n;
                b_m2 += y * y * w / n;
            }
        }
    }
    let nee = (a / mf + (1.0 - 1.0 / mf) * z * c - mean * mean).max(0.0);
    (nee, (b_m2 - b_mean * b_mean).max(0.0))
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

/// The variance of the one-sample estimator that resamples `m` light
/// candidates *and the BSDF sample* together (ReSTIR's initial candidates;
/// the BSDF sample is traced anyway to continue the path): candidate `i`
/// from strategy `k_i` gets the weight `w_i = target_k(x_i) / D(x_i)`, with
/// the balance heuristic's `D = m P p_l + p_b`, one is kept in proportion
/// to its weight and `f(x) W`, `W = sum_i w_i / target_k(x)`, is the
/// estimate. There is no second sample and no MIS weight: the emission a
/// BSDF sample finds counts only if it is kept.
///
/// Each strategy may have its own target (the estimate divides the kept
/// candidate's integrand by its own target, so the estimator stays
/// unbiased): the light candidates' is the unshadowed `g` times
/// `visibility[i]`; the BSDF candidate's the same, or, with `bsdf_seen`,
/// `g` alone (its ray reached the light: it is visible).
///
/// For independent candidates (`m` i.i.d. from the light strategy, one
/// from the BSDF's), with `A_k = int q_k f^2 / (target_k D)` and
/// `B_k = E[w | strategy k] = int q_k target_k / D`:
///
/// ```text
/// E[Y^2] = int f^2 / D + (m A_l + A_b) (m B_l + B_b) - m A_l B_l - A_b B_b
/// ```
///
/// (condition on the candidates as in [`resampled_parts`]: the pairs `s ==
/// k` give `int f^2 / D`, the others factor into the strategies' terms).
/// The BSDF strategy's density of a light point is `p_b V`: an occluded
/// light point is never its candidate (its ray stops at the occluder), so
/// `B_b` runs over visible points only, `B_l` over all of them. Integrals
/// are over the same light samples as [`parts`], the occluded ones kept for
/// `B_l`.
pub fn bsdf_candidate_variance(
    t: &PointTerms,
    pmf: &[f64],
    visibility: &[f64],
    m: usize,
    bsdf_seen: bool,
) -> f64 {
    let n = t.m.max(1) as f64;
    let mf = m as f64;
    let (mut f2d, mut mean) = (0.0f64, 0.0f64);
    let (mut a_l, mut a_b, mut b_l, mut b_b) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for ((term, &p), &v) in t.lights.iter().zip(pmf).zip(visibility) {
        let p = if p.is_nan() || p <= 0.0 { 0.0 } else { p };
        let v_b = if bsdf_seen { 1.0 } else { v };
        for (x, visible) in term
            .eval
            .iter()
            .map(|x| (x, true))
            .chain(term.occluded.iter().map(|x| (x, false)))
        {
            let q = p * x.pdf_light;
            let pb = x.pdf_bsdf;
            let d = mf * q + pb;
            if d <= 0.0 {
                continue;
            }
            let (t_l, t_b) = (x.g * v, x.g * v_b);
            // Integrals in the light-sample domain: h / p_l per sample.
            let per = 1.0 / (x.pdf_light * n);
            b_l += q * t_l / d * per;
            if visible {
                let f = x.g;
                f2d += f * f / d * per;
                a_l += q * f * f / (t_l * d) * per;
                a_b += pb * f * f / (t_b * d) * per;
                b_b += pb * t_b / d * per;
                mean += f * per;
            }
        }
    }
    let m2 = f2d + (mf * a_l + a_b) * (mf * b_l + b_b) - mf * a_l * b_l - a_b * b_b;
    (m2 - mean * mean).max(0.0)
}
