//! Multiple importance sampling weights for combining next-event estimation
//! with BSDF (or guided) sampling: the pdfs are those of the two techniques
//! for the same sample, in the same measure (solid angle), light selection
//! included (`pmf * pdf_light`).

/// Veach's power heuristic (beta = 2), the weight of technique `a` against
/// `b`: `a^2 / (a^2 + b^2)`, squared in `f64` so that neither tiny nor huge
/// pdfs underflow or overflow. An infinite `a` (a delta technique) gets 1,
/// two zero pdfs get 0, NaN gives 0.
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    if a.is_infinite() && a > 0.0 {
        return 1.0;
    }
    let (a, b) = (f64::from(a), f64::from(b));
    let (a2, b2) = (a * a, b * b);
    let w = a2 / (a2 + b2);
    if w.is_finite() { w as f32 } else { 0.0 }
}

/// Veach's balance heuristic, the weight of technique `a` against `b`:
/// `a / (a + b)`, with the same edges as [`power_heuristic`].
#[inline]
pub fn balance_heuristic(a: f32, b: f32) -> f32 {
    if a.is_infinite() && a > 0.0 {
        return 1.0;
    }
    let (a, b) = (f64::from(a), f64::from(b));
    let w = a / (a + b);
    if w.is_finite() { w as f32 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_edges_are_defined() {
        for (a, b) in [(1.0, 1.0), (0.3, 7.0), (1e-30, 1e-30), (1e20, 3.0)] {
            for h in [power_heuristic, balance_heuristic] {
                let s = h(a, b) + h(b, a);
                assert!((s - 1.0).abs() < 1e-6, "{a} {b}: {s}");
            }
        }
        assert_eq!(power_heuristic(2.0, 1.0), 0.8);
        assert_eq!(balance_heuristic(3.0, 1.0), 0.75);
        for h in [power_heuristic, balance_heuristic] {
            assert_eq!(h(f32::INFINITY, 1.0), 1.0);
            assert_eq!(h(1.0, f32::INFINITY), 0.0);
            assert_eq!(h(0.0, 0.0), 0.0);
            assert_eq!(h(f32::NAN, 1.0), 0.0);
            assert_eq!(h(0.0, 1.0), 0.0);
        }
    }
}
