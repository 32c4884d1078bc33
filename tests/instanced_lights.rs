//! Instanced emissive meshes (`InstancedLightTree`): a hierarchy that
//! stands for the flat tree of every instance's triangles in world space.
//! Checked against that flat scene: the structure names every emitter once
//! and its bounds contain the world-space triangles below; every tree
//! sampler and the GLT sample it exactly (pmf sums to 1, sample == pmf bit
//! for bit, chi-square) and without bias (every light that contributes has
//! a positive pmf, so the estimate's expectation is the flat sum).

use glam::{Affine3A, Quat, Vec3};
use guiding::LightChoice;
use guiding::cut::CutConfig;
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::{ImportanceTreeSampler, PowerTreeSampler};
use guiding::light_tree::{BuildHeuristic, fingerprint, shape_fingerprint};
use guiding::math::Aabb;
use guiding::persist::LoadError;
use guiding::{
    BuildError, Emitter, Instance, InstancedLightTree, LightHierarchy, LightId, LightSampler,
    LightTree, ShadingContext,
};

mod common;
use common::{Flattened, LightsAt, Rand, contribution, emitter_draws};

/// A triangle of a mesh: corners, power, two-sided.
type Triangle = ([Vec3; 3], f32, bool);

/// A mesh of `n` small triangles in the unit box around the origin (one-
/// and two-sided, powers spread over two decades).
fn mesh(n: usize, r: &mut Rand) -> Vec<Triangle> {
    (0..n)
        .map(|_| {
            let c = r.point(1.0);
            let p = [c, c + r.dir() * 0.1, c + r.dir() * 0.1];
            (p, 10f32.powf(r.range(-1.0, 1.0)), r.f() < 0.3)
        })
        .collect()
}

fn emitters(triangles: &[Triangle], inst: &Instance) -> Vec<Emitter> {
    triangles
        .iter()
        .map(|&(p, power, two_sided)| {
            let p = p.map(|c| inst.transform.transform_point3(c));
            Emitter::triangle(p, power * inst.power_scale, two_sided)
        })
        .collect()
}

/// A mesh's tree, built in mesh space.
fn mesh_tree(triangles: &[Triangle]) -> LightTree {
    let local = emitters(triangles, &Instance::new(0, Affine3A::IDENTITY));
    LightTree::build(local.as_slice(), BuildHeuristic::Sarh).unwrap()
}

struct Scene {
    tree: InstancedLightTree,
    /// The same lights flat in world space, in the instanced tree's
    /// emitter order.
    flat: Vec<Emitter>,
}

/// Three meshes (40 triangles, one triangle, none) in 12 instances:
/// rotated and scaled, mirrored, stretched (a non-uniform scale), one
/// emitting 5x.
fn scene() -> Scene {
    scene_with(|_| {})
}

/// [`scene`] with its instances changed by `change` before the build.
fn scene_with(change: impl Fn(&mut Vec<Instance>)) -> Scene {
    let mut r = Rand::new(71);
    let meshes: Vec<Vec<Triangle>> = [40, 1, 0].map(|n| mesh(n, &mut r)).into();
    let trees: Vec<LightTree> = meshes.iter().map(|m| mesh_tree(m)).collect();
    let mut instances = Vec::new();
    for i in 0..12 {
        let at = Vec3::new(
            i as f32 * 7.0 - 40.0,
            r.range(-5.0, 5.0),
            r.range(-20.0, 20.0),
        );
        let turn = Quat::from_axis_angle(r.dir(), r.range(0.0, 6.0));
        let transform = match i % 4 {
            0 => Affine3A::from_scale_rotation_translation(Vec3::splat(3.0), turn, at),
            1 => Affine3A::from_scale_rotation_translation(Vec3::new(-2.0, 2.0, 2.0), turn, at),
            2 => Affine3A::from_scale_rotation_translation(Vec3::new(4.0, 1.0, 0.5), turn, at),
            _ => Affine3A::from_rotation_translation(turn, at),
        };
        let mesh = match i {
            5 => 1,
            7 => 2,
            _ => 0,
        };
        let inst = Instance::new(mesh, transform);
        instances.push(if i == 3 { inst.emitting(5.0) } else { inst });
    }
    change(&mut instances);
    let tree = InstancedLightTree::build(trees, &instances, BuildHeuristic::Sarh).unwrap();
    let flat = instances
        .iter()
        .flat_map(|inst| emitters(&meshes[inst.mesh as usize], inst))
        .collect();
    Scene { tree, flat }
}

