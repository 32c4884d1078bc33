//! Helpers shared by the tests, the benchmarks and the example: a seeded
//! random-number wrapper, the mixed emitter scene, the two-room scene and
//! the incomplete gamma function behind the chi-square tests.
//!
//! Tests include it with `mod common;`, benchmarks and examples with
//! `#[path = "../tests/common/mod.rs"] mod common;`. Not every crate uses
//! every helper.
#![allow(dead_code)]

use glam::Vec3;
use guiding::math::{Aabb, LightCone};
use guiding::{Emitter, LightChoice};
use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};

// ---------------------------------------------------------------------------
// Random numbers
// ---------------------------------------------------------------------------

/// A seeded generator with the draws the tests need; `R` is the PCG
/// variant (the field tests use `Pcg32`, everything else `Pcg64Mcg`).
pub struct Rand<R = Pcg64Mcg>(pub R);

impl Rand {
    /// A `Pcg64Mcg` seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self::seeded(seed)
    }
}

impl<R: SeedableRng> Rand<R> {
    /// An `R` seeded with `seed`.
    pub fn seeded(seed: u64) -> Self {
        Self(R::seed_from_u64(seed))
    }
}

impl<R: Rng> Rand<R> {
    /// Uniform f32 in [0, 1) on the 2^-24 grid.
    pub fn f(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }
    /// Uniform f64 in [0, 1) on the 2^-53 grid.
    pub fn f64(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    /// 32 random bits.
    pub fn bits(&mut self) -> u32 {
        self.0.next_u32()
    }
    /// Uniform integer in [0, n).
    pub fn below(&mut self, n: u32) -> u32 {
        (((self.0.next_u64() >> 32) * n as u64) >> 32) as u32
    }
    /// Uniform in the cube [-r, r)^3.
    pub fn point(&mut self, r: f32) -> Vec3 {
        Vec3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
    /// A uniform unit direction (rejection from the cube).
    pub fn dir(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if let Some(d) = v.try_normalize() {
                return d;
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The mixed scene
// ---------------------------------------------------------------------------

/// A quad of half-size `s` centred at `c` facing `n`.
pub fn quad(c: Vec3, n: Vec3, s: f32, power: f32) -> Emitter {
    let (t, b) = n.any_orthonormal_pair();
    let mut bounds = Aabb::EMPTY;
    for (u, v) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
        bounds = bounds.extend(c + (t * u + b * v) * s);
    }
    Emitter::area(bounds, n, 4.0 * s * s, power)
}

/// `n` emitters of [`mixed_scene_from`] drawn from a `Pcg64Mcg` seeded with
/// `seed`.
pub fn mixed_scene(n: usize, seed: u64) -> Vec<Emitter> {
    mixed_scene_from(n, &mut Rand::new(seed))
}

/// 40% quads (half facing down, a tenth of them two-sided), 30% spheres,
/// 20% point and 10% spot lights in a 100^3 box; power log-uniform over
/// 1e-2..1e3 (five decades).
pub fn mixed_scene_from<R: Rng>(n: usize, r: &mut Rand<R>) -> Vec<Emitter> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
            );
            let power = 10f32.powf(r.range(-2.0, 3.0));
            let kind = r.f();
            if kind < 0.4 {
                let normal = if r.f() < 0.5 { -Vec3::Y } else { r.dir() };
                let mut e = quad(c, normal, r.range(0.05, 2.0), power);
                e.two_sided = r.f() < 0.1;
                e
            } else if kind < 0.7 {
                Emitter::sphere(c, r.range(0.05, 1.0), power)
            } else if kind < 0.9 {
                Emitter::point(c, power)
            } else {
                let mut e = Emitter::point(c, power);
                e.cone = Some(LightCone::spot(r.dir(), r.range(0.1, 1.2)));
                e
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------
// The two rooms
// ---------------------------------------------------------------------------

/// [`two_rooms_with`] drawn from `Pcg64Mcg`.
pub fn two_rooms() -> Vec<Emitter> {
    two_rooms_with::<Pcg64Mcg>()
}

/// 40 lights at x = -8 and 40 at x = +8; a wall at x = 0 means each half of
/// the scene sees only its own side's lights. Drawn from an `R` seeded with
/// 17.
pub fn two_rooms_with<R: Rng + SeedableRng>() -> Vec<Emitter> {
    let mut rng = Rand::<R>::seeded(17);
    (0..80)
        .map(|i| {
            let x = if i < 40 { -8.0 } else { 8.0 };
            Emitter::point(
                Vec3::new(x, rng.range(-4.0, 4.0), rng.range(-4.0, 4.0)),
                rng.range(1.0, 3.0),
            )
        })
        .collect()
}

/// The two rooms' bounds.
pub fn scene() -> Aabb {
    Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0))
}

/// An unshadowed contribution of `e` at `p`: power over squared distance,
/// times the emitter's cosine (Lambertian surfaces) or its cone (spots).
pub fn contribution(e: &Emitter, p: Vec3) -> f64 {
    let c = e.bounds.min * 0.5 + e.bounds.max * 0.5;
    let d = p - c;
    let d2 = d.length_squared().max(1.0) as f64;
    let g = match e.cone {
        None => 1.0,
        Some(cone) => {
            let cos = cone.axis.dot(d.normalize_or_zero());
            let cos = if e.two_sided { cos.abs() } else { cos };
            if cone.cos_theta_e <= 0.0 {
                cos.max(0.0)
            } else if cos >= cone.cos_theta_e {
                1.0
            } else {
                0.0
            }
        }
    };
    e.power as f64 * g as f64 / d2
}

/// Contribution of light `e` at `p` in the two rooms.
pub fn value(lights: &[Emitter], e: u32, p: Vec3) -> f32 {
    let c = lights[e as usize].bounds.center();
    if (c.x < 0.0) != (p.x < 0.0) {
        return 0.0;
    }
    unshadowed(lights, e, p)
}

/// Contribution of light `e` at `p` as if the wall were not there.
pub fn unshadowed(lights: &[Emitter], e: u32, p: Vec3) -> f32 {
    let c = lights[e as usize].bounds.center();
    lights[e as usize].power / (c - p).length_squared().max(1.0)
}

// ---------------------------------------------------------------------------
// Chi-square
// ---------------------------------------------------------------------------

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, 9 terms; ~1e-15 relative).
pub fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised upper incomplete gamma function Q(a, x).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // Series for P(a, x).
        let (mut sum, mut term, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        1.0 - sum * front
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        front * h
    }
}

