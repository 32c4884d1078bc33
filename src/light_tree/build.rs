//! Building the light tree: validation, top-down splitting with one of four
//! heuristics, bottom-up aggregation, then quantisation into [`LightNode`]s.

use super::node::{LEAF_BIT, LightNode, NO_PARENT, NodeData};
use super::{BuildError, LightTree};
use crate::emitter::Emitters;
use crate::math::scalar::{cos, safe_acos, sin_cos};
use crate::math::{Aabb, LightCone, cone_angle_between};
use alloc::vec::Vec;
use core::f32::consts::PI;
use glam::{Quat, Vec3};

/// How the builder chooses where to split a set of emitters.
///
/// The three of the paper weight the classic surface-area cost
/// `SA(left) * W(left) + SA(right) * W(right)` differently; SAOH is pbrt-v4's
/// orientation-aware cost. All binned ones evaluate 12 buckets per axis.
/// Where a weight sums to zero (point lights under SAH, dark lights under
/// SARH) the split falls back to counting emitters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildHeuristic {
    /// Median split by count along the widest axis: equal weight per
    /// emitter, depth `ceil(log2 n)`.
    Balanced,
    /// Surface-area heuristic weighted by emitter surface area.
    Sah,
    /// Surface-area-radiance heuristic: SAH weighted by area x radiosity
    /// (= power). The paper's choice: a few percent lower RMSE and memory.
    #[default]
    Sarh,
    /// pbrt-v4's surface-area-orientation heuristic: power x M_omega(cone)
    /// x surface area x the box's aspect factor.
    Saoh,
}

const BUCKETS: usize = 12;

/// One emitter during the build, copied so partitioning stays local.
#[derive(Clone, Copy)]
struct Item {
    bounds: Aabb,
    centroid: Vec3,
    cone: LightCone,
    /// `safe_acos(cone.cos_theta_o)`, for SAOH's cone unions.
    theta_o: f32,
    power: f32,
    area: f32,
    emitter: u32,
    two_sided: bool,
}

/// Exact (unquantised) data of a node while building.
#[derive(Clone, Copy)]
struct Aggregate {
    bounds: Aabb,
    cone: ConeBound,
    two_sided: bool,
    power: f64,
    link: u32,
    parent: u32,
}

/// A node's direction bound while aggregating: pbrt-v4's cone union, but
/// with `theta_o` kept as an angle. [`LightCone`] stores `cos(theta_o)` in
/// `f32`, whose spacing near 1 hides angles up to ~3e-4 rad, so repeated
/// unions through it can end up narrower than their children; here every
/// union is widened by its own rounding error instead, so the result always
/// bounds the children.
#[derive(Clone, Copy, Debug)]
struct ConeBound {
    axis: Vec3,
    /// Half-angle of the normal cone; `>= pi` is the whole sphere.
    theta_o: f32,
    cos_theta_e: f32,
}

/// Covers the float error of one angle computation or rotation (a few
/// ulps of pi, with room to spare).
const ANGLE_SLACK: f32 = 2e-6;

impl ConeBound {
    fn sphere(cos_theta_e: f32) -> Self {
        Self {
            axis: Vec3::Z,
            theta_o: PI,
            cos_theta_e,
        }
    }

    fn of(c: &LightCone) -> Self {
        if c.is_sphere() {
            return Self::sphere(c.cos_theta_e);
        }
        Self {
            axis: c.axis,
            // Rounded to nearest; the node encoder's margin covers the
            // half ulp.
            theta_o: libm::acos(c.cos_theta_o.clamp(-1.0, 1.0) as f64) as f32,
            cos_theta_e: c.cos_theta_e,
        }
    }

    fn is_sphere(&self) -> bool {
        self.theta_o.partial_cmp(&PI) != Some(core::cmp::Ordering::Less)
    }

