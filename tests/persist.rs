//! Saved and loaded structures behave bit for bit like the originals;
//! learned state only loads against its own light tree; corrupted,
//! truncated and hostile buffers give typed errors (or, if they still
//! parse, structures that keep every contract), never a panic.

mod common;
use common::{ByPosition, LightsAt};

use common::{Rand, scene, two_rooms, value};
use glam::Vec3;
use guiding::LightChoice;
use guiding::cut::CutConfig;
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Accumulation;
use guiding::{
    Emitter, LightId, LightSampler, LightTree, LoadError, ShadingContext, UnboundedLights,
};

/// FNV-1a 64, the format's checksum (over the header before it and the
/// payload): a test that rewrites a payload fixes the header with it (a
/// hostile buffer, not a damaged one).
fn fnv(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

const HEADER: usize = 38;

/// `bytes` with its checksum recomputed.
fn resealed(mut bytes: Vec<u8>) -> Vec<u8> {
    let covered: Vec<u8> = bytes[..HEADER - 8]
        .iter()
        .chain(&bytes[HEADER..])
        .copied()
        .collect();
    let sum = fnv(&covered);
    bytes[HEADER - 8..HEADER].copy_from_slice(&sum.to_le_bytes());
    bytes
}

fn config(accumulation: Accumulation, unbounded: UnboundedLights) -> GltConfig {
    GltConfig {
        cut: CutConfig {
            accumulation,
            unbounded,
            ..CutConfig::default()
        },
        spatial_threshold: 300.0,
        ..GltConfig::default()
    }
}

/// Trains `glt` on `n` records per iteration from `seed`.
fn train<H: guiding::LightHierarchy>(
    glt: &mut Glt<H>,
    lights: &[Emitter],
    seed: u64,
    rounds: usize,
    n: usize,
) {
    let mut rng = Rand::new(seed);
    for round in 0..rounds {
        record(glt, lights, &mut rng, n);
        if round + 1 < rounds {
            glt.refine();
        }
    }
}

/// `n` light records into `glt` (leaves them accumulating).
fn record<H: guiding::LightHierarchy>(glt: &Glt<H>, lights: &[Emitter], rng: &mut Rand, n: usize) {
    for i in 0..n {
        let p = rng.point(9.5);
        let x = ByPosition(glt)
            .sample(&ShadingContext::at(p), rng.f())
            .unwrap();
        let v = match x.light {
            LightId::Emitter(e) => value(lights, e, p) / x.pmf,
            LightId::Unbounded(_) => (i % 3) as f32,
        };
        glt.record_light_at(p, x.light, v);
    }
}

/// The two answer the same, bit for bit, at random points.
fn assert_same_answers<H: guiding::LightHierarchy>(a: &Glt<H>, b: &Glt<H>, seed: u64) {
    let mut rng = Rand::new(seed);
    let lights = (0..80)
        .map(LightId::Emitter)
        .chain((0..3).map(LightId::Unbounded));
    let lights: Vec<LightId> = lights.collect();
    for _ in 0..300 {
        let ctx = ShadingContext::on_surface(rng.point(11.0), rng.dir());
        let u = rng.f64();
        assert_eq!(
            ByPosition(a).sample_exact(&ctx, u),
            ByPosition(b).sample_exact(&ctx, u)
        );
        let l = lights[rng.below(lights.len() as u32) as usize];
        assert_eq!(
            ByPosition(a).pmf_exact(&ctx, l).to_bits(),
            ByPosition(b).pmf_exact(&ctx, l).to_bits()
        );
    }
}

#[test]
fn light_tree_round_trips() {
    for lights in [
        Vec::new(),
        vec![Emitter::point(Vec3::ONE, 2.0)],
        two_rooms(),
    ] {
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        let bytes = tree.to_bytes();
        let back = LightTree::from_bytes(&bytes).unwrap();
        assert_eq!(back.nodes(), tree.nodes());
        assert_eq!(back.depth(), tree.depth());
        assert_eq!(back.to_bytes(), bytes);
        assert_eq!(
            guiding::light_tree::fingerprint(&back),
            guiding::light_tree::fingerprint(&tree)
        );
    }
}

#[test]
fn glt_round_trips_and_learns_on_identically() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    for accumulation in [Accumulation::Fast, Accumulation::Deterministic] {
        for unbounded in [UnboundedLights::NONE, UnboundedLights::new(2, 0.2).unwrap()] {
            let mut glt = Glt::new(&tree, scene(), config(accumulation, unbounded)).unwrap();
            train(&mut glt, &lights, 1, 3, 6000);
            assert!(glt.spatial().data_slice().len() > 2);
            let bytes = glt.to_bytes();
            let mut back = Glt::from_bytes(&bytes, &tree).unwrap();
            assert_same_answers(&glt, &back, 2);
            assert_eq!(back.to_bytes(), bytes);
            assert_eq!(back.dropped_records(), glt.dropped_records());
            // Both go on learning from the same records: still the same.
            let mut rng = (Rand::new(3), Rand::new(3));
            record(&glt, &lights, &mut rng.0, 4000);
            record(&back, &lights, &mut rng.1, 4000);
            glt.refine();
            back.refine();
            if accumulation == Accumulation::Deterministic {
                assert_eq!(back.to_bytes(), glt.to_bytes());
            }
            assert_same_answers(&glt, &back, 4);
        }
    }
}

