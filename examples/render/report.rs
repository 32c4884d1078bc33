//! Per-method results: the JSON records of `--json` and the printed table.

use std::fmt::Write as _;

/// One scene + method result.
#[derive(Clone, Debug, Default)]
pub struct Record {
    /// Scene name.
    pub scene: String,
    /// Method name (with ` s=<sigma>` in a sigma study).
    pub method: String,
    /// The GLT's sigma it ran with.
    pub sigma: f64,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Samples per pixel, training included.
    pub spp: u64,
    /// Samples per pixel of the combined final iterations.
    pub spp_final: u64,
    /// Wall-clock seconds, training included.
    pub seconds: f64,
    /// RMSE against the reference (its noise removed).
    pub rmse: f64,
    /// Relative MSE (its noise removed).
    pub relmse: f64,
    /// `1 / (relmse * seconds)`.
    pub efficiency: f64,
    /// RMSE without removing the reference's noise.
    pub rmse_raw: f64,
    /// Relative MSE without removing the reference's noise.
    pub relmse_raw: f64,
    /// The reference's own relative MSE.
    pub reference_relmse: f64,
    /// Mean luminance of the image.
    pub mean: f64,
    /// Standard error of `mean`.
    pub mean_error: f64,
    /// Mean luminance of the reference.
    pub reference_mean: f64,
    /// Bytes of the SD-tree.
    pub sdtree_bytes: usize,
    /// Bytes of the GLT.
    pub glt_bytes: usize,
    /// Number of emitters in the scene.
    pub emitters: usize,
    /// Training iterations.
    pub iterations: u32,
    /// The convergence curve (empty with `--no-curve`): what the render
    /// would have delivered at each recorded point.
    pub curve: Vec<CurvePoint>,
}

/// One point of a convergence curve.
#[derive(Clone, Copy, Debug)]
pub struct CurvePoint {
    /// Seconds of rendering so far.
    pub seconds: f64,
    /// Samples per pixel so far.
    pub spp: u64,
    /// Relative MSE of the image delivered then (reference noise removed).
    pub relmse: f64,
    /// Bytes of the learned structures then.
    pub bytes: usize,
}

/// A JSON number (`null` for non-finite values).
fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".to_string()
    }
}

/// A JSON string (names here are plain ASCII; quotes and backslashes are
/// escaped anyway).
fn string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The records as a JSON array, one object per line.
pub fn to_json(records: &[Record]) -> String {
    let mut out = String::from("[\n");
    for (i, r) in records.iter().enumerate() {
        let fields = [
            ("scene", string(&r.scene)),
            ("method", string(&r.method)),
            ("sigma", num(r.sigma)),
            ("width", r.width.to_string()),
            ("height", r.height.to_string()),
            ("spp", r.spp.to_string()),
            ("spp_final", r.spp_final.to_string()),
            ("seconds", num(r.seconds)),
            ("rmse", num(r.rmse)),
            ("relmse", num(r.relmse)),
            ("efficiency", num(r.efficiency)),
            ("rmse_raw", num(r.rmse_raw)),
            ("relmse_raw", num(r.relmse_raw)),
            ("reference_relmse", num(r.reference_relmse)),
            ("mean", num(r.mean)),
            ("mean_error", num(r.mean_error)),
            ("reference_mean", num(r.reference_mean)),
            ("sdtree_bytes", r.sdtree_bytes.to_string()),
            ("glt_bytes", r.glt_bytes.to_string()),
            ("emitters", r.emitters.to_string()),
            ("iterations", r.iterations.to_string()),
            (
                "curve",
                format!(
                    "[{}]",
                    r.curve
                        .iter()
                        .map(|p| format!(
                            "{{\"seconds\": {}, \"spp\": {}, \"relmse\": {}, \"bytes\": {}}}",
                            num(p.seconds),
                            p.spp,
                            num(p.relmse),
                            p.bytes
                        ))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ),
        ];
        let body: Vec<String> = fields
            .iter()
            .map(|(k, v)| format!("{}: {v}", string(k)))
            .collect();
        let comma = if i + 1 < records.len() { "," } else { "" };
        let _ = writeln!(out, "  {{{}}}{comma}", body.join(", "));
    }
    out.push(']');
    out.push('\n');
    out
}

/// Efficiency of `r` relative to the method `base` of the same scene.
fn relative(records: &[Record], r: &Record, base: &str) -> String {
    records
        .iter()
        .find(|b| b.scene == r.scene && b.method == base && b.efficiency > 0.0)
        .map_or_else(
            || "-".to_string(),
            |b| format!("{:.2}x", r.efficiency / b.efficiency),
        )
}

/// A plain-text table of one scene's records.
pub fn table(records: &[Record]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<16} {:>6} {:>7} {:>10} {:>10} {:>9} {:>8} {:>8} {:>17} {:>9} {:>9}",
        "method",
        "spp",
        "seconds",
        "RMSE",
        "relMSE",
        "eff",
        "vs bvh",
        "vs ppg",
        "mean +- err",
        "SD MB",
        "GLT MB"
    );
    for r in records {
        let _ = writeln!(
            out,
            "{:<16} {:>6} {:>7.1} {:>10.3e} {:>10.3e} {:>9.3} {:>8} {:>8} {:>8.4} +-{:<7.4} {:>9.2} {:>9.2}",
            r.method,
            r.spp,
            r.seconds,
            r.rmse,
            r.relmse,
            r.efficiency,
            relative(records, r, "pt-bvh"),
            relative(records, r, "ppg"),
            r.mean,
            r.mean_error,
            r.sdtree_bytes as f64 / 1e6,
            r.glt_bytes as f64 / 1e6
        );
    }
    let floor = records.first().map_or(f64::NAN, |r| r.reference_relmse);
    let _ = writeln!(
        out,
        "eff = 1 / (relMSE x seconds); `vs X` = eff / eff of X (above 1: fewer seconds than X to the same error); the reference's own relMSE {floor:.2e} is subtracted"
    );
    out
}
