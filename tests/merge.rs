//! N workers that each record part of the samples into a copy of the same
//! structure, exchange their state as bytes, merge and refine once, learn
//! bit for bit what one process recording every sample itself learns
//! (deterministic mode), for 1, 2 and 4 workers; merging mismatched
//! structures is refused and changes nothing.

mod common;
use common::LightsAt;
use guiding::ShadingContext;

use common::{Rand, scene, two_rooms, unshadowed, value};
use glam::Vec3;
use guiding::cut::CutConfig;
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Accumulation;
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::{LightId, LightTree};

/// One sample's records: a position, a light and its value, a direction
/// and its radiance, and the numbers a jittered record draws.
#[derive(Clone, Copy)]
struct Sample {
    p: Vec3,
    light: u32,
    light_value: f32,
    /// What the light's record would have been without the wall.
    unshadowed: f32,
    dir: Vec3,
    radiance: f32,
}

fn samples(seed: u64, n: usize) -> Vec<Sample> {
    let lights = two_rooms();
    let mut rng = Rand::new(seed);
    (0..n)
        .map(|_| {
            let p = rng.point(9.5);
            let light = rng.below(80);
            let dir = rng.dir();
            let f = rng.range(0.5, 2.0);
            Sample {
                p,
                light,
                light_value: value(&lights, light, p) * f,
                unshadowed: unshadowed(&lights, light, p) * f,
                dir,
                radiance: 1.0 + 30.0 * dir.y.max(0.0).powi(6),
            }
        })
        .collect()
}

/// What a structure must offer for the farm test.
trait Farmable: Sized {
    fn record(&self, s: &Sample);
    fn clear(&mut self);
    fn bytes(&self) -> Vec<u8>;
    fn load(bytes: &[u8], tree: &LightTree) -> Self;
    fn merge_in(&mut self, other: &Self) -> bool;
    fn refine_once(&mut self);
}

impl Farmable for Glt<&'static LightTree> {
    fn record(&self, s: &Sample) {
        self.record_light_at(s.p, LightId::Emitter(s.light), s.light_value);
        self.record_visibility_at(s.p, LightId::Emitter(s.light), s.light_value, s.unshadowed);
    }
    fn clear(&mut self) {
        self.clear_records();
    }
    fn bytes(&self) -> Vec<u8> {
        self.to_bytes()
    }
    fn load(bytes: &[u8], _: &LightTree) -> Self {
        Glt::from_bytes(bytes, tree()).unwrap()
    }
    fn merge_in(&mut self, other: &Self) -> bool {
        self.merge(other)
    }
    fn refine_once(&mut self) {
        self.refine();
    }
}

impl Farmable for SdTree {
    fn record(&self, s: &Sample) {
        let v = self.vertex(&ShadingContext::at(s.p)).unwrap();
        v.record_radiance(s.dir, s.radiance, 0.4);
        v.record_fraction(0.3, 0.5, s.radiance);
    }
    fn clear(&mut self) {
        self.clear_records();
    }
    fn bytes(&self) -> Vec<u8> {
        self.to_bytes()
    }
    fn load(bytes: &[u8], _: &LightTree) -> Self {
        SdTree::from_bytes(bytes).unwrap()
    }
    fn merge_in(&mut self, other: &Self) -> bool {
        self.merge(other)
    }
    fn refine_once(&mut self) {
        self.refine();
    }
}

impl Farmable for GuidingField<&'static LightTree> {
    fn record(&self, s: &Sample) {
        let v = self.vertex(&ShadingContext::at(s.p)).unwrap();
        v.light
            .record_light(LightId::Emitter(s.light), s.light_value);
        v.light
            .record_visibility(LightId::Emitter(s.light), s.light_value, s.unshadowed);
        v.direction.record_radiance(s.dir, s.radiance, 0.4);
    }
    fn clear(&mut self) {
        self.clear_records();
    }
    fn bytes(&self) -> Vec<u8> {
        self.to_bytes()
    }
    fn load(bytes: &[u8], _: &LightTree) -> Self {
        GuidingField::from_bytes(bytes, tree()).unwrap()
    }
    fn merge_in(&mut self, other: &Self) -> bool {
        self.merge(other)
    }
    fn refine_once(&mut self) {
        self.refine();
    }
}

