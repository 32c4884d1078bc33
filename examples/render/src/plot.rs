//! Convergence plots: relMSE against render time, log-log, one line per
//! method, each written as SVG (text as SVG text, in the reader's
//! sans-serif) and as PNG (text in DejaVu Sans, `text.rs`).

use crate::raster::{Canvas, Viewport};
use crate::report::Record;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Draws one chart onto a drawing area of any backend.
trait Chart {
    /// Draws onto `area`.
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Writes `chart` as `<stem>.svg` and `<stem>.png`, `size` pixels, and
/// returns both paths.
fn write_svg_and_png(
    stem: &Path,
    size: (u32, u32),
    chart: &impl Chart,
) -> Result<[PathBuf; 2], String> {
    let (svg, png) = (stem.with_extension("svg"), stem.with_extension("png"));
    let err = |p: &Path, e: &dyn std::fmt::Display| format!("{}: {e}", p.display());
    {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&svg, &e))?;
        chart.draw(&root).map_err(|e| err(&svg, &e))?;
        root.present().map_err(|e| err(&svg, &e))?;
    }
    let mut canvas = Canvas::new(size.0 as usize, size.1 as usize, 255);
    {
        let root = Viewport::new(&mut canvas, (0, 0), size).into_drawing_area();
        chart.draw(&root).map_err(|e| err(&png, &e))?;
    }
    canvas.write_png(&png)?;
    Ok([svg, png])
}

/// Line colours, one per method in table order (a sigma study draws
/// seven lines).
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// A log axis range `(lo, hi)` with `lo` lowered to the power of ten
/// below it when that costs little or when the range holds no power of
/// ten: plotters places a log axis's ticks from the first power of ten in
/// the range upwards, so without one the axis has no tick at all. (Just
/// below the power of ten: plotters finds its first tick by rounding a
/// logarithm up, which at the power itself may round past it.)
fn with_decade(lo: f64, hi: f64) -> (f64, f64) {
    let decade = 10f64.powf(lo.log10().floor());
    if lo < 2.5 * decade || 10.0 * decade > hi {
        (decade * 0.999, hi)
    } else {
        (lo, hi)
    }
}

/// The label of the log axis tick at `v` on an axis spanning `range`:
/// every tick when the axis spans less than a decade (few ticks),
/// otherwise only 1, 2 and 5 times a power of ten, so labels never crowd.
pub fn tick(v: f64, range: (f64, f64)) -> String {
    let mantissa = v / 10f64.powf(v.log10().floor());
    let round = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .any(|m| (mantissa - m).abs() < 1e-6);
    if range.1 < 10.0 * range.0 || round {
        number(v)
    } else {
        String::new()
    }
}

/// `v` as a plot's reader expects it: to three significant digits
/// without trailing zeros (0.01, 0.25, 1, 10, 2000), and as a power of
/// ten (3·10⁻⁶, 10⁷) outside 0.0001-999,999, where decimals get long.
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let exponent = v.abs().log10().floor() as i32;
    if (-4..6).contains(&exponent) {
        let decimals = (2 - exponent).max(0) as usize;
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            &s
        };
        return s.to_string();
    }
    // Rounding may carry the mantissa to 10 (9.996e-7 is 10⁻⁶).
    let (mut mantissa, mut exponent) = (v / 10f64.powi(exponent), exponent);
    if (mantissa.abs() * 100.0).round() >= 1000.0 {
        (mantissa, exponent) = (mantissa / 10.0, exponent + 1);
    }
    let power = format!("10{}", superscript(exponent));
    if (mantissa - 1.0).abs() < 0.005 {
        power
    } else {
        format!("{}·{power}", number(mantissa))
    }
}

/// `n` in superscript digits (⁻¹²).
fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let digits = n.unsigned_abs().to_string();
    let sign = if n < 0 { "⁻" } else { "" };
    sign.chars()
        .chain(digits.bytes().map(|b| DIGITS[usize::from(b - b'0')]))
        .collect()
}

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
        .caption(caption, ("sans-serif", 21))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(76)
        .build_cartesian_2d(
            {
                let (lo, hi) = with_decade(x.0, x.1);
                (lo..hi).log_scale()
            },
            {
                let (lo, hi) = with_decade(y.0, y.1);
                (lo..hi).log_scale()
            },
        )
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        // plotters' log axes crowd their minor grid lines near 1.
        .light_line_style(TRANSPARENT)
        .axis_desc_style(("sans-serif", 17))
        .label_style(("sans-serif", 16))
        .x_label_formatter(&|v| tick(*v, x))
        .y_label_formatter(&|v| tick(*v, y))
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
        .position(SeriesLabelPosition::LowerLeft)
        .label_font(("sans-serif", 17))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))
}

/// The points of `r`'s curve a log-log chart can show.
fn curve(r: &Record) -> impl Iterator<Item = &crate::report::CurvePoint> {
    r.curve.iter().filter(|p| p.relmse > 0.0 && p.seconds > 0.0)
}

/// The relMSE-over-time chart of one scene's records.
pub struct Convergence<'a> {
    /// The scene's name (the caption).
    pub scene: &'a str,
    /// Its records, one line each.
    pub records: &'a [Record],
}

