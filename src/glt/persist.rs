//! Saving and loading the GLT's configuration, its cuts and the standalone
//! [`Glt`] (`src/persist/mod.rs` has the header, `docs/format.md` the
//! layout); merging two GLTs' statistics.

use super::cell::GltCell;
use super::config::{BelowCut, CutConfig, Modulation, Prior, SplitPrior};
use super::cut::{GuidingCut, MIN_VISIBILITY, anchor_sums, sum_count, visibility_slots};
use super::cut_node::CutNode;
use super::cut_rules::CutRules;
use super::octants::OctantSplats;
use super::standalone::{Glt, GltConfig};
use crate::dropped::DropCounters;
use crate::light_sampler::UnboundedLights;
use crate::light_tree::LightHierarchy;
use crate::math::{Counter, SumBuffer};
use crate::persist::{
    ACCUMULATION, FILTERS, Kind, LoadError, Reader, Writer, config_error, fingerprint,
    read_fingerprint, tag, untag,
};
use alloc::vec::Vec;

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
        w.u32(self.min_splats);
        w.bool(self.visibility);
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
            min_splats: r.u32("cut config: min_splats")?,
            // Version 1 had no learned visibility.
            visibility: r.version() >= 2 && r.bool("cut config: visibility")?,
        };
        config.validate().map_err(|e| config_error(e, at))?;
        Ok(config)
    }
}

impl GltConfig {
    fn write(&self, w: &mut Writer) {
        self.cut.write(w);
        w.f64(self.spatial_threshold);
        w.bool(self.max_bytes.is_some());
        w.u64(self.max_bytes.unwrap_or(0) as u64);
        w.u8(tag(&FILTERS, self.light_filter));
    }

    fn read(r: &mut Reader<'_>) -> Result<Self, LoadError> {
        let at = r.offset();
        let cut = CutConfig::read(r)?;
        let spatial_threshold = r.f64("glt config: spatial_threshold")?;
        let capped = r.bool("glt config: max_bytes")?;
        let bytes = r.u64("glt config: max_bytes")?;
        let config = Self {
            cut,
            spatial_threshold,
            max_bytes: capped.then_some(usize::try_from(bytes).unwrap_or(usize::MAX)),
            light_filter: untag(r, "glt config: filter", &FILTERS)?,
        };
        config.validate().map_err(|e| config_error(e, at))?;
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

impl<H: LightHierarchy> Glt<H> {
    /// The learned state as bytes: a header, the light hierarchy's
    /// `fingerprint`, the configuration, the
    /// iteration, the drop counts and every cell (cut, sums, counts).
    /// Accumulating sums are included, so a saved GLT can be merged or go
    /// on learning.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(fingerprint(self.light_tree()));
        self.config.write(&mut w);
        w.u32(self.iteration);
        self.dropped.write(&mut w);
        self.spatial.write(&mut w, |cell, w| {
            cell.cut.write(w);
            // Version 3: the splats per octant, the splats that fell in the
            // cell before its last refinement, its refinement count.
            cell.octants.write(w);
            w.u64(cell.used);
            w.u32(cell.generation);
        });
        w.finish(Kind::Glt)
    }

    /// The GLT saved by [`Glt::to_bytes`] over `tree`, which must be the
    /// hierarchy it was trained with ([`LoadError::LightTreeMismatch`]
    /// otherwise). Everything is checked; a GLT that loads samples, gives
    /// pmfs and learns exactly like the one saved.
    pub fn from_bytes(bytes: &[u8], tree: H) -> Result<Self, LoadError> {
        let mut r = Reader::open(bytes, Kind::Glt)?;
        read_fingerprint(&mut r, &tree)?;
        let at = r.offset();
        let config = GltConfig::read(&mut r)?;
        let guide = CutRules::new(tree, config.cut).map_err(|e| config_error(e, at))?;
        let iteration = r.u32("iteration")?;
        let dropped = DropCounters::read(&mut r)?;
        let spatial = crate::spatial::BinaryTree::read(&mut r, |r| {
            let cut = GuidingCut::read(r, &guide)?;
            if r.version() < 3 {
                // Versions 1 and 2 counted a cell's splats as one number
                // (and a split count that only lives inside a refinement):
                // spread evenly over the octants; every cell had taken
                // part in every refinement.
                let splats = r.u64("cell: splats")?;
                r.u64("cell: split count")?;
                let octants = OctantSplats::with(core::array::from_fn(|o| {
                    splats / 8 + u64::from((o as u64) < splats % 8)
                }));
                return Ok(GltCell::with_counts(cut, octants, 0, iteration));
            }
            let octants = OctantSplats::read(r, "cell: octant splats")?;
            let used = r.u64("cell: splats used")?;
            let generation = r.u32("cell: generation")?;
            Ok(GltCell::with_counts(cut, octants, used, generation))
        })?;
        r.end()?;
        Ok(Self {
            guide,
            config,
            spatial,
            iteration,
            dropped,
        })
    }

    /// Zeroes everything recorded since the last refinement (sums, splat
    /// and drop counts), keeping what was learned: the starting point of a
    /// worker's share (see [`Glt::merge`]).
    pub fn clear_records(&mut self) {
        for cell in self.spatial.data_slice_mut() {
            cell.cut.clear_records();
            cell.octants.reset();
        }
        self.dropped.reset();
    }

    /// Adds what `other` recorded to this GLT, so that N workers that each
    /// record part of the samples refine once, together. The protocol: the
    /// coordinator sends its state; each worker loads it, calls
    /// [`Glt::clear_records`] (so its share holds only its own records,
    /// not the coordinator's, which may carry sums a cut below
    /// [`CutConfig::min_splats`](super::CutConfig::min_splats) keeps from
    /// earlier iterations), records, and sends the share back; the
    /// coordinator merges every share into its state and refines. Both
    /// must have the same light hierarchy, configuration, spatial tree and
    /// cuts (copies of one GLT after the same refinements); otherwise
    /// nothing changes and this is `false`. In
    /// [`Accumulation::Deterministic`](crate::math::Accumulation::Deterministic)
    /// the merged state is bit for bit what one GLT recording all the
    /// workers' records would hold (`tests/merge.rs`, `examples/render/src/bin/farm.rs`).
    pub fn merge(&mut self, other: &Self) -> bool {
        let same = fingerprint(self.light_tree()) == fingerprint(other.light_tree())
            && self.config == other.config
            && self.iteration == other.iteration
            && self.spatial.same_layout(&other.spatial)
            && self
                .spatial
                .data_slice()
                .iter()
                .zip(other.spatial.data_slice())
                .all(|(a, b)| {
                    a.used == b.used && a.generation == b.generation && a.cut.same_layout(&b.cut)
                });
        if !same {
            return false;
        }
        let cells = self.spatial.data_slice_mut();
        for (a, b) in cells.iter_mut().zip(other.spatial.data_slice()) {
            a.cut.merge(&b.cut);
            a.octants.merge(&b.octants);
        }
        self.dropped.merge(&other.dropped);
        true
    }
}
