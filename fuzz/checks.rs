//! What each fuzz target checks, shared with the corpus regression test
//! (`tests/fuzz_corpus.rs`): loading arbitrary bytes, building a light
//! tree from arbitrary emitters, arbitrary record / refine / sample
//! sequences. Each either gets a typed error or keeps every contract;
//! none may panic.

#![allow(dead_code)]

pub mod load {

    use guiding::field::GuidingField;
    use guiding::glam::Vec3;
    use guiding::glt::Glt;
    use guiding::sd_tree::SdTree;
    use guiding::{Emitter, LightChoice, LightId, LightSampler, LightTree, ShadingContext};

    /// The light tree the learned structures are loaded against (a corpus
    /// built from it gets past the fingerprint check).
    pub fn tree() -> &'static LightTree {
        static TREE: std::sync::OnceLock<LightTree> = std::sync::OnceLock::new();
        TREE.get_or_init(|| {
            let lights: Vec<Emitter> = (0..8)
                .map(|i| {
                    Emitter::point(
                        Vec3::new(i as f32 - 4.0, 1.0, 0.5 * i as f32),
                        1.0 + i as f32,
                    )
                })
                .collect();
            LightTree::build(&lights, Default::default()).unwrap()
        })
    }

    /// Where the loaded samplers are checked.
    const AT: Vec3 = Vec3::new(0.3, -0.2, 0.1);

    fn check(s: &impl LightChoice, n: u32) {
        let total: f64 = (0..n)
            .map(|e| s.pmf_exact(LightId::Emitter(e)))
            .sum::<f64>()
            + (0..4)
                .map(|i| s.pmf_exact(LightId::Unbounded(i)))
                .sum::<f64>();
        assert_sums_to_one(s, total);
        if let Some(x) = s.sample(0.37) {
            assert_eq!(x.pmf, s.pmf(x.light));
        }
    }

    /// A sampler's pmfs sum to 1 at a finite point, or to exactly 0 when it
    /// can sample nothing (a loaded light tree whose powers are all 0).
    fn assert_sums_to_one(s: &impl LightChoice, total: f64) {
        if s.is_empty() {
            assert_eq!(total, 0.0);
        } else {
            assert!((total - 1.0).abs() < 1e-5, "{total}");
        }
    }

    /// Valid saved structures over [`tree`] (the seeds of the `load`
    /// corpus): a light tree, and a trained GLT, SD-tree and field.
    pub fn seeds() -> Vec<Vec<u8>> {
        use guiding::field::FieldConfig;
        use guiding::glt::GltConfig;
        use guiding::math::Aabb;
        use guiding::sd_tree::SdTreeConfig;
        let scene = Aabb::new(Vec3::splat(-6.0), Vec3::splat(6.0));
        let glt_config = GltConfig {
            spatial_threshold: 20.0,
            ..GltConfig::default()
        };
        let mut glt = Glt::new(tree(), scene, glt_config).unwrap();
        // A GLT that learns visibility, with a sun and a sky: the
        // visibility slots and unbounded fractions in the payload.
        let mut seen_config = glt_config;
        seen_config.cut.visibility = true;
        seen_config.cut.unbounded = guiding::UnboundedLights::new(2, 0.2).unwrap();
        let mut seen = Glt::new(tree(), scene, seen_config).unwrap();
        let mut sd_config = SdTreeConfig::improved();
        sd_config.spatial_threshold = 20.0;
        let mut sd = SdTree::new(scene, sd_config).unwrap();
        let mut field = GuidingField::new(
            tree(),
            scene,
            FieldConfig {
                sd: sd_config,
                ..FieldConfig::default()
            },
        )
        .unwrap();
        for round in 0..2 {
            for i in 0..200u32 {
                let t = i as f32 * 0.37 + round as f32;
                let p = Vec3::new(5.0 * t.sin(), 4.0 * (1.3 * t).cos(), 3.0 * (0.7 * t).sin());
                let d = Vec3::new(t.cos(), 0.5, t.sin()).normalize();
                let light = LightId::Emitter(i % 8);
                let at = ShadingContext::at(p);
                let located = glt.vertex(&at).unwrap();
                located.record_light(light, 1.0 + (i % 5) as f32);
                let light_or_sky = if i % 7 == 0 {
                    LightId::Unbounded(i % 2)
                } else {
                    light
                };
                let seen_there = seen.vertex(&at).unwrap();
                seen_there.record_light(light_or_sky, 1.0 + (i % 5) as f32);
                let shadowed = if i % 3 == 0 { 0.0 } else { 1.0 };
                seen_there.record_visibility(light_or_sky, shadowed, 1.0);
                sd.vertex(&at)
                    .unwrap()
                    .record_radiance(d, 1.0 + t.fract(), 0.5);
                let v = field.vertex(&at).unwrap();
                v.light.record_light(light, 2.0);
                v.direction.record_radiance(d, 1.0, 0.5);
            }
            glt.refine();
            seen.refine();
            sd.refine();
            field.refine();
        }
        vec![
            tree().to_bytes(),
            glt.to_bytes(),
            sd.to_bytes(),
            field.to_bytes(),
            seen.to_bytes(),
        ]
    }

    /// `data` with the header's checksum recomputed (FNV-1a 64 over the 30
    /// header bytes before it and the payload), so that the structural checks,
    /// not the checksum, must catch what the fuzzer changed.
    fn resealed(data: &[u8]) -> Option<Vec<u8>> {
        const HEADER: usize = 38;
        if data.len() < HEADER {
            return None;
        }
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        for &b in data[..HEADER - 8].iter().chain(&data[HEADER..]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
        let mut out = data.to_vec();
        out[HEADER - 8..HEADER].copy_from_slice(&h.to_le_bytes());
        Some(out)
    }

    pub fn load(data: &[u8]) {
        load_checked(data);
        if let Some(hostile) = resealed(data) {
            load_checked(&hostile);
        }
    }

    fn load_checked(data: &[u8]) {
        if let Ok(t) = LightTree::from_bytes(data) {
            let sampler = guiding::ImportanceTreeSampler::new(&t);
            check(&sampler.at(&ShadingContext::at(AT)), t.nodes().len() as u32);
        }
        if let Ok(g) = Glt::from_bytes(data, tree()) {
            check(&g.vertex(&ShadingContext::at(AT)).unwrap(), 8);
        }
        if let Ok(f) = GuidingField::from_bytes(data, tree()) {
            check(&f.vertex(&ShadingContext::at(AT)).unwrap().light, 8);
            let v = f.vertex(&ShadingContext::at(Vec3::ZERO)).unwrap();
            let (_, pdf) = v.direction.sample_direction([0.3, 0.6]);
            assert!(pdf > 0.0 && pdf.is_finite());
        }
        if let Ok(t) = SdTree::from_bytes(data) {
            let v = t.vertex(&ShadingContext::at(Vec3::ZERO)).unwrap();
            let (d, pdf) = v.sample_direction([0.3, 0.6]);
            assert!(pdf > 0.0 && pdf.is_finite() && d.is_finite());
        }
    }
}

