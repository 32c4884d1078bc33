//! Saved files frozen in the repository (`tests/frozen/v<N>/`), one per
//! structure and configuration, written by the format version `N` they are
//! named for. docs/format.md promises that the version changes with any
//! layout change and that a build reads every version up to its own; these
//! tests hold the crate to it:
//!
//! - every frozen file of a version up to the crate's loads, with every
//!   configuration field as it was saved (the non-default ones included:
//!   filters, `max_bytes`, the paper's rules, deterministic sums, unbounded
//!   lights), and answers (pmfs, pdfs) what it answered when it was frozen
//!   (`answers.txt` beside the files);
//! - a file of the crate's own version saves back to the same bytes (the
//!   crate-version field and the checksum aside): a layout change that keeps
//!   the version number fails here;
//! - a file that claims a newer version is refused with
//!   `LoadError::UnsupportedVersion`.
//!
//! Freezing a new version (after raising `FORMAT_VERSION`):
//! `GUIDING_FREEZE=1 cargo test --release --test frozen_format`, which
//! writes `tests/frozen/v<FORMAT_VERSION>/` if it does not exist yet. Older
//! versions' files are never rewritten.

mod common;
use common::{ByPosition, LightsAt};

use common::{Rand, scene, two_rooms, value};
use glam::Vec3;
use guiding::cut::{BelowCut, CutConfig, ImportanceBound, Modulation, Prior, SplitPrior};
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::ImportanceTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Accumulation;
use guiding::persist::FORMAT_VERSION;
use guiding::quadtree::DirectionalFilter;
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::SpatialFilter;
use guiding::{LightId, LightSampler, LightTree, LoadError, ShadingContext, UnboundedLights};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Header bytes: the crate version that wrote a file is at 12..18, the
/// checksum at 30..38 (docs/format.md).
const HEADER: usize = 38;

fn frozen_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/frozen")
}

fn tree() -> &'static LightTree {
    static TREE: std::sync::OnceLock<LightTree> = std::sync::OnceLock::new();
    TREE.get_or_init(|| LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap())
}

/// The GLT configuration with every field away from its default.
fn glt_configured() -> GltConfig {
    GltConfig {
        cut: CutConfig {
            sigma: 0.05,
            alpha: 0.3,
            below_cut: BelowCut::Power,
            modulation: Modulation::None,
            prior: Prior::Power,
            split_prior: SplitPrior::Power,
            importance_bound: ImportanceBound::Children,
            unbounded: UnboundedLights::new(2, 0.25).unwrap(),
            accumulation: Accumulation::Deterministic,
            min_records: 10,
            visibility: true,
        },
        spatial_threshold: 300.0,
        max_bytes: Some(1 << 20),
        light_filter: SpatialFilter::StochasticBox,
    }
}

fn glt_default() -> GltConfig {
    GltConfig {
        spatial_threshold: 300.0,
        ..GltConfig::default()
    }
}

/// The SD-tree configuration with every field away from its default.
fn sd_configured() -> SdTreeConfig {
    let mut c = SdTreeConfig {
        spatial_threshold: 300.0,
        spatial_filter: SpatialFilter::Box,
        directional_filter: DirectionalFilter::Box,
        accumulation: Accumulation::Deterministic,
        max_bytes: Some(1 << 22),
        bsdf_fraction: 0.3,
        learn_bsdf_fraction: true,
        fraction_steps: 17,
        ..SdTreeConfig::default()
    };
    c.quadtree.rho = 0.02;
    c.quadtree.max_depth = 12;
    c
}

fn sd_default() -> SdTreeConfig {
    SdTreeConfig {
        spatial_threshold: 300.0,
        ..SdTreeConfig::default()
    }
}

fn field_configured() -> FieldConfig {
    FieldConfig {
        sd: sd_configured(),
        cut: glt_configured().cut,
        light_filter: SpatialFilter::StochasticBox,
    }
}

/// Three iterations of records from the two rooms (with a sun and a sky),
/// through `record`, then `refine`.
fn train<T>(t: &mut T, record: impl Fn(&T, Vec3, u32, f32, &mut Rand), refine: impl Fn(&mut T)) {
    let lights = two_rooms();
    let mut rng = Rand::new(77);
    for _ in 0..3 {
        for _ in 0..1500 {
            let p = rng.point(9.5);
            let e = rng.below(82);
            let v = if e < 80 {
                value(&lights, e, p) * rng.range(0.5, 2.0)
            } else {
                1.0
            };
            record(t, p, e, v, &mut rng);
        }
        refine(t);
    }
}

