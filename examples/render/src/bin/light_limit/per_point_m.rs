//! How much a per-point choice of the candidate count could gain: the
//! bound of "pay only where it pays" (resample, and with how many
//! candidates, decided per cell from what was learned).
//!
//! Every option (plain GLT sampling, or resampling with `M` candidates)
//! has an exact variance at each point and a cost per path: plain
//! sampling's, plus for resampling a fixed overhead and `M - 1` candidates
//! (the first candidate is the walk plain sampling makes too). A rule that
//! picks an option per cell can do no better than an oracle that picks per
//! point, knowing every point's variances:
//! for each `lambda` it takes the option minimizing `r_i + lambda cost`
//! (`r_i` the point's share of the relative variance), which traces the
//! lowest mean variance for each mean cost; the best efficiency
//! `1 / (variance x cost)` along it is the bound. Set beside the best
//! single option for all points, it says whether a per-cell rule is worth
//! building.

/// One way to choose a light at every point: its name, candidates per
/// path (0 for plain sampling) and each point's share of the relative
/// variance (`variance::shares`).
pub struct Choice {
    pub name: String,
    pub candidates: usize,
    pub shares: Vec<f64>,
}

/// Instructions per path (or any cost unit): plain sampling's, resampling's
/// fixed overhead, and each candidate after the first.
#[derive(Clone, Copy, Debug)]
pub struct Costs {
    pub path: f64,
    pub overhead: f64,
    pub candidate: f64,
}

/// The best single choice and the per-point oracle, as printed lines; the
/// first of `choices` (plain sampling) is what the efficiencies are
/// relative to.
pub fn report(choices: &[Choice], costs: Costs) -> String {
    let cost = |m: usize| match m {
        0 => costs.path,
        m => costs.path + costs.overhead + (m - 1) as f64 * costs.candidate,
    };
    let Some(first) = choices.first().filter(|c| !c.shares.is_empty()) else {
        return String::new();
    };
    let n = first.shares.len();
    let efficiency = |variance: f64, cost: f64| 1.0 / (variance * cost);
    let base = efficiency(first.shares.iter().sum(), cost(first.candidates));
    let mut best_single = (f64::NEG_INFINITY, 0usize);
    let mut lines = String::new();
    for (k, c) in choices.iter().enumerate() {
        let v: f64 = c.shares.iter().sum();
        let e = efficiency(v, cost(c.candidates));
        if e > best_single.0 {
            best_single = (e, k);
        }
        lines += &format!(
            "    {:<48} variance {v:>9.4}  cost {:>8.0}  efficiency x {:.3}\n",
            c.name,
            cost(c.candidates),
            e / base,
        );
    }
    // The oracle along lambda (a log grid wide enough for any cost scale).
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0, 0.0);
    for step in 0..=400 {
        let lambda = 10f64.powf(-14.0 + step as f64 * 0.05) / costs.candidate;
        let (mut v, mut c, mut m) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let pick = choices
                .iter()
                .min_by(|a, b| {
                    let fa = a.shares[i] + lambda * cost(a.candidates);
                    let fb = b.shares[i] + lambda * cost(b.candidates);
                    fa.total_cmp(&fb)
                })
                .expect("at least the first choice");
            v += pick.shares[i];
            c += cost(pick.candidates) / n as f64;
            m += pick.candidates as f64 / n as f64;
        }
        let e = efficiency(v, c);
        if e > best.0 {
            best = (e, v, c, m);
        }
    }
    lines += &format!(
        "    best single choice: {} (efficiency x {:.3} of the first)\n",
        choices[best_single.1].name,
        best_single.0 / base
    );
    lines += &format!(
        "    per-point oracle: variance {:.4}, cost {:.0} ({:.2} candidates per path on average): efficiency x {:.3} of the first, x {:.3} of the best single choice\n",
        best.1,
        best.2,
        best.3,
        best.0 / base,
        best.0 / best_single.0
    );
    lines
}
