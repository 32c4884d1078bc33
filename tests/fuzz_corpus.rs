//! The fuzz targets' checks (`fuzz/checks.rs`) on their seeds and on every
//! input in `fuzz/corpus/<target>/` (the committed `load` seeds; a fuzzing
//! run adds what it explores) and `fuzz/artifacts/<target>/` (inputs that
//! crashed a target: committed, they stay regression tests), without
//! libFuzzer, and on generated inputs that reach the hard cases (emitters
//! that are degenerate, coincident, of zero or huge power; records far
//! outside the scene or not finite) without a fuzzing run.

#[path = "../fuzz/checks.rs"]
mod checks;

use std::path::Path;

/// Every file under `fuzz/<kind>/<target>/`.
fn inputs(target: &str) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for kind in ["corpus", "artifacts"] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fuzz")
            .join(kind)
            .join(target);
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            if let Ok(bytes) = std::fs::read(e.path()) {
                out.push(bytes);
            }
        }
    }
    out
}

#[test]
fn load_seeds_and_corpus() {
    let seeds = checks::load::seeds();
    for s in &seeds {
        checks::load::load(s);
    }
    // Each seed loads as what it is, today's and the committed ones (a
    // committed seed that stops loading fuzzes only the refusal paths).
    let tree = checks::load::tree();
    let committed = |i: usize| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("fuzz/corpus/load/seed-{i}"));
        std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    };
    for bytes in [seeds.clone(), (0..5).map(committed).collect()] {
        assert!(guiding::LightTree::from_bytes(&bytes[0]).is_ok());
        assert!(guiding::glt::Glt::from_bytes(&bytes[1], tree).is_ok());
        assert!(guiding::sd_tree::SdTree::from_bytes(&bytes[2]).is_ok());
        assert!(guiding::field::GuidingField::from_bytes(&bytes[3], tree).is_ok());
        // The GLT that learned visibility (and a sun and a sky) has some.
        let seen = guiding::glt::Glt::from_bytes(&bytes[4], tree).unwrap();
        let ctx = guiding::ShadingContext::at(glam::Vec3::ZERO);
        let there = seen.vertex(&ctx).unwrap();
        let learned =
            (0..8).map(|e| guiding::LightChoice::visibility(&there, guiding::LightId::Emitter(e)));
        assert!(learned.fold(1.0f32, f32::min) < 0.9);
    }
    for input in inputs("load") {
        checks::load::load(&input);
    }
}

/// A small deterministic generator for the replayed inputs below; while
/// `hostile`, its floats are now and then values that break arithmetic.
struct Bytes(u64, bool);

impl Bytes {
    fn next(&mut self) -> u64 {
        // SplitMix64.
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Ordinary numbers in `[-scale, scale)`; while hostile, now and then
    /// one of the values that break arithmetic.
    fn float(&mut self, scale: f32) -> f32 {
        const HARD: [f32; 10] = [
            0.0,
            -0.0,
            1e30,
            -1e30,
            1e-30,
            f32::MIN_POSITIVE / 4.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
        ];
        if self.1 && self.below(12) == 0 {
            HARD[self.below(HARD.len() as u64) as usize]
        } else {
            scale * (2.0 * self.unit() - 1.0)
        }
    }
}

fn push(out: &mut Vec<u8>, x: f32) {
    out.extend_from_slice(&x.to_le_bytes());
}

/// 64 emitter lists of 1 to 64 emitters in the `build_light_tree` layout:
/// ordinary, degenerate, coincident, zero- and huge-power emitters,
/// inverted boxes, cones and flags; every fourth list hostile (NaN,
/// infinities, subnormals).
fn build_inputs() -> Vec<Vec<u8>> {
    let mut g = Bytes(0x5eed, false);
    (0..64)
        .map(|i| {
            g.1 = i % 4 == 1;
            let n = 1 + g.below(64) as usize;
            let coincident = i % 8 == 3;
            let mut out = Vec::new();
            for _ in 0..n {
                let c = if coincident {
                    [1.0, 2.0, 3.0]
                } else {
                    [g.float(50.0), g.float(50.0), g.float(50.0)]
                };
                let r = g.unit() * [0.0, 0.01, 1.0, 10.0][g.below(4) as usize];
                let inverted = g.1 && g.below(16) == 0;
                let (lo, hi) = if inverted { (r, -r) } else { (-r, r) };
                for x in c {
                    push(&mut out, x + lo);
                }
                for x in c {
                    push(&mut out, x + hi);
                }
                let power = match g.below(8) {
                    0 => 0.0,
                    1 => 1e30,
                    2 if g.1 => g.float(1.0),
                    _ => 10f32.powf(4.0 * g.unit() - 2.0),
                };
                push(&mut out, power);
                push(&mut out, g.unit() * 4.0);
                push(&mut out, g.float(1.0));
                out.push(g.below(8) as u8);
                out.push(g.below(256) as u8);
                out.push(g.below(256) as u8);
                out.push(0);
            }
            out
        })
        .collect()
}

/// 32 sequences of 50 to 400 operations in the `operations` layout:
/// records (mostly inside the scene, some far outside or not finite),
/// refinements and queries.
fn operation_inputs() -> Vec<Vec<u8>> {
    let mut g = Bytes(0x0b5, false);
    (0..32)
        .map(|i| {
            g.1 = i % 4 == 1;
            let n = 50 + g.below(350) as usize;
            let mut out = Vec::new();
            for _ in 0..n {
                // Refinements are rarer than records and queries.
                let kind = if g.below(10) == 0 {
                    2
                } else {
                    [0, 1, 3, 4][g.below(4) as usize]
                };
                out.push(kind);
                out.push(g.below(256) as u8);
                let scale = if g.below(20) == 0 { 1e6 } else { 8.0 };
                for _ in 0..3 {
                    push(&mut out, g.float(scale));
                }
                let value = if g.below(4) == 0 {
                    g.float(10.0)
                } else {
                    4.0 * g.unit()
                };
                push(&mut out, value);
                push(&mut out, g.unit());
            }
            out
        })
        .collect()
}

#[test]
fn build_light_tree_corpus() {
    for input in inputs("build_light_tree") {
        checks::build::build_light_tree(&input);
    }
    // The generated lists reach the checks: most build (the rest are
    // refused with a typed error, e.g. NaN bounds).
    let generated = build_inputs();
    let built: usize = generated
        .iter()
        .map(|i| checks::build::build_light_tree(i))
        .sum();
    assert!(
        built >= generated.len(),
        "{built} of {} builds",
        2 * generated.len()
    );
    checks::build::build_light_tree(&[0u8; 400]);
}

#[test]
fn operations_corpus() {
    for input in inputs("operations").iter().chain(&operation_inputs()) {
        checks::operations::operations(input);
    }
    let ramp: Vec<u8> = (0..2200u32).map(|i| (i * 37 % 251) as u8).collect();
    checks::operations::operations(&ramp);
}

/// Writes the `load` seeds into `fuzz/corpus/load/` (run by hand when the
/// format changes: `cargo test --test fuzz_corpus -- --ignored`).
#[test]
#[ignore]
fn write_load_seeds() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/load");
    std::fs::create_dir_all(&dir).unwrap();
    for (i, s) in checks::load::seeds().iter().enumerate() {
        std::fs::write(dir.join(format!("seed-{i}")), s).unwrap();
    }
}