fn light(e: u32) -> LightId {
    if e < 80 {
        LightId::Emitter(e)
    } else {
        LightId::Unbounded(e - 80)
    }
}

fn trained_glt(config: GltConfig) -> Glt<&'static LightTree> {
    let mut g = Glt::new(tree(), scene(), config).unwrap();
    let k = config.cut.unbounded.count + 80;
    train(
        &mut g,
        |g, p, e, v, _| {
            if e < k {
                g.record_light_at(p, light(e), v);
                g.record_visibility_at(p, light(e), 0.5 * v, v);
            }
        },
        |g| {
            g.refine();
        },
    );
    g
}

fn trained_sd(config: SdTreeConfig) -> SdTree {
    let mut t = SdTree::new(scene(), config).unwrap();
    train(
        &mut t,
        |t, p, _, v, rng| {
            let x = t.vertex(&ShadingContext::at(p)).unwrap();
            let d = rng.dir();
            x.record_radiance(d, v + 5.0 * d.y.max(0.0), 0.3);
            x.record_fraction(0.2 + rng.f(), 0.1 + rng.f(), v);
        },
        |t| {
            t.refine();
        },
    );
    t
}

fn trained_field(config: FieldConfig) -> GuidingField<&'static LightTree> {
    let mut f = GuidingField::new(tree(), scene(), config).unwrap();
    let k = config.cut.unbounded.count + 80;
    train(
        &mut f,
        |f, p, e, v, rng| {
            let x = f.vertex(&ShadingContext::at(p)).unwrap();
            let d = rng.dir();
            if e < k {
                x.light.record_light(light(e), v);
                x.light.record_visibility(light(e), 0.5 * v, v);
            }
            x.direction.record_radiance(d, v + 5.0 * d.y.max(0.0), 0.3);
            x.direction.record_fraction(0.2 + rng.f(), 0.1 + rng.f(), v);
        },
        |f| {
            f.refine();
        },
    );
    f
}

/// The frozen files' names and the structures they hold.
const FILES: [&str; 7] = [
    "light_tree",
    "glt_default",
    "glt_configured",
    "sd_tree_default",
    "sd_tree_configured",
    "field_default",
    "field_configured",
];

fn fresh(name: &str) -> Vec<u8> {
    match name {
        "light_tree" => tree().to_bytes(),
        "glt_default" => trained_glt(glt_default()).to_bytes(),
        "glt_configured" => trained_glt(glt_configured()).to_bytes(),
        "sd_tree_default" => trained_sd(sd_default()).to_bytes(),
        "sd_tree_configured" => trained_sd(sd_configured()).to_bytes(),
        "field_default" => trained_field(FieldConfig {
            sd: sd_default(),
            ..FieldConfig::default()
        })
        .to_bytes(),
        "field_configured" => trained_field(field_configured()).to_bytes(),
        _ => unreachable!(),
    }
}

/// Where the answers are asked.
fn points() -> [Vec3; 4] {
    [
        Vec3::new(-5.0, -3.0, 1.0),
        Vec3::new(4.0, 2.0, -2.0),
        Vec3::new(0.3, 0.0, 0.0),
        Vec3::new(9.0, 9.0, 9.0),
    ]
}

/// Every light the frozen samplers can choose.
fn lights() -> impl Iterator<Item = LightId> {
    (0..80)
        .map(LightId::Emitter)
        .chain((0..2).map(LightId::Unbounded))
}

fn light_answers(s: &impl LightSampler, out: &mut String) {
    for p in points() {
        let ctx = ShadingContext::on_surface(p, Vec3::new(0.0, 0.6, 0.8));
        for l in lights() {
            write!(out, "{:e} ", s.pmf_exact(&ctx, l)).unwrap();
        }
        out.push('\n');
    }
}

fn direction_answers(pdf: impl Fn(Vec3, Vec3) -> f32, out: &mut String) {
    let mut rng = Rand::new(3);
    for p in points() {
        for _ in 0..16 {
            write!(out, "{:e} ", pdf(p, rng.dir())).unwrap();
        }
        out.push('\n');
    }
}

