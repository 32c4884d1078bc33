//! Crossing points: from how many seconds on a guided method's
//! convergence curve stays below its unguided counterpart's, and their
//! efficiency ratio at the end.

use crate::report::Record;

/// Each guided method and the unguided method it adds guiding to:
/// `pt-glt` learns what `pt-bvh`'s light tree only estimates, `ppg-glt`
/// adds the GLT to `ppg`.
pub const PAIRS: [(&str, &str); 2] = [("pt-glt", "pt-bvh"), ("ppg-glt", "ppg")];

/// How a guided method compares with its unguided counterpart over time.
#[derive(Clone, Debug)]
pub struct Crossing {
    /// The guided method's label (with ` s=<sigma>` in a sigma study).
    pub guided: String,
    /// Its unguided counterpart.
    pub unguided: String,
    /// The time from which on the guided curve stays below the unguided
    /// one to the end of both (`None`: it is not below at the end).
    pub from: Option<f64>,
    /// The end of the compared stretch (the shorter curve's end).
    pub until: f64,
    /// Efficiency of the guided method over the unguided one's at the end
    /// of the render (above 1: the guided one needs less time).
    pub end_ratio: f64,
}

/// The crossing of `guided` with `unguided` on 400 log-spaced times over
/// the stretch both curves cover (`None` without two curves that overlap).
pub fn crossing(guided: &Record, unguided: &Record) -> Option<Crossing> {
    let span = |r: &Record| {
        let t = r.curve.iter().filter(|p| p.seconds > 0.0 && p.relmse > 0.0);
        t.fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.seconds), hi.max(p.seconds))
        })
    };
    let ((a0, a1), (b0, b1)) = (span(guided), span(unguided));
    let (lo, hi) = (a0.max(b0).ln(), a1.min(b1).ln());
    // Also without curves (`--no-curve`): then `hi` is NaN.
    if lo.is_nan() || hi.is_nan() || lo >= hi {
        return None;
    }
    const STEPS: usize = 400;
    let times = (0..=STEPS).map(|i| (lo + (hi - lo) * i as f64 / STEPS as f64).clamp(lo, hi));
    let mut from = Some(a0.max(b0));
    for t in times {
        let (a, b) = (guided.log_relmse_at(t)?, unguided.log_relmse_at(t)?);
        if a >= b {
            from = None;
        } else if from.is_none() {
            from = Some(t.exp());
        }
    }
    let end_ratio = if unguided.efficiency > 0.0 {
        guided.efficiency / unguided.efficiency
    } else {
        f64::NAN
    };
    Some(Crossing {
        guided: guided.method.clone(),
        unguided: unguided.method.clone(),
        from,
        until: a1.min(b1),
        end_ratio,
    })
}

/// The crossings of every guided method in `records` (one scene) with its
/// counterpart, when both were rendered with a curve.
pub fn crossings(records: &[Record]) -> Vec<Crossing> {
    let counterpart = |label: &str| {
        let name = label.split(" s=").next()?;
        PAIRS.iter().find(|(g, _)| *g == name).map(|(_, u)| *u)
    };
    records
        .iter()
        .filter_map(|g| {
            let u = counterpart(&g.method)?;
            crossing(g, records.iter().find(|r| r.method == u)?)
        })
        .collect()
}

/// One line per crossing, as the render prints them under its table.
pub fn describe(crossings: &[Crossing]) -> String {
    crossings
        .iter()
        .map(|c| {
            let (g, u, end) = (&c.guided, &c.unguided, c.until);
            let verdict = match c.from {
                Some(t) => format!("{g} beats {u} from {t:.2} s on (to {end:.0} s)"),
                None => format!("{g} does not beat {u} at the end of the curves ({end:.0} s)"),
            };
            format!("{verdict}; efficiency at the end {:.2}x\n", c.end_ratio)
        })
        .collect()
}
