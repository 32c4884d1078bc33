//! The iteration schedule and the inverse-variance combination of the last
//! iterations, including an unbiasedness check of the variance estimate by
//! simulation.

use guiding::schedule::{
    InverseVarianceCombiner, Iterations, PassStats, next_iteration, next_iteration_by_time,
};
use rand_pcg::Pcg64;
use rand_pcg::rand_core::{Rng, SeedableRng};

fn uniform(rng: &mut Pcg64) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// Exponentially distributed with the given mean (skewed, like radiance).
fn exponential(rng: &mut Pcg64, mean: f64) -> f64 {
    -mean * (1.0 - uniform(rng)).ln()
}

#[test]
fn doubling_passes_and_last_takes_at_least_half() {
    for budget in 1..=3000u64 {
        let plan: Vec<_> = Iterations::new(budget).collect();
        assert_eq!(plan.iter().map(|i| i.passes).sum::<u64>(), budget);
        let (last, rest) = plan.split_last().unwrap();
        assert!(last.is_last);
        assert!(2 * last.passes >= budget, "{budget}: {plan:?}");
        for (k, it) in rest.iter().enumerate() {
            assert_eq!(it.index, k as u32);
            assert_eq!(it.passes, 1 << k);
            assert!(!it.is_last);
        }
        assert_eq!(last.index as usize, rest.len());
        // The last could not have been followed by another full iteration.
        assert!(last.passes < 3 << last.index);
    }
    let passes = |b| Iterations::new(b).map(|i| i.passes).collect::<Vec<_>>();
    assert_eq!(passes(1), [1]);
    assert_eq!(passes(4), [1, 3]);
    assert_eq!(passes(7), [1, 2, 4]);
    assert_eq!(passes(100), [1, 2, 4, 8, 16, 69]);
    assert!(Iterations::new(0).next().is_none());
    // Huge budgets neither overflow nor stall.
    let big: Vec<_> = Iterations::new(u64::MAX).collect();
    assert_eq!(
        big.iter().map(|i| i.passes as u128).sum::<u128>(),
        u64::MAX as u128
    );
    assert!(next_iteration(200, 5).unwrap().is_last);
}

#[test]
fn time_budget_decides_from_measured_pass_time() {
    // 100 passes affordable at iteration 3: 8 now, 92 left >= 16.
    let it = next_iteration_by_time(3, 10.0, 0.1).unwrap();
    assert_eq!((it.passes, it.is_last), (8, false));
    // At iteration 6 the rest cannot pay for 64 + 128: last, all 100.
    let it = next_iteration_by_time(6, 10.0, 0.1).unwrap();
    assert_eq!((it.passes, it.is_last), (100, true));
    // No measurement yet: plan 2^k, not last.
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let it = next_iteration_by_time(2, 10.0, bad).unwrap();
        assert_eq!((it.passes, it.is_last), (4, false));
    }
    assert!(next_iteration_by_time(0, 0.0, 0.1).is_none());
    assert!(next_iteration_by_time(0, f64::NAN, 0.1).is_none());
    assert!(next_iteration_by_time(0, 0.05, 0.1).is_none());

    // A simulated renderer whose guided passes get slower: the last
    // iteration still gets at least half of the time.
    for budget in [1.0, 7.5, 60.0, 300.0] {
        let mut spent = 0.0;
        let mut per_pass = f64::NAN;
        let mut last_time = 0.0;
        let mut index = 0;
        while let Some(it) = next_iteration_by_time(index, budget - spent, per_pass) {
            let cost = if index == 0 { 0.01 } else { 0.012 };
            let t = it.passes as f64 * cost;
            spent += t;
            per_pass = cost;
            if it.is_last {
                last_time = t;
                break;
            }
            index += 1;
        }
        // The unmeasured first pass may overrun a tiny budget by one pass.
        assert!(spent <= budget + 0.012, "{spent} > {budget}");
        assert!(
            2.0 * last_time >= spent - 0.02,
            "{budget}: last {last_time} of {spent}"
        );
    }
}