/// The light tree every structure here uses (leaked once: `'static`).
fn tree() -> &'static LightTree {
    static TREE: std::sync::OnceLock<LightTree> = std::sync::OnceLock::new();
    TREE.get_or_init(|| LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap())
}

/// Three iterations of the farm protocol: every worker loads the
/// coordinator's state from bytes, clears its records, records its share
/// (sample `i` goes to worker `i % n`) and sends it back as bytes; the
/// coordinator merges every share into its state and refines. Returns the
/// final state's bytes.
fn farm<F: Farmable>(start: &F, workers: usize, stream: &[Vec<Sample>]) -> Vec<u8> {
    let mut state = F::load(&start.bytes(), tree());
    for round in stream {
        let sent = state.bytes();
        let shares: Vec<Vec<u8>> = (0..workers)
            .map(|w| {
                let mut local = F::load(&sent, tree());
                local.clear();
                for s in round.iter().skip(w).step_by(workers) {
                    local.record(s);
                }
                local.bytes()
            })
            .collect();
        for share in &shares {
            assert!(state.merge_in(&F::load(share, tree())));
        }
        state.refine_once();
    }
    state.bytes()
}

/// One process: records every sample of each round itself and refines.
/// Returns the final state's bytes.
fn one_process<F: Farmable>(start: &F, stream: &[Vec<Sample>]) -> Vec<u8> {
    let mut state = F::load(&start.bytes(), tree());
    for round in stream {
        for s in round {
            state.record(s);
        }
        state.refine_once();
    }
    state.bytes()
}

/// The same number of refinements with no records at all.
fn unfed<F: Farmable>(start: &F, rounds: usize) -> Vec<u8> {
    let mut state = F::load(&start.bytes(), tree());
    for _ in 0..rounds {
        state.refine_once();
    }
    state.bytes()
}

fn check_farm<F: Farmable>(start: F) {
    let stream: Vec<Vec<Sample>> = (0..3).map(|k| samples(10 + k, 6000)).collect();
    let one = one_process(&start, &stream);
    for n in [1, 2, 4] {
        assert!(
            farm(&start, n, &stream) == one,
            "{n} workers differ from one process recording every sample"
        );
    }
    // And the state did learn: it is not what refining without records
    // gives (which differs from the start in its iteration counter alone).
    assert_ne!(one, unfed(&start, stream.len()));
}

#[test]
fn glt_workers_merge_bit_for_bit() {
    let config = GltConfig {
        cut: CutConfig {
            accumulation: Accumulation::Deterministic,
            // Many cuts stay below the floor and carry their sums into the
            // next iteration: a share must not carry them again.
            min_records: 300,
            visibility: true,
            ..CutConfig::default()
        },
        spatial_threshold: 400.0,
        ..GltConfig::default()
    };
    check_farm(Glt::new(tree(), scene(), config).unwrap());
}

#[test]
fn sd_tree_workers_merge_bit_for_bit() {
    let mut config = SdTreeConfig::improved();
    config.accumulation = Accumulation::Deterministic;
    config.spatial_threshold = 400.0;
    check_farm(SdTree::new(scene(), config).unwrap());
}

#[test]
fn field_workers_merge_bit_for_bit() {
    let mut config = FieldConfig {
        sd: SdTreeConfig::improved(),
        ..FieldConfig::default()
    };
    config.sd.accumulation = Accumulation::Deterministic;
    config.sd.spatial_threshold = 400.0;
    config.cut.accumulation = Accumulation::Deterministic;
    config.cut.visibility = true;
    check_farm(GuidingField::new(tree(), scene(), config).unwrap());
}

/// Structures that are not copies of one (another configuration, another
/// refinement) refuse to merge and stay as they were.
#[test]
fn mismatched_merges_are_refused() {
    let config = GltConfig {
        spatial_threshold: 400.0,
        ..GltConfig::default()
    };
    let mut a = Glt::new(tree(), scene(), config).unwrap();
    let other = Glt::new(
        tree(),
        scene(),
        GltConfig {
            spatial_threshold: 500.0,
            ..config
        },
    )
    .unwrap();
    for s in &samples(1, 3000) {
        a.record(s);
    }
    let before = a.to_bytes();
    assert!(!a.merge(&other));
    assert_eq!(a.to_bytes(), before);
    let mut refined = Glt::new(tree(), scene(), config).unwrap();
    for s in &samples(2, 3000) {
        refined.record(s);
    }
    refined.refine();
    assert!(!a.merge(&refined));
    assert_eq!(a.to_bytes(), before);
    let mut sd = SdTree::new(scene(), SdTreeConfig::default()).unwrap();
    let mut sd2 = SdTree::new(scene(), SdTreeConfig::default()).unwrap();
    for s in &samples(3, 3000) {
        sd2.record(s);
    }
    sd2.refine();
    assert!(!sd.merge(&sd2));
}