/// The standard normal quantile of 1 - 1e-4: a Wilson–Hilferty z above it
/// is a p-value below 1e-4.
pub const Z_P_1E4: f64 = 3.719_016_5;

/// Draws `draws` emitters from the light choice `s` (each draw reporting
/// exactly its `pmf`), counts them over emitters `0..n`, and returns the
/// counts and the chi-square z against `pmf_exact` (below 4 for a sampler
/// that draws what it says).
pub fn emitter_draws<S: guiding::LightChoice + ?Sized>(
    s: &S,
    n: usize,
    draws: usize,
    r: &mut Rand,
) -> (Vec<u64>, f64) {
    use guiding::LightId;
    let mut counts = vec![0u64; n];
    for _ in 0..draws {
        let x = s.sample(r.f()).expect("a light");
        let LightId::Emitter(e) = x.light else {
            panic!("{:?}", x.light)
        };
        assert_eq!(x.pmf.to_bits(), s.pmf(x.light).to_bits());
        counts[e as usize] += 1;
    }
    let probs: Vec<f64> = (0..n as u32)
        .map(|e| s.pmf_exact(LightId::Emitter(e)))
        .collect();
    let (z, _) = chi_square_z(&counts, &probs).expect("no draw of pmf 0");
    (counts, z)
}