#[test]
fn pass_variance_estimate_is_unbiased() {
    // Per-pass pixel values ~ Exp(mean 3): variance 9, so the variance of
    // an n-pass mean is 9 / n. 1000 pixels x 40 trials per pass count.
    let mut rng = Pcg64::seed_from_u64(7);
    let (mean, sigma2, pixels, trials) = (3.0, 9.0, 1000, 40);
    for n in [2u64, 4, 8] {
        let mut ours = 0.0;
        let mut ppg_like = 0.0;
        for _ in 0..trials {
            let mut stats = PassStats::new(pixels);
            let mut second_moment = vec![0.0f64; pixels];
            for _ in 0..n {
                let pass: Vec<f32> = (0..pixels)
                    .map(|_| exponential(&mut rng, mean) as f32)
                    .collect();
                for (m, &x) in second_moment.iter_mut().zip(&pass) {
                    *m += (x as f64) * (x as f64) / n as f64;
                }
                assert!(stats.add_pass(&pass));
            }
            ours += stats.image_variance().unwrap() / trials as f64;
            // The estimator that uses the second moment where the variance
            // belongs: E = (sigma^2 + mu^2) / n.
            ppg_like +=
                second_moment.iter().sum::<f64>() / pixels as f64 / n as f64 / trials as f64;
        }
        let truth = sigma2 / n as f64;
        assert!(
            (ours / truth - 1.0).abs() < 0.03,
            "n={n}: estimate {ours} vs {truth}"
        );
        // The simulation can tell a biased estimator apart.
        assert!(ppg_like / truth > 1.5, "n={n}: {ppg_like} vs {truth}");
    }
    let mut one = PassStats::new(3);
    assert!(one.add_pass(&[1.0, 2.0, 3.0]));
    assert!(!one.add_pass(&[1.0]));
    assert_eq!(one.passes(), 1);
    assert_eq!(one.image_variance(), None);
    assert_eq!(one.variance_of_mean(0), None);
    assert!(one.add_pass(&[3.0, 2.0, 1.0]));
    assert_eq!(one.mean(), [2.0, 2.0, 2.0]);
    assert_eq!(one.variance_of_mean(0), Some(1.0));
    assert_eq!(one.variance_of_mean(1), Some(0.0));
}

#[test]
fn weights_are_inverse_variance_and_sum_to_one() {
    let mut c = InverseVarianceCombiner::new();
    assert!(c.weights().is_empty());
    c.push_image(&[1.0], Some(1.0), 4);
    c.push_image(&[2.0], Some(2.0), 8);
    c.push_image(&[4.0], Some(4.0), 16);
    let w = c.weights();
    let expect = [4.0 / 7.0, 2.0 / 7.0, 1.0 / 7.0];
    for (a, b) in w.iter().zip(expect) {
        assert!((a - b).abs() < 1e-12, "{w:?}");
    }
    assert!((c.combine()[0] - (4.0 + 4.0 + 4.0) / 7.0).abs() < 1e-6);

    // Only the last four are kept.
    for v in 1..=6 {
        c.push_image(&[v as f32], Some(1.0), 1);
    }
    assert_eq!(c.len(), InverseVarianceCombiner::MAX_COMBINED);
    assert_eq!(c.weights(), [0.25; 4]);
    assert_eq!(c.combine(), [(3.0 + 4.0 + 5.0 + 6.0) / 4.0]);

    // Unknown variance: weight 0 beside known ones; by passes if none known.
    let mut c = InverseVarianceCombiner::new();
    c.push_image(&[10.0], None, 1);
    c.push_image(&[2.0], Some(0.5), 2);
    c.push_image(&[4.0], Some(f64::NAN), 4);
    assert_eq!(c.weights(), [0.0, 1.0, 0.0]);
    let mut c = InverseVarianceCombiner::new();
    c.push_image(&[1.0], None, 1);
    c.push_image(&[4.0], None, 3);
    assert_eq!(c.weights(), [0.25, 0.75]);
    // Zero variance wins outright; tiny variances do not overflow.
    let mut c = InverseVarianceCombiner::new();
    c.push_image(&[1.0], Some(0.0), 1);
    c.push_image(&[4.0], Some(1.0), 3);
    assert_eq!(c.weights(), [1.0, 0.0]);
    let mut c = InverseVarianceCombiner::new();
    c.push_image(&[1.0], Some(1e-320), 1);
    c.push_image(&[4.0], Some(1.0), 3);
    let w = c.weights();
    assert!(
        (w.iter().sum::<f64>() - 1.0).abs() < 1e-12 && w[0] > 0.99,
        "{w:?}"
    );
}

