//! `CutRules::bytes` (the GLT's and the field's `shared_bytes`) is what
//! the tables hold on the heap: measured by an allocator that counts the
//! bytes this thread has live, around `CutRules::new`, for a flat tree and
//! an instanced one (mirrored and stretched instances, so every view of a
//! mesh's table is built), with and without the importance tables.
//!
//! The one `unsafe` here is the allocator interface's own (`GlobalAlloc`
//! is an unsafe trait); every call goes straight to the system allocator.

use glam::{Affine3A, Quat, Vec3};
use guiding::cut::{CutConfig, CutRules};
use guiding::light_tree::BuildHeuristic;
use guiding::{Emitter, Instance, InstancedLightTree, LightHierarchy, LightTree};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

mod common;
use common::{Rand, mixed_scene};

thread_local! {
    /// Heap bytes this thread allocated and has not freed.
    static LIVE: Cell<isize> = const { Cell::new(0) };
}

struct Counting;

fn count(delta: isize) {
    // During thread teardown the counter may be gone: nothing to count.
    let _ = LIVE.try_with(|l| l.set(l.get() + delta));
}

// SAFETY: every method forwards to `System` with the caller's arguments,
// which upholds the contract the caller upheld.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size() as isize);
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count(layout.size() as isize);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        count(-(layout.size() as isize));
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count(new_size as isize - layout.size() as isize);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The heap bytes `CutRules::new(tree, config)` leaves live, and what the
/// rules report.
fn measured<H: LightHierarchy>(tree: H, config: CutConfig) -> (isize, usize) {
    let before = LIVE.with(Cell::get);
    let rules = CutRules::new(tree, config).unwrap();
    let live = LIVE.with(Cell::get) - before;
    let reported = rules.bytes();
    drop(rules);
    (live, reported)
}

#[test]
fn the_tables_report_the_heap_they_hold() {
    let lights = mixed_scene(3000, 5);
    let flat = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut r = Rand::new(81);
    let meshes: Vec<LightTree> = [300, 7]
        .map(|n| {
            let tris: Vec<Emitter> = (0..n)
                .map(|_| {
                    let c = r.point(1.0);
                    Emitter::triangle([c, c + r.dir() * 0.1, c + r.dir() * 0.1], 1.0, false)
                })
                .collect();
            LightTree::build(tris.as_slice(), BuildHeuristic::Sarh).unwrap()
        })
        .into();
    let instances: Vec<Instance> = (0..60)
        .map(|i| {
            let scale = match i % 3 {
                0 => Vec3::splat(2.0),
                1 => Vec3::new(-1.0, 1.0, 1.0),
                _ => Vec3::new(3.0, 1.0, 0.5),
            };
            let turn = Quat::from_axis_angle(r.dir(), r.range(0.0, 6.0));
            let t = Affine3A::from_scale_rotation_translation(scale, turn, r.point(50.0));
            Instance::new(i % 2, t)
        })
        .collect();
    let instanced = InstancedLightTree::build(meshes, &instances, BuildHeuristic::Sarh).unwrap();
    for config in [
        CutConfig::default(),
        CutConfig::default().with_paper_rules(),
    ] {
        let (live, reported) = measured(&flat, config);
        assert_eq!(live, reported as isize, "flat tree, {config:?}");
        let (live, reported) = measured(&instanced, config);
        assert_eq!(live, reported as isize, "instanced tree, {config:?}");
        assert!(reported > 0);
    }
}
