//! The distributions the learned samplers actually draw from, against the
//! pmf they report: a chi-square goodness-of-fit test of 200,000 draws (by
//! `f32` and by `f64` numbers) for the GLT, its vertex, the combined field,
//! its vertex and the GLT strategy, untrained and trained, with and without
//! unbounded lights (a sun and a sky in the GLT's mixture), under the
//! default rules and the paper's.
//!
//! `sample == pmf` bit for bit (tested elsewhere) does not show this: a
//! sampler that draws the wrong light and reports that light's pmf agrees
//! with itself. Every check carries two controls on the same draws: the
//! pmf with its largest entry a quarter off is rejected, and so is a sampler that
//! draws one light in place of another while reporting the pmf of the one it
//! returns ([`Swapped`]).

mod common;
use common::{ByPosition, DirectionsAt, LightsAt};

use common::{Rand, Z_P_1E4, chi_square_z, scene, two_rooms, value};
use glam::Vec3;
use guiding::LightChoice;
use guiding::cut::CutConfig;
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::sd_tree::SdTreeConfig;
use guiding::{
    LightId, LightSample, LightSampler, LightTree, ShadingContext, Strategy, UnboundedLights,
};

const DRAWS: usize = 200_000;
/// Emitters of the two rooms.
const EMITTERS: u32 = 80;

/// The shading points every sampler is tested at: inside each room, near
/// the wall, and on a surface (the importance rules read the normal).
fn contexts() -> [ShadingContext; 3] {
    [
        ShadingContext::on_surface(Vec3::new(-5.0, -3.0, 1.0), Vec3::new(-0.6, 0.8, 0.0)),
        ShadingContext::at(Vec3::new(4.0, 2.0, -2.0)),
        ShadingContext::on_surface(Vec3::new(0.3, 0.0, 0.0), Vec3::X),
    ]
}

/// Every light a sampler with `unbounded` lights can choose, emitters first.
fn ids(unbounded: u32) -> Vec<LightId> {
    (0..EMITTERS)
        .map(LightId::Emitter)
        .chain((0..unbounded).map(LightId::Unbounded))
        .collect()
}

fn slot(light: LightId) -> usize {
    match light {
        LightId::Emitter(e) => e as usize,
        LightId::Unbounded(i) => (EMITTERS + i) as usize,
    }
}

/// Counts of `DRAWS` lights drawn at `ctx` by `sample` (or, when `exact`,
/// `sample_exact`), each one's reported pmf checked against `pmf`.
fn draw(
    s: &dyn LightSampler,
    ctx: &ShadingContext,
    slots: usize,
    exact: bool,
    seed: u64,
) -> Vec<u64> {
    let mut rng = Rand::new(seed);
    let mut counts = vec![0u64; slots];
    for _ in 0..DRAWS {
        let light = if exact {
            let (light, pmf) = s.sample_exact(ctx, rng.f64()).expect("a light");
            assert_eq!(pmf, s.pmf_exact(ctx, light));
            light
        } else {
            let x = s.sample(ctx, rng.f()).expect("a light");
            assert_eq!(x.pmf, s.pmf(ctx, x.light));
            x.light
        };
        counts[slot(light)] += 1;
    }
    counts
}

/// `probs` with its largest entry a quarter larger, renormalised.
fn perturbed(probs: &[f64]) -> Vec<f64> {
    let big = (0..probs.len())
        .max_by(|&a, &b| probs[a].total_cmp(&probs[b]))
        .unwrap();
    let mut p = probs.to_vec();
    p[big] *= 1.25;
    let total: f64 = p.iter().sum();
    p.iter_mut().for_each(|x| *x /= total);
    p
}

/// Whether counts are rejected against `probs` (p < 1e-4, or a light of pmf
/// 0 was drawn).
fn rejected(counts: &[u64], probs: &[f64]) -> bool {
    chi_square_z(counts, probs).is_none_or(|(z, _)| z > Z_P_1E4)
}

