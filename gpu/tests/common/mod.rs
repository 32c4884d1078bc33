//! The trained city both the GPU test and the throughput example use: the
//! render example's `city` (108,693 lights), a GLT trained as
//! `pt-glt` trains it, and queries at the first non-specular vertices of
//! camera paths with their numbers.
#![allow(dead_code)]

use guiding::glam::Vec3;
use guiding::snapshot::Snapshot;
use guiding::{Glt, LightChoice, LightTree, ShadingContext};
use guiding_gpu::{Answer, Query};
use guiding_render::methods::{GuideParams, Method};
use guiding_render::scene::Scene;
use guiding_render::{run, scenes, shading_points};

/// The city scene.
pub fn city() -> Scene {
    scenes::build("city", scenes::Size::Full).expect("the city scene")
}

/// A GLT trained on `scene` by the render example's `pt-glt` schedule at
/// `width` x `height` for `spp` samples per pixel.
pub fn trained(scene: &Scene, (width, height): (u32, u32), spp: u64) -> Glt<&LightTree> {
    trained_with(scene, (width, height), spp, GuideParams::default())
}

/// [`trained`] with the guide's parameters `params`.
pub fn trained_with(
    scene: &Scene,
    (width, height): (u32, u32),
    spp: u64,
    params: GuideParams,
) -> Glt<&LightTree> {
    let settings = run::Settings {
        width,
        height,
        budget: run::Budget::Spp(spp),
        params,
        seed: 1,
        progress: false,
        guide_files: Default::default(),
    };
    let (_, trained) = run::render_trained(scene, Method::PtGlt, &settings);
    trained.glt.expect("pt-glt trains a GLT")
}

/// `points` shading points of `scene` (camera paths' first non-specular
/// vertices, normals as the integrator's context normalises them), each
/// with `per_point` numbers: `points * per_point` queries.
pub fn queries(scene: &Scene, points: usize, per_point: usize) -> Vec<Query> {
    let at = shading_points::pick(scene, points, 1, (256, 192), 5);
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    at.iter()
        .flat_map(|v| {
            let ctx = ShadingContext::on_surface(v.p, v.n);
            let n = ctx.normal.map(|n| n.to_array());
            (0..per_point)
                .map(|_| Query::new(v.p.to_array(), n, next()))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// How two answer lists agree.
#[derive(Debug)]
pub struct Agreement {
    /// The fraction of queries with the same choice (or both none).
    pub same: f64,
    /// The largest relative pmf difference among the same choices.
    pub pmf: f64,
    /// Same choices whose visibilities differ.
    pub visibility: usize,
}

pub fn compare(a: &[Answer], b: &[Answer]) -> Agreement {
    let (mut same, mut pmf, mut visibility) = (0usize, 0f64, 0usize);
    for (x, y) in a.iter().zip(b) {
        if x.light == y.light {
            same += 1;
            if x.light != u32::MAX {
                pmf = pmf.max((f64::from(x.pmf) / f64::from(y.pmf) - 1.0).abs());
                visibility += usize::from(x.visibility != y.visibility);
            }
        }
    }
    Agreement {
        same: same as f64 / a.len() as f64,
        pmf,
        visibility,
    }
}

/// The snapshot's own answers on the CPU, in the kernel's encoding.
pub fn cpu_answers(snapshot: &Snapshot, queries: &[Query]) -> Vec<Answer> {
    let view = snapshot.view();
    queries
        .iter()
        .map(|q| {
            let n = Vec3::from_array(q.n);
            let ctx = ShadingContext {
                normal: (n != Vec3::ZERO).then_some(n),
                ..ShadingContext::at(Vec3::from_array(q.p))
            };
            match view
                .vertex(&ctx)
                .and_then(|v| v.sample_with_visibility(q.u))
            {
                Some((s, visibility)) => Answer {
                    light: Query::light_word(s.light),
                    pmf: s.pmf,
                    visibility,
                    pad: 0,
                },
                None => Answer {
                    light: u32::MAX,
                    ..Default::default()
                },
            }
        })
        .collect()
}

/// The query as the GLT's context.
pub fn context(q: &Query) -> ShadingContext {
    ShadingContext {
        normal: Some(Vec3::from_array(q.n)),
        ..ShadingContext::at(Vec3::from_array(q.p))
    }
}

/// The GLT's own answers (its `f64` descent), in the kernel's encoding.
pub fn glt_answers(glt: &Glt<&LightTree>, queries: &[Query]) -> Vec<Answer> {
    queries
        .iter()
        .map(|q| {
            let ctx = context(q);
            let v = glt.vertex(&ctx).expect("a cell");
            match v.sample_with_visibility(q.u) {
                Some((s, visibility)) => Answer {
                    light: Query::light_word(s.light),
                    pmf: s.pmf,
                    visibility,
                    pad: 0,
                },
                None => Answer {
                    light: u32::MAX,
                    ..Default::default()
                },
            }
        })
        .collect()
}
