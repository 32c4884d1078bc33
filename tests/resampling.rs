//! Resampled light choice (`guiding::resampling`): the one-number reservoir
//! keeps each candidate with exactly its share of the weights; at one
//! candidate it is plain sampling (weight = 1 / pmf); the resampled
//! estimate is unbiased against brute force for 1, 4 and 16 candidates,
//! with and without a target factor, from a trained GLT and from the
//! light BVH, and with pbrt-v4 MIS against a BSDF sample; bad evaluations
//! are ignored, never kept; the choice is deterministic.

mod common;
use common::{ByPosition, LightsAt};

use common::{Rand, scene, two_rooms, unshadowed, value};
use glam::Vec3;
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::{ImportanceTreeSampler, UniformSampler};
use guiding::light_tree::BuildHeuristic;
use guiding::resampling::{Evaluated, resample};
use guiding::{LightId, LightSampler, LightTree, SamplerAt, ShadingContext};

/// Candidate numbers that make a uniform sampler over `n` lights draw
/// exactly `lights`.
fn forcing(lights: &[u32], n: u32) -> Vec<f32> {
    lights
        .iter()
        .map(|&l| (l as f32 + 0.5) / n as f32)
        .collect()
}

/// Over a grid of 2^16 selection numbers, each candidate is kept with its
/// share `w_j / sum w` (to the grid's resolution), repeated lights and
/// zero contributions included; zero-contribution candidates are never
/// kept.
#[test]
fn the_reservoir_keeps_each_candidate_with_its_share() {
    let n = 5;
    let s = UniformSampler::new(n as usize);
    let ctx = ShadingContext::at(Vec3::ZERO);
    let contributions = [3.0f32, 0.5, 0.0, 7.0, 1.25];
    for lights in [
        vec![0u32, 1, 3],
        vec![3, 3, 4, 2, 0, 1],
        vec![2, 4],
        vec![1],
    ] {
        let cands = forcing(&lights, n);
        let w: Vec<f64> = lights
            .iter()
            .map(|&l| f64::from(contributions[l as usize]))
            .collect();
        let total: f64 = w.iter().sum();
        let grid = 1u32 << 16;
        let mut kept = vec![0u32; lights.len()];
        for g in 0..grid {
            let u = (g as f32 + 0.5) / grid as f32;
            let r = resample(&s.at(&ctx), &cands, u, None, |l, j| {
                assert_eq!(LightId::Emitter(lights[j]), l);
                Some(Evaluated::new(contributions[lights[j] as usize], j))
            })
            .unwrap();
            kept[r.payload] += 1;
            // weight = (sum_j c_j / pmf / M) / c_s; with the uniform pmf
            // 1 / n that is (sum c / M) / c_s * n.
            let expect = (total / lights.len() as f64) / w[r.payload] * f64::from(n);
            assert!((f64::from(r.weight) / expect - 1.0).abs() < 1e-6);
            assert_eq!(r.candidates as usize, lights.len());
        }
        for (j, &k) in kept.iter().enumerate() {
            let share = f64::from(k) / f64::from(grid);
            assert!(
                (share - w[j] / total).abs() < 1e-4,
                "{lights:?}: candidate {j} kept {share}, share {}",
                w[j] / total
            );
        }
    }
}

/// The target is the contribution times the renderer's factor: with
/// factors, each candidate is kept with its share of `c_j * factor_j`
/// (a target that divided by the factor would keep other shares).
#[test]
fn the_target_multiplies_the_factor() {
    let n = 4;
    let s = UniformSampler::new(n as usize);
    let ctx = ShadingContext::at(Vec3::ZERO);
    let (contributions, factors) = ([2.0f32, 1.0, 4.0, 0.5], [0.25f32, 3.0, 1.0, 8.0]);
    let lights = [0u32, 1, 2, 3];
    let cands = forcing(&lights, n);
    let w: Vec<f64> = (0..4)
        .map(|j| f64::from(contributions[j]) * f64::from(factors[j]))
        .collect();
    let total: f64 = w.iter().sum();
    let grid = 1u32 << 14;
    let mut kept = [0u32; 4];
    for g in 0..grid {
        let u = (g as f32 + 0.5) / grid as f32;
        let r = resample(&s.at(&ctx), &cands, u, None, |_, j| {
            let mut e = Evaluated::new(contributions[j], j);
            e.factor = factors[j];
            Some(e)
        })
        .unwrap();
        kept[r.payload] += 1;
    }
    for j in 0..4 {
        let share = f64::from(kept[j]) / f64::from(grid);
        assert!(
            (share - w[j] / total).abs() < 1e-3,
            "{j}: {share} vs {}",
            w[j] / total
        );
    }
}