#[test]
fn learned_state_loads_only_against_its_light_tree() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(&tree, scene(), GltConfig::default()).unwrap();
    train(&mut glt, &lights, 5, 2, 3000);
    let bytes = glt.to_bytes();
    // Another build of the same lights, another order, one light fewer.
    let other_build = LightTree::build(&lights, BuildHeuristic::Balanced).unwrap();
    let mut reordered = lights.clone();
    reordered.swap(0, 50);
    let reordered = LightTree::build(&reordered, BuildHeuristic::Sarh).unwrap();
    let fewer = LightTree::build(&lights[1..], BuildHeuristic::Sarh).unwrap();
    for other in [&other_build, &reordered, &fewer] {
        assert!(matches!(
            Glt::from_bytes(&bytes, other),
            Err(LoadError::LightTreeMismatch { .. })
        ));
    }
    // The tree refitted to lights that moved and changed power has the
    // same shape: the state loads over it, and is the state carried over
    // in memory.
    let mut moved = lights.clone();
    for (i, l) in moved.iter_mut().enumerate() {
        let d = Vec3::new(0.1, -0.05 * (i % 3) as f32, 0.02);
        l.bounds = guiding::Aabb::new(l.bounds.min + d, l.bounds.max + d);
        l.power *= 1.0 + 0.01 * (i % 7) as f32;
    }
    let mut refitted = tree.clone();
    refitted.refit(moved.as_slice()).unwrap();
    let loaded = Glt::from_bytes(&bytes, &refitted).unwrap();
    let mut carried = Glt::from_bytes(&bytes, &tree).unwrap();
    carried.set_light_tree(&refitted).unwrap();
    assert_same_answers(&loaded, &carried, 7);
    assert_eq!(loaded.to_bytes(), bytes);
    // The tree itself can travel with the state.
    let tree_bytes = tree.to_bytes();
    let loaded = LightTree::from_bytes(&tree_bytes).unwrap();
    let back = Glt::from_bytes(&bytes, loaded).unwrap();
    assert_same_answers(&glt, &Glt::from_bytes(&bytes, &tree).unwrap(), 6);
    assert_eq!(back.to_bytes(), bytes);
}

#[test]
fn header_errors_are_typed() {
    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    let glt = Glt::new(&tree, scene(), GltConfig::default()).unwrap();
    let bytes = glt.to_bytes();
    assert_eq!(
        Glt::from_bytes(&[], &tree).unwrap_err(),
        LoadError::Truncated {
            field: "magic",
            offset: 0
        }
    );
    let mut bad = bytes.clone();
    bad[0] = b'X';
    assert_eq!(
        Glt::from_bytes(&bad, &tree).unwrap_err(),
        LoadError::NotGuidingData
    );
    let mut newer = bytes.clone();
    newer[8..12].copy_from_slice(&99u32.to_le_bytes());
    assert!(matches!(
        Glt::from_bytes(&newer, &tree),
        Err(LoadError::UnsupportedVersion { found: 99, .. })
    ));
    assert!(matches!(
        LightTree::from_bytes(&bytes),
        Err(LoadError::WrongKind { .. })
    ));
    let mut flipped = bytes.clone();
    *flipped.last_mut().unwrap() ^= 1;
    assert_eq!(
        Glt::from_bytes(&flipped, &tree).unwrap_err(),
        LoadError::Checksum
    );
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(matches!(
        Glt::from_bytes(&longer, &tree),
        Err(LoadError::TrailingBytes { .. })
    ));
}

