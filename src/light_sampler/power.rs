//! Light selection proportional to power, with Walker's alias method.

use super::ShadingContext;
use super::{LightId, LightSample, LightSampler, pmf_to_f32};
use crate::emitter::Emitters;
use crate::math::Descent;
use alloc::vec::Vec;

/// The most emitters a [`LightId::Emitter`] can name.
const MAX_EMITTERS: usize = u32::MAX as usize;

/// One slot of the alias table, and the pmf of the emitter with its index.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bin {
    /// Keep this slot's own emitter when the fractional part of `u * n` is
    /// below this; otherwise take `alias`.
    threshold: f64,
    /// The emitter that fills the rest of the slot.
    alias: u32,
    /// `power / total` of this slot's own emitter, as returned by `pmf`.
    pmf: f32,
}

/// Chooses emitters with probability proportional to their power, in O(1)
/// per sample with an alias table (Walker, Vose), whatever the shading point.
///
/// The table is built in `f64`; each emitter's `f32` pmf is computed once and
/// stored, so the pmf `sample` returns is exactly what `pmf` returns. Powers
/// that are zero, negative or not finite count as zero: such emitters are
/// never chosen and have pmf 0. When the total power is zero the sampler is
/// empty. 16 bytes per emitter.
///
/// The table maps one `u` to a slot (`floor(u * n)`) and the slot's fraction
/// to one of two emitters, so an `f32` `u` resolves probabilities to about
/// `2^-24`: with millions of emitters, a renderer that needs more should use
/// a tree sampler, whose descent keeps `u`'s full relative precision.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PowerSampler {
    bins: Vec<Bin>,
    /// Each emitter's light sets and weight, when some emitter is not in
    /// every set (light linking): a point that receives some sets only is
    /// answered from these, in O(n).
    linked: Option<alloc::boxed::Box<Linked>>,
}

/// The emitters' light sets and weights, for points lit by some sets only.
#[derive(Clone, Debug, Default, PartialEq)]
struct Linked {
    sets: Vec<u64>,
    weights: Vec<f64>,
}

impl Linked {
    /// The total weight of the emitters `receives` sees.
    fn total(&self, receives: u64) -> f64 {
        self.sets
            .iter()
            .zip(&self.weights)
            .filter(|(s, _)| *s & receives != 0)
            .map(|(_, w)| w)
            .sum()
    }

    /// The pmf of emitter `i` at a point lit by `receives`, from `total`.
    fn pmf(&self, i: usize, receives: u64, total: f64) -> f32 {
        match (self.sets.get(i), self.weights.get(i)) {
            (Some(s), Some(w)) if s & receives != 0 && total > 0.0 => pmf_to_f32(w / total),
            _ => 0.0,
        }
    }

    /// The inverse CDF of the emitters `receives` sees, in index order.
    fn sample(&self, u: f32, receives: u64) -> Option<LightSample> {
        let total = self.total(receives);
        if total <= 0.0 {
            return None;
        }
        let target = Descent::new(u).u() * total;
        let mut acc = 0.0;
        let mut last = None;
        for (i, (s, w)) in self.sets.iter().zip(&self.weights).enumerate() {
            if s & receives == 0 || *w <= 0.0 {
                continue;
            }
            last = Some(i);
            acc += w;
            if target < acc {
                break;
            }
        }
        let i = last?;
        let pmf = self.pmf(i, receives, total);
        (pmf > 0.0).then_some(LightSample {
            light: LightId::Emitter(i as u32),
            pmf,
        })
    }
}

impl PowerSampler {
    /// A sampler over the powers of `emitters`, each times its weight
    /// ([`Emitters::weight`]; a product that is not a positive finite
    /// number counts as zero).
    pub fn new<E: Emitters + ?Sized>(emitters: &E) -> Self {
        let powers = (0..emitters.len()).map(|i| emitters.power(i) * emitters.weight(i));
        Self::from_powers(powers).linked_by(emitters)
    }