pub mod build {

    use guiding::glam::Vec3;
    use guiding::light_sampler::ImportanceTreeSampler;
    use guiding::light_tree::BuildHeuristic;
    use guiding::math::{Aabb, LightCone};
    use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};

    fn f(b: &[u8]) -> f32 {
        f32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }

    /// Builds a light tree of the emitters `data` describes with two
    /// heuristics and checks each tree that builds; returns how many did.
    pub fn build_light_tree(data: &[u8]) -> usize {
        // 40 bytes per emitter: bounds (6 f32), power, area, cone axis x, a
        // flag byte, the cone's two cosines and a weight... read loosely.
        let emitters: Vec<Emitter> = data
            .chunks_exact(40)
            .take(64)
            .map(|c| {
                let v = |i: usize| f(&c[4 * i..4 * i + 4]);
                Emitter {
                    bounds: Aabb {
                        min: Vec3::new(v(0), v(1), v(2)),
                        max: Vec3::new(v(3), v(4), v(5)),
                    },
                    power: v(6),
                    area: v(7),
                    cone: (c[36] & 1 == 1).then(|| LightCone {
                        axis: Vec3::new(v(8), 1.0, 0.0),
                        cos_theta_o: f32::from(c[37]) / 255.0,
                        cos_theta_e: f32::from(c[38]) / 255.0,
                    }),
                    two_sided: c[36] & 2 == 2,
                    delta: c[36] & 4 == 4,
                    // Flag bit 3: a weight from the last byte (0 to ~4).
                    weight: match c[36] & 8 {
                        8 => f32::from(c[39]) / 64.0,
                        _ => 1.0,
                    },
                    // Flag bit 4: in the light sets of the flag byte.
                    light_sets: match c[36] & 16 {
                        16 => u64::from(c[36]),
                        _ => u64::MAX,
                    },
                }
            })
            .collect();
        let mut built = 0;
        for h in [BuildHeuristic::Sarh, BuildHeuristic::Balanced] {
            if let Ok(tree) = LightTree::build(&emitters, h) {
                built += 1;
                let back = LightTree::from_bytes(&tree.to_bytes()).expect("a built tree reloads");
                assert_eq!(back.nodes(), tree.nodes());
                let s = ImportanceTreeSampler::new(&tree);
                let ctx = ShadingContext::at(Vec3::new(0.5, 0.25, -1.0));
                let total: f64 = (0..emitters.len() as u32)
                    .map(|e| s.pmf_exact(&ctx, LightId::Emitter(e)))
                    .sum();
                if emitters.iter().any(|e| e.power * e.weight > 0.0) {
                    assert!((total - 1.0).abs() < 1e-4, "{total}");
                } else {
                    assert!(s.is_empty() && total == 0.0, "{total}");
                }
                if let Some(x) = s.sample(&ctx, 0.61) {
                    assert_eq!(x.pmf, s.pmf(&ctx, x.light));
                }
            }
        }
        built
    }
}