/// The header holds the crate's version, and each error says exactly
/// where: a header length short of the payload ends it at the right byte,
/// a payload with bytes after the structure (length and checksum made to
/// match: a hostile buffer) is refused where the structure ended, a count
/// one item more than the bytes left could hold is refused at the count.
/// Every error's message names its field and offset.
#[test]
fn errors_say_exactly_where() {
    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    let bytes = tree.to_bytes();
    let version: Vec<u16> = env!("CARGO_PKG_VERSION")
        .split(['.', '-'])
        .take(3)
        .map(|p| p.parse().unwrap())
        .collect();
    let header: Vec<u16> = bytes[12..18]
        .chunks(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect();
    assert_eq!(header, version);
    let payload = bytes.len() - HEADER;
    let set_len = |b: &mut Vec<u8>, len: usize| {
        b[HEADER - 16..HEADER - 8].copy_from_slice(&(len as u64).to_le_bytes());
    };
    let mut short = bytes.clone();
    set_len(&mut short, payload - 4);
    assert_eq!(
        LightTree::from_bytes(&short).unwrap_err(),
        LoadError::TrailingBytes {
            offset: bytes.len() - 4
        }
    );
    let mut extra = bytes.clone();
    extra.extend_from_slice(&[0; 4]);
    set_len(&mut extra, payload + 4);
    assert_eq!(
        LightTree::from_bytes(&resealed(extra)).unwrap_err(),
        LoadError::TrailingBytes {
            offset: bytes.len()
        }
    );
    // The node count follows the 24-byte scene box; nodes are 32 bytes.
    let at = HEADER + 24;
    let left = bytes.len() - (at + 8);
    let mut hostile = bytes.clone();
    hostile[at..at + 8].copy_from_slice(&((left / 32 + 1) as u64).to_le_bytes());
    assert_eq!(
        LightTree::from_bytes(&resealed(hostile)).unwrap_err(),
        LoadError::Truncated {
            field: "light tree: node count",
            offset: at
        }
    );
    let errors = [
        LoadError::Truncated {
            field: "some field",
            offset: 1234,
        },
        LoadError::Invalid {
            field: "some field",
            offset: 1234,
        },
        LoadError::TrailingBytes { offset: 1234 },
        LoadError::UnsupportedVersion {
            found: 1234,
            supported: 2,
        },
        LoadError::WrongKind {
            expected: 1,
            found: 1234,
        },
        LoadError::LightTreeMismatch {
            saved: 0x1234,
            given: 0,
        },
    ];
    for e in errors {
        let text = e.to_string();
        assert!(text.contains("1234"), "{text}");
        if matches!(e, LoadError::Truncated { .. } | LoadError::Invalid { .. }) {
            assert!(text.contains("some field"), "{text}");
        }
    }
    for e in [LoadError::NotGuidingData, LoadError::Checksum] {
        assert!(!e.to_string().is_empty());
    }
}

/// Whatever loads keeps the sampler contract: pmf sums to 1 and sampling
/// returns exactly the pmf.
fn assert_contract<H: guiding::LightHierarchy>(glt: &Glt<H>, n: u32, rng: &mut Rand) {
    for _ in 0..4 {
        let ctx = ShadingContext::at(rng.point(10.0));
        let total: f64 = (0..n)
            .map(|e| ByPosition(glt).pmf_exact(&ctx, LightId::Emitter(e)))
            .sum::<f64>()
            + (0..3)
                .map(|i| ByPosition(glt).pmf_exact(&ctx, LightId::Unbounded(i)))
                .sum::<f64>();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        if let Some(x) = ByPosition(glt).sample(&ctx, rng.f()) {
            assert_eq!(x.pmf, ByPosition(glt).pmf(&ctx, x.light));
        }
    }
}

/// Every truncation, and every single-byte change of a small saved GLT,
/// both as damage (the checksum catches it) and as a hostile rewrite (the
/// checksum recomputed, so the structural checks must): a typed error or
/// a GLT that keeps every contract; never a panic.
#[test]
fn corrupted_and_hostile_buffers_never_panic() {
    let lights: Vec<Emitter> = two_rooms().into_iter().take(6).collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(
        &tree,
        scene(),
        GltConfig {
            spatial_threshold: 40.0,
            ..config(Accumulation::Fast, UnboundedLights::new(1, 0.1).unwrap())
        },
    )
    .unwrap();
    train(&mut glt, &lights, 7, 2, 300);
    let bytes = glt.to_bytes();
    assert!(bytes.len() < 20_000, "{}", bytes.len());
    for len in 0..bytes.len() {
        assert!(
            Glt::from_bytes(&bytes[..len], &tree).is_err(),
            "truncated at {len}"
        );
    }
    let mut rng = Rand::new(8);
    let (mut loaded, mut refused) = (0, 0);
    for i in 0..bytes.len() {
        for flip in [0x01u8, 0x80, 0xff] {
            let mut damaged = bytes.clone();
            damaged[i] ^= flip;
            assert!(Glt::from_bytes(&damaged, &tree).is_err());
            if i >= HEADER {
                match Glt::from_bytes(&resealed(damaged), &tree) {
                    Ok(g) => {
                        loaded += 1;
                        assert_contract(&g, lights.len() as u32, &mut rng);
                        // And it can go on recording. (Not refining: a
                        // rewritten record count of 2^60 makes the next
                        // refine split the cell as 2^60 records would;
                        // see the persist module docs.)
                        record(&g, &lights, &mut rng, 50);
                        assert_contract(&g, lights.len() as u32, &mut rng);
                    }
                    Err(_) => refused += 1,
                }
            }
        }
    }
    // Most hostile rewrites are caught by a check; some (a count, a
    // learned probability) still describe a valid GLT.
    assert!(
        refused > 0 && loaded > 0,
        "{refused} refused, {loaded} loaded"
    );
}

/// A length field claiming more than the buffer holds is refused before
/// anything is allocated for it.
#[test]
fn hostile_lengths_allocate_nothing() {
    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    let bytes = tree.to_bytes();
    // The node count follows the 24-byte scene box.
    let mut hostile = bytes.clone();
    hostile[HEADER + 24..HEADER + 32].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(
        LightTree::from_bytes(&resealed(hostile)),
        Err(LoadError::Truncated {
            field: "light tree: node count",
            ..
        })
    ));
}

