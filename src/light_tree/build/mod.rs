//! Building the light tree: the emitters checked ([`items`]), split top-down
//! with one of four heuristics ([`heuristic`], [`binned`]), aggregated
//! bottom-up ([`cone_bound`]), then quantised into [`LightNode`]s; and
//! [`refit`](mod@refit), the same aggregation over a built tree's shape when its
//! emitters move.

mod binned;
mod bucket;
mod cone_bound;
mod heuristic;
mod items;
mod refit;

use super::node::{LEAF_BIT, LightNode, NO_PARENT, NodeData};
use super::{BuildError, LightTree};
use crate::emitter::Emitters;
use crate::math::Aabb;
use alloc::vec::Vec;
use binned::{best_binned_split, bucket_of, partition};
use cone_bound::ConeBound;
pub use heuristic::BuildHeuristic;
use heuristic::OrientationMemo;
use items::{Item, validate};
pub(super) use refit::{refit, spread};

/// Exact (unquantised) data of a node while building.
#[derive(Clone, Copy)]
struct Aggregate {
    bounds: Aabb,
    cone: ConeBound,
    two_sided: bool,
    /// The light sets of the emitters below (their union).
    sets: u64,
    power: f64,
    link: u32,
    parent: u32,
}

struct Task {
    start: usize,
    end: usize,
    parent: u32,
    is_right: bool,
    depth: usize,
}

pub(super) fn build<E: Emitters + ?Sized>(
    emitters: &E,
    heuristic: BuildHeuristic,
) -> Result<LightTree, BuildError> {
    build_with(emitters, heuristic, best_binned_split)
}

/// Chooses the split of a node's items: the (axis, last left bucket) of the
/// cheapest binned split, or `None`; fills `scratch` with each item's bucket
/// on every axis that can be split. [`best_binned_split`] in the crate; the
/// tests compare it with a straightforward implementation.
type ChooseSplit = fn(
    &[Item],
    &mut [[u8; 3]],
    &mut OrientationMemo,
    BuildHeuristic,
    &Aabb,
    &Aabb,
) -> Option<(usize, usize)>;

fn build_with<E: Emitters + ?Sized>(
    emitters: &E,
    heuristic: BuildHeuristic,
    choose: ChooseSplit,
) -> Result<LightTree, BuildError> {
    let mut items = validate(emitters)?;
    let n = items.len();
    if n == 0 {
        return Ok(LightTree {
            nodes: Vec::new(),
            leaf_of: Vec::new(),
            scene: Aabb::EMPTY,
            depth: 0,
            built_spread: 0.0,
            sets: Vec::new(),
        });
    }
    // Past this depth, splits become medians: keeps the build O(n log n) and
    // the depth bounded for adversarial inputs, while still allowing the
    // deep, skewed trees power-weighted heuristics rightly make.
    let median_depth = 64 + 4 * (usize::BITS - n.leading_zeros()) as usize;

    let mut agg: Vec<Aggregate> = Vec::with_capacity(2 * n - 1);
    let mut scratch = alloc::vec![[0u8; 3]; n];
    let mut memo = OrientationMemo::default();
    let mut leaf_of = alloc::vec![0u32; n];
    let mut depth = 0;
    let mut stack = alloc::vec![Task {
        start: 0,
        end: n,
        parent: NO_PARENT,
        is_right: false,
        depth: 0,
    }];
    while let Some(t) = stack.pop() {
        let index = agg.len() as u32;
        if t.is_right {
            agg[t.parent as usize].link = index;
        }
        depth = depth.max(t.depth);
        if t.end - t.start == 1 {
            let it = &items[t.start];
            leaf_of[it.emitter as usize] = index;
            agg.push(Aggregate {
                bounds: it.bounds,
                cone: ConeBound::of(&it.cone),
                two_sided: it.two_sided,
                sets: it.sets,
                power: it.power as f64,
                link: LEAF_BIT | it.emitter,
                parent: t.parent,
            });
            continue;
        }
        let mid = t.start
            + split(
                &mut items[t.start..t.end],
                &mut scratch[t.start..t.end],
                &mut memo,
                heuristic,
                t.depth >= median_depth,
                choose,
            );
        agg.push(Aggregate {
            bounds: Aabb::EMPTY,
            cone: ConeBound::sphere(0.0),
            two_sided: false,
            sets: 0,
            power: 0.0,
            link: 0,
            parent: t.parent,
        });
        let child = |start, end, is_right| Task {
            start,
            end,
            parent: index,
            is_right,
            depth: t.depth + 1,
        };
        stack.push(child(mid, t.end, true));
        stack.push(child(t.start, mid, false));
    }
    drop(items);
    drop(scratch);
    let Encoded { nodes, scene, sets } = aggregate_and_encode(&mut agg)?;
    let built_spread = spread(&nodes, &scene);
    Ok(LightTree {
        nodes,
        leaf_of,
        scene,
        depth,
        built_spread,
        sets,
    })
}