/// A choice whose weight leaves `f32` (it would make the estimate infinite
/// or zero) is no choice: `None`, never an infinite or zero weight.
#[test]
fn a_weight_outside_f32_is_no_choice() {
    let s = UniformSampler::new(2);
    let ctx = ShadingContext::at(Vec3::ZERO);
    let cands = forcing(&[0, 1], 2);
    // u = 0 keeps the last candidate offered; its target is 1e60 times
    // below the total: the weight overflows.
    let huge_then_tiny = [1e30f32, 1e-30];
    let r = resample(&s.at(&ctx), &cands, 0.0, None, |_, j| {
        Some(Evaluated::new(huge_then_tiny[j], j))
    });
    assert!(r.is_none(), "{:?}", r.map(|r| r.weight));
    // The control: the same candidates the other way round keep a finite
    // weight.
    let r = resample(&s.at(&ctx), &cands, 0.0, None, |_, j| {
        Some(Evaluated::new(huge_then_tiny[1 - j], j))
    })
    .unwrap();
    assert!(r.weight > 0.0 && r.weight.is_finite());
    // A BSDF density 1e60 times the light's: the weight underflows.
    let r = resample(&s.at(&ctx), &cands[..1], 0.0, None, |_, j| {
        Some(Evaluated::new(1.0, j).with_densities(1e-30, 1e30))
    });
    assert!(r.is_none(), "{:?}", r.map(|r| r.weight));
}

/// One candidate: the sampler's own choice, weight 1 / pmf.
#[test]
fn one_candidate_is_plain_sampling() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let s = ImportanceTreeSampler::new(&tree);
    let mut rng = Rand::new(3);
    for _ in 0..1000 {
        let ctx = ShadingContext::at(rng.point(9.0));
        let u = rng.f();
        let plain = s.sample(&ctx, u).unwrap();
        let r = resample(&s.at(&ctx), &[u], rng.f(), None, |_, _| {
            Some(Evaluated::new(2.5, ()))
        })
        .unwrap();
        assert_eq!(r.light, plain.light);
        assert_eq!(r.pmf, plain.pmf);
        assert!(
            (r.weight * plain.pmf - 1.0).abs() < 1e-6,
            "{} {}",
            r.weight,
            plain.pmf
        );
    }
}

/// The brute-force truth at `p`: every light's contribution behind the
/// two rooms' wall.
fn truth(lights: &[guiding::Emitter], p: Vec3) -> f64 {
    (0..lights.len() as u32)
        .map(|e| f64::from(value(lights, e, p)))
        .sum()
}

/// Mean and standard error of `n` resampled estimates at `p`, the target
/// factor given by `factor` (the shadowed contribution is the estimate;
/// point lights: `p_l = 1`). With `plain`, the weight is replaced by
/// `1 / pmf` (the control: biased for M > 1).
fn estimate(
    s: &dyn LightSampler,
    lights: &[guiding::Emitter],
    p: Vec3,
    m: usize,
    factor: impl Fn(u32) -> f32,
    plain: bool,
    seed: u64,
) -> (f64, f64) {
    let ctx = ShadingContext::at(p);
    let mut rng = Rand::new(seed);
    let n = 100_000;
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    let mut cands = vec![0.0f32; m];
    for _ in 0..n {
        cands.iter_mut().for_each(|c| *c = rng.f());
        let r = resample(&SamplerAt::new(s, &ctx), &cands, rng.f(), None, |l, _| {
            let LightId::Emitter(e) = l else { return None };
            Some(Evaluated {
                factor: factor(e),
                ..Evaluated::new(unshadowed(lights, e, p), e)
            })
        });
        let x = r.map_or(0.0, |r| {
            let w = if plain {
                1.0 / f64::from(r.pmf)
            } else {
                f64::from(r.weight)
            };
            f64::from(value(lights, r.payload, p)) * w
        });
        s1 += x;
        s2 += x * x;
    }
    let mean = s1 / n as f64;
    (mean, ((s2 / n as f64 - mean * mean) / n as f64).sqrt())
}

