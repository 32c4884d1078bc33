//! Invalid configurations are typed errors at construction, field by
//! field; boundary values are accepted; nothing is clamped silently.

mod common;

use common::{scene, two_rooms};
use guiding::cut::{CutConfig, CutRules};
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::quadtree::QuadtreeConfig;
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::{ConfigError, Error, LightTree, UnboundedLights};

fn tree() -> LightTree {
    LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap()
}

/// Every constructor that takes `cut` rejects it with the error for
/// `field`, or accepts it.
fn check_cut(cut: CutConfig, field: Option<&str>) {
    let tree = tree();
    let direct = CutRules::new(&tree, cut).map(|_| ());
    let glt = Glt::new(
        &tree,
        scene(),
        GltConfig {
            cut,
            ..GltConfig::default()
        },
    )
    .map(|_| ());
    let field_ = GuidingField::new(
        &tree,
        scene(),
        FieldConfig {
            cut,
            ..FieldConfig::default()
        },
    )
    .map(|_| ());
    match field {
        Some(name) => {
            let e = direct.unwrap_err();
            assert_eq!(e.field, name, "{cut:?}");
            // Debug, not ==: the value may be NaN.
            let want = format!("{:?}", Err::<(), _>(Error::Config(e)));
            assert_eq!(format!("{glt:?}"), want);
            assert_eq!(format!("{field_:?}"), want);
            assert!(format!("{e}").contains(name));
        }
        None => {
            assert_eq!(direct, Ok(()), "{cut:?}");
            assert_eq!(glt, Ok(()));
            assert_eq!(field_, Ok(()));
        }
    }
}

#[test]
fn cut_config_fields() {
    let d = CutConfig::default();
    check_cut(d, None);
    check_cut(d.with_paper_rules(), None);
    for sigma in [0.0, 1e-9, 1.0] {
        check_cut(CutConfig { sigma, ..d }, None);
    }
    for sigma in [-0.01, 1.01, f64::NAN, f64::INFINITY] {
        check_cut(CutConfig { sigma, ..d }, Some("CutConfig::sigma"));
    }
    for alpha in [0.0, 1.0] {
        check_cut(CutConfig { alpha, ..d }, None);
    }
    for alpha in [-1e-9, 1.5, f64::NAN, f64::NEG_INFINITY] {
        check_cut(CutConfig { alpha, ..d }, Some("CutConfig::alpha"));
    }
    let unbounded = |count, probability| CutConfig {
        unbounded: UnboundedLights { count, probability },
        ..d
    };
    for (count, q) in [(0, 0.0), (1, 1e-9), (2, 0.5), (3, 0.999)] {
        check_cut(unbounded(count, q), None);
    }
    // At 1 no emitter could ever be sampled (was clamped silently); at 0 a
    // sun would never be; a share for no light is a mistake.
    for (count, q) in [
        (1, 1.0),
        (1, 2.0),
        (2, -0.1),
        (1, f64::NAN),
        (2, 0.0),
        (0, 0.3),
    ] {
        check_cut(unbounded(count, q), Some("UnboundedLights::probability"));
    }
}

#[test]
fn glt_spatial_threshold() {
    let tree = tree();
    let make = |spatial_threshold| {
        Glt::new(
            &tree,
            scene(),
            GltConfig {
                spatial_threshold,
                ..GltConfig::default()
            },
        )
        .map(|_| ())
    };
    assert_eq!(make(1e-3), Ok(()));
    // 0 split every cell on every record (99,772 cells from 30k records).
    for c in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        match make(c) {
            Err(Error::Config(ConfigError { field, .. })) => {
                assert_eq!(field, "GltConfig::spatial_threshold")
            }
            other => panic!("{c}: {other:?}"),
        }
    }
}

/// `SdTree::new` and `GuidingField::new` both reject an invalid SD-tree
/// configuration with the error for `field`.
fn check_sd(sd: SdTreeConfig, field: Option<&str>) {
    let tree = tree();
    let a = SdTree::new(scene(), sd).map(|_| ());
    let b = GuidingField::new(
        &tree,
        scene(),
        FieldConfig {
            sd,
            ..FieldConfig::default()
        },
    )
    .map(|_| ());
    match field {
        Some(name) => {
            let Err(Error::Config(e)) = a else {
                panic!("{sd:?}: {a:?}")
            };
            assert_eq!(e.field, name);
            let want = format!("{:?}", Err::<(), _>(Error::Config(e)));
            assert_eq!(format!("{b:?}"), want);
        }
        None => {
            assert_eq!(a, Ok(()), "{sd:?}");
            assert_eq!(b, Ok(()));
        }
    }
}

#[test]
fn sd_tree_config_fields() {
    let d = SdTreeConfig::default();
    check_sd(d, None);
    check_sd(SdTreeConfig::improved(), None);
    for c in [0.0, -5.0, f64::NAN, f64::INFINITY] {
        check_sd(
            SdTreeConfig {
                spatial_threshold: c,
                ..d
            },
            Some("SdTreeConfig::spatial_threshold"),
        );
    }
    for s in [0.0, 1.0] {
        check_sd(
            SdTreeConfig {
                bsdf_fraction: s,
                ..d
            },
            None,
        );
    }
    for s in [-0.1, 1.1, f32::NAN] {
        check_sd(
            SdTreeConfig {
                bsdf_fraction: s,
                ..d
            },
            Some("SdTreeConfig::bsdf_fraction"),
        );
    }
    let q = |rho, max_depth| SdTreeConfig {
        quadtree: QuadtreeConfig { rho, max_depth },
        ..d
    };
    for (rho, depth) in [(1e-6, 1), (1.0, 24), (0.01, 20)] {
        check_sd(q(rho, depth), None);
    }
    for rho in [0.0, 1e-7, 1.5, -0.1, f32::NAN] {
        check_sd(q(rho, 20), Some("QuadtreeConfig::rho"));
    }
    for depth in [0, 25, u32::MAX] {
        check_sd(q(0.01, depth), Some("QuadtreeConfig::max_depth"));
    }
}