#[test]
fn it_names_every_emitter_once_and_bounds_what_is_below() {
    let Scene { tree, flat } = scene();
    assert_eq!(tree.emitter_count(), flat.len());
    for (i, e) in flat.iter().enumerate() {
        let e_id = i as u32;
        let leaf = tree.leaf(e_id).unwrap();
        assert_eq!(tree.emitter(leaf), Some(e_id));
        assert_eq!(tree.children(leaf), None);
        let (inst, t) = tree.locate(e_id).unwrap();
        assert_eq!(tree.emitter_id(inst, t), Some(e_id));
        // Every node on its path bounds it.
        let mut node = Some(leaf);
        while let Some(n) = node {
            let b = tree.node_bounds(n);
            let grown = Aabb::new(b.bounds.min - 1e-3, b.bounds.max + 1e-3);
            assert!(
                grown.contains(e.bounds.min) && grown.contains(e.bounds.max),
                "node {n} does not bound emitter {i}"
            );
            // Its normal lies in the node's normal cone (turned, mirrored
            // or stretched with the instance).
            if let (Some(c), true) = (e.cone, b.cone.cos_theta_o > -1.0) {
                let angle = c.axis.angle_between(b.cone.axis);
                let bound = b.cone.cos_theta_o.clamp(-1.0, 1.0).acos();
                assert!(
                    angle <= bound + 1e-4,
                    "node {n}: emitter {i}'s normal {angle} off, bound {bound}"
                );
            }
            node = tree.parent(n);
        }
    }
    // Every node reached once from the root, powers adding up.
    let mut seen = vec![false; tree.node_count()];
    let mut stack = vec![tree.root().unwrap()];
    let mut leaves = 0;
    while let Some(n) = stack.pop() {
        assert!(
            !std::mem::replace(&mut seen[n as usize], true),
            "node {n} twice"
        );
        match tree.children(n) {
            Some([a, b]) => {
                assert_eq!(tree.parent(a), Some(n));
                assert_eq!(tree.parent(b), Some(n));
                let sum = tree.power(a) + tree.power(b);
                assert!(
                    (tree.power(n) - sum).abs() <= 1e-3 * sum.max(1e-6),
                    "node {n}"
                );
                stack.extend([a, b]);
            }
            None => leaves += 1,
        }
    }
    assert!(seen.iter().all(|&s| s));
    // The empty mesh's instance is a leaf with no emitter.
    assert_eq!(leaves, flat.len() + 1);
    assert_eq!(tree.locate(flat.len() as u32), None);
    assert_eq!(tree.emitter_id(0, 40), None);
}

/// The contract of `s` at `ctx` over the flat lights: pmf sums to 1,
/// draws report their pmf bit for bit, and no light that contributes has
/// pmf 0 (so the estimate is unbiased: its expectation is the flat sum).
fn check(name: &str, s: &dyn LightChoice, flat: &[Emitter], ctx: &ShadingContext, r: &mut Rand) {
    let mut total = 0.0;
    let mut expectation = 0.0;
    let mut sum = 0.0;
    for (i, e) in flat.iter().enumerate() {
        let pmf = s.pmf_exact(LightId::Emitter(i as u32));
        let f = contribution(e, ctx.position);
        assert!(
            f == 0.0 || pmf > 0.0,
            "{name}: light {i} contributes with pmf 0"
        );
        if pmf > 0.0 {
            expectation += pmf * (f / pmf);
        }
        sum += f;
        total += pmf;
    }
    assert!((total - 1.0).abs() < 1e-6, "{name}: total {total}");
    assert!((expectation - sum).abs() <= 1e-9 * sum, "{name}");
    for _ in 0..40 {
        let x = s.sample(r.f()).unwrap();
        assert_eq!(x.pmf.to_bits(), s.pmf(x.light).to_bits(), "{name}");
    }
}

