//! Convergence plots: relMSE against render time, log-log, one line per
//! method, as SVG (text as SVG text: no fonts needed).

use crate::report::Record;
use plotters::prelude::*;
use std::path::Path;

/// Line colours, one per method in table order.
const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// One log-log chart on `area`: `caption`, the axes' descriptions and
/// ranges, and every `(label, points)` line with its points and a legend.
fn log_log_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    caption: &str,
    (x_desc, x): (&str, (f64, f64)),
    (y_desc, y): (&str, (f64, f64)),
    lines: &[(String, Vec<(f64, f64)>)],
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(|e| err(&e))?;
    for (i, (label, points)) in lines.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        chart
            .draw_series(LineSeries::new(
                points.iter().copied(),
                colour.stroke_width(2),
            ))
            .map_err(|e| err(&e))?
            .label(label.clone())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(|e| err(&e))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))
}

/// Writes the relMSE-over-time plot of `records` (one scene) to `path`.
pub fn convergence(path: &Path, scene: &str, records: &[Record]) -> Result<(), String> {
    let points = records
        .iter()
        .flat_map(|r| r.curve.iter())
        .filter(|p| p.relmse > 0.0 && p.seconds > 0.0);
    let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in points {
        t0 = t0.min(p.seconds);
        t1 = t1.max(p.seconds);
        e0 = e0.min(p.relmse);
        e1 = e1.max(p.relmse);
    }
    if t0 >= t1 || e0 >= e1 {
        return Err(format!("{scene}: no curve to plot"));
    }
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let root = SVGBackend::new(path, (720, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let lines: Vec<(String, Vec<(f64, f64)>)> = records
        .iter()
        .map(|r| {
            let points = r.curve.iter().filter(|p| p.relmse > 0.0 && p.seconds > 0.0);
            (
                r.method.clone(),
                points.map(|p| (p.seconds, p.relmse)).collect(),
            )
        })
        .collect();
    log_log_chart(
        &root,
        &format!("{scene}: relMSE over time"),
        ("seconds (training included)", (t0 * 0.8, t1 * 1.25)),
        ("relMSE", (e0 * 0.8, e1 * 1.25)),
        &lines,
    )
    .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// A number read off a record.
type Quantity = dyn Fn(&Record) -> f64;

/// Writes the sigma study of `records` (one scene; methods named
/// `<method> s=<sigma>`) to `path`: the final relMSE and the GLT's memory
/// (the cuts, for ppg-glt) against sigma, one line per method.
pub fn sigma_study(path: &Path, scene: &str, records: &[Record]) -> Result<(), String> {
    let studied: Vec<&Record> = records
        .iter()
        .filter(|r| r.method.contains(" s="))
        .collect();
    let mut methods: Vec<&str> = studied
        .iter()
        .filter_map(|r| r.method.split(" s=").next())
        .collect();
    methods.dedup();
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let range = |f: &dyn Fn(&Record) -> f64| {
        let v: Vec<f64> = studied.iter().map(|r| f(r)).filter(|x| *x > 0.0).collect();
        let lo = v.iter().copied().fold(f64::MAX, f64::min);
        let hi = v.iter().copied().fold(f64::MIN, f64::max);
        (lo * 0.8, hi * 1.25)
    };
    let (s0, s1) = range(&|r| r.sigma);
    if studied.is_empty() || s0 >= s1 {
        return Err(format!("{scene}: no sigma study to plot"));
    }
    let root = SVGBackend::new(path, (960, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let panels = root.split_evenly((1, 2));
    let quantities: [(&str, &Quantity); 2] = [
        ("relMSE at the end", &|r: &Record| r.relmse),
        ("GLT memory (MB)", &|r: &Record| r.glt_bytes as f64 / 1e6),
    ];
    for (panel, (name, f)) in panels.iter().zip(quantities) {
        let (y0, y1) = range(f);
        let lines: Vec<(String, Vec<(f64, f64)>)> = methods
            .iter()
            .map(|m| {
                let mine = studied
                    .iter()
                    .filter(|r| r.method.split(" s=").next() == Some(m));
                let mut points: Vec<(f64, f64)> = mine
                    .map(|r| (r.sigma, f(r)))
                    .filter(|p| p.1 > 0.0)
                    .collect();
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                (m.to_string(), points)
            })
            .collect();
        log_log_chart(
            panel,
            &format!("{scene}: {name} vs sigma"),
            ("sigma", (s0, s1)),
            (name, (y0, y1)),
            &lines,
        )
        .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))
}