/// Unbiased against brute force at points on both sides of the wall, from
/// a trained GLT and from the light BVH, with 1, 4 and 16 candidates, a
/// visibility-blind target and one that favours the point's own room (a
/// learned visibility would), within 4.5 standard errors; the control
/// (weighing the kept light by 1 / pmf where the kept light's distribution
/// differs from the sampler's) is biased by far more.
#[test]
fn resampled_estimates_are_unbiased() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        spatial_threshold: 2000.0,
        ..GltConfig::default()
    };
    let mut glt = Glt::new(&tree, scene(), config).unwrap();
    let mut rng = Rand::new(8);
    for _ in 0..3 {
        for _ in 0..8000 {
            let p = rng.point(9.5);
            let Some(x) = ByPosition(&glt).sample(&ShadingContext::at(p), rng.f()) else {
                continue;
            };
            let LightId::Emitter(e) = x.light else {
                continue;
            };
            glt.record_light_at(p, x.light, value(&lights, e, p) / x.pmf);
        }
        glt.refine();
    }
    let bvh = ImportanceTreeSampler::new(&tree);
    let samplers: [(&str, &dyn LightSampler); 2] = [("glt", &ByPosition(&glt)), ("bvh", &bvh)];
    for (i, p) in [Vec3::new(-3.0, 1.0, 2.0), Vec3::new(0.5, -2.0, -1.0)]
        .into_iter()
        .enumerate()
    {
        let want = truth(&lights, p);
        let blind = |_: u32| 1.0f32;
        let own_room = |e: u32| {
            if (lights[e as usize].bounds.center().x < 0.0) == (p.x < 0.0) {
                1.0f32
            } else {
                0.1
            }
        };
        let factors: [(&str, &dyn Fn(u32) -> f32); 2] = [("blind", &blind), ("room", &own_room)];
        for (name, s) in samplers {
            for m in [1, 4, 16] {
                for (f, factor) in factors {
                    let seed = (i * 100 + m) as u64;
                    let (mean, se) = estimate(s, &lights, p, m, factor, false, seed);
                    assert!(
                        (mean - want).abs() < 4.5 * se,
                        "{name} at {i}, M = {m}, {f}: {mean} +- {se} vs {want}"
                    );
                    // The control where the kept light's distribution is
                    // far from the sampler's: the BVH does not know the
                    // wall, the room factor does.
                    if m == 16 && f == "room" && name == "bvh" {
                        let (biased, se) = estimate(s, &lights, p, m, factor, true, seed);
                        assert!(
                            (biased - want).abs() > 10.0 * se,
                            "control: {biased} vs {want}"
                        );
                    }
                }
            }
        }
    }
}

/// Candidates whose evaluation is missing, zero, negative, NaN or infinite
/// are never kept; hostile factors count as 1; no candidate that
/// contributes gives `None`; an empty candidate list gives `None`;
/// candidates with densities that cannot be used are ignored.
#[test]
fn bad_evaluations_are_ignored() {
    let s = UniformSampler::new(4);
    let ctx = ShadingContext::at(Vec3::ZERO);
    let cands = forcing(&[0, 1, 2, 3], 4);
    let bad = [
        None,
        Some(0.0f32),
        Some(-1.0),
        Some(f32::NAN),
        Some(f32::INFINITY),
    ];
    for b in bad {
        let none = resample(&s.at(&ctx), &cands, 0.5, None, |_, _| {
            b.map(|c| Evaluated::new(c, ()))
        });
        assert!(none.is_none(), "{b:?}");
    }
    for u in [0.0, 0.3, 0.7, 0.999_999] {
        let r = resample(&s.at(&ctx), &cands, u, None, |l, j| {
            let c = if j == 2 {
                1.0
            } else {
                [0.0, f32::NAN, 0.0, -3.0][j]
            };
            Some(Evaluated {
                factor: [f32::NAN, 0.0, f32::INFINITY, -1.0][j],
                ..Evaluated::new(c, l)
            })
        })
        .unwrap();
        assert_eq!(r.payload, LightId::Emitter(2));
        // Factor infinite counts as 1: weight = (c/pmf / 4) / c = 1.
        assert!((r.weight - 1.0).abs() < 1e-6, "{}", r.weight);
    }
    assert!(
        resample(&s.at(&ctx), &[], 0.5, None, |_, _| Some(Evaluated::new(
            1.0,
            ()
        )))
        .is_none()
    );
    // Densities that cannot be used: the candidate is ignored, whether a
    // light candidate or the BSDF's (which also needs a positive BSDF
    // density).
    let densities = [
        (1.0, f32::NAN),
        (1.0, -1.0),
        (1.0, f32::INFINITY),
        (0.0, 1.0),
        (f32::NAN, 1.0),
        (-2.0, 1.0),
    ];
    let evaluated = |(pl, pb): (f32, f32)| Evaluated::new(1.0, ()).with_densities(pl, pb);
    for d in densities {
        let light = resample(&s.at(&ctx), &cands, 0.5, None, |_, _| Some(evaluated(d)));
        assert!(light.is_none(), "{d:?}");
    }
    // A BSDF candidate without a BSDF density is ignored too.
    for d in densities.into_iter().chain([(1.0, 0.0)]) {
        let bsdf = Some((LightId::Emitter(1), evaluated(d)));
        let found = resample(&s.at(&ctx), &[], 0.5, bsdf, |_, _| None);
        assert!(found.is_none(), "{d:?}");
        // Beside light candidates (whose weights would make it count).
        for u in [0.1, 0.5, 0.9] {
            let light = |_, _| Some(Evaluated::new(1.0, ()));
            let with = resample(&s.at(&ctx), &cands, u, bsdf, light);
            assert_eq!(with, resample(&s.at(&ctx), &cands, u, None, light), "{d:?}");
        }
    }
}