mod sd_and_field {
    use super::*;
    use guiding::field::{FieldConfig, GuidingField};
    use guiding::sd_tree::{SdTree, SdTreeConfig};

    fn sd_config(accumulation: Accumulation) -> SdTreeConfig {
        let mut c = SdTreeConfig::improved();
        c.spatial_threshold = 300.0;
        c.accumulation = accumulation;
        c
    }

    /// Radiance records: bright around +y.
    fn radiance(rng: &mut Rand) -> (Vec3, f32) {
        let d = rng.dir();
        (d, 1.0 + 50.0 * d.y.max(0.0).powi(8))
    }

    fn train_sd(sd: &SdTree, rng: &mut Rand, n: usize) {
        for _ in 0..n {
            let p = rng.point(9.5);
            let v = sd.vertex(&ShadingContext::at(p)).unwrap();
            let (d, r) = radiance(rng);
            v.record_radiance(d, r, 0.3);
            v.record_fraction(0.2, 0.4, r);
        }
    }

    fn assert_same_sd(a: &SdTree, b: &SdTree, seed: u64) {
        let mut rng = Rand::new(seed);
        for _ in 0..300 {
            let p = rng.point(11.0);
            let (va, vb) = (
                a.vertex(&ShadingContext::at(p)).unwrap(),
                b.vertex(&ShadingContext::at(p)).unwrap(),
            );
            let u = [rng.f(), rng.f()];
            let (da, pa) = va.sample_direction(u);
            let (db, pb) = vb.sample_direction(u);
            assert_eq!((da, pa.to_bits()), (db, pb.to_bits()));
            let d = rng.dir();
            assert_eq!(va.direction_pdf(d).to_bits(), vb.direction_pdf(d).to_bits());
            assert_eq!(va.bsdf_fraction().to_bits(), vb.bsdf_fraction().to_bits());
        }
    }