/// A sampler that returns light `b` whenever `inner` draws `a` (and `a`
/// for `b`), reporting the pmf of the light it returns: consistent with its
/// own `pmf`, drawn from the wrong distribution. The plausible bug the
/// sample == pmf checks cannot see.
struct Swapped<S> {
    inner: S,
    a: LightId,
    b: LightId,
}

impl<S: LightSampler> Swapped<S> {
    fn swap(&self, l: LightId) -> LightId {
        if l == self.a {
            self.b
        } else if l == self.b {
            self.a
        } else {
            l
        }
    }
}

impl<S: LightSampler> LightSampler for Swapped<S> {
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        let x = self.inner.sample(ctx, u)?;
        let light = self.swap(x.light);
        Some(LightSample {
            light,
            pmf: self.inner.pmf(ctx, light),
        })
    }
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        self.inner.pmf(ctx, light)
    }
    fn is_empty(&self) -> bool {
        self.inner.is_empty()
    }
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        let (l, _) = self.inner.sample_exact(ctx, u)?;
        let light = self.swap(l);
        Some((light, self.inner.pmf_exact(ctx, light)))
    }
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        self.inner.pmf_exact(ctx, light)
    }
}

/// The goodness-of-fit check with its controls: at every context, draws by
/// `f32` and by `f64` numbers fit `pmf_exact` (which sums to 1); the same
/// draws are rejected against a pmf a quarter off on its largest entry; the draws
/// of [`Swapped`] (the most likely light exchanged with one at most half as
/// likely) are rejected against its own pmf.
fn check(what: &str, s: &dyn LightSampler, unbounded: u32, seed: u64) {
    let ids = ids(unbounded);
    for (c, ctx) in contexts().iter().enumerate() {
        let probs: Vec<f64> = ids.iter().map(|&l| s.pmf_exact(ctx, l)).collect();
        // The baselines' pmfs are f32 (widened): within their rounding.
        let total: f64 = probs.iter().sum();
        assert!(
            (total - 1.0).abs() < 1e-6,
            "{what} at {c}: pmf sums to {total}"
        );
        for exact in [false, true] {
            let what = format!("{what} at {c} (exact numbers: {exact})");
            let counts = draw(s, ctx, ids.len(), exact, seed + c as u64);
            let (z, dof) = chi_square_z(&counts, &probs)
                .unwrap_or_else(|| panic!("{what}: a light of pmf 0 was drawn"));
            assert!(z < Z_P_1E4, "{what}: z = {z:.2} with {dof} dof");
            assert!(
                rejected(&counts, &perturbed(&probs)),
                "{what}: control 1 passed"
            );
        }
        // Control 2: the same numbers through a swapping sampler.
        let top = (0..ids.len())
            .max_by(|&a, &b| probs[a].total_cmp(&probs[b]))
            .unwrap();
        let other = (0..ids.len())
            .filter(|&i| probs[i] > 0.0 && probs[i] < 0.5 * probs[top])
            .max_by(|&a, &b| probs[a].total_cmp(&probs[b]))
            .expect("a light at most half as likely as the top one");
        let swapped = Swapped {
            inner: s,
            a: ids[top],
            b: ids[other],
        };
        let counts = draw(&swapped, ctx, ids.len(), false, seed + c as u64);
        assert!(rejected(&counts, &probs), "{what} at {c}: control 2 passed");
    }
}

fn tree() -> &'static LightTree {
    static TREE: std::sync::OnceLock<LightTree> = std::sync::OnceLock::new();
    TREE.get_or_init(|| LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap())
}

/// A sun (seen from where z > 0) and a sky (everywhere), together 0.2.
fn sun_and_sky() -> UnboundedLights {
    UnboundedLights::new(2, 0.2).unwrap()
}

/// What NEE at `p` finds for `light`: the two rooms' lights behind their
/// wall, the sun above z = 0, a dim sky.
fn found(p: Vec3, light: LightId) -> f32 {
    match light {
        LightId::Emitter(e) => value(&two_rooms(), e, p),
        LightId::Unbounded(0) => {
            if p.z > 0.0 {
                2.0
            } else {
                0.0
            }
        }
        LightId::Unbounded(_) => 0.05,
    }
}

