//! [`SdState`]: what an SD-tree keeps besides its cells. Its operations
//! (`record`, `record_fraction`, `refine` and the memory report) work on a
//! spatial tree of any cell type that holds an [`SdCell`], so the SD-tree
//! and the combined guiding field ([`crate::field`]) share them.

use super::SdCell;
use super::config::SdTreeConfig;
use crate::dropped::DropCounters;

/// The SD-tree's configuration, iteration count and dropped-input counters.
#[derive(Clone, Debug)]
pub(crate) struct SdState {
    pub(crate) config: SdTreeConfig,
    /// How many refinements were made (the `k` of the next split threshold).
    pub(crate) iteration: u32,
    pub(crate) dropped: DropCounters,
}

impl SdState {
    pub(crate) fn new(config: SdTreeConfig) -> Self {
        Self {
            config,
            iteration: 0,
            dropped: DropCounters::default(),
        }
    }

    /// A fresh cell: uniform quadtree, the configured starting fraction.
    pub(crate) fn new_cell(&self) -> SdCell {
        SdCell::new(
            self.config.accumulation,
            self.config.learn_bsdf_fraction,
            self.config.effective_bsdf_fraction(),
        )
    }
}