    /// This sampler with `emitters`' light sets, when some is not in every
    /// set: a point lit by some sets only then chooses among their emitters
    /// (exactly, in O(n) per query).
    pub(crate) fn linked_by<E: Emitters + ?Sized>(mut self, emitters: &E) -> Self {
        let n = emitters.len().min(self.bins.len());
        let sets: Vec<u64> = (0..n).map(|i| emitters.light_sets(i)).collect();
        if sets.iter().any(|&s| s != u64::MAX) {
            let weights = self.bins.iter().map(|b| f64::from(b.pmf)).collect();
            self.linked = Some(alloc::boxed::Box::new(Linked { sets, weights }));
        }
        self
    }

    /// A sampler over emitters `0..n` with the given powers (at most
    /// `u32::MAX` of them are used).
    pub fn from_powers(powers: impl IntoIterator<Item = f32>) -> Self {
        let weights: Vec<f64> = powers
            .into_iter()
            .take(MAX_EMITTERS)
            .map(|p| {
                if p > 0.0 && p.is_finite() {
                    p as f64
                } else {
                    0.0
                }
            })
            .collect();
        let total: f64 = weights.iter().sum();
        // A sum of finite non-negative numbers: never NaN.
        if total <= 0.0 {
            return Self::default();
        }
        Self {
            bins: alias_table(&weights, total),
            linked: None,
        }
    }

    /// Number of emitters (0 when the sampler is empty).
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// True when nothing can be sampled (no emitters or no power).
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// Bytes of heap memory the table holds.
    pub fn bytes(&self) -> usize {
        self.bins.len() * core::mem::size_of::<Bin>()
    }
}

/// Vose's construction of the alias table for `weights` (non-negative,
/// summing to `total > 0`).
fn alias_table(weights: &[f64], total: f64) -> Vec<Bin> {
    let n = weights.len();
    let mut scaled: Vec<f64> = weights.iter().map(|w| w / total * n as f64).collect();
    let mut bins: Vec<Bin> = weights
        .iter()
        .enumerate()
        .map(|(i, w)| Bin {
            threshold: 1.0,
            alias: i as u32,
            pmf: pmf_to_f32(w / total),
        })
        .collect();
    // Zero weights are pushed last so they are paired first, while plenty of
    // mass is left: rounding can then never leave one of them unpaired.
    let mut small: Vec<u32> = Vec::new();
    let mut large: Vec<u32> = Vec::new();
    for (i, &q) in scaled.iter().enumerate() {
        if q >= 1.0 {
            large.push(i as u32);
        } else if q > 0.0 {
            small.push(i as u32);
        }
    }
    small.extend((0..n as u32).filter(|&i| scaled[i as usize] == 0.0));
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        let qs = scaled[s as usize];
        bins[s as usize].threshold = qs;
        bins[s as usize].alias = l;
        let ql = &mut scaled[l as usize];
        *ql -= 1.0 - qs;
        if *ql < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // Leftovers hold (up to rounding) exactly one slot of mass each: they
    // keep threshold 1. A weightless leftover, which rounding alone could
    // cause, hands its slot to the heaviest emitter instead.
    let heaviest = (0..n)
        .max_by(|&a, &b| weights[a].total_cmp(&weights[b]))
        .unwrap_or(0) as u32;
    for i in small {
        if weights[i as usize] == 0.0 {
            bins[i as usize].threshold = 0.0;
            bins[i as usize].alias = heaviest;
        }
    }
    bins
}