/// What a loaded file answers: pmfs of every light at a few points (light
/// tree, GLT, field), directional pdfs and BSDF fractions (SD-tree, field).
/// Loading also checks the configuration it holds, field by field.
///
/// The GLT and the field load over `tree`, the frozen light tree of the
/// same version (so a change of the tree builder does not unbind them).
///
/// Files of format version 1 hold no learned visibility: their expected
/// configurations have it off.
fn load_and_answer(
    name: &str,
    bytes: &[u8],
    tree: &LightTree,
    version: u32,
) -> Result<(String, Vec<u8>), LoadError> {
    // What an older version could not hold loads as its rule then was.
    let learned = |mut cut: CutConfig| {
        cut.visibility &= version >= 2;
        if version < 6 {
            cut.importance_bound = ImportanceBound::Children;
        }
        cut
    };
    let mut out = String::new();
    let resaved = match name {
        "light_tree" => {
            let t = LightTree::from_bytes(bytes)?;
            light_answers(&ImportanceTreeSampler::new(&t), &mut out);
            t.to_bytes()
        }
        "glt_default" | "glt_configured" => {
            let g = Glt::from_bytes(bytes, tree)?;
            let mut want = if name == "glt_default" {
                glt_default()
            } else {
                glt_configured()
            };
            want.cut = learned(want.cut);
            assert_eq!(*g.config(), want, "{name}: configuration");
            assert_eq!(g.iteration(), 3);
            light_answers(&ByPosition(&g), &mut out);
            g.to_bytes()
        }
        "sd_tree_default" | "sd_tree_configured" => {
            let t = SdTree::from_bytes(bytes)?;
            let want = if name == "sd_tree_default" {
                sd_default()
            } else {
                sd_configured()
            };
            assert_eq!(*t.config(), want, "{name}: configuration");
            direction_answers(
                |p, d| {
                    let v = t.vertex(&ShadingContext::at(p)).unwrap();
                    v.direction_pdf(d) + 1000.0 * v.bsdf_fraction()
                },
                &mut out,
            );
            t.to_bytes()
        }
        "field_default" | "field_configured" => {
            let f = GuidingField::from_bytes(bytes, tree)?;
            let mut want = if name == "field_default" {
                FieldConfig {
                    sd: sd_default(),
                    ..FieldConfig::default()
                }
            } else {
                field_configured()
            };
            want.cut = learned(want.cut);
            assert_eq!(f.config(), want, "{name}: configuration");
            light_answers(&ByPosition(&f), &mut out);
            direction_answers(
                |p, d| {
                    let v = f.vertex(&ShadingContext::at(p)).unwrap();
                    v.direction.direction_pdf(d) + 1000.0 * v.direction.bsdf_fraction()
                },
                &mut out,
            );
            f.to_bytes()
        }
        _ => unreachable!(),
    };
    Ok((out, resaved))
}

