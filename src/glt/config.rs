//! [`GltConfig`]: the parameters of a [`Glt`](super::Glt), its cuts' and
//! its spatial tree's.

use crate::cut::CutConfig;
use crate::error::ConfigError;
use crate::spatial::SpatialFilter;

/// Parameters of a [`Glt`](super::Glt): the cuts' and the spatial tree's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltConfig {
    /// How each cell's cut is refined and sampled.
    pub cut: CutConfig,
    /// PPG's spatial threshold `c`: a cell that takes part in its `g`-th
    /// refinement (counted from 0, see [`Glt::refine`](super::Glt::refine)) splits while its
    /// number of records exceeds `c * sqrt(2^g)`; each split halves the
    /// count and gives both halves a copy of the cut and its statistics.
    /// Default 250: a cut learns from far fewer records than a quadtree,
    /// and finer cells paid off in every measurement (at 64 spp on `ring`
    /// and `city`, relMSE 0.206 and 0.491 at 250, 0.218 and 0.524 at
    /// 1000, 0.244 and 0.573 at PPG's 12,000, for 3x and 1.4x the memory
    /// of 12,000; docs/experiments/tile-order.md). Memory grows with the
    /// square root of the records (the threshold doubles every two
    /// refinements); cap it with `max_bytes`.
    pub spatial_threshold: f64,
    /// Cap, in bytes, on the spatial tree plus the cells' cuts (their
    /// nodes and sums) after every [`Glt::refine`](super::Glt::refine); `None` for none. Cell
    /// splits are refused once it is reached (a split is charged the cut
    /// it copies), then every cut's growth is scaled down by one factor:
    /// each is rebuilt with a coarser `sigma` until it has at most that
    /// share of the nodes it would have had (`src/spatial/budget.rs`). The
    /// cap cannot shrink below what the cells hold whatever their nodes
    /// (one sum each, the anchor sums).
    pub max_bytes: Option<usize>,
    /// The spatial filter of light records
    /// ([`LightVertex::record_light`](crate::LightVertex::record_light)). Default
    /// [`SpatialFilter::Nearest`]: the estimate goes to the cell holding
    /// the shading point. A jittering filter carries a record into the
    /// neighbouring cells, also through walls, where the light it saw may
    /// be invisible; a dim room beside bright ones then learns its
    /// neighbours' lights and samples worse than without learning
    /// (`tests/glt_walls.rs`).
    pub light_filter: SpatialFilter,
}

impl GltConfig {
    /// Checks every field: the cut's ([`CutConfig::validate`]) and
    /// `spatial_threshold` finite and positive (at 0 every cell would
    /// split on every record).
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.cut.validate()?;
        crate::error::positive("GltConfig::spatial_threshold", self.spatial_threshold)
    }
}

impl Default for GltConfig {
    fn default() -> Self {
        Self {
            cut: CutConfig::default(),
            spatial_threshold: 250.0,
            max_bytes: None,
            light_filter: SpatialFilter::Nearest,
        }
    }
}
