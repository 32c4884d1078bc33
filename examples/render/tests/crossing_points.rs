//! The render example's crossing points (when a guided method's curve
//! goes below its unguided counterpart's for good) are found where they
//! are, on curves whose crossing is known.

use guiding_render::{crossing, report};

use crossing::{crossing, crossings};
use report::{CurvePoint, Record};

fn record(method: &str, curve: &[(f64, f64)], efficiency: f64) -> Record {
    Record {
        method: method.into(),
        efficiency,
        curve: curve
            .iter()
            .map(|&(seconds, relmse)| CurvePoint {
                seconds,
                spp: 1,
                relmse,
                bytes: 0,
            })
            .collect(),
        ..Record::default()
    }
}

#[test]
fn crossing_is_where_the_guided_curve_stays_below() {
    // Unguided: 1 / t. Guided: 4 / t^2 (training pays off): equal at t = 4.
    let ts = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];
    let u: Vec<(f64, f64)> = ts.iter().map(|&t| (t, 1.0 / t)).collect();
    let g: Vec<(f64, f64)> = ts.iter().map(|&t| (t, 4.0 / (t * t))).collect();
    let c = crossing(&record("pt-glt", &g, 4.0), &record("pt-bvh", &u, 1.0)).unwrap();
    let from = c.from.unwrap();
    assert!((from / 4.0 - 1.0).abs() < 0.02, "{from}");
    assert_eq!(c.until, 16.0);
    assert_eq!(c.end_ratio, 4.0);
    // Swapped: the 1/t curve is above 4/t^2 at the end.
    let c = crossing(&record("pt-bvh", &u, 1.0), &record("pt-glt", &g, 4.0)).unwrap();
    assert!(c.from.is_none());
    // Below everywhere: from the start of the shared stretch.
    let low: Vec<(f64, f64)> = ts.iter().map(|&t| (t, 0.1 / t)).collect();
    let c = crossing(&record("ppg-glt", &low, 10.0), &record("ppg", &u, 1.0)).unwrap();
    assert_eq!(c.from, Some(0.5));
    let all = [record("ppg-glt s=0.05", &low, 10.0), record("ppg", &u, 1.0)];
    assert_eq!(crossings(&all).len(), 1);
    // Without curves (`--no-curve`), or with one: no crossing, no panic.
    assert!(crossing(&record("pt-glt", &[], 4.0), &record("pt-bvh", &[], 1.0)).is_none());
    assert!(crossing(&record("pt-glt", &g, 4.0), &record("pt-bvh", &[], 1.0)).is_none());
}