/// Copies whose cuts would sample differently refuse to merge even where
/// their cut nodes are equal: other learned fractions of the unbounded
/// lights, other learned visibilities. A true copy merges.
#[test]
fn cuts_with_equal_nodes_that_sample_differently_refuse_to_merge() {
    let config = GltConfig {
        // One cell: only the cuts can differ.
        spatial_threshold: 1e12,
        cut: CutConfig {
            unbounded: guiding::UnboundedLights {
                count: 1,
                probability: 0.1,
            },
            visibility: true,
            ..CutConfig::default()
        },
        ..GltConfig::default()
    };
    let n = two_rooms().len() as u32;
    // The same emitter records; the sky's value and the share of the
    // emitters' records that were shadowed vary.
    let learned = |sky: f32, shadowed: u32| {
        let mut glt = Glt::new(tree(), scene(), config).unwrap();
        for k in 0..4000u32 {
            let p = Vec3::new(-4.0, 0.0, 1.0);
            let light = LightId::Emitter(k % n);
            glt.record_light_at(p, light, 1.0);
            let seen = if k % 8 < shadowed { 0.0 } else { 1.0 };
            glt.record_visibility_at(p, light, seen, 1.0);
            glt.record_light_at(p, LightId::Unbounded(0), sky);
        }
        glt.refine();
        glt
    };
    let a = learned(1.0, 0);
    let cut = |g: &Glt<&LightTree>| g.spatial().data_slice()[0].cut().clone();
    for (b, what) in [
        (learned(3.0, 0), "sky fraction"),
        (learned(1.0, 4), "visibility"),
    ] {
        assert_eq!(cut(&a).nodes(), cut(&b).nodes(), "{what}");
        assert_ne!(
            (cut(&a).unbounded_fractions(), cut(&a).visibility()),
            (cut(&b).unbounded_fractions(), cut(&b).visibility()),
            "{what}"
        );
        let mut merged = a.clone();
        assert!(!merged.merge(&b), "{what}");
        assert_eq!(merged.to_bytes(), a.to_bytes(), "{what}");
    }
    assert!(a.clone().merge(&learned(1.0, 0)));
}

/// Fields that are not copies of one refuse to merge and stay as they
/// were: another cut configuration, another light filter, another
/// refinement, cuts with equal nodes that learned another sky fraction.
/// A true copy merges.
#[test]
fn mismatched_fields_refuse_to_merge() {
    let config = FieldConfig {
        cut: CutConfig {
            unbounded: guiding::UnboundedLights {
                count: 1,
                probability: 0.1,
            },
            ..CutConfig::default()
        },
        ..FieldConfig::default()
    };
    let learned = |config: FieldConfig, sky: f32, refine: bool| {
        let mut field = GuidingField::new(tree(), scene(), config).unwrap();
        let stream = samples(1, 3000);
        for s in &stream {
            field.record(s);
        }
        for s in stream.iter().take(50) {
            let v = field.vertex(&ShadingContext::at(s.p)).unwrap();
            v.light.record_light(LightId::Unbounded(0), sky);
        }
        if refine {
            field.refine();
        }
        field
    };
    let a = learned(config, 1.0, true);
    let finer = FieldConfig {
        cut: CutConfig {
            sigma: 0.02,
            ..config.cut
        },
        ..config
    };
    let jittered = FieldConfig {
        light_filter: guiding::spatial::SpatialFilter::StochasticBox,
        ..config
    };
    let others = [
        (learned(finer, 1.0, true), "cut configuration"),
        (learned(jittered, 1.0, true), "light filter"),
        (learned(config, 1.0, false), "refinement"),
        (learned(config, 5.0, true), "sky fraction"),
    ];
    for (b, what) in &others {
        let mut merged = a.clone();
        assert!(!merged.merge(b), "{what}");
        assert_eq!(merged.to_bytes(), a.to_bytes(), "{what}");
    }
    assert!(a.clone().merge(&learned(config, 1.0, true)));
}
