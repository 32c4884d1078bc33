//! Both MIS conventions of `guiding::mis` are unbiased, for the pixel and
//! for the GLT's records: on a one-dimensional "hemisphere" (directions
//! `x` in `[0, 1)`) with three area lights, one partly occluded, and one
//! delta light, the mean contribution equals the direct light computed in
//! closed form, and each light's mean recorded value equals its radiance
//! integrated over the directions it covers (visibility included), within
//! five standard errors of 400,000 samples.

mod common;

use common::Rand;
use guiding::mis::{Convention, DirectLight};

/// An area light covering directions `[a, b)` with radiance `le`.
struct Area {
    a: f32,
    b: f32,
    le: f32,
}

const AREAS: [Area; 3] = [
    Area {
        a: 0.1,
        b: 0.3,
        le: 2.0,
    },
    Area {
        a: 0.5,
        b: 0.9,
        le: 0.5,
    },
    Area {
        a: 0.92,
        b: 0.97,
        le: 8.0,
    },
];
/// The delta light: direction and intensity (light 3).
const DELTA: (f32, f32) = (0.4, 0.3);
/// Light selection probabilities, lights 0..4.
const PMF: [f32; 4] = [0.2, 0.3, 0.4, 0.1];

/// BSDF times cosine.
fn f_cos(x: f32) -> f32 {
    1.0 + x
}

/// Directions in `[0.5, 0.6)` are blocked.
fn visible(x: f32) -> f32 {
    if (0.5..0.6).contains(&x) { 0.0 } else { 1.0 }
}

/// The area light a direction hits.
fn hit(x: f32) -> Option<usize> {
    AREAS.iter().position(|l| (l.a..l.b).contains(&x))
}

/// The BSDF's direction pdf `2x` and its sample.
fn bsdf_pdf(x: f32) -> f32 {
    2.0 * x
}

/// The closed forms: the direct light, and each light's visible radiance
/// integrated over its directions.
fn expected() -> (f64, [f64; 4]) {
    // The integral of (1 + x) over [a, b).
    let int_f = |a: f64, b: f64| (b - a) + 0.5 * (b * b - a * a);
    let mut per_light = [0.0; 4];
    let mut direct = 0.0;
    for (i, l) in AREAS.iter().enumerate() {
        let (a, b, le) = (f64::from(l.a), f64::from(l.b), f64::from(l.le));
        // Light 1 loses [0.5, 0.6) to the blocker.
        let a = if i == 1 { 0.6 } else { a };
        per_light[i] = le * (b - a);
        direct += le * int_f(a, b);
    }
    let (x, i) = (f64::from(DELTA.0), f64::from(DELTA.1));
    per_light[3] = i;
    direct += i * (1.0 + x);
    (direct, per_light)
}

/// Running mean and variance.
#[derive(Default, Clone, Copy)]
struct Mean {
    sum: f64,
    sum2: f64,
}

impl Mean {
    fn add(&mut self, v: f64) {
        self.sum += v;
        self.sum2 += v * v;
    }

    fn check(&self, n: f64, want: f64, what: &str) {
        let mean = self.sum / n;
        let se = ((self.sum2 / n - mean * mean).max(0.0) / n).sqrt();
        assert!(
            (mean - want).abs() <= 5.0 * se + 1e-9,
            "{what}: {mean} vs {want} (standard error {se})"
        );
    }
}