/// pbrt-v4 MIS with the candidate density as the proxy: the resampled
/// light sample plus a BSDF sample weighed with the proxy pmf of the light
/// it hits is unbiased (a one-dimensional check: lights are intervals of a
/// line, the "BSDF" samples the line uniformly).
#[test]
fn resampled_mis_is_unbiased() {
    use guiding::mis::{Convention, resampled_light_sample};
    // Four lights on [0, 4): light k covers [k, k + 1), radiance r_k(y)
    // linear in y; two are blocked for half their length.
    let radiance = |k: u32, y: f32| (1.0 + k as f32) * (0.5 + (y - k as f32));
    let visible = |k: u32, y: f32| !(k % 2 == 1 && y - (k as f32) < 0.5);
    let truth: f64 = (0..4u32)
        .map(|k| {
            (0..100_000)
                .map(|i| {
                    let y = k as f32 + (i as f32 + 0.5) / 100_000.0;
                    if visible(k, y) {
                        f64::from(radiance(k, y))
                    } else {
                        0.0
                    }
                })
                .sum::<f64>()
                / 100_000.0
        })
        .sum();
    let s = UniformSampler::new(4);
    let ctx = ShadingContext::at(Vec3::ZERO);
    let v4 = Convention::PbrtV4;
    let pdf_bsdf = 0.25; // uniform on [0, 4)
    let mut rng = Rand::new(12);
    let n = 200_000;
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let cands = [rng.f(), rng.f(), rng.f(), rng.f(), rng.f(), rng.f()];
        // Light sample: uniform on the light (pdf 1).
        let ys: Vec<f32> = (0..cands.len()).map(|_| rng.f()).collect();
        let mut x = 0.0f64;
        if let Some(r) = resample(&s.at(&ctx), &cands, rng.f(), None, |l, j| {
            let LightId::Emitter(k) = l else { return None };
            let y = k as f32 + ys[j];
            Some(Evaluated::new(radiance(k, y), (k, y)))
        }) {
            let (k, y) = r.payload;
            let d = resampled_light_sample(r.pmf, r.weight, 1.0, pdf_bsdf);
            if visible(k, y) {
                x += f64::from(radiance(k, y) * d.factor);
            }
        }
        // BSDF sample: uniform on the line; the light it hits and its
        // proxy pmf.
        let y = 4.0 * rng.f();
        let k = (y as u32).min(3);
        let pmf = s.pmf(&ctx, LightId::Emitter(k));
        let d = v4.bsdf_sample(pmf, 1.0, pdf_bsdf);
        if visible(k, y) {
            x += f64::from(radiance(k, y) * d.factor);
        }
        s1 += x;
        s2 += x * x;
    }
    let mean = s1 / n as f64;
    let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
    assert!((mean - truth).abs() < 4.5 * se, "{mean} +- {se} vs {truth}");
}

