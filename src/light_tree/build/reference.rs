//! The straightforward binned builder the fast one is tested against:
//! docs/design.md promises that the binned builder's trees are bit-identical
//! to it. Per axis, the items are binned into 12 buckets (cones merged by
//! [`LightCone::union`], angles recomputed every time, no memo), every
//! boundary between buckets is evaluated with both sides merged from
//! scratch, and the cheapest split wins (ties towards balanced counts, the
//! first axis and boundary among equals). No pass shares work with another.

use super::binned::{BUCKETS, bucket_of};
use super::heuristic::{BuildHeuristic, OrientationMemo, m_omega};
use super::items::Item;
use crate::math::Aabb;
use crate::math::LightCone;
use alloc::vec::Vec;

/// What one side of a split holds.
#[derive(Clone, Copy)]
struct Side {
    bounds: Aabb,
    area: f64,
    power: f64,
    count: usize,
    cone: LightCone,
}

const NOTHING: Side = Side {
    bounds: Aabb::EMPTY,
    area: 0.0,
    power: 0.0,
    count: 0,
    cone: LightCone::SPHERE,
};

impl Side {
    /// This side with `o` added after it (an empty side adds nothing).
    fn and(self, o: &Side) -> Side {
        let cone = if o.count == 0 {
            self.cone
        } else if self.count == 0 {
            o.cone
        } else {
            self.cone.union(&o.cone)
        };
        Side {
            bounds: self.bounds.union(&o.bounds),
            area: self.area + o.area,
            power: self.power + o.power,
            count: self.count + o.count,
            cone,
        }
    }

    fn of(it: &Item) -> Side {
        Side {
            bounds: NOTHING.bounds.union(&it.bounds),
            area: 0.0 + it.area as f64,
            power: 0.0 + it.power as f64,
            count: 1,
            cone: it.cone,
        }
    }
}

/// [`super::ChooseSplit`], written plainly.
pub(super) fn best_split_straightforward(
    items: &[Item],
    scratch: &mut [[u8; 3]],
    _memo: &mut OrientationMemo,
    heuristic: BuildHeuristic,
    centroids: &Aabb,
    bounds: &Aabb,
) -> Option<(usize, usize)> {
    straightforward(items, scratch, heuristic, centroids, bounds, true)
}

/// The straightforward choice; `aspect` false drops SAOH's `Kr` (only the
/// tests' control does).
fn straightforward(
    items: &[Item],
    scratch: &mut [[u8; 3]],
    heuristic: BuildHeuristic,
    centroids: &Aabb,
    bounds: &Aabb,
    aspect: bool,
) -> Option<(usize, usize)> {
    let saoh = heuristic == BuildHeuristic::Saoh;
    let total_area = items.iter().fold(0.0f64, |a, it| a + it.area as f64);
    let total_power = items.iter().fold(0.0f64, |a, it| a + it.power as f64);
    let weight = |s: &Side| match heuristic {
        BuildHeuristic::Sah if total_area > 0.0 => s.area,
        BuildHeuristic::Sarh | BuildHeuristic::Saoh if total_power > 0.0 => s.power,
        _ => s.count as f64,
    };
    let diag = bounds.diagonal();
    let mut best: Option<(f64, usize, usize, usize)> = None;
    for axis in 0..3 {
        if centroids.max[axis] <= centroids.min[axis] {
            continue;
        }
        let mut buckets = [NOTHING; BUCKETS];
        for (it, s) in items.iter().zip(scratch.iter_mut()) {
            let b = bucket_of(it, centroids, axis);
            s[axis] = b as u8;
            buckets[b] = buckets[b].and(&Side::of(it));
        }
        let kr = if aspect && saoh && diag[axis] > 0.0 {
            (diag.max_element() / diag[axis]) as f64
        } else {
            1.0
        };
        let cost = |s: &Side| {
            let sa = s.bounds.surface_area() as f64;
            if saoh {
                let m = m_omega(s.cone.theta_o(), s.cone.cos_theta_e) as f64;
                weight(s) * m * sa * kr
            } else {
                weight(s) * sa
            }
        };
        for boundary in 0..BUCKETS - 1 {
            let left = buckets[..=boundary].iter().fold(NOTHING, |a, b| a.and(b));
            let right = buckets[boundary + 1..]
                .iter()
                .rev()
                .fold(NOTHING, |a, b| a.and(b));
            if left.count == 0 || right.count == 0 {
                continue;
            }
            let c = cost(&left) + cost(&right);
            if !c.is_finite() {
                continue;
            }
            let imbalance = left.count.abs_diff(right.count);
            if best.is_none_or(|(bc, bi, _, _)| c < bc || (c == bc && imbalance < bi)) {
                best = Some((c, imbalance, axis, boundary));
            }
        }
    }
    best.map(|(_, _, axis, bucket)| (axis, bucket))
}