#[test]
fn every_tree_sampler_samples_it_exactly() {
    let Scene { tree, flat } = scene();
    let importance = ImportanceTreeSampler::new(&tree);
    let power = PowerTreeSampler::new(&tree);
    let mut r = Rand::new(72);
    for _ in 0..30 {
        let p = r.point(50.0);
        for ctx in [
            ShadingContext::at(p),
            ShadingContext::on_surface(p, r.dir()),
        ] {
            check("importance", &importance.at(&ctx), &flat, &ctx, &mut r);
            check("power", &power.at(&ctx), &flat, &ctx, &mut r);
        }
    }
    // The power tree's pmf is each light's share of the power, as flat.
    let total: f64 = flat.iter().map(|e| f64::from(e.power)).sum();
    let ctx = ShadingContext::at(Vec3::ZERO);
    for (i, e) in flat.iter().enumerate() {
        let pmf = power.pmf_exact(&ctx, LightId::Emitter(i as u32));
        let share = f64::from(e.power) / total;
        assert!(
            (pmf - share).abs() <= 1e-4 * share,
            "light {i}: {pmf} vs {share}"
        );
    }
}

#[test]
fn draws_follow_the_pmf() {
    let Scene { tree, flat } = scene();
    let s = ImportanceTreeSampler::new(&tree);
    let ctx = ShadingContext::on_surface(Vec3::new(3.0, 1.0, -2.0), Vec3::Y);
    let (_, z) = emitter_draws(&s.at(&ctx), flat.len(), 200_000, &mut Rand::new(73));
    assert!(z < 4.0, "chi-square z {z}");
}

/// A GLT over `tree` trained on `flat`'s contributions at random points
/// (4 rounds of 20,000 records, one cell).
fn trained_glt<H: LightHierarchy>(tree: H, flat: &[Emitter], cut: CutConfig) -> Glt<H> {
    let bounds = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
    let config = GltConfig {
        spatial_threshold: 1e9,
        cut,
        ..GltConfig::default()
    };
    let mut glt = Glt::new(tree, bounds, config).unwrap();
    let mut r = Rand::new(74);
    for _ in 0..4 {
        for _ in 0..20_000 {
            let p = r.point(50.0);
            let e = r.below(flat.len() as u32);
            let v = contribution(&flat[e as usize], p) as f32 * flat.len() as f32;
            glt.record_light_at(p, LightId::Emitter(e), v);
        }
        glt.refine();
    }
    glt
}

/// The GLT over instances: its cuts descend into the instances' subtrees,
/// and it samples exactly, trained, under the default rules (importance
/// everywhere, read from the meshes' tables in mesh space) and the
/// paper's (power below the cut).
#[test]
fn the_glt_learns_inside_instances() {
    let Scene { tree, flat } = scene();
    let mut r = Rand::new(76);
    for config in [
        CutConfig::default(),
        CutConfig::default().with_paper_rules(),
    ] {
        let glt = trained_glt(&tree, &flat, config);
        let top = tree.top().node_count() as u32;
        let v = glt.light_at(Vec3::ZERO);
        v.cut().check(&tree).unwrap();
        let deepest = v.cut().clusters(&tree).iter().map(|c| c.0).max().unwrap();
        assert!(
            deepest >= top,
            "the cut stays in the top tree ({deepest} < {top})"
        );
        for _ in 0..20 {
            let p = r.point(50.0);
            check(
                "glt",
                &glt.light_at(p),
                &flat,
                &ShadingContext::at(p),
                &mut r,
            );
            let on_surface = ShadingContext::on_surface(p, r.dir());
            let v = glt.vertex(&on_surface).unwrap();
            check("glt", &v, &flat, &on_surface, &mut r);
            // Walks into the instances' tables share only the top tree's
            // steps; together or alone, the same candidates.
            assert!(common::candidates_match(&v, &mut r) > 0);
        }
    }
}

