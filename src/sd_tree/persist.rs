//! Saving and loading the SD-tree (its configuration, state and cells),
//! checked; merging two SD-trees' statistics.

use super::SdTree;
use super::cell::SdCell;
use super::config::SdTreeConfig;
use super::fraction::{FRACTION_SUMS, FractionLearner};
use super::state::SdState;
use crate::dropped::DropCounters;
use crate::math::ACCUMULATION;
use crate::math::SumBuffer;
use crate::persist::{Kind, LoadError, Reader, Writer, tag, untag};
use crate::quadtree::{DirectionalFilter, DirectionalTree, QuadtreeConfig};
use crate::spatial::BinaryTree;
use crate::spatial::FILTERS;
use alloc::vec::Vec;

const DIRECTIONAL: [DirectionalFilter; 2] = [DirectionalFilter::Nearest, DirectionalFilter::Box];

impl SdTreeConfig {
    pub(crate) fn write(&self, w: &mut Writer) {
        w.f64(self.spatial_threshold);
        w.f32(self.quadtree.rho);
        w.u32(self.quadtree.max_depth);
        w.u8(tag(&FILTERS, self.spatial_filter));
        w.u8(tag(&DIRECTIONAL, self.directional_filter));
        w.u8(tag(&ACCUMULATION, self.accumulation));
        w.bool(self.max_bytes.is_some());
        w.u64(self.max_bytes.unwrap_or(0) as u64);
        w.f32(self.bsdf_fraction);
        w.bool(self.learn_bsdf_fraction);
        w.u32(self.fraction_steps);
    }

    pub(crate) fn read(r: &mut Reader<'_>) -> Result<Self, LoadError> {
        let at = r.offset();
        let spatial_threshold = r.f64("sd config: spatial_threshold")?;
        let quadtree = QuadtreeConfig {
            rho: r.f32("sd config: rho")?,
            max_depth: r.u32("sd config: max_depth")?,
        };
        let spatial_filter = untag(r, "sd config: spatial_filter", &FILTERS)?;
        let directional_filter = untag(r, "sd config: directional_filter", &DIRECTIONAL)?;
        let accumulation = untag(r, "sd config: accumulation", &ACCUMULATION)?;
        let capped = r.bool("sd config: max_bytes")?;
        let bytes = r.u64("sd config: max_bytes")?;
        let config = Self {
            spatial_threshold,
            quadtree,
            spatial_filter,
            directional_filter,
            accumulation,
            max_bytes: capped.then_some(usize::try_from(bytes).unwrap_or(usize::MAX)),
            bsdf_fraction: r.f32("sd config: bsdf_fraction")?,
            learn_bsdf_fraction: r.bool("sd config: learn_bsdf_fraction")?,
            fraction_steps: r.u32("sd config: fraction_steps")?,
        };
        config.validate().map_err(|e| e.at(at))?;
        Ok(config)
    }
}

impl SdState {
    pub(crate) fn write(&self, w: &mut Writer) {
        self.config.write(w);
        w.u32(self.iteration);
        self.dropped.write(w);
    }

    pub(crate) fn read(r: &mut Reader<'_>) -> Result<Self, LoadError> {
        Ok(Self {
            config: SdTreeConfig::read(r)?,
            iteration: r.u32("iteration")?,
            dropped: DropCounters::read(r)?,
        })
    }

    /// Whether `other` can be merged into this state (same configuration
    /// and iteration); then adds its drop counts.
    pub(crate) fn merge(&mut self, other: &Self) -> bool {
        if self.config != other.config || self.iteration != other.iteration {
            return false;
        }
        self.dropped.merge(&other.dropped);
        true
    }
}

impl SdCell {
    pub(crate) fn write(&self, w: &mut Writer) {
        self.directions.write(w);
        self.stats.write(w);
        self.learner.write(w);
        w.f64(self.split_weight);
    }

    /// Reads a cell of an SD-tree configured by `config`.
    pub(crate) fn read(r: &mut Reader<'_>, config: &SdTreeConfig) -> Result<Self, LoadError> {
        let mode = config.accumulation;
        let sums = 1 + if config.learn_bsdf_fraction {
            FRACTION_SUMS
        } else {
            0
        };
        Ok(Self {
            directions: DirectionalTree::read(r, mode)?,
            stats: SumBuffer::read(r, "sd cell: statistics", mode, sums)?,
            learner: FractionLearner::read(r)?,
            split_weight: r.check("sd cell: split weight", Reader::f64, |w| {
                *w >= 0.0 && w.is_finite()
            })?,
        })
    }

    /// Whether `other` holds the same distributions (so their statistics
    /// add up to one cell's).
    pub(crate) fn same_layout(&self, other: &Self) -> bool {
        self.directions.same_layout(&other.directions) && self.learner == other.learner
    }

    /// Zeroes the cell's records (building sums, statistics).
    pub(crate) fn clear_records(&mut self) {
        self.directions.clear_records();
        self.stats.clear();
        self.split_weight = 0.0;
    }

    /// Adds `other`'s statistics (same layout).
    pub(crate) fn merge(&mut self, other: &Self) {
        self.directions.merge(&other.directions);
        self.stats.merge(&other.stats);
        self.split_weight += other.split_weight;
    }
}

impl SdTree {
    /// The SD-tree as bytes: a header, the configuration, the iteration,
    /// the drop counts, the spatial tree and every cell (both quadtree
    /// copies, the building sums, the fraction's optimiser state).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::default();
        self.state.write(&mut w);
        self.spatial.write(&mut w, |cell, w| cell.write(w));
        w.finish(Kind::SdTree)
    }

    /// The SD-tree saved by [`SdTree::to_bytes`], checked; it samples,
    /// evaluates and learns exactly like the one saved.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, LoadError> {
        let mut r = Reader::open(bytes, Kind::SdTree)?;
        let state = SdState::read(&mut r)?;
        let spatial = BinaryTree::read(&mut r, |r| SdCell::read(r, &state.config))?;
        r.end()?;
        Ok(Self { spatial, state })
    }

    /// Zeroes everything recorded since the last refinement (building
    /// sums, statistics, drop counts), keeping what was learned: the
    /// starting point of a worker's share (see [`SdTree::merge`]).
    pub fn clear_records(&mut self) {
        for cell in self.spatial.data_slice_mut() {
            cell.clear_records();
        }
        self.state.dropped.reset();
    }

    /// Adds what `other` recorded to this SD-tree, with the protocol of
    /// [`Glt::merge`](crate::Glt::merge) (workers start from the
    /// coordinator's state after [`SdTree::clear_records`]): both must be
    /// copies of one SD-tree after the same refinements, else nothing
    /// changes and this is `false`.
    pub fn merge(&mut self, other: &Self) -> bool {
        let same = self.state.config == other.state.config
            && self.state.iteration == other.state.iteration
            && self.spatial.same_layout(&other.spatial)
            && self
                .spatial
                .data_slice()
                .iter()
                .zip(other.spatial.data_slice())
                .all(|(a, b)| a.same_layout(b));
        if !same || !self.state.merge(&other.state) {
            return false;
        }
        for (a, b) in self
            .spatial
            .data_slice_mut()
            .iter_mut()
            .zip(other.spatial.data_slice())
        {
            a.merge(b);
        }
        true
    }
}
