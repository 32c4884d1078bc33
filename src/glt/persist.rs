//! Saving and loading the GLT's configuration and the [`Glt`]
//! (`src/persist/mod.rs` has the header, `docs/format.md` the layout);
//! merging two GLTs' statistics.

use super::Glt;
use super::cell::GltCell;
use super::config::GltConfig;
use crate::cut::{CutConfig, CutRules, GuidingCut, OctantRecords};
use crate::dropped::DropCounters;
use crate::light_tree::LightHierarchy;
use crate::light_tree::{fingerprint, read_fingerprint, shape_fingerprint};
use crate::persist::{Kind, LoadError, Reader, Writer, tag, untag};
use crate::spatial::FILTERS;
use alloc::vec::Vec;

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
        config.validate().map_err(|e| e.at(at))?;
        Ok(config)
    }
}

impl<H: LightHierarchy> Glt<H> {
    /// The learned state as bytes: a header, the light hierarchy's
    /// `shape_fingerprint`, the configuration, the
    /// iteration, the drop counts and every cell (cut, sums, counts).
    /// Accumulating sums are included, so a saved GLT can be merged or go
    /// on learning.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(shape_fingerprint(self.light_tree()));
        self.config.write(&mut w);
        w.u32(self.iteration);
        self.dropped.write(&mut w);
        self.spatial.write(&mut w, |cell, w| {
            cell.cut.write(w);
            // Version 3: the records per octant, the records that fell in the
            // cell before its last refinement, its refinement count.
            cell.octants.write(w);
            w.u64(cell.used);
            w.u32(cell.generation);
        });
        w.finish(Kind::Glt)
    }

    /// The GLT saved by [`Glt::to_bytes`] over `tree`, which must be the
    /// hierarchy it was trained with or a refit of it
    /// ([`LightTree::refit`](crate::LightTree::refit): the same shape;
    /// files before format version 4: the very same tree), else
    /// [`LoadError::LightTreeMismatch`]. Everything is checked; a GLT that loads samples, gives
    /// pmfs and learns exactly like the one saved.
    pub fn from_bytes(bytes: &[u8], light_tree: H) -> Result<Self, LoadError> {
        let mut r = Reader::open(bytes, Kind::Glt)?;
        read_fingerprint(&mut r, &light_tree)?;
        let at = r.offset();
        let config = GltConfig::read(&mut r)?;
        let rules = CutRules::new(light_tree, config.cut).map_err(|e| e.at(at))?;
        let iteration = r.u32("iteration")?;
        let dropped = DropCounters::read(&mut r)?;
        let spatial = crate::spatial::BinaryTree::read(&mut r, |r| {
            let cut = GuidingCut::read(r, &rules)?;
            if r.version() < 3 {
                // Versions 1 and 2 counted a cell's records as one number
                // (and a split count that only lives inside a refinement):
                // spread evenly over the octants; every cell had taken
                // part in every refinement.
                let records = r.u64("cell: records")?;
                r.u64("cell: split count")?;
                let octants = OctantRecords::spread(records);
                return Ok(GltCell::with_counts(cut, octants, 0, iteration));
            }
            let octants = OctantRecords::read(r, "cell: octant records")?;
            let used = r.u64("cell: records used")?;
            let generation = r.u32("cell: generation")?;
            Ok(GltCell::with_counts(cut, octants, used, generation))
        })?;
        r.end()?;
        Ok(Self {
            rules,
            config,
            spatial,
            iteration,
            dropped,
        })
    }

    /// Zeroes everything recorded since the last refinement (sums, record
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
    /// [`CutConfig::min_records`](crate::CutConfig::min_records) keeps from
    /// earlier iterations), records, and sends the share back; the
    /// coordinator merges every share into its state and refines. Both
    /// must have the same light hierarchy, configuration, spatial tree and
    /// cuts (copies of one GLT after the same refinements); otherwise
    /// nothing changes and this is `false`. In
    /// [`Accumulation::Deterministic`](crate::Accumulation::Deterministic)
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