/// Where an instance's world bounds are its mesh's moved exactly (turns by
/// right angles, uniform scales, a mirror, translations), the tables
/// shared per mesh, read with the point in mesh space, give the light
/// choice of world-space tables over every node up to rounding: total
/// variation below 1e-5 at every point (3e-7 seen), fresh and trained,
/// with and without a normal.
/// Turned emitters, turned normals and mirrored one-sided triangles all
/// count in it.
#[test]
fn per_mesh_tables_choose_as_world_tables_do() {
    let mut r = Rand::new(77);
    let triangles = mesh(40, &mut r);
    let mesh_tree = mesh_tree(&triangles);
    let quarter = core::f32::consts::FRAC_PI_2;
    let instances: Vec<Instance> = (0..10)
        .map(|i| {
            let at = Vec3::new(
                i as f32 * 9.0 - 40.0,
                r.range(-5.0, 5.0),
                r.range(-20.0, 20.0),
            );
            let turn = match i % 3 {
                0 => Quat::IDENTITY,
                1 => Quat::from_rotation_z(quarter),
                _ => Quat::from_rotation_x(quarter) * Quat::from_rotation_y(2.0 * quarter),
            };
            let scale = match i % 4 {
                0 => Vec3::splat(2.0),
                1 => Vec3::new(-3.0, 3.0, 3.0),
                2 => Vec3::new(1.0, -1.0, 1.0),
                _ => Vec3::ONE,
            };
            Instance::new(
                0,
                Affine3A::from_scale_rotation_translation(scale, turn, at),
            )
        })
        .collect();
    let tree =
        InstancedLightTree::build(vec![mesh_tree], &instances, BuildHeuristic::Sarh).unwrap();
    let flat: Vec<Emitter> = instances
        .iter()
        .flat_map(|inst| emitters(&triangles, inst))
        .collect();
    for trained in [false, true] {
        let config = CutConfig::default();
        let (shared, world) = match trained {
            true => (
                trained_glt(&tree, &flat, config),
                trained_glt(Flattened(&tree), &flat, config),
            ),
            false => {
                let bounds = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
                let config = GltConfig::default();
                (
                    Glt::new(&tree, bounds, config).unwrap(),
                    Glt::new(Flattened(&tree), bounds, config).unwrap(),
                )
            }
        };
        for _ in 0..40 {
            let p = r.point(50.0);
            for ctx in [
                ShadingContext::at(p),
                ShadingContext::on_surface(p, r.dir()),
            ] {
                let (a, b) = (shared.light_at(p), world.light_at(p));
                let tv: f64 = (0..flat.len() as u32)
                    .map(|e| {
                        let l = LightId::Emitter(e);
                        (a.pmf_exact(l) - b.pmf_exact(l)).abs()
                    })
                    .sum::<f64>()
                    / 2.0;
                assert!(
                    tv < 1e-5,
                    "trained {trained}, {ctx:?}: total variation {tv}"
                );
            }
        }
    }
}

/// The GLT's tables over instances take the meshes' and instances' room,
/// not the placed triangles': 200 instances of a 500-triangle mesh need
/// under 1/20 of what tables over every node of the flat tree take.
#[test]
fn the_glts_tables_grow_with_meshes_not_placed_triangles() {
    let mut r = Rand::new(78);
    let triangles = mesh(500, &mut r);
    let mesh_tree = mesh_tree(&triangles);
    let instances: Vec<Instance> = (0..200)
        .map(|i| Instance::new(0, Affine3A::from_translation(Vec3::X * i as f32 * 3.0)))
        .collect();
    let tree =
        InstancedLightTree::build(vec![mesh_tree], &instances, BuildHeuristic::Sarh).unwrap();
    let bounds = Aabb::new(Vec3::splat(-10.0), Vec3::splat(700.0));
    let shared = Glt::new(&tree, bounds, GltConfig::default()).unwrap();
    let world = Glt::new(Flattened(&tree), bounds, GltConfig::default()).unwrap();
    let (s, w) = (shared.memory().shared_bytes, world.memory().shared_bytes);
    assert!(20 * s < w, "{s} bytes shared vs {w} over every node");
    // The guiding field's cuts share the same tables.
    let field = GuidingField::new(&tree, bounds, FieldConfig::default()).unwrap();
    assert_eq!(field.memory().shared_bytes, s);
}