    fn union(&self, o: &Self) -> Self {
        let cos_theta_e = self.cos_theta_e.min(o.cos_theta_e);
        if self.is_sphere() || o.is_sphere() {
            return Self::sphere(cos_theta_e);
        }
        if self.axis == o.axis {
            return Self {
                theta_o: self.theta_o.max(o.theta_o),
                cos_theta_e,
                ..*self
            };
        }
        let d = cone_angle_between(self.axis, o.axis) + ANGLE_SLACK;
        if d + o.theta_o <= self.theta_o {
            return Self {
                cos_theta_e,
                ..*self
            };
        }
        if d + self.theta_o <= o.theta_o {
            return Self { cos_theta_e, ..*o };
        }
        let theta_o = (self.theta_o + d + o.theta_o) * 0.5;
        if theta_o + ANGLE_SLACK >= PI {
            return Self::sphere(cos_theta_e);
        }
        let Some(wr) = self.axis.cross(o.axis).try_normalize() else {
            return Self::sphere(cos_theta_e);
        };
        let Some(axis) =
            (Quat::from_axis_angle(wr, theta_o - self.theta_o) * self.axis).try_normalize()
        else {
            return Self::sphere(cos_theta_e);
        };
        Self {
            axis,
            theta_o: theta_o + ANGLE_SLACK,
            cos_theta_e,
        }
    }
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

/// The fast binned choice: one pass over the items for all three axes
/// ([`best_bucket_split`]), two-item nodes without buckets
/// ([`best_pair_split`]).
fn best_binned_split(
    items: &[Item],
    scratch: &mut [[u8; 3]],
    memo: &mut OrientationMemo,
    heuristic: BuildHeuristic,
    centroids: &Aabb,
    bounds: &Aabb,
) -> Option<(usize, usize)> {
    let saoh = heuristic == BuildHeuristic::Saoh;
    match (items.len() == 2, saoh) {
        (true, true) => best_pair_split::<true>(items, memo, heuristic, centroids, bounds),
        (true, false) => best_pair_split::<false>(items, memo, heuristic, centroids, bounds),
        (false, true) => {
            best_bucket_split::<true>(items, scratch, memo, heuristic, centroids, bounds)
        }
        (false, false) => {
            best_bucket_split::<false>(items, scratch, memo, heuristic, centroids, bounds)
        }
    }
}

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