/// The BSDF sample as one more candidate (balance-heuristic weights over
/// the two strategies, no MIS weight, the emission it found counted only
/// through the kept candidate): unbiased with 0, 1 and 4 light candidates,
/// from a sampler that can choose every light and from one that cannot
/// choose the last (only the BSDF sample finds it). The same line of four
/// lights as above, the "BSDF" now sampling it with density `y / 8`. The
/// control: light candidates that leave out the BSDF's density (the two
/// strategies counted twice) are biased by far more than the noise.
#[test]
fn the_bsdf_sample_as_a_candidate_is_unbiased() {
    let radiance = |k: u32, y: f32| (1.0 + k as f32) * (0.5 + (y - k as f32));
    let visible = |k: u32, y: f32| !(k % 2 == 1 && y - (k as f32) < 0.5);
    let truth: f64 = (0..400_000)
        .map(|i| {
            let y = 4.0 * (i as f32 + 0.5) / 400_000.0;
            let k = (y as u32).min(3);
            if visible(k, y) {
                f64::from(radiance(k, y))
            } else {
                0.0
            }
        })
        .sum::<f64>()
        / 100_000.0;
    let pdf_bsdf = |y: f32| y / 8.0;
    // Points on a light: uniform (density 1), or warped to density
    // `0.5 + t` at `t = y - k` (so that `p_b / p_l` differs from `p_b`).
    let density = |warp: bool, t: f32| if warp { 0.5 + t } else { 1.0 };
    let point = |warp: bool, u: f32| {
        if warp {
            -0.5 + (0.25 + 2.0 * u).sqrt()
        } else {
            u
        }
    };
    let ctx = ShadingContext::at(Vec3::ZERO);
    let run = |s: &dyn LightSampler, m: usize, densities: bool, warp: bool, seed: u64| {
        let mut rng = Rand::new(seed);
        let n = 200_000;
        let (mut s1, mut s2) = (0.0f64, 0.0f64);
        let mut cands = vec![0.0f32; m];
        for _ in 0..n {
            cands.iter_mut().for_each(|c| *c = rng.f());
            let ys: Vec<f32> = (0..m).map(|_| point(warp, rng.f())).collect();
            // The BSDF sample: `y = 4 sqrt(u)` has density `y / 8`; its
            // ray stops where the light is blocked.
            let y = 4.0 * rng.f().sqrt();
            let k = (y as u32).min(3);
            let bsdf = visible(k, y).then(|| {
                let pl = density(warp, y - k as f32);
                let e = Evaluated::new(radiance(k, y) / pl, (k, y)).with_densities(pl, pdf_bsdf(y));
                (LightId::Emitter(k), e)
            });
            let r = resample(&SamplerAt::new(s, &ctx), &cands, rng.f(), bsdf, |l, j| {
                let LightId::Emitter(k) = l else { return None };
                let y = k as f32 + ys[j];
                let pl = density(warp, ys[j]);
                let e = Evaluated::new(radiance(k, y) / pl, (k, y));
                Some(if densities {
                    e.with_densities(pl, pdf_bsdf(y))
                } else {
                    e
                })
            });
            // The kept light's estimate `Le / p_l` times the weight.
            let x = r.map_or(0.0, |r| {
                let (k, y) = r.payload;
                if r.bsdf || visible(k, y) {
                    let pl = density(warp, y - k as f32);
                    f64::from(radiance(k, y) / pl) * f64::from(r.weight)
                } else {
                    0.0
                }
            });
            s1 += x;
            s2 += x * x;
        }
        let mean = s1 / n as f64;
        (mean, ((s2 / n as f64 - mean * mean) / n as f64).sqrt())
    };
    let all = UniformSampler::new(4);
    let three = UniformSampler::new(3);
    for (name, s) in [("all", &all), ("three", &three)] {
        for m in [0usize, 1, 4] {
            let (mean, se) = run(s, m, true, false, 40 + m as u64);
            assert!(
                (mean - truth).abs() < 4.5 * se,
                "{name}, M = {m}: {mean} +- {se} vs {truth}"
            );
        }
    }
    // Light points of density other than 1: the BSDF's share in each
    // weight is `p_b / p_l` (`p_b p_l` in its place was unbiased above).
    for m in [1usize, 4] {
        let (mean, se) = run(&all, m, true, true, 60 + m as u64);
        assert!(
            (mean - truth).abs() < 4.5 * se,
            "warped, M = {m}: {mean} +- {se} vs {truth}"
        );
    }
    let (biased, se) = run(&all, 4, false, false, 99);
    assert!(
        (biased - truth).abs() > 10.0 * se,
        "control: {biased} +- {se} vs {truth}"
    );
}

/// The same numbers and evaluations give the same choice and weight.
#[test]
fn resampling_is_deterministic() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let s = ImportanceTreeSampler::new(&tree);
    let mut rng = Rand::new(4);
    for _ in 0..200 {
        let p = rng.point(9.0);
        let ctx = ShadingContext::at(p);
        let cands: Vec<f32> = (0..8).map(|_| rng.f()).collect();
        let u = rng.f();
        let eval = |l: LightId, _| {
            let LightId::Emitter(e) = l else { return None };
            Some(Evaluated::new(unshadowed(&lights, e, p), e))
        };
        let a = resample(&s.at(&ctx), &cands, u, None, eval).unwrap();
        let b = resample(&s.at(&ctx), &cands, u, None, eval).unwrap();
        assert_eq!(a, b);
    }
}