/// A GLT over instances is saved, loaded, refitted and merged by the
/// parts of its tree (`shape_fingerprint` and `fingerprint` hash the top
/// tree, the meshes and the instances, not the flat tree node by node):
/// it loads back exactly, over the tree moved as a whole too (the same
/// shape), and nowhere the instances place other meshes; it merges only
/// with a copy over the same tree.
#[test]
fn a_glt_over_instances_saves_and_binds_by_its_parts() {
    let Scene { tree, flat } = scene();
    let glt = trained_glt(&tree, &flat, CutConfig::default());
    let bytes = glt.to_bytes();
    let back = Glt::from_bytes(&bytes, &tree).unwrap();
    let mut r = Rand::new(79);
    for _ in 0..20 {
        let ctx = ShadingContext::on_surface(r.point(50.0), r.dir());
        let (a, b) = (glt.vertex(&ctx).unwrap(), back.vertex(&ctx).unwrap());
        for e in 0..flat.len() as u32 {
            let l = LightId::Emitter(e);
            assert_eq!(a.pmf_exact(l).to_bits(), b.pmf_exact(l).to_bits());
        }
    }
    // Moved as a whole: the same shape, other bounds.
    let moved = scene_with(|instances| {
        for inst in instances.iter_mut() {
            inst.transform.translation += glam::Vec3A::new(64.0, 0.0, 0.0);
        }
    });
    assert_eq!(shape_fingerprint(&moved.tree), shape_fingerprint(&tree));
    assert_ne!(fingerprint(&moved.tree), fingerprint(&tree));
    assert!(Glt::from_bytes(&bytes, &moved.tree).is_ok());
    let mut refitted = glt.clone();
    assert!(refitted.set_light_tree(&moved.tree).is_ok());
    // Two instances of different meshes swapped: another shape.
    let swapped = scene_with(|instances| {
        let (a, b) = (instances[4].mesh, instances[5].mesh);
        instances[4].mesh = b;
        instances[5].mesh = a;
    });
    assert_ne!(shape_fingerprint(&swapped.tree), shape_fingerprint(&tree));
    assert!(matches!(
        Glt::from_bytes(&bytes, &swapped.tree),
        Err(LoadError::LightTreeMismatch { .. })
    ));
    let mut other = glt.clone();
    assert!(other.set_light_tree(&swapped.tree).is_err());
    // Merged with a copy over the same tree, not over the moved one.
    let mut copy = back;
    assert!(copy.merge(&glt));
    assert!(!refitted.merge(&glt));
}

/// Two meshes of 40 triangles each (trees of different shapes) in two
/// instances far apart, then with the meshes swapped: the top trees, the
/// counts and the mesh list are the same, the flat trees' shapes are not,
/// and neither are the fingerprints (which hash each instance's mesh);
/// state saved over one does not load over the other.
#[test]
fn the_shape_binds_each_instance_to_its_mesh() {
    let mut r = Rand::new(80);
    let meshes = [mesh(40, &mut r), mesh(40, &mut r)];
    let build = |first: u32| {
        let trees = meshes.iter().map(|m| mesh_tree(m)).collect();
        let placed = [
            Instance::new(first, Affine3A::from_translation(Vec3::X * -20.0)),
            Instance::new(1 - first, Affine3A::from_translation(Vec3::X * 20.0)),
        ];
        InstancedLightTree::build(trees, &placed, BuildHeuristic::Sarh).unwrap()
    };
    let (a, b) = (build(0), build(1));
    assert_eq!(shape_fingerprint(a.top()), shape_fingerprint(b.top()));
    assert_eq!(a.node_count(), b.node_count());
    let differs = (0..a.node_count() as u32).any(|n| a.children(n) != b.children(n));
    assert!(differs, "the meshes' trees have the same shape: no test");
    assert_ne!(shape_fingerprint(&a), shape_fingerprint(&b));
    let bounds = Aabb::new(Vec3::splat(-30.0), Vec3::splat(30.0));
    let glt = Glt::new(&a, bounds, GltConfig::default()).unwrap();
    assert!(Glt::from_bytes(&glt.to_bytes(), &b).is_err());
    assert!(glt.clone().set_light_tree(&b).is_err());
}

#[test]
fn bad_instances_are_typed_errors() {
    let mut r = Rand::new(75);
    let triangles = mesh(5, &mut r);
    let meshes = || vec![mesh_tree(&triangles)];
    let ok = Instance::new(0, Affine3A::IDENTITY);
    let cases = [
        Instance { mesh: 1, ..ok },
        Instance::new(0, Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0))),
        Instance::new(0, Affine3A::from_translation(Vec3::NAN)),
        Instance {
            power_scale: -1.0,
            ..ok
        },
        Instance {
            power_scale: f32::INFINITY,
            ..ok
        },
    ];
    for bad in cases {
        let got = InstancedLightTree::build(meshes(), &[ok, bad], BuildHeuristic::Sarh);
        assert_eq!(
            got.err(),
            Some(BuildError::InvalidInstance { instance: 1 }),
            "{bad:?}"
        );
    }
    // No instance: an empty hierarchy that chooses nothing.
    let empty = InstancedLightTree::build(meshes(), &[], BuildHeuristic::Sarh).unwrap();
    assert_eq!(empty.root(), None);
    let s = ImportanceTreeSampler::new(&empty);
    assert!(s.sample(&ShadingContext::at(Vec3::ZERO), 0.5).is_none());
}