    #[test]
    fn sd_tree_round_trips_and_learns_on_identically() {
        for accumulation in [Accumulation::Fast, Accumulation::Deterministic] {
            let mut sd = SdTree::new(scene(), sd_config(accumulation)).unwrap();
            let mut rng = Rand::new(1);
            for _ in 0..3 {
                train_sd(&sd, &mut rng, 5000);
                sd.refine();
            }
            train_sd(&sd, &mut rng, 1000);
            let bytes = sd.to_bytes();
            let mut back = SdTree::from_bytes(&bytes).unwrap();
            assert_eq!(back.to_bytes(), bytes);
            assert_same_sd(&sd, &back, 2);
            let (mut ra, mut rb) = (Rand::new(3), Rand::new(3));
            train_sd(&sd, &mut ra, 3000);
            train_sd(&back, &mut rb, 3000);
            sd.refine();
            back.refine();
            if accumulation == Accumulation::Deterministic {
                assert_eq!(back.to_bytes(), sd.to_bytes());
            }
            assert_same_sd(&sd, &back, 4);
        }
    }

    #[test]
    fn field_round_trips_and_checks_its_light_tree() {
        let lights = two_rooms();
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        for accumulation in [Accumulation::Fast, Accumulation::Deterministic] {
            let config = FieldConfig {
                sd: sd_config(accumulation),
                cut: CutConfig {
                    accumulation,
                    unbounded: UnboundedLights::new(1, 0.1).unwrap(),
                    ..CutConfig::default()
                },
                ..FieldConfig::default()
            };
            let mut field = GuidingField::new(&tree, scene(), config).unwrap();
            let mut rng = Rand::new(5);
            for _ in 0..3 {
                for _ in 0..4000 {
                    let p = rng.point(9.5);
                    let v = field.vertex(&ShadingContext::at(p)).unwrap();
                    let x = v.light.sample(rng.f()).unwrap();
                    let val = match x.light {
                        LightId::Emitter(e) => value(&lights, e, p) / x.pmf,
                        LightId::Unbounded(_) => 0.5,
                    };
                    v.light.record_light(x.light, val);
                    let (d, r) = radiance(&mut rng);
                    v.direction.record_radiance(d, r, 0.3);
                }
                field.refine();
            }
            let bytes = field.to_bytes();
            let back = GuidingField::from_bytes(&bytes, &tree).unwrap();
            assert_eq!(back.to_bytes(), bytes);
            let mut rng = Rand::new(6);
            for _ in 0..300 {
                let p = rng.point(11.0);
                let ctx = ShadingContext::on_surface(p, rng.dir());
                let u = rng.f64();
                assert_eq!(
                    ByPosition(&field).sample_exact(&ctx, u),
                    ByPosition(&back).sample_exact(&ctx, u)
                );
                let (a, b) = (
                    field.vertex(&ShadingContext::at(p)).unwrap(),
                    back.vertex(&ShadingContext::at(p)).unwrap(),
                );
                let d = rng.dir();
                assert_eq!(
                    a.direction.direction_pdf(d).to_bits(),
                    b.direction.direction_pdf(d).to_bits()
                );
            }
            let mut other = lights.clone();
            other.pop();
            let other = LightTree::build(&other, BuildHeuristic::Sarh).unwrap();
            assert!(matches!(
                GuidingField::from_bytes(&bytes, &other),
                Err(LoadError::LightTreeMismatch { .. })
            ));
            assert!(matches!(
                SdTree::from_bytes(&bytes),
                Err(LoadError::WrongKind { .. })
            ));
        }
    }