/// One vertex's direct light under `c`: the contribution, and the values
/// recorded per light.
fn vertex(c: Convention, rng: &mut Rand) -> (f64, [f64; 4]) {
    let mut contribution = 0.0;
    let mut records = [0.0f64; 4];
    let mut add = |light: usize, le: f32, f: f32, d: DirectLight| {
        contribution += f64::from(f * le * d.factor);
        records[light] += f64::from(le * d.factor);
    };
    // Choose a light.
    let u = rng.f();
    let mut chosen = 3;
    let mut cdf = 0.0;
    for (i, p) in PMF.iter().enumerate() {
        cdf += p;
        if u < cdf {
            chosen = i;
            break;
        }
    }
    let pmf = PMF[chosen];
    // Its light sample.
    if chosen == 3 {
        let (x, intensity) = DELTA;
        add(3, intensity, f_cos(x), c.light_sample(pmf, 1.0, 0.0));
    } else {
        let l = &AREAS[chosen];
        let x = l.a + (l.b - l.a) * rng.f();
        let pdf_light = 1.0 / (l.b - l.a);
        let d = c.light_sample(pmf, pdf_light, bsdf_pdf(x));
        add(chosen, l.le * visible(x), f_cos(x), d);
    }
    // The BSDF sample.
    let x = rng.f().sqrt();
    if let Some(i) = hit(x) {
        let l = &AREAS[i];
        let pdf_light = 1.0 / (l.b - l.a);
        let d = match c {
            Convention::PbrtV4 => Some(c.bsdf_sample(PMF[i], pdf_light, bsdf_pdf(x))),
            // Only an estimate of the chosen light.
            Convention::PbrtV3 => (i == chosen).then(|| c.bsdf_sample(pmf, pdf_light, bsdf_pdf(x))),
        };
        if let Some(d) = d {
            add(i, l.le * visible(x), f_cos(x), d);
        }
    }
    (contribution, records)
}

#[test]
fn both_conventions_are_unbiased_for_pixels_and_records() {
    let (direct, per_light) = expected();
    const N: usize = 400_000;
    for (k, c) in [Convention::PbrtV4, Convention::PbrtV3]
        .into_iter()
        .enumerate()
    {
        let mut rng = Rand::new(17 + k as u64);
        let mut pixel = Mean::default();
        let mut records = [Mean::default(); 4];
        for _ in 0..N {
            let (v, r) = vertex(c, &mut rng);
            pixel.add(v);
            for (m, x) in records.iter_mut().zip(r) {
                m.add(x);
            }
        }
        pixel.check(N as f64, direct, &format!("{c:?} direct light"));
        for (i, (m, want)) in records.iter().zip(per_light).enumerate() {
            m.check(N as f64, want, &format!("{c:?} records of light {i}"));
        }
    }
}

#[test]
fn weights_of_one_sample_sum_to_one_and_edges_count_nothing() {
    let (pmf, pl, pb) = (0.25, 3.0, 0.7);
    let v4 = Convention::PbrtV4;
    let sum = v4.light_sample(pmf, pl, pb).weight + v4.bsdf_sample(pmf, pl, pb).weight;
    assert!((sum - 1.0).abs() < 1e-6);
    let v3 = Convention::PbrtV3;
    let sum = v3.light_sample(pmf, pl, pb).weight + v3.bsdf_sample(pmf, pl, pb).weight;
    assert!((sum - 1.0).abs() < 1e-6);
    // A delta light: weight 1, factor 1 / pmf.
    for c in [v4, v3] {
        let d = c.light_sample(0.5, 1.0, 0.0);
        assert_eq!((d.weight, d.factor), (1.0, 2.0));
    }
    // Zero, NaN and infinite pdfs (and pmfs) count nothing: weight and
    // factor exactly 0, as documented.
    let bad = [0.0, f32::NAN, f32::INFINITY];
    for c in [v4, v3] {
        for x in bad {
            for (pmf, pl, pb) in [(x, 1.0, 1.0), (0.5, x, 1.0), (0.5, 1.0, x)] {
                // A light sample with pdf_bsdf 0 is a delta light's: it counts.
                if pb == 0.0 {
                    continue;
                }
                let d = c.light_sample(pmf, pl, pb);
                assert_eq!(d, DirectLight::NONE, "{c:?} light {pmf} {pl} {pb}");
            }
            for (pmf, pl, pb) in [(x, 1.0, 1.0), (0.5, 1.0, x)] {
                let d = c.bsdf_sample(pmf, pl, pb);
                // pbrt-v4: a light NEE never chooses (pmf 0) leaves the BSDF
                // sample all the weight.
                if c == v4 && pmf == 0.0 {
                    assert_eq!((d.weight, d.factor), (1.0, 1.0));
                    continue;
                }
                assert_eq!(d, DirectLight::NONE, "{c:?} bsdf {pmf} {pl} {pb}");
            }
        }
    }
}