#[test]
fn combined_variance_is_the_inverse_sum_of_inverse_variances() {
    let mut c = InverseVarianceCombiner::new();
    assert_eq!(c.combined_variance(), None);
    c.push_image(&[1.0; 4], Some(4.0), 8);
    c.push_image(&[1.0; 4], Some(1.0), 16);
    c.push_image(&[1.0; 4], Some(0.25), 32);
    let expected = 1.0 / (1.0 / 4.0 + 1.0 + 4.0);
    assert!((c.combined_variance().unwrap() - expected).abs() < 1e-15);
    // An iteration without an estimate gets weight 0 and is ignored ...
    c.push_image(&[1.0; 4], None, 1);
    assert!((c.combined_variance().unwrap() - expected).abs() < 1e-15);
    // ... but with no estimate anywhere the variance is unknown.
    let mut d = InverseVarianceCombiner::new();
    d.push_image(&[1.0; 4], None, 4);
    assert_eq!(d.combined_variance(), None);
}

#[test]
fn combining_the_last_iterations_beats_the_last_alone() {
    // Iteration k renders 2^k passes with per-pass variance shrinking as
    // guiding improves; the true pixel value is 2 everywhere.
    let mut rng = Pcg64::seed_from_u64(11);
    let pixels = 400;
    let trials = 30;
    let (mut err_combined, mut err_last, mut bias) = (0.0, 0.0, 0.0);
    let mut predicted = 0.0;
    for _ in 0..trials {
        let mut c = InverseVarianceCombiner::new();
        let mut last = Vec::new();
        for it in Iterations::new(120) {
            let noise = 4.0 / (1.0 + it.index as f64);
            let mut stats = PassStats::new(pixels);
            for _ in 0..it.passes {
                let pass: Vec<f32> = (0..pixels)
                    .map(|_| (2.0 + noise * (uniform(&mut rng) - 0.5) * 3.46) as f32)
                    .collect();
                stats.add_pass(&pass);
            }
            c.push_stats(&stats);
            last = stats.mean().to_vec();
        }
        let w = c.weights();
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let v = c.combined_variance().unwrap();
        predicted += v;
        assert!(w.iter().all(|&w| w > 0.0));
        let img = c.combine();
        for (a, b) in img.iter().zip(&last) {
            err_combined += (*a as f64 - 2.0).powi(2);
            err_last += (b - 2.0).powi(2);
            bias += *a as f64 - 2.0;
        }
    }
    let n = (pixels * trials) as f64;
    assert!(
        err_combined < 0.9 * err_last,
        "{err_combined} vs {err_last}"
    );
    // The combiner's own variance estimate predicts the measured error.
    let measured = err_combined / n;
    let predicted = predicted / trials as f64;
    assert!(
        (predicted / measured - 1.0).abs() < 0.15,
        "predicted {predicted} measured {measured}"
    );
    // Unbiased: the mean error is within a few standard errors of 0.
    let se = (err_combined / n).sqrt() / n.sqrt();
    assert!((bias / n).abs() < 4.0 * se, "bias {} se {se}", bias / n);
}