/// Wilson–Hilferty z-score of `observed` counts against probabilities
/// `probs`, pooling bins expected below 5; `None` when a light with pmf 0
/// was drawn. Returns (z, degrees of freedom).
pub fn chi_square_z(observed: &[u64], probs: &[f64]) -> Option<(f64, usize)> {
    let draws: u64 = observed.iter().sum();
    let mut bins = Vec::new();
    for (&o, &p) in observed.iter().zip(probs) {
        if p <= 0.0 {
            if o > 0 {
                return None;
            }
            continue;
        }
        bins.push((draws as f64 * p, o as f64));
    }
    bins.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut pooled = (0.0, 0.0);
    let mut kept: Vec<(f64, f64)> = Vec::new();
    for (e, o) in bins {
        if e < 5.0 {
            pooled = (pooled.0 + e, pooled.1 + o);
        } else {
            kept.push((e, o));
        }
    }
    if pooled.0 > 0.0 {
        if pooled.0 >= 5.0 || kept.is_empty() {
            kept.push(pooled);
        } else {
            kept[0] = (kept[0].0 + pooled.0, kept[0].1 + pooled.1);
        }
    }
    let k = kept.len().saturating_sub(1);
    if k == 0 {
        return Some((f64::NEG_INFINITY, 0));
    }
    let chi2: f64 = kept.iter().map(|(e, o)| (o - e) * (o - e) / e).sum();
    let k = k as f64;
    let v = 2.0 / (9.0 * k);
    let z = ((chi2 / k).cbrt() - (1.0 - v)) / v.sqrt();
    Some((z, kept.len() - 1))
}

/// Trains `glt` as a renderer trains it, without shadows: `rounds` rounds
/// of `records` records, each the contribution ([`contribution`]) of a
/// light the GLT chooses at a random point within `half` of the origin on
/// a random surface, over its pmf; a refinement after each round.
pub fn train_on_own_choices<H: guiding::LightHierarchy>(
    glt: &mut guiding::glt::Glt<H>,
    lights: &[Emitter],
    half: f32,
    (rounds, records): (usize, usize),
    r: &mut Rand,
) {
    for _ in 0..rounds {
        for _ in 0..records {
            let ctx = guiding::ShadingContext::on_surface(r.point(half), r.dir());
            let Some(vertex) = glt.vertex(&ctx) else {
                continue;
            };
            if let Some(s) = vertex.sample(r.f()) {
                let guiding::LightId::Emitter(e) = s.light else {
                    continue;
                };
                let v = contribution(&lights[e as usize], ctx.position) / f64::from(s.pmf);
                vertex.record_light(s.light, v as f32);
            }
        }
        glt.refine();
    }
}

mod at_point;
#[allow(unused_imports)]
pub use at_point::{ByPosition, DirectionsAt, LightsAt};

mod chain;
#[allow(unused_imports)]
pub use chain::Chain;

mod flattened;
#[allow(unused_imports)]
pub use flattened::Flattened;

/// Checks that `s.sample_candidates` answers each number exactly as
/// `sample_with_visibility` does (light, pmf and visibility to the bit),
/// on batches of 0 to 70 numbers (past a sort batch of 64) drawn at
/// random, sorted, repeated, and with NaN and numbers outside `[0, 1)`,
/// and that it writes no further than the shorter slice. Returns how many
/// candidates answered (the caller asserts the check saw something).
pub fn candidates_match<S: guiding::LightChoice + ?Sized>(s: &S, r: &mut Rand) -> usize {
    let bits = |c: Option<(guiding::LightSample, f32)>| {
        c.map(|(x, v)| (x.light, x.pmf.to_bits(), v.to_bits()))
    };
    let mut answered = 0;
    for m in [0usize, 1, 2, 8, 9, 33, 70] {
        let mut u: Vec<f32> = (0..m).map(|_| r.f()).collect();
        match m % 3 {
            0 => u.sort_by(f32::total_cmp),
            1 if m > 2 => {
                u[1] = u[0];
                u[2] = f32::NAN;
                u[m - 1] = 1.5;
            }
            _ => {}
        }
        if m > 3 {
            u[3] = -0.25;
        }
        // One slot more than numbers: it must stay as it was.
        let sentinel = Some((
            guiding::LightSample {
                light: guiding::LightId::Emitter(u32::MAX),
                pmf: 7.0,
            },
            7.0,
        ));
        let mut out = vec![sentinel; m + 1];
        s.sample_candidates(&u, &mut out);
        for (j, &uj) in u.iter().enumerate() {
            let want = s.sample_with_visibility(uj);
            assert_eq!(bits(out[j]), bits(want), "candidate {j} of {m}, u = {uj}");
            answered += usize::from(want.is_some());
        }
        assert_eq!(bits(out[m]), bits(sentinel), "wrote past {m} numbers");
    }
    answered
}
