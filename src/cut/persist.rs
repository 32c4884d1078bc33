//! Saving and loading a cut's configuration and a cut
//! (`src/persist/mod.rs` has the header, `docs/format.md` the layout);
//! the GLT and the field save their cells' cuts through these.

use super::config::{BelowCut, CutConfig, ImportanceBound, Modulation, Prior, SplitPrior};
use super::cut_node::CutNode;
use super::cut_rules::CutRules;
use super::guiding_cut::{GuidingCut, MIN_VISIBILITY, anchor_sums, sum_count, visibility_slots};
use crate::light_sampler::UnboundedLights;
use crate::light_tree::LightHierarchy;
use crate::math::ACCUMULATION;
use crate::math::{Counter, SumBuffer};
use crate::persist::{LoadError, Reader, Writer, tag, untag};
use alloc::vec::Vec;

/// The bounds in the order of their tags.
const BOUNDS: [ImportanceBound; 2] = [ImportanceBound::Children, ImportanceBound::Grandchildren];

impl CutConfig {
    pub(crate) fn write(&self, w: &mut Writer) {
        w.f64(self.sigma);
        w.f64(self.alpha);
        w.u8(tag(
            &[BelowCut::Power, BelowCut::Importance],
            self.below_cut,
        ));
        w.u8(tag(
            &[Modulation::None, Modulation::Importance],
            self.modulation,
        ));
        w.u8(tag(&[Prior::Power, Prior::Importance], self.prior));
        w.u8(tag(
            &[SplitPrior::Half, SplitPrior::Power],
            self.split_prior,
        ));
        w.u32(self.unbounded.count);
        w.f64(self.unbounded.probability);
        w.u8(tag(&ACCUMULATION, self.accumulation));
        w.u32(self.min_records);
        w.bool(self.visibility);
        w.u8(tag(&BOUNDS, self.importance_bound));
    }

    pub(crate) fn read(r: &mut Reader<'_>) -> Result<Self, LoadError> {
        let at = r.offset();
        let config = Self {
            sigma: r.f64("cut config: sigma")?,
            alpha: r.f64("cut config: alpha")?,
            below_cut: untag(
                r,
                "cut config: below_cut",
                &[BelowCut::Power, BelowCut::Importance],
            )?,
            modulation: untag(
                r,
                "cut config: modulation",
                &[Modulation::None, Modulation::Importance],
            )?,
            prior: untag(r, "cut config: prior", &[Prior::Power, Prior::Importance])?,
            split_prior: untag(
                r,
                "cut config: split_prior",
                &[SplitPrior::Half, SplitPrior::Power],
            )?,
            unbounded: UnboundedLights {
                count: r.u32("cut config: unbounded count")?,
                probability: r.f64("cut config: unbounded probability")?,
            },
            accumulation: untag(r, "cut config: accumulation", &ACCUMULATION)?,
            min_records: r.u32("cut config: min_records")?,
            // Version 1 had no learned visibility.
            visibility: r.version() >= 2 && r.bool("cut config: visibility")?,
            // Before version 6 every importance weighed children by their
            // own bounds: files of those versions keep answering as they
            // did.
            importance_bound: match r.version() >= 6 {
                true => untag(r, "cut config: importance_bound", &BOUNDS)?,
                false => ImportanceBound::Children,
            },
        };
        config.validate().map_err(|e| e.at(at))?;
        Ok(config)
    }
}

impl GuidingCut {
    pub(crate) fn write(&self, w: &mut Writer) {
        w.len(self.nodes.len());
        for n in &self.nodes {
            let (p, [a, b]) = n.raw();
            w.f32(p);
            w.u32(a);
            w.u32(b);
        }
        self.sums.write(w);
        w.len(self.unbounded.len());
        for &f in self.unbounded.iter() {
            w.f32(f);
        }
        w.u64(self.recorded.get());
        self.anchor.write(w);
        w.bool(self.modulated);
        // Version 3: how much of what it learned came from its own cell.
        w.f32(self.confidence);
        // Version 2: the learned visibility, when the configuration learns
        // it (its length is the sums').
        if !self.visibility.is_empty() {
            for &v in self.visibility.iter() {
                w.f32(v);
            }
            self.seen.write(w);
            w.u64(self.seen_records.get());
        }
    }