/// Aggregates the nodes bottom-up (each inner node's bounds, cone, sides
/// and power from its two children; the leaves and every link filled in),
/// then quantises them against the root's bounds: the end of a build and
/// all of a refit. Children come after their parent, so one reverse sweep
/// aggregates.
fn aggregate_and_encode(agg: &mut [Aggregate]) -> Result<Encoded, BuildError> {
    if agg.is_empty() {
        return Ok(Encoded {
            nodes: Vec::new(),
            scene: Aabb::EMPTY,
            sets: Vec::new(),
        });
    }
    for i in (0..agg.len()).rev() {
        if agg[i].link & LEAF_BIT != 0 {
            continue;
        }
        let (l, r) = (agg[i + 1], agg[agg[i].link as usize]);
        let a = &mut agg[i];
        a.bounds = l.bounds.union(&r.bounds);
        a.cone = l.cone.union(&r.cone);
        a.two_sided = l.two_sided || r.two_sided;
        a.sets = l.sets | r.sets;
        a.power = l.power + r.power;
    }
    if !((agg[0].power as f32).is_finite()) {
        return Err(BuildError::PowerOverflow);
    }
    let scene = agg[0].bounds;
    let nodes = agg
        .iter()
        .map(|a| {
            LightNode::encode(
                &scene,
                &NodeData {
                    bounds: a.bounds,
                    axis: a.cone.axis,
                    theta_o: a.cone.theta_o,
                    cos_theta_e: a.cone.cos_theta_e,
                    two_sided: a.two_sided,
                    power: a.power as f32,
                    link: a.link,
                    parent: a.parent,
                },
            )
        })
        .collect();
    // The light sets per node only when some emitter is not in every set:
    // no memory, and no work for the walks, otherwise.
    let sets = match agg.iter().all(|a| a.sets == u64::MAX) {
        true => Vec::new(),
        false => agg.iter().map(|a| a.sets).collect(),
    };
    Ok(Encoded { nodes, scene, sets })
}

/// What [`aggregate_and_encode`] makes of the aggregated nodes.
pub(super) struct Encoded {
    pub(super) nodes: Vec<LightNode>,
    pub(super) scene: Aabb,
    /// Each node's light sets; empty when every node is in every set.
    pub(super) sets: Vec<u64>,
}

/// Reorders `items` and returns where the right child starts (in
/// `1..items.len()`). `scratch` (as long as `items`) receives each item's
/// bucket per axis.
fn split(
    items: &mut [Item],
    scratch: &mut [[u8; 3]],
    memo: &mut OrientationMemo,
    heuristic: BuildHeuristic,
    force_median: bool,
    choose: ChooseSplit,
) -> usize {
    let (centroids, bounds) = items.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(c, b), it| {
        (c.extend(it.centroid), b.union(&it.bounds))
    });
    let extent = centroids.diagonal();
    if force_median || heuristic == BuildHeuristic::Balanced || extent.max_element() <= 0.0 {
        return median_split(items, centroids.longest_axis());
    }
    let best = choose(items, scratch, memo, heuristic, &centroids, &bounds);
    match best {
        Some((axis, bucket)) if items.len() == 2 => {
            // The pair's buckets differ on `axis`: the lower one goes left.
            if bucket_of(&items[0], &centroids, axis) > bucket {
                items.swap(0, 1);
            }
            1
        }
        Some((axis, bucket)) => {
            let mid = partition(items, scratch, axis, bucket);
            if mid == 0 || mid == items.len() {
                median_split(items, axis)
            } else {
                mid
            }
        }
        None => median_split(items, centroids.longest_axis()),
    }
}

fn median_split(items: &mut [Item], axis: usize) -> usize {
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    mid
}

#[cfg(test)]
mod reference;
