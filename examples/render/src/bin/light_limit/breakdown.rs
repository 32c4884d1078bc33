//! Where a pmf's variance comes from: which points, and which lights by
//! how far their pmf is below the clairvoyant one (`--breakdown`).

use crate::brute_force::PointTerms;
use std::fmt::Write as _;

/// Each light's NEE second moment `E[(g/pdf)^2]` at `t` (evaluation set,
/// no MIS).
fn second_moments(t: &PointTerms) -> Vec<f64> {
    let m = t.m.max(1) as f64;
    t.lights
        .iter()
        .map(|l| {
            l.eval
                .iter()
                .map(|x| (x.g / x.pdf_light).powi(2))
                .sum::<f64>()
                / m
        })
        .collect()
}

/// A report of `pmfs` (one vector per point) against the clairvoyant pmf:
/// the share of the relative variance from the worst points, and the share
/// of the NEE second moment by `clairvoyant / pmf` bucket, with how much of
/// it sits on lights at the prior floor (`pmf <= 1.05 alpha prior`).
pub fn report(
    points: &[PointTerms],
    per_point: &[f64],
    clair_per_point: &[f64],
    pmfs: &[Vec<f64>],
    prior: &[Vec<f64>],
    alpha: f64,
) -> String {
    let mut s = String::new();
    let n = points.len().max(1) as f64;
    let mean_i = points.iter().map(|t| t.direct).sum::<f64>() / n;
    let floor = 0.01 * mean_i * mean_i;
    let rel: Vec<f64> = points
        .iter()
        .zip(per_point)
        .map(|(t, v)| v / (t.direct * t.direct + floor).max(1e-300))
        .collect();
    let total: f64 = rel.iter().sum();
    let mut sorted = rel.clone();
    sorted.sort_by(|a, b| b.total_cmp(a));
    let top = |k: usize| sorted.iter().take(k.max(1)).sum::<f64>() / total;
    let mut ratios: Vec<f64> = per_point
        .iter()
        .zip(clair_per_point)
        .filter(|(_, c)| **c > 0.0)
        .map(|(v, c)| v / c)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let med = ratios.get(ratios.len() / 2).copied().unwrap_or(f64::NAN);
    let _ = writeln!(
        s,
        "    worst 1% of points: {:.0}% of the variance, worst 10%: {:.0}%; median point / clairvoyant {:.1}x",
        100.0 * top(points.len() / 100),
        100.0 * top(points.len() / 10),
        med
    );
    let edges = [2.0, 10.0, 100.0, f64::INFINITY];
    let mut share = [0.0f64; 4];
    let mut floor_share = [0.0f64; 4];
    let mut all = 0.0;
    for ((t, pmf), pr) in points.iter().zip(pmfs).zip(prior) {
        let norm = (t.direct * t.direct + floor).max(1e-300);
        let e = second_moments(t);
        let sqrt_total: f64 = e.iter().map(|x| x.sqrt()).sum();
        for ((&e, &p), &q) in e.iter().zip(pmf).zip(pr) {
            if e <= 0.0 || p <= 0.0 {
                continue;
            }
            let v = e / p / norm;
            // The clairvoyant pmf over the pmf.
            let r = e.sqrt() / sqrt_total / p;
            let b = edges.iter().position(|&x| r < x).unwrap_or(3);
            share[b] += v;
            if p <= 1.05 * alpha * q {
                floor_share[b] += v;
            }
            all += v;
        }
    }
    let _ = write!(s, "    NEE second moment by clairvoyant/pmf:");
    for (i, label) in ["<2", "2-10", "10-100", ">100"].iter().enumerate() {
        let _ = write!(
            s,
            " {label}: {:.0}% ({:.0}% at the floor);",
            100.0 * share[i] / all,
            100.0 * floor_share[i] / all
        );
    }
    let _ = writeln!(s);
    s
}
