//! The render example's plots: tick labels written as a reader expects
//! them, text drawn in the committed font, and records read back from the
//! JSON the example writes, so committed plots can be redrawn from their
//! data (`render --replot`).

use guiding_render::plot::{number, tick};
use guiding_render::report::{CurvePoint, Record};
use guiding_render::{plot, report, text};

#[test]
fn tick_labels_are_numbers_as_a_reader_writes_them() {
    let cases = [
        (0.01, "0.01"),
        (0.1, "0.1"),
        (1.0, "1"),
        (10.0, "10"),
        (0.25, "0.25"),
        (0.2, "0.2"),
        (2000.0, "2000"),
        (0.0001, "0.0001"),
        (0.000_099_999_999_9, "10⁻⁴"),
        (1e-5, "10⁻⁵"),
        (3e-6, "3·10⁻⁶"),
        (2.5e-7, "2.5·10⁻⁷"),
        (9.9996e-7, "10⁻⁶"),
        (1e6, "10⁶"),
        (999_999.0, "999999"),
        (0.099_999_999_9, "0.1"),
        (9.999_999_9, "10"),
    ];
    for (v, want) in cases {
        assert_eq!(number(v), want, "{v:e}");
    }
}

#[test]
fn a_log_axis_over_decades_labels_only_one_two_and_five() {
    let wide = (0.05, 150.0);
    assert_eq!(tick(0.1, wide), "0.1");
    assert_eq!(tick(0.2, wide), "0.2");
    assert_eq!(tick(50.0, wide), "50");
    assert_eq!(tick(100.0, wide), "100");
    assert_eq!(tick(0.3, wide), "");
    assert_eq!(tick(7.0, wide), "");
    // Less than a decade: every tick.
    assert_eq!(tick(0.3, (0.15, 0.9)), "0.3");
}

#[test]
fn every_character_the_plots_write_has_a_glyph_in_the_committed_font() {
    // Glyph 0 is the font's "missing" box: its coverage equals that of any
    // other missing character.
    let missing = text::coverage("\u{E000}", 20.0);
    let written = "relMSE over time: seconds (training included) pt-glt ppg+glt s=0.01 \
                   0123456789 RMSE spp, ×·σ≥≤⁻⁰¹²³⁴⁵⁶⁷⁸⁹";
    for c in written.chars().filter(|c| !c.is_whitespace()) {
        let s = c.to_string();
        assert_ne!(text::coverage(&s, 20.0), missing, "{c:?} has no glyph");
    }
}

#[test]
fn text_is_anti_aliased_and_stays_in_its_box() {
    let s = "pt-glt 0.01";
    let (w, h) = text::measure(s, 14.0);
    assert!((50..120).contains(&w) && (14..20).contains(&h), "{w}x{h}");
    let px = text::coverage(s, 14.0);
    let partial = px.iter().filter(|p| p.2 < 0.9).count();
    assert!(
        partial * 4 > px.len(),
        "{partial} of {} pixels partly covered",
        px.len()
    );
    for &(x, y, c) in &px {
        assert!(
            (-1..=w as i32).contains(&x) && (0..h as i32).contains(&y),
            "({x}, {y})"
        );
        assert!(c > 0.0 && c <= 1.0 + 1e-6);
    }
    // Longer text is wider; a larger size is taller.
    assert!(text::measure("pt-glt 0.01 s", 14.0).0 > w);
    assert!(text::measure(s, 28.0).1 >= 2 * h - 1);
}

fn record(scene: &str, method: &str, curve: &[(f64, f64)]) -> Record {
    Record {
        scene: scene.into(),
        method: method.into(),
        sigma: 0.01,
        width: 256,
        height: 192,
        spp: 64,
        seconds: 20.0,
        relmse: curve.last().unwrap().1,
        efficiency: f64::INFINITY,
        mean: 0.3,
        curve: curve
            .iter()
            .map(|&(seconds, relmse)| CurvePoint {
                seconds,
                spp: (seconds * 3.0) as u64,
                relmse,
                bytes: 1 << 20,
            })
            .collect(),
        ..Record::default()
    }
}

#[test]
fn records_read_back_from_their_json_are_the_records_written() {
    let written = vec![
        record(
            "city-street",
            "pt-bvh",
            &[(0.4, 4.5), (2.0, 0.93), (20.0, 0.082)],
        ),
        record(
            "city-street",
            "ppg-glt \"quoted\"",
            &[(0.3, 7.6), (20.0, 0.031)],
        ),
    ];
    let read = report::from_json(&report::to_json(&written)).unwrap();
    assert_eq!(read.len(), written.len());
    for (r, w) in read.iter().zip(&written) {
        assert_eq!(
            (&r.scene, &r.method, r.spp, r.width),
            (&w.scene, &w.method, w.spp, w.width)
        );
        assert_eq!((r.seconds, r.relmse, r.mean), (w.seconds, w.relmse, w.mean));
        // Infinity is written as null and read as NaN.
        assert!(r.efficiency.is_nan());
        let pairs: Vec<_> = r
            .curve
            .iter()
            .map(|p| (p.seconds, p.spp, p.relmse, p.bytes))
            .collect();
        let want: Vec<_> = w
            .curve
            .iter()
            .map(|p| (p.seconds, p.spp, p.relmse, p.bytes))
            .collect();
        assert_eq!(pairs, want);
    }
    assert!(report::from_json("[{\"scene\": \"x\"}]").is_err());
    assert!(report::from_json("[1, 2").is_err());
}

#[test]
fn a_convergence_plot_writes_its_ticks_as_numbers_in_svg_and_png() {
    let records = vec![
        record(
            "city-street",
            "pt-bvh",
            &[(0.4, 4.5), (2.0, 0.93), (20.0, 0.082)],
        ),
        record(
            "city-street",
            "pt-glt",
            &[(0.3, 4.6), (2.0, 0.5), (20.0, 0.022)],
        ),
    ];
    let dir = std::env::temp_dir().join(format!("guiding-plots-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let [svg, png] = plot::convergence(&dir.join("convergence"), "city-street", &records).unwrap();
    let svg = std::fs::read_to_string(svg).unwrap();
    for label in [
        ">\n0.1\n<",
        ">\n1\n<",
        ">\n10\n<",
        ">\n0.01\n<",
        "relMSE over time",
        ">\npt-glt\n<",
    ] {
        assert!(svg.contains(label), "the SVG has no {label}");
    }
    // plotters writes each text on a line of its own.
    let texts: Vec<&str> = svg.lines().filter(|l| !l.starts_with('<')).collect();
    let numbers = texts
        .iter()
        .filter(|t| t.starts_with(|c: char| c.is_ascii_digit()));
    assert!(numbers.clone().count() >= 6, "{texts:?}");
    for t in numbers {
        assert!(
            t.parse::<f64>().is_ok() && !t.contains('e'),
            "tick label {t:?}"
        );
    }
    let png = std::fs::metadata(png).unwrap();
    assert!(png.len() > 10_000);
    std::fs::remove_dir_all(&dir).ok();
}
