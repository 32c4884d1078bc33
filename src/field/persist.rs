//! Saving and loading the combined field, checked; merging two fields'
//! statistics.

use super::{FieldCell, GuidingField};
use crate::cut::{CutConfig, CutRules, GuidingCut, OctantRecords};
use crate::light_tree::LightHierarchy;
use crate::light_tree::{fingerprint, read_fingerprint, shape_fingerprint};
use crate::persist::{Kind, LoadError, Reader, Writer, tag, untag};
use crate::sd_tree::{SdCell, SdState};
use crate::spatial::BinaryTree;
use crate::spatial::FILTERS;
use alloc::vec::Vec;

impl<H: LightHierarchy> GuidingField<H> {
    /// The field as bytes: a header, the light hierarchy's shape fingerprint, the
    /// SD-tree's configuration and state, the cuts' configuration, the
    /// light filter and every cell (quadtrees, fraction, cut, sums).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(shape_fingerprint(self.light_tree()));
        self.sd.write(&mut w);
        self.rules.config().write(&mut w);
        w.u8(tag(&FILTERS, self.light_filter));
        self.spatial.write(&mut w, |cell, w| {
            cell.sd.write(w);
            cell.cut.write(w);
            // Version 3: the light records per octant.
            cell.octants.write(w);
        });
        w.finish(Kind::Field)
    }

    /// The field saved by [`GuidingField::to_bytes`] over `lights`, which
    /// must be the hierarchy it was trained with or a refit of it (as
    /// [`Glt::from_bytes`](crate::Glt::from_bytes))
    /// ([`LoadError::LightTreeMismatch`] otherwise); checked, and then
    /// exactly like the one saved.
    pub fn from_bytes(bytes: &[u8], light_tree: H) -> Result<Self, LoadError> {
        let mut r = Reader::open(bytes, Kind::Field)?;
        read_fingerprint(&mut r, &light_tree)?;
        let sd = SdState::read(&mut r)?;
        let at = r.offset();
        let config = CutConfig::read(&mut r)?;
        let rules = CutRules::new(light_tree, config).map_err(|e| e.at(at))?;
        let light_filter = untag(&mut r, "light filter", &FILTERS)?;
        let spatial = BinaryTree::read(&mut r, |r| {
            let sd_cell = SdCell::read(r, &sd.config)?;
            let cut = GuidingCut::read(r, &rules)?;
            let octants = match r.version() {
                3.. => OctantRecords::read(r, "cell: octant light records")?,
                _ => OctantRecords::default(),
            };
            Ok(FieldCell::with_counts(sd_cell, cut, octants))
        })?;
        r.end()?;
        Ok(Self {
            spatial,
            sd,
            rules,
            light_filter,
        })
    }

    /// Zeroes everything recorded since the last refinement, keeping what
    /// was learned: the starting point of a worker's share (see
    /// [`GuidingField::merge`]).
    pub fn clear_records(&mut self) {
        for cell in self.spatial.data_slice_mut() {
            cell.sd.clear_records();
            cell.cut.clear_records();
            cell.octants.reset();
        }
        self.sd.dropped.reset();
    }

    /// Adds what `other` recorded to this field, with the protocol of
    /// [`Glt::merge`](crate::Glt::merge) (workers start from the
    /// coordinator's state after [`GuidingField::clear_records`]): both
    /// must be copies of one field after the same refinements, else
    /// nothing changes and this is `false`. Deterministic mode merges bit
    /// for bit.
    pub fn merge(&mut self, other: &Self) -> bool {
        let same = fingerprint(self.light_tree()) == fingerprint(other.light_tree())
            && self.rules.config() == other.rules.config()
            && self.light_filter == other.light_filter
            && self.spatial.same_layout(&other.spatial)
            && self
                .spatial
                .data_slice()
                .iter()
                .zip(other.spatial.data_slice())
                .all(|(a, b)| a.sd.same_layout(&b.sd) && a.cut.same_layout(&b.cut));
        if !same || !self.sd.merge(&other.sd) {
            return false;
        }
        for (a, b) in self
            .spatial
            .data_slice_mut()
            .iter_mut()
            .zip(other.spatial.data_slice())
        {
            a.sd.merge(&b.sd);
            a.cut.merge(&b.cut);
            a.octants.merge(&b.octants);
        }
        true
    }
}