#[cfg(test)]
mod tests {
    use super::super::{build, build_with};
    use super::*;
    use crate::emitter::Emitter;
    use alloc::format;
    use glam::Vec3;

    /// A small deterministic generator (SplitMix64).
    struct Numbers(u64);

    impl Numbers {
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }
        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next()
        }
        fn dir(&mut self) -> Vec3 {
            Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            )
            .normalize_or(Vec3::Y)
        }
    }

    /// `n` emitters of every kind: quads (facing down, or a shared or a
    /// random normal), spheres, points and spots, powers over five decades
    /// or all zero, some coincident.
    fn scene(n: usize, seed: u64, zero_power: bool) -> Vec<Emitter> {
        let mut r = Numbers(seed);
        let shared = r.dir();
        (0..n)
            .map(|i| {
                let c = if i % 17 == 5 {
                    Vec3::new(1.0, 2.0, 3.0)
                } else {
                    Vec3::new(
                        r.range(-50.0, 50.0),
                        r.range(-50.0, 50.0),
                        r.range(-50.0, 50.0),
                    )
                };
                let power = if zero_power {
                    0.0
                } else {
                    10f32.powf(r.range(-2.0, 3.0))
                };
                let kind = r.next();
                if kind < 0.4 {
                    let normal = match i % 3 {
                        0 => -Vec3::Y,
                        1 => shared,
                        _ => r.dir(),
                    };
                    let s = r.range(0.05, 2.0);
                    let (t, b) = normal.any_orthonormal_pair();
                    let bounds = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
                        .iter()
                        .fold(Aabb::EMPTY, |a, &(u, v)| a.extend(c + (t * u + b * v) * s));
                    let mut e = Emitter::area(bounds, normal, 4.0 * s * s, power);
                    e.two_sided = r.next() < 0.1;
                    e
                } else if kind < 0.7 {
                    Emitter::sphere(c, r.range(0.05, 1.0), power)
                } else if kind < 0.9 {
                    Emitter::point(c, power)
                } else {
                    let mut e = Emitter::point(c, power);
                    e.cone = Some(LightCone::spot(r.dir(), r.range(0.1, 1.2)));
                    e
                }
            })
            .collect()
    }

    const HEURISTICS: [BuildHeuristic; 4] = [
        BuildHeuristic::Balanced,
        BuildHeuristic::Sah,
        BuildHeuristic::Sarh,
        BuildHeuristic::Saoh,
    ];

    fn assert_same(e: &[Emitter], h: BuildHeuristic, what: &str) {
        let fast = build(e, h).unwrap();
        let plain = build_with(e, h, best_split_straightforward).unwrap();
        assert!(
            fast.nodes == plain.nodes && fast.leaf_of == plain.leaf_of,
            "{what} {h:?}: the binned build differs from the straightforward one"
        );
    }

    /// 40 mixed scenes of 1 to 3000 emitters (every fifth with all powers
    /// zero), every heuristic: the same node arrays, bit for bit.
    #[test]
    fn binned_builder_equals_the_straightforward_one() {
        let mut sizes = Numbers(11);
        for s in 0..40u64 {
            let n = 1 + (sizes.next() * sizes.next() * 3000.0) as usize;
            let e = scene(n, s, s % 5 == 4);
            for h in HEURISTICS {
                assert_same(&e, h, &format!("scene {s} ({n} emitters)"));
            }
        }
    }

    /// The control: a plausible slip in one of the two (SAOH without its
    /// aspect factor `Kr`) gives other trees, so the comparison above can
    /// fail.
    #[test]
    fn a_slip_in_the_cost_is_seen() {
        fn without_aspect(
            items: &[Item],
            scratch: &mut [[u8; 3]],
            _: &mut OrientationMemo,
            heuristic: BuildHeuristic,
            centroids: &Aabb,
            bounds: &Aabb,
        ) -> Option<(usize, usize)> {
            straightforward(items, scratch, heuristic, centroids, bounds, false)
        }
        let e = scene(2000, 3, false);
        let fast = build(&e, BuildHeuristic::Saoh).unwrap();
        let slipped = build_with(&e, BuildHeuristic::Saoh, without_aspect).unwrap();
        assert!(fast.nodes != slipped.nodes);
    }
}