    // Children come after their parent, so a reverse sweep aggregates.
    for i in (0..agg.len()).rev() {
        if agg[i].link & LEAF_BIT != 0 {
            continue;
        }
        let (l, r) = (agg[i + 1], agg[agg[i].link as usize]);
        let a = &mut agg[i];
        a.bounds = l.bounds.union(&r.bounds);
        a.cone = l.cone.union(&r.cone);
        a.two_sided = l.two_sided || r.two_sided;
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
    Ok(LightTree {
        nodes,
        leaf_of,
        scene,
        depth,
    })
}

fn validate<E: Emitters + ?Sized>(emitters: &E) -> Result<Vec<Item>, BuildError> {
    let count = emitters.len();
    if count > (LEAF_BIT - 1) as usize {
        return Err(BuildError::TooManyEmitters { count });
    }
    let mut items = Vec::with_capacity(count);
    for i in 0..count {
        let bounds = emitters.bounds(i);
        if !bounds.is_finite() || bounds.is_empty() {
            return Err(BuildError::InvalidBounds { emitter: i });
        }
        let power = emitters.power(i);
        if !(power >= 0.0 && power.is_finite()) {
            return Err(BuildError::InvalidPower { emitter: i, power });
        }
        let area = emitters.area(i);
        if !(area >= 0.0 && area.is_finite()) {
            return Err(BuildError::InvalidArea { emitter: i, area });
        }
        let cone = match emitters.cone(i) {
            None => LightCone::SPHERE,
            Some(c) => {
                if !(c.axis.is_finite() && c.cos_theta_o.is_finite() && c.cos_theta_e.is_finite()) {
                    return Err(BuildError::InvalidCone { emitter: i });
                }
                // Keep the caller's cosines (a cos/acos round trip would
                // narrow small cones); only the axis is normalised.
                match c.axis.try_normalize() {
                    Some(axis) => LightCone {
                        axis,
                        cos_theta_o: c.cos_theta_o.clamp(-1.0, 1.0),
                        cos_theta_e: c.cos_theta_e.clamp(-1.0, 1.0),
                    },
                    None => LightCone {
                        cos_theta_e: c.cos_theta_e.clamp(-1.0, 1.0),
                        ..LightCone::SPHERE
                    },
                }
            }
        };
        items.push(Item {
            bounds,
            // Halves first: `min + max` overflows for boxes near f32::MAX.
            centroid: bounds.min * 0.5 + bounds.max * 0.5,
            power,
            area,
            theta_o: safe_acos(cone.cos_theta_o),
            cone,
            two_sided: emitters.two_sided(i),
            emitter: i as u32,
        });
    }
    Ok(items)
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

#[inline]
fn bucket_of(it: &Item, centroids: &Aabb, axis: usize) -> usize {
    let t = (it.centroid[axis] - centroids.min[axis]) / (centroids.max[axis] - centroids.min[axis]);
    // `as u32` saturates like `as usize` (NaN -> 0) but converts cheaply.
    ((t * BUCKETS as f32) as u32 as usize).min(BUCKETS - 1)
}

/// The emitters of one bucket (or a run of buckets) on one axis. Under SAOH
/// it also bounds their cones (meaningful when `count > 0`), carrying
/// `theta_o` beside the cone so that `acos` is only taken when the cone
/// changes.
#[derive(Clone, Copy)]
struct Bucket {
    bounds: Aabb,
    area: f64,
    power: f64,
    count: usize,
    cone: LightCone,
    theta_o: f32,
}

const EMPTY_BUCKET: Bucket = Bucket {
    bounds: Aabb::EMPTY,
    area: 0.0,
    power: 0.0,
    count: 0,
    cone: LightCone::SPHERE,
    theta_o: PI,
};

impl Bucket {
    #[inline]
    fn add<const SAOH: bool>(&mut self, it: &Item) {
        if SAOH {
            (self.cone, self.theta_o) = if self.count == 0 {
                (it.cone, it.theta_o)
            } else {
                cone_union(&self.cone, self.theta_o, &it.cone, it.theta_o)
            };
        }
        self.count += 1;
        self.bounds = self.bounds.union(&it.bounds);
        self.area += it.area as f64;
        self.power += it.power as f64;
    }

    #[inline]
    fn merge<const SAOH: bool>(&self, o: &Bucket) -> Bucket {
        let (cone, theta_o) = if !SAOH || o.count == 0 {
            (self.cone, self.theta_o)
        } else if self.count == 0 {
            (o.cone, o.theta_o)
        } else {
            cone_union(&self.cone, self.theta_o, &o.cone, o.theta_o)
        };
        Bucket {
            bounds: self.bounds.union(&o.bounds),
            area: self.area + o.area,
            power: self.power + o.power,
            count: self.count + o.count,
            cone,
            theta_o,
        }
    }
}

/// Exactly [`LightCone::union`] (same operations, same result bits), with
/// each cone's `theta_o = safe_acos(cos_theta_o)` passed in instead of
/// recomputed; returns the union and its `theta_o`. Binning calls this once
/// per emitter and axis, and most calls merge equal or nested cones, where
/// the cached angles save every `acos`.
#[inline]
fn cone_union(a: &LightCone, theta_a: f32, b: &LightCone, theta_b: f32) -> (LightCone, f32) {
    if a.is_sphere() || b.is_sphere() {
        let cos_theta_e = a.cos_theta_e.min(b.cos_theta_e);
        // A sphere's cached angle is `safe_acos(-1)`, as `theta_o()` would
        // compute it; pass it on rather than assume it equals `PI`.
        let theta = if a.is_sphere() { theta_a } else { theta_b };
        return (
            LightCone {
                cos_theta_e,
                ..LightCone::SPHERE
            },
            theta,
        );
    }
    if a == b {
        // angle_between(x, x) == 0, so the union is `a`.
        return (*a, theta_a);
    }
    cone_union_general(a, theta_a, b, theta_b)
}

#[inline(never)]
fn cone_union_general(
    a: &LightCone,
    theta_a: f32,
    b: &LightCone,
    theta_b: f32,
) -> (LightCone, f32) {
    let cos_theta_e = a.cos_theta_e.min(b.cos_theta_e);
    let sphere = || {
        let c = LightCone {
            cos_theta_e,
            ..LightCone::SPHERE
        };
        (c, safe_acos(c.cos_theta_o))
    };
    let theta_d = cone_angle_between(a.axis, b.axis);
    if (theta_d + theta_b).min(PI) <= theta_a {
        return (LightCone { cos_theta_e, ..*a }, theta_a);
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return (LightCone { cos_theta_e, ..*b }, theta_b);
    }
    let theta_o = (theta_a + theta_d + theta_b) * 0.5;
    if theta_o >= PI {
        return sphere();
    }
    let Some(wr) = a.axis.cross(b.axis).try_normalize() else {
        return sphere();
    };
    let axis = Quat::from_axis_angle(wr, theta_o - theta_a) * a.axis;
    let c = LightCone {
        axis: axis.normalize_or(Vec3::Z),
        cos_theta_o: cos(theta_o),
        cos_theta_e,
    };
    (c, safe_acos(c.cos_theta_o))
}

/// The (axis, last left bucket) of the cheapest split, ties broken towards
/// balanced counts; `None` when no axis can be split. Fills `scratch` with
/// every item's bucket on every axis that can be split.
///
/// All three axes are binned in one pass over the items, and only the
/// boundaries between non-empty buckets are evaluated: every boundary inside
/// a run of empty buckets gives the same partition and the same cost, and the
/// first of them is the one a full scan would keep.
fn best_bucket_split<const SAOH: bool>(
    items: &[Item],
    scratch: &mut [[u8; 3]],
    memo: &mut OrientationMemo,
    heuristic: BuildHeuristic,
    centroids: &Aabb,
    bounds: &Aabb,
) -> Option<(usize, usize)> {
    let splittable = [0, 1, 2].map(|a| centroids.max[a] > centroids.min[a]);
    let mut buckets = [[EMPTY_BUCKET; BUCKETS]; 3];
    let mut total_area = 0.0f64;
    let mut total_power = 0.0f64;
    for (it, s) in items.iter().zip(scratch.iter_mut()) {
        total_area += it.area as f64;
        total_power += it.power as f64;
        for axis in 0..3 {
            if splittable[axis] {
                let b = bucket_of(it, centroids, axis);
                s[axis] = b as u8;
                buckets[axis][b].add::<SAOH>(it);
            }
        }
    }
    let weights = Weights::new(heuristic, total_area, total_power);
    let diag = bounds.diagonal();
    let mut best: Option<(f64, usize, usize, usize)> = None; // cost, imbalance, axis, bucket
    for axis in 0..3 {
        if !splittable[axis] {
            continue;
        }
        let buckets = &buckets[axis];
        let mut full = [0usize; BUCKETS];
        let mut m = 0;
        for (i, b) in buckets.iter().enumerate() {
            if b.count > 0 {
                full[m] = i;
                m += 1;
            }
        }
        // Suffix merges: right[j] = full buckets j..m.
        let mut right = [EMPTY_BUCKET; BUCKETS];
        let mut acc = EMPTY_BUCKET;
        for j in (0..m).rev() {
            acc = acc.merge::<SAOH>(&buckets[full[j]]);
            right[j] = acc;
        }
        let kr = aspect::<SAOH>(&diag, axis);
        let mut cost = |b: &Bucket| weights.cost::<SAOH>(b, kr, memo);
        let mut left = EMPTY_BUCKET;
        for j in 0..m.saturating_sub(1) {
            left = left.merge::<SAOH>(&buckets[full[j]]);
            let r = &right[j + 1];
            let c = cost(&left) + cost(r);
            if !c.is_finite() {
                continue;
            }
            let imbalance = left.count.abs_diff(r.count);
            let better = match best {
                None => true,
                Some((bc, bi, _, _)) => c < bc || (c == bc && imbalance < bi),
            };
            if better {
                best = Some((c, imbalance, axis, full[j]));
            }
        }
    }
    best.map(|(_, _, axis, bucket)| (axis, bucket))
}

/// [`best_bucket_split`] for two items, without the buckets: each item is
/// alone in bucket 0 or 11 of an axis (or both share one), so there is at
/// most one candidate per axis; its cost is computed from the same one-item
/// buckets the general path would build, so the choice is the same.
fn best_pair_split<const SAOH: bool>(
    items: &[Item],
    memo: &mut OrientationMemo,
    heuristic: BuildHeuristic,
    centroids: &Aabb,
    bounds: &Aabb,
) -> Option<(usize, usize)> {
    let [a, b] = items else {
        return None;
    };
    let total_area = 0.0 + a.area as f64 + b.area as f64;
    let total_power = 0.0 + a.power as f64 + b.power as f64;
    let weights = Weights::new(heuristic, total_area, total_power);
    let one = |it: &Item| {
        let mut bucket = EMPTY_BUCKET;
        bucket.add::<SAOH>(it);
        EMPTY_BUCKET.merge::<SAOH>(&bucket)
    };
    let (ba, bb) = (one(a), one(b));
    let diag = bounds.diagonal();
    let mut best: Option<(f64, usize, usize)> = None; // cost, axis, bucket
    for axis in 0..3 {
        let splittable = centroids.max[axis] > centroids.min[axis];
        if !splittable {
            continue;
        }
        let (ka, kb) = (bucket_of(a, centroids, axis), bucket_of(b, centroids, axis));
        if ka == kb {
            continue;
        }
        let (left, right, k) = if ka < kb {
            (&ba, &bb, ka)
        } else {
            (&bb, &ba, kb)
        };
        let kr = aspect::<SAOH>(&diag, axis);
        let c = weights.cost::<SAOH>(left, kr, memo) + weights.cost::<SAOH>(right, kr, memo);
        if !c.is_finite() {
            continue;
        }
        // Both sides hold one item: the imbalance tie-break never fires.
        if best.is_none_or(|(bc, _, _)| c < bc) {
            best = Some((c, axis, k));
        }
    }
    best.map(|(_, axis, bucket)| (axis, bucket))
}

/// What a bucket's cost weighs: area (SAH), power (SARH, SAOH) or, where
/// those sum to zero, the emitter count.
struct Weights {
    heuristic: BuildHeuristic,
    total_area: f64,
    total_power: f64,
}

impl Weights {
    fn new(heuristic: BuildHeuristic, total_area: f64, total_power: f64) -> Self {
        Self {
            heuristic,
            total_area,
            total_power,
        }
    }

    #[inline]
    fn weight(&self, b: &Bucket) -> f64 {
        match self.heuristic {
            BuildHeuristic::Sah if self.total_area > 0.0 => b.area,
            BuildHeuristic::Sarh | BuildHeuristic::Saoh if self.total_power > 0.0 => b.power,
            _ => b.count as f64,
        }
    }

    /// The cost of one side: weight x surface area (x `M_omega` x the
    /// aspect factor `kr` under SAOH).
    #[inline]
    fn cost<const SAOH: bool>(&self, b: &Bucket, kr: f64, memo: &mut OrientationMemo) -> f64 {
        let sa = b.bounds.surface_area() as f64;
        if SAOH {
            let m = memo.get(b.theta_o, b.cone.cos_theta_e) as f64;
            self.weight(b) * m * sa * kr
        } else {
            self.weight(b) * sa
        }
    }
}

/// SAOH's `Kr`: the box's longest extent over its extent along `axis`.
#[inline]
fn aspect<const SAOH: bool>(diag: &Vec3, axis: usize) -> f64 {
    if SAOH && diag[axis] > 0.0 {
        (diag.max_element() / diag[axis]) as f64
    } else {
        1.0
    }
}

/// The last few values of [`m_omega`]: most buckets' cones are the whole
/// sphere or one shared emitter cone, so a handful of entries saves nearly
/// every evaluation (three transcendental functions each).
#[derive(Default)]
struct OrientationMemo {
    keys: [Option<(u32, u32)>; 4],
    values: [f32; 4],
    next: usize,
}

impl OrientationMemo {
    #[inline]
    fn get(&mut self, theta_o: f32, cos_theta_e: f32) -> f32 {
        let key = Some((theta_o.to_bits(), cos_theta_e.to_bits()));
        if let Some(i) = self.keys.iter().position(|&k| k == key) {
            return self.values[i];
        }
        let v = m_omega(theta_o, cos_theta_e);
        self.keys[self.next] = key;
        self.values[self.next] = v;
        self.next = (self.next + 1) % self.keys.len();
        v
    }
}

/// pbrt-v4's orientation measure (`M_omega`) of a cone with half-angle
/// `theta_o` (as `safe_acos` of its cosine) and emission cosine
/// `cos_theta_e`.
fn m_omega(theta_o: f32, cos_theta_e: f32) -> f32 {
    let theta_e = safe_acos(cos_theta_e);
    let theta_w = (theta_o + theta_e).min(PI);
    let (sin_o, cos_o) = sin_cos(theta_o);
    2.0 * PI * (1.0 - cos_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - cos(theta_o - 2.0 * theta_w) - 2.0 * theta_o * sin_o + cos_o)
}

/// Moves the items whose bucket on `axis` is at most `bucket` to the front;
/// returns how many. `scratch[i]` is read before position `i` is ever
/// written, so it still describes the item that started there.
fn partition(items: &mut [Item], scratch: &[[u8; 3]], axis: usize, bucket: usize) -> usize {
    let mut mid = 0;
    for (i, s) in scratch[..items.len()].iter().enumerate() {
        if s[axis] as usize <= bucket {
            items.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

#[cfg(test)]
#[path = "build_reference.rs"]
mod reference;
