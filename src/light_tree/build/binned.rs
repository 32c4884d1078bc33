//! The binned split: 12 buckets per axis, all three axes in one pass over
//! the items, the cheapest boundary by the heuristic's cost.

use super::bucket::{Bucket, EMPTY_BUCKET};
use super::heuristic::{BuildHeuristic, OrientationMemo, Weights, aspect};
use super::items::Item;
use crate::math::Aabb;

pub(super) const BUCKETS: usize = 12;

/// The fast binned choice: one pass over the items for all three axes
/// ([`best_bucket_split`]), two-item nodes without buckets
/// ([`best_pair_split`]).
pub(super) fn best_binned_split(
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

#[inline]
pub(super) fn bucket_of(it: &Item, centroids: &Aabb, axis: usize) -> usize {
    let t = (it.centroid[axis] - centroids.min[axis]) / (centroids.max[axis] - centroids.min[axis]);
    // `as u32` saturates like `as usize` (NaN -> 0) but converts cheaply.
    ((t * BUCKETS as f32) as u32 as usize).min(BUCKETS - 1)
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

/// Moves the items whose bucket on `axis` is at most `bucket` to the front;
/// returns how many. `scratch[i]` is read before position `i` is ever
/// written, so it still describes the item that started there.
pub(super) fn partition(
    items: &mut [Item],
    scratch: &[[u8; 3]],
    axis: usize,
    bucket: usize,
) -> usize {
    let mut mid = 0;
    for (i, s) in scratch[..items.len()].iter().enumerate() {
        if s[axis] as usize <= bucket {
            items.swap(i, mid);
            mid += 1;
        }
    }
    mid
}