/// The frozen versions present: `(N, dir)` for every `tests/frozen/vN/`.
fn versions() -> Vec<(u32, PathBuf)> {
    let mut out: Vec<(u32, PathBuf)> = std::fs::read_dir(frozen_dir())
        .map(|d| {
            d.flatten()
                .filter_map(|e| {
                    let n = e.file_name().to_str()?.strip_prefix('v')?.parse().ok()?;
                    Some((n, e.path()))
                })
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

/// Writes `tests/frozen/v<FORMAT_VERSION>/` when asked to and absent.
fn freeze_if_asked() {
    if std::env::var_os("GUIDING_FREEZE").is_none() {
        return;
    }
    let dir = frozen_dir().join(format!("v{FORMAT_VERSION}"));
    if dir.exists() {
        return;
    }
    std::fs::create_dir_all(&dir).unwrap();
    let mut answers = String::new();
    for name in FILES {
        let bytes = fresh(name);
        std::fs::write(dir.join(format!("{name}.bin")), &bytes).unwrap();
        let (a, _) = load_and_answer(name, &bytes, tree(), FORMAT_VERSION).unwrap();
        writeln!(answers, "# {name}\n{a}").unwrap();
    }
    std::fs::write(dir.join("answers.txt"), answers).unwrap();
}

/// `a` and `b` equal but for the crate-version field and the checksum.
fn same_layout(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len()
        && a.len() >= HEADER
        && a[..12] == b[..12]
        && a[18..30] == b[18..30]
        && a[HEADER..] == b[HEADER..]
}

#[test]
fn frozen_files_load_and_answer_as_when_frozen() {
    freeze_if_asked();
    let versions = versions();
    assert!(
        versions.iter().any(|&(n, _)| n == FORMAT_VERSION),
        "no frozen files of format version {FORMAT_VERSION}: a layout changed and the \
         version went up without freezing the new one (see this file's header)"
    );
    for (n, dir) in versions {
        assert!(n <= FORMAT_VERSION, "frozen files of a future version {n}");
        let answers = std::fs::read_to_string(dir.join("answers.txt")).unwrap();
        let mut want = answers.split("# ").filter(|s| !s.is_empty());
        let tree = LightTree::from_bytes(&std::fs::read(dir.join("light_tree.bin")).unwrap())
            .unwrap_or_else(|e| panic!("v{n}/light_tree.bin no longer loads: {e}"));
        for name in FILES {
            let bytes = std::fs::read(dir.join(format!("{name}.bin")))
                .unwrap_or_else(|e| panic!("v{n}/{name}.bin: {e}"));
            let (got, resaved) = load_and_answer(name, &bytes, &tree, n)
                .unwrap_or_else(|e| panic!("v{n}/{name}.bin no longer loads: {e}"));
            let expected = want.next().unwrap().strip_prefix(name).unwrap().trim();
            assert_answers(&format!("v{n}/{name}"), got.trim(), expected);
            if n == FORMAT_VERSION {
                assert!(
                    same_layout(&resaved, &bytes),
                    "v{n}/{name}: saving what was loaded gives other bytes: the layout \
                     changed without a new format version"
                );
            }
        }
    }
}

/// Numbers equal to 1e-6 relative (the files hold every bit; the answers
/// are printed in full, so this leaves room only for a compiler's `f64`
/// library differences).
fn assert_answers(what: &str, got: &str, want: &str) {
    let got: Vec<f64> = got.split_whitespace().map(|x| x.parse().unwrap()).collect();
    let want: Vec<f64> = want
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(got.len(), want.len(), "{what}: number of answers");
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!(
            (g - w).abs() <= 1e-6 * w.abs().max(1e-30),
            "{what}: answer {i} is {g}, was {w} when frozen"
        );
    }
}

/// A file of a version the crate does not know yet is refused, saying
/// which version it found and which it reads.
#[test]
fn a_newer_version_is_refused_with_a_typed_error() {
    let dir = frozen_dir().join(format!("v{FORMAT_VERSION}"));
    let mut bytes = std::fs::read(dir.join("light_tree.bin")).unwrap();
    bytes[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    match LightTree::from_bytes(&bytes) {
        Err(LoadError::UnsupportedVersion { found, supported }) => {
            assert_eq!((found, supported), (FORMAT_VERSION + 1, FORMAT_VERSION));
        }
        other => panic!("{other:?}"),
    }
}

/// What learned state binds to: a file of version 4 on loads over the tree
/// refitted to lights that moved (the same shape); a file of an earlier
/// version only over the very tree it was saved with.
#[test]
fn from_version_4_state_loads_over_a_refitted_tree() {
    let mut lights = two_rooms();
    for l in &mut lights {
        let d = Vec3::new(0.05, 0.1, -0.1);
        l.bounds = guiding::Aabb::new(l.bounds.min + d, l.bounds.max + d);
    }
    let mut refitted = tree().clone();
    refitted.refit(lights.as_slice()).unwrap();
    for (n, dir) in versions() {
        for name in [
            "glt_default",
            "glt_configured",
            "field_default",
            "field_configured",
        ] {
            let bytes = std::fs::read(dir.join(format!("{name}.bin"))).unwrap();
            let (glt, field) = match name.starts_with("glt") {
                true => (Glt::from_bytes(&bytes, &refitted).err(), None),
                false => (None, GuidingField::from_bytes(&bytes, &refitted).err()),
            };
            let refused =
                |e: &Option<LoadError>| matches!(e, Some(LoadError::LightTreeMismatch { .. }));
            match n {
                4.. => assert!(
                    glt.is_none() && field.is_none(),
                    "v{n} {name}: {glt:?} {field:?}"
                ),
                _ => assert!(refused(&glt) || refused(&field), "v{n} {name}"),
            }
        }
    }
}

/// Control: the layout check sees a changed byte in the payload, and the
/// answers check sees a changed answer.
#[test]
fn the_checks_can_fail() {
    let a = fresh("light_tree");
    let mut b = a.clone();
    assert!(same_layout(&a, &b));
    b[12] ^= 1; // the crate version: ignored
    b[31] ^= 1; // the checksum: ignored
    assert!(same_layout(&a, &b));
    b[HEADER + 3] ^= 1;
    assert!(!same_layout(&a, &b));
    let r = std::panic::catch_unwind(|| assert_answers("x", "1e0 2e0", "1e0 2.00001e0"));
    assert!(r.is_err());
}