pub mod operations {

    use guiding::field::{FieldConfig, GuidingField};
    use guiding::glam::Vec3;
    use guiding::glt::{Glt, GltConfig};
    use guiding::math::Aabb;
    use guiding::{Emitter, LightChoice, LightId, LightTree, ShadingContext};

    fn tree() -> &'static LightTree {
        static TREE: std::sync::OnceLock<LightTree> = std::sync::OnceLock::new();
        TREE.get_or_init(|| {
            let lights: Vec<Emitter> = (0..12)
                .map(|i| {
                    Emitter::point(
                        Vec3::new(i as f32 - 6.0, (i % 3) as f32, 0.0),
                        1.0 + (i % 4) as f32,
                    )
                })
                .collect();
            LightTree::build(&lights, Default::default()).unwrap()
        })
    }

    fn f(b: &[u8]) -> f32 {
        f32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }

    fn check(s: &impl LightChoice, u: f32) {
        let total: f64 = (0..12).map(|e| s.pmf_exact(LightId::Emitter(e))).sum();
        // Every light of the operations' tree has power: the pmf sums to 1
        // wherever the (finite, located) point is.
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        if let Some(x) = s.sample(u) {
            assert!(x.pmf > 0.0 && x.pmf.is_finite());
            assert_eq!(x.pmf, s.pmf(x.light));
        }
    }

    pub fn operations(data: &[u8]) {
        let scene = Aabb::new(Vec3::splat(-8.0), Vec3::splat(8.0));
        let small = GltConfig {
            spatial_threshold: 8.0,
            ..GltConfig::default()
        };
        let mut glt = Glt::new(tree(), scene, small).unwrap();
        let mut config = FieldConfig::default();
        config.sd.spatial_threshold = 8.0;
        let mut field = GuidingField::new(tree(), scene, config).unwrap();
        // 20 bytes per operation: kind, light, position (3 f32), value.
        for op in data.chunks_exact(22).take(400) {
            let p = Vec3::new(f(&op[2..6]), f(&op[6..10]), f(&op[10..14]));
            let v = f(&op[14..18]);
            let u = f(&op[18..22]);
            let light = LightId::Emitter(u32::from(op[1] % 14));
            match op[0] % 5 {
                0 => {
                    if let Some(vx) = glt.vertex(&ShadingContext::at(p)) {
                        vx.record_light(light, v);
                    }
                }
                1 => {
                    if let Some(vx) = glt.vertex(&ShadingContext::at(p)) {
                        vx.record_light(light, v);
                    }
                    if let Some(vx) = field.vertex(&ShadingContext::at(p)) {
                        vx.light.record_light(light, v);
                        vx.direction.record_radiance(Vec3::new(u, v, 1.0), v, u);
                    }
                }
                2 => {
                    glt.refine();
                    field.refine();
                }
                _ => {
                    let ctx = ShadingContext::at(p);
                    match (glt.vertex(&ctx), field.vertex(&ctx)) {
                        (Some(g), Some(f)) => {
                            check(&g, u);
                            check(&f.light, u);
                        }
                        // Only points that are not finite have no vertex.
                        (g, f) => assert!(g.is_none() && f.is_none() && !ctx.is_finite()),
                    }
                }
            }
        }
        let origin = ShadingContext::at(Vec3::ZERO);
        check(&glt.vertex(&origin).unwrap(), 0.5);
        check(&field.vertex(&origin).unwrap().light, 0.5);
    }
}