impl LightSampler for PowerSampler {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        let n = self.bins.len();
        if n == 0 || !ctx.is_finite() {
            return None;
        }
        if ctx.restricts(self.linked.is_some()) {
            return self.linked.as_ref()?.sample(u, ctx.receives);
        }
        let x = Descent::new(u).u() * n as f64;
        // x >= 0, so truncation is floor (and avoids a libm call).
        let slot = x as usize;
        let i = slot.min(n - 1);
        let bin = &self.bins[i];
        let chosen = if x - (slot as f64) < bin.threshold {
            i
        } else {
            bin.alias as usize
        };
        let pmf = self.bins.get(chosen)?.pmf;
        (pmf > 0.0).then_some(LightSample {
            light: LightId::Emitter(chosen as u32),
            pmf,
        })
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        match light {
            _ if !ctx.is_finite() => 0.0,
            LightId::Emitter(i) if ctx.restricts(self.linked.is_some()) => match &self.linked {
                Some(l) => l.pmf(i as usize, ctx.receives, l.total(ctx.receives)),
                None => 0.0,
            },
            LightId::Emitter(i) => self.bins.get(i as usize).map_or(0.0, |b| b.pmf),
            LightId::Unbounded(_) => 0.0,
        }
    }

    #[inline]
    fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        if self.is_empty() || !ctx.is_finite() {
            return true;
        }
        match &self.linked {
            _ if !ctx.restricts(self.linked.is_some()) => false,
            Some(l) => l.total(ctx.receives) <= 0.0,
            None => true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The exact probability the table gives each emitter, from its slots.
    fn table_distribution(s: &PowerSampler) -> Vec<f64> {
        let n = s.bins.len();
        let mut p = alloc::vec![0.0; n];
        for (i, b) in s.bins.iter().enumerate() {
            let keep = b.threshold.clamp(0.0, 1.0);
            p[i] += keep / n as f64;
            p[b.alias as usize] += (1.0 - keep) / n as f64;
        }
        p
    }

    #[test]
    fn table_reproduces_weights() {
        let powers = [0.0, 1.0, 3.0, 0.0, 1e-20, 1e20, 7.5, 0.0, f32::NAN, -2.0];
        let s = PowerSampler::from_powers(powers);
        let total: f64 = powers.iter().filter(|w| **w > 0.0).map(|&w| w as f64).sum();
        for (i, p) in table_distribution(&s).into_iter().enumerate() {
            let w = powers[i];
            let expect = if w > 0.0 { w as f64 / total } else { 0.0 };
            assert!((p - expect).abs() <= 1e-15, "{i}: {p} vs {expect}");
            if expect == 0.0 {
                assert_eq!(p, 0.0, "zero-weight emitter {i} reachable");
            }
        }
    }

    #[test]
    fn zero_power_is_empty() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        for s in [
            PowerSampler::from_powers([0.0, 0.0]),
            PowerSampler::from_powers([]),
            PowerSampler::from_powers([f32::NAN, f32::INFINITY, -1.0]),
        ] {
            assert!(s.is_empty());
            assert_eq!(s.sample(&ctx, 0.3), None);
            assert_eq!(s.pmf(&ctx, LightId::Emitter(0)), 0.0);
        }
    }

    #[test]
    fn reports_its_size() {
        let s = PowerSampler::from_powers([1.0, 0.0, 2.0]);
        assert_eq!((s.len(), s.is_empty()), (3, false));
        assert_eq!(core::mem::size_of::<Bin>(), 16);
        assert_eq!(s.bytes(), 48);
    }

    /// A light whose pmf rounds to 0 in `f32` is never returned, also
    /// where its slot's threshold is met (`u = 0`: `x - slot = 0` is below
    /// any positive threshold).
    #[test]
    fn a_pmf_that_rounds_to_zero_is_never_sampled() {
        let s = PowerSampler::from_powers([1e-30, 1e30]);
        let ctx = ShadingContext::at(Vec3::ZERO);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(0)), 0.0);
        assert!(
            s.bins[0].threshold > 0.0,
            "the tiny light keeps its slot share"
        );
        assert_eq!(s.sample(&ctx, 0.0), None);
        for k in 1..1000 {
            let x = s.sample(&ctx, k as f32 / 1000.0).unwrap();
            assert_eq!((x.light, x.pmf), (LightId::Emitter(1), 1.0));
        }
    }

    #[test]
    fn never_picks_zero_power() {
        let mut powers = alloc::vec![0.0f32; 1000];
        powers[17] = 1.0;
        powers[900] = 3.0;
        let s = PowerSampler::from_powers(powers);
        let ctx = ShadingContext::at(Vec3::ZERO);
        for k in 0..=10_000 {
            let u = k as f32 / 10_000.0;
            let x = s.sample(&ctx, u).unwrap();
            assert!(matches!(x.light, LightId::Emitter(17 | 900)), "{x:?}");
            assert_eq!(x.pmf, s.pmf(&ctx, x.light));
        }
    }
}
