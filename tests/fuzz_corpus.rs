//! The fuzz targets' checks (`fuzz/checks.rs`) on their seeds and on every
//! input in `fuzz/corpus/<target>/` (the committed `load` seeds; a fuzzing
//! run adds what it explores) and `fuzz/artifacts/<target>/` (inputs that
//! crashed a target: committed, they stay regression tests), without
//! libFuzzer.

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
    // Each seed loads as what it is.
    let tree = checks::load::tree();
    assert!(guiding::LightTree::from_bytes(&seeds[0]).is_ok());
    assert!(guiding::glt::Glt::from_bytes(&seeds[1], tree).is_ok());
    assert!(guiding::sd_tree::SdTree::from_bytes(&seeds[2]).is_ok());
    assert!(guiding::field::GuidingField::from_bytes(&seeds[3], tree).is_ok());
    for input in inputs("load") {
        checks::load::load(&input);
    }
}

#[test]
fn build_light_tree_corpus() {
    for input in inputs("build_light_tree") {
        checks::build::build_light_tree(&input);
    }
    checks::build::build_light_tree(&[0u8; 400]);
}

#[test]
fn operations_corpus() {
    for input in inputs("operations") {
        checks::operations::operations(&input);
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