impl Chart for Convergence<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in self.records.iter().flat_map(curve) {
            t0 = t0.min(p.seconds);
            t1 = t1.max(p.seconds);
            e0 = e0.min(p.relmse);
            e1 = e1.max(p.relmse);
        }
        if t0 >= t1 || e0 >= e1 {
            return Err(format!("{}: no curve to plot", self.scene));
        }
        area.fill(&WHITE).map_err(|e| e.to_string())?;
        let lines: Vec<(String, Vec<(f64, f64)>)> = self
            .records
            .iter()
            .map(|r| {
                (
                    r.method.clone(),
                    curve(r).map(|p| (p.seconds, p.relmse)).collect(),
                )
            })
            .collect();
        log_log_chart(
            area,
            &format!("{}: relMSE over time", self.scene),
            ("seconds (training included)", (t0 * 0.8, t1 * 1.25)),
            ("relMSE", (e0 * 0.8, e1 * 1.25)),
            &lines,
        )
    }
}

/// Writes the relMSE-over-time plot of `records` (one scene) to
/// `<stem>.svg` and `<stem>.png`.
pub fn convergence(stem: &Path, scene: &str, records: &[Record]) -> Result<[PathBuf; 2], String> {
    write_svg_and_png(stem, (720, 480), &Convergence { scene, records })
}

/// Draws the relMSE-over-time chart into `viewport` (the comparison
/// sheet's side column).
pub fn convergence_into(
    viewport: Viewport<'_>,
    scene: &str,
    records: &[Record],
) -> Result<(), String> {
    Convergence { scene, records }.draw(&viewport.into_drawing_area())
}

/// A number read off a record.
type Quantity = dyn Fn(&Record) -> f64;

/// The sigma study's two charts (final relMSE and the GLT's memory
/// against sigma) side by side.
struct SigmaStudy<'a> {
    scene: &'a str,
    /// The records of the study (methods named `<method> s=<sigma>`).
    studied: Vec<&'a Record>,
}

impl SigmaStudy<'_> {
    /// The range of `f` over the studied records, padded for the axes.
    fn range(&self, f: &Quantity) -> (f64, f64) {
        let v = self.studied.iter().map(|r| f(r)).filter(|x| *x > 0.0);
        let (lo, hi) = v.fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        (lo * 0.8, hi * 1.25)
    }
}

impl Chart for SigmaStudy<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let mut methods: Vec<&str> = self
            .studied
            .iter()
            .filter_map(|r| r.method.split(" s=").next())
            .collect();
        methods.dedup();
        let (s0, s1) = self.range(&|r| r.sigma);
        if self.studied.is_empty() || s0 >= s1 {
            return Err(format!("{}: no sigma study to plot", self.scene));
        }
        let quantities: [(&str, &Quantity); 2] = [
            ("relMSE at the end", &|r: &Record| r.relmse),
            ("GLT memory (MB)", &|r: &Record| r.glt_bytes as f64 / 1e6),
        ];
        for (panel, (name, f)) in area.split_evenly((1, 2)).iter().zip(quantities) {
            let lines: Vec<(String, Vec<(f64, f64)>)> = methods
                .iter()
                .map(|m| {
                    let mine = self
                        .studied
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
                &format!("{}: {name} vs sigma", self.scene),
                ("sigma", (s0, s1)),
                (name, self.range(f)),
                &lines,
            )?;
        }
        Ok(())
    }
}

/// Writes the sigma study of `records` (one scene; methods named
/// `<method> s=<sigma>`) to `<stem>.svg` and `<stem>.png`: the final
/// relMSE and the GLT's memory (the cuts, for ppg-glt) against sigma, one
/// line per method.
pub fn sigma_study(stem: &Path, scene: &str, records: &[Record]) -> Result<[PathBuf; 2], String> {
    let studied = records
        .iter()
        .filter(|r| r.method.contains(" s="))
        .collect();
    write_svg_and_png(stem, (960, 420), &SigmaStudy { scene, studied })
}

/// A log-log chart of `lines` (each a label and its points), captioned
/// `caption`, with the axes `x` and `y` described as given; written to
/// `<stem>.svg` and `<stem>.png`.
pub fn log_log(
    stem: &Path,
    caption: &str,
    (x_desc, y_desc): (&str, &str),
    lines: &[(String, Vec<(f64, f64)>)],
) -> Result<[PathBuf; 2], String> {
    struct Lines<'a> {
        caption: &'a str,
        desc: (&'a str, &'a str),
        lines: &'a [(String, Vec<(f64, f64)>)],
    }
    impl Chart for Lines<'_> {
        fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
            let points = || self.lines.iter().flat_map(|(_, p)| p.iter().copied());
            let range = |f: fn((f64, f64)) -> f64| {
                let v = points().map(f).filter(|v| *v > 0.0);
                let (lo, hi) = v.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
                (lo * 0.8, hi * 1.25)
            };
            let (x, y) = (range(|p| p.0), range(|p| p.1));
            if !(x.0 < x.1 && y.0 < y.1) {
                return Err(format!("{}: nothing to plot", self.caption));
            }
            log_log_chart(
                area,
                self.caption,
                (self.desc.0, x),
                (self.desc.1, y),
                self.lines,
            )
        }
    }
    let chart = Lines {
        caption,
        desc: (x_desc, y_desc),
        lines,
    };
    write_svg_and_png(stem, (760, 480), &chart)
}
