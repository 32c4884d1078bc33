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
    /// Non-specular path vertices rendered, training included (0 where a
    /// results file predates the count).
    pub vertices: u64,
    /// The convergence curve (empty with `--no-curve`): what the render
    /// would have delivered at each recorded point.
    pub curve: Vec<CurvePoint>,
}

impl Record {
    /// `ln relMSE` of the curve at `ln t` (`log_t`), linear in log-log
    /// between the recorded points (`None` outside the curve).
    pub fn log_relmse_at(&self, log_t: f64) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .curve
            .iter()
            .filter(|p| p.seconds > 0.0 && p.relmse > 0.0)
            .map(|p| (p.seconds.ln(), p.relmse.ln()))
            .collect();
        let k = pts
            .windows(2)
            .position(|w| w[0].0 <= log_t && log_t <= w[1].0)?;
        let ((t0, e0), (t1, e1)) = (pts[k], pts[k + 1]);
        let f = if t1 > t0 {
            (log_t - t0) / (t1 - t0)
        } else {
            0.0
        };
        Some(e0 + f * (e1 - e0))
    }
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
            ("vertices", r.vertices.to_string()),
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

/// Reads records back from [`to_json`]'s output (`--replot`).
pub fn from_json(text: &str) -> Result<Vec<Record>, String> {
    let crate::json::Json::Array(items) = crate::json::parse(text)? else {
        return Err("JSON: the records are not an array".into());
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let missing = |k: &str| format!("JSON record {i}: no {k:?}");
            let text = |k: &str| match item.get(k) {
                Some(crate::json::Json::String(s)) => Ok(s.clone()),
                _ => Err(missing(k)),
            };
            let num = |k: &str| {
                item.get(k)
                    .and_then(crate::json::Json::number)
                    .ok_or_else(|| missing(k))
            };
            let int = |k: &str| num(k).map(|x| x as u64);
            let curve = match item.get("curve") {
                Some(crate::json::Json::Array(points)) => points
                    .iter()
                    .map(|p| {
                        let n = |k: &str| {
                            p.get(k)
                                .and_then(crate::json::Json::number)
                                .ok_or_else(|| missing(k))
                        };
                        Ok(CurvePoint {
                            seconds: n("seconds")?,
                            spp: n("spp")? as u64,
                            relmse: n("relmse")?,
                            bytes: n("bytes")? as usize,
                        })
                    })
                    .collect::<Result<_, String>>()?,
                _ => return Err(missing("curve")),
            };
            Ok(Record {
                scene: text("scene")?,
                method: text("method")?,
                sigma: num("sigma")?,
                width: int("width")? as u32,
                height: int("height")? as u32,
                spp: int("spp")?,
                spp_final: int("spp_final")?,
                seconds: num("seconds")?,
                rmse: num("rmse")?,
                relmse: num("relmse")?,
                efficiency: num("efficiency")?,
                rmse_raw: num("rmse_raw")?,
                relmse_raw: num("relmse_raw")?,
                reference_relmse: num("reference_relmse")?,
                mean: num("mean")?,
                mean_error: num("mean_error")?,
                reference_mean: num("reference_mean")?,
                sdtree_bytes: int("sdtree_bytes")? as usize,
                glt_bytes: int("glt_bytes")? as usize,
                emitters: int("emitters")? as usize,
                iterations: int("iterations")? as u32,
                vertices: int("vertices").unwrap_or(0),
                curve,
            })
        })
        .collect()
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

/// A plain-text table of what each record's paths cost: non-specular
/// vertices (where a path chooses a light) per path, and wall time per
/// such vertex, training included. A method whose paths are longer
/// renders fewer of them in the same time; this tells that apart from a
/// costlier vertex. Records without a vertex count are left out.
pub fn work_table(records: &[Record]) -> String {
    let mut out = String::new();
    let counted: Vec<&Record> = records.iter().filter(|r| r.vertices > 0).collect();
    if counted.is_empty() {
        return out;
    }
    let _ = writeln!(
        out,
        "{:<16} {:>14} {:>10}",
        "work", "vertices/path", "ns/vertex"
    );
    for r in counted {
        let paths = r.spp as f64 * f64::from(r.width) * f64::from(r.height);
        let _ = writeln!(
            out,
            "{:<16} {:>14.3} {:>10.1}",
            r.method,
            r.vertices as f64 / paths,
            r.seconds * 1e9 / r.vertices as f64
        );
    }
    out.push('\n');
    out
}

/// The times a curve table shows: 1, 3, 10, 30, 100, 300, ... seconds.
fn table_times(end: f64) -> Vec<f64> {
    let times = (0..).map(|k| {
        if k % 2 == 0 {
            10f64.powi(k / 2)
        } else {
            3.0 * 10f64.powi(k / 2)
        }
    });
    times.take_while(|&t| t < end * 0.999).collect()
}

/// A plain-text table of the convergence curves of one scene's records:
/// the relMSE each method would deliver at 1, 3, 10, 30, ... seconds
/// (log-log interpolation of its curve) and at the end, with the samples
/// and memory then. Empty without curves.
pub fn curve_table(records: &[Record]) -> String {
    let end = records.iter().map(|r| r.seconds).fold(0.0, f64::max);
    if records.iter().all(|r| r.curve.is_empty()) {
        return String::new();
    }
    let times = table_times(end);
    let mut out = String::new();
    let _ = write!(out, "{:<16}", "relMSE at");
    for t in &times {
        let _ = write!(out, " {:>9}", format!("{t} s"));
    }
    let _ = writeln!(out, " {:>9} {:>7} {:>8}", "end", "spp", "MB");
    for r in records {
        let _ = write!(out, "{:<16}", r.method);
        for t in &times {
            match r.log_relmse_at(t.ln()) {
                Some(e) => write!(out, " {:>9.3e}", e.exp()),
                None => write!(out, " {:>9}", "-"),
            }
            .ok();
        }
        let bytes = r.curve.last().map_or(0, |p| p.bytes);
        let _ = writeln!(
            out,
            " {:>9.3e} {:>7} {:>8.1}",
            r.relmse,
            r.spp,
            bytes as f64 / 1e6
        );
    }
    out
}