    /// Every truncation and every single-byte change of a small saved
    /// field: refused; the same changes with the checksum recomputed (a
    /// hostile buffer): typed errors or fields that keep their contracts,
    /// never a panic.
    #[test]
    fn hostile_sd_and_field_buffers_never_panic() {
        let lights: Vec<Emitter> = two_rooms().into_iter().take(4).collect();
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        let mut config = FieldConfig::default();
        config.sd.spatial_threshold = 30.0;
        config.sd.learn_bsdf_fraction = true;
        let mut field = GuidingField::new(&tree, scene(), config).unwrap();
        let mut rng = Rand::new(9);
        for _ in 0..2 {
            for _ in 0..200 {
                let p = rng.point(9.5);
                let v = field.vertex(&ShadingContext::at(p)).unwrap();
                let (d, r) = radiance(&mut rng);
                v.direction.record_radiance(d, r, 0.3);
                v.light.record_light(LightId::Emitter(rng.below(4)), 1.0);
            }
            field.refine();
        }
        let bytes = field.to_bytes();
        assert!(bytes.len() < 60_000, "{}", bytes.len());
        for len in 0..bytes.len() {
            assert!(GuidingField::from_bytes(&bytes[..len], &tree).is_err());
        }
        let mut loaded = 0;
        for i in 0..bytes.len() {
            let mut hostile = bytes.clone();
            hostile[i] ^= 0x41;
            // Damaged: the checksum (or the header check) refuses it.
            assert!(GuidingField::from_bytes(&hostile, &tree).is_err());
            if i < HEADER {
                continue;
            }
            if let Ok(f) = GuidingField::from_bytes(&resealed(hostile), &tree) {
                loaded += 1;
                let p = rng.point(9.0);
                let ctx = ShadingContext::at(p);
                let total: f64 = (0..4)
                    .map(|e| ByPosition(&f).pmf_exact(&ctx, LightId::Emitter(e)))
                    .sum();
                assert!((total - 1.0).abs() < 1e-5);
                let v = f.vertex(&ShadingContext::at(p)).unwrap();
                let (d, pdf) = v.direction.sample_direction([rng.f(), rng.f()]);
                assert!(pdf > 0.0 && pdf.is_finite(), "{pdf}");
                assert!((v.direction.direction_pdf(d) - pdf).abs() <= 1e-3 * pdf);
            }
        }
        assert!(loaded > 0);
    }
}

/// A light tree's saved light sets are checked: one per node, each inner
/// node's the union of its children's (a flipped bit, checksum fixed, is
/// refused naming the field), and a count of sets that is not the node
/// count is refused.
#[test]
fn saved_light_sets_are_checked() {
    let lights: Vec<guiding::Emitter> = two_rooms()
        .into_iter()
        .enumerate()
        .map(|(i, e)| e.in_light_sets(1 << (i % 3)))
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let bytes = tree.to_bytes();
    let n = tree.nodes().len();
    assert_eq!(
        LightTree::from_bytes(&bytes).unwrap().to_bytes(),
        bytes,
        "round trip"
    );
    // The sets are the payload's last 8 n bytes; the first is the root's.
    let root_set = bytes.len() - 8 * n;
    let mut bad = bytes.clone();
    bad[root_set] ^= 0x40;
    match LightTree::from_bytes(&resealed(bad)) {
        Err(LoadError::Invalid { field, .. }) => assert_eq!(field, "light tree: light sets"),
        other => panic!("{other:?}"),
    }
    // One set fewer than nodes: the count says n - 1, the bytes end early
    // for the checksum's sake.
    let mut short = bytes[..bytes.len() - 8].to_vec();
    let count_at = root_set - 8;
    short[count_at..count_at + 8].copy_from_slice(&((n - 1) as u64).to_le_bytes());
    let len = (short.len() - HEADER) as u64;
    short[HEADER - 16..HEADER - 8].copy_from_slice(&len.to_le_bytes());
    assert!(LightTree::from_bytes(&resealed(short)).is_err());
}