/// `iterations` of NEE training: at random points, a light drawn from
/// `sample`, its estimate recorded through `record`, then `refine`.
/// Trains `guide` by light samples drawn from it, each recorded through
/// the vertex that drew it, with `also` recording more at the point.
fn train<G: LightsAt>(
    guide: &mut G,
    iterations: usize,
    also: impl Fn(&G, Vec3, f32, &mut Rand),
    refine: impl Fn(&mut G),
) {
    let mut rng = Rand::new(5);
    for _ in 0..iterations {
        for _ in 0..8000 {
            let p = rng.point(9.5);
            let v = guide.light_at(p);
            let Some(x) = v.sample(rng.f()) else {
                continue;
            };
            let value = found(p, x.light) / x.pmf;
            v.record_light(x.light, value);
            also(guide, p, value, &mut rng);
        }
        refine(guide);
    }
}

fn glt_config(paper: bool, unbounded: UnboundedLights) -> GltConfig {
    let cut = CutConfig {
        unbounded,
        ..CutConfig::default()
    };
    GltConfig {
        cut: if paper { cut.with_paper_rules() } else { cut },
        spatial_threshold: 2000.0,
        ..GltConfig::default()
    }
}

fn glt(paper: bool, unbounded: UnboundedLights, iterations: usize) -> Glt<&'static LightTree> {
    let mut g = Glt::new(tree(), scene(), glt_config(paper, unbounded)).unwrap();
    train(
        &mut g,
        iterations,
        |_, _, _, _| {},
        |g| {
            g.refine();
        },
    );
    g
}

fn field(unbounded: UnboundedLights, iterations: usize) -> GuidingField<&'static LightTree> {
    let mut config = FieldConfig {
        sd: SdTreeConfig::improved(),
        ..FieldConfig::default()
    };
    config.sd.spatial_threshold = 2000.0;
    config.cut.unbounded = unbounded;
    let mut f = GuidingField::new(tree(), scene(), config).unwrap();
    train(
        &mut f,
        iterations,
        |f, p, v, rng| {
            f.record_radiance_at(p, rng.dir(), v + 0.1, 0.25);
        },
        |f| {
            f.refine();
        },
    );
    f
}

#[test]
fn glt_draws_from_its_pmf() {
    for paper in [false, true] {
        for (unbounded, k) in [(UnboundedLights::NONE, 0), (sun_and_sky(), 2)] {
            for iterations in [0, 4] {
                let g = glt(paper, unbounded, iterations);
                if iterations > 0 {
                    assert!(g.memory().cells > 1, "the GLT learned cells");
                }
                let what = format!("GLT paper={paper} unbounded={k} trained={iterations}");
                check(&what, &ByPosition(&g), k, 100);
            }
        }
    }
}

#[test]
fn field_draws_from_its_pmf() {
    for (unbounded, k) in [(UnboundedLights::NONE, 0), (sun_and_sky(), 2)] {
        for iterations in [0, 4] {
            let f = field(unbounded, iterations);
            if iterations > 0 {
                assert!(f.cell_count() > 1, "the field learned cells");
            }
            check(
                &format!("field unbounded={k} trained={iterations}"),
                &ByPosition(&f),
                k,
                300,
            );
        }
    }
}

/// The GLT strategy, as a renderer names it, with a sun and a sky.
#[test]
fn strategy_draws_from_its_pmf() {
    let lights = two_rooms();
    for name in Strategy::NAMES {
        let mut s = Strategy::new(name, &lights[..], sun_and_sky(), scene()).unwrap();
        if let Some(g) = s.glt_mut() {
            let mut config = *g.config();
            config.spatial_threshold = 2000.0;
            *g = Glt::new(
                LightTree::build(&lights, Default::default()).unwrap(),
                scene(),
                config,
            )
            .unwrap();
            train(
                g,
                3,
                |_, _, _, _| {},
                |g| {
                    g.refine();
                },
            );
        }
        check(&format!("strategy {name}"), &s, 2, 500);
    }
}