    /// Reads a cut of `rules`' light tree and configuration, checked
    /// ([`GuidingCut::check`], sum counts, fractions in `[0, 1]`).
    pub(crate) fn read<H: LightHierarchy>(
        r: &mut Reader<'_>,
        rules: &CutRules<H>,
    ) -> Result<Self, LoadError> {
        let config = rules.config();
        let at = r.offset();
        let count = r.len("cut: node count", 12)?;
        let mut nodes = Vec::with_capacity(count);
        for _ in 0..count {
            let p = r.f32("cut: p_left")?;
            let a = r.u32("cut: slot")?;
            let b = r.u32("cut: slot")?;
            nodes.push(CutNode::from_raw(p, [a, b]));
        }
        let k = config.unbounded.count;
        let sums = SumBuffer::read(r, "cut: sums", config.accumulation, sum_count(count, k))?;
        let fractions_at = r.offset();
        let n = r.len("cut: unbounded fractions", 4)?;
        if n != k as usize {
            return Err(Reader::invalid("cut: unbounded fractions", fractions_at));
        }
        let mut unbounded = Vec::with_capacity(n);
        for _ in 0..n {
            unbounded.push(r.check("cut: unbounded fraction", Reader::f32, |f| {
                (0.0..=1.0).contains(f)
            })?);
        }
        let recorded = Counter::with(r.u64("cut: recorded")?);
        let anchor = SumBuffer::read(r, "cut: anchor", config.accumulation, anchor_sums(config))?;
        let modulated = r.bool("cut: modulated")?;
        let confidence = if r.version() >= 3 {
            r.check("cut: confidence", Reader::f32, |c| (0.0..=1.0).contains(c))?
        } else {
            1.0
        };
        let slots = visibility_slots(count, config);
        let mut visibility = Vec::with_capacity(slots.min(r.left() / 4));
        for _ in 0..slots {
            visibility.push(r.check("cut: visibility", Reader::f32, |v| {
                (MIN_VISIBILITY..=1.0).contains(v)
            })?);
        }
        let (seen, seen_records) = if slots > 0 {
            let seen = SumBuffer::read(r, "cut: visibility sums", config.accumulation, 2 * slots)?;
            (seen, Counter::with(r.u64("cut: visibility records")?))
        } else {
            (SumBuffer::new(0, config.accumulation), Counter::new())
        };
        let cut = Self {
            nodes,
            sums,
            unbounded: unbounded.into_boxed_slice(),
            recorded,
            anchor,
            modulated,
            visibility: visibility.into_boxed_slice(),
            seen,
            seen_records,
            confidence,
        };
        cut.check(rules.light_tree())
            .map_err(|_| Reader::invalid("cut: nodes", at))?;
        Ok(cut)
    }

    /// Whether `other` samples the same distribution (what a merge
    /// requires).
    pub(crate) fn same_layout(&self, other: &Self) -> bool {
        self.nodes == other.nodes
            && self.unbounded == other.unbounded
            && self.modulated == other.modulated
            && self.visibility == other.visibility
            && self.confidence.to_bits() == other.confidence.to_bits()
    }

    /// Zeroes what was recorded since the last refinement (sums, anchor,
    /// count), keeping the distribution.
    pub(crate) fn clear_records(&mut self) {
        self.sums.clear();
        self.anchor.clear();
        self.recorded.reset();
        self.seen.clear();
        self.seen_records.reset();
    }

    /// Adds `other`'s accumulating state (same layout) to this cut's.
    pub(crate) fn merge(&mut self, other: &Self) -> bool {
        if !self.same_layout(other) {
            return false;
        }
        if !(self.sums.merge(&other.sums)
            && self.anchor.merge(&other.anchor)
            && self.seen.merge(&other.seen))
        {
            return false;
        }
        self.recorded.merge(&other.recorded);
        self.seen_records.merge(&other.seen_records);
        true
    }
}
