//! SD-tree parameters.

use crate::error::{self, ConfigError};
use crate::math::Accumulation;
use crate::quadtree::{DirectionalFilter, QuadtreeConfig};
use crate::spatial::SpatialFilter;

/// Everything an [`SdTree`](super::SdTree) is configured with. `Default` is
/// PPG's paper setup; [`SdTreeConfig::improved`] the later recommendations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SdTreeConfig {
    /// `c` of the spatial split rule: after iteration `k` a cell splits
    /// while the statistical weight it collected (about its number of
    /// records) exceeds `c * sqrt(2^k)`. Default 12000 (the paper). The
    /// "improved" setting 4000 splits at a third of the samples, giving a
    /// finer spatial subdivision for the same budget; PPG's released code
    /// uses 4000 scaled by `sqrt(spp per pass / 4)`. Finite and positive.
    pub spatial_threshold: f64,
    /// Directional refinement: `rho` and the depth limit of the quadtrees.
    pub quadtree: QuadtreeConfig,
    /// Spatial filter of radiance records
    /// ([`DirectionVertex::record_radiance`](super::DirectionVertex::record_radiance)).
    pub spatial_filter: SpatialFilter,
    /// Directional filter of radiance records.
    pub directional_filter: DirectionalFilter,
    /// How training sums accumulate; `Deterministic` makes the learned state
    /// bit-identical whatever the thread count.
    pub accumulation: Accumulation,
    /// Optional cap on the SD-tree's bytes (spatial tree plus every cell's
    /// quadtrees and sums, as `SdTreeMemory::total`
    /// counts them) after every refine. The quadtrees are refined first,
    /// their growth scaled down by one factor for all cells when it would
    /// not fit (each rebuilt with a coarser `rho` until it has at most that
    /// share of the nodes it would have had; `src/spatial/budget.rs`); then
    /// a spatial split that would take the total above the cap is not
    /// made. The total is within the cap after every refine, the first
    /// included (`tests/memory_budget.rs` checks each).
    pub max_bytes: Option<usize>,
    /// The BSDF sampling fraction `s` (probability of sampling the BSDF
    /// rather than the guiding distribution). Fixed when
    /// `learn_bsdf_fraction` is false, the starting value otherwise. In
    /// `[0, 1]`.
    pub bsdf_fraction: f32,
    /// Learn `s` per cell (Müller 2019), see the
    /// module docs.
    pub learn_bsdf_fraction: bool,
    /// Adam steps per refinement for the learned fraction, at most one per
    /// recorded sample of the cell. Default 256.
    pub fraction_steps: u32,
}

impl Default for SdTreeConfig {
    fn default() -> Self {
        Self {
            spatial_threshold: 12000.0,
            quadtree: QuadtreeConfig::default(),
            spatial_filter: SpatialFilter::Nearest,
            directional_filter: DirectionalFilter::Nearest,
            accumulation: Accumulation::Fast,
            max_bytes: None,
            bsdf_fraction: 0.5,
            learn_bsdf_fraction: false,
            fraction_steps: 256,
        }
    }
}

impl SdTreeConfig {
    /// The later recommendations (Müller 2019): threshold 4000, stochastic
    /// box spatial filter, box directional filter, learned BSDF fraction.
    pub fn improved() -> Self {
        Self {
            spatial_threshold: 4000.0,
            spatial_filter: SpatialFilter::StochasticBox,
            directional_filter: DirectionalFilter::Box,
            learn_bsdf_fraction: true,
            ..Self::default()
        }
    }

    /// The split threshold after iteration `k`: `c * sqrt(2^k)` (computed in
    /// `f64`, saturating to infinity).
    pub fn split_threshold(&self, k: u32) -> f64 {
        crate::spatial::split_threshold(self.spatial_threshold.max(0.0), k)
    }

    /// Checks every field: `spatial_threshold` finite and positive, the
    /// quadtrees' ([`QuadtreeConfig::validate`]), `bsdf_fraction` in
    /// `[0, 1]`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        error::positive("SdTreeConfig::spatial_threshold", self.spatial_threshold)?;
        self.quadtree.validate()?;
        error::unit("SdTreeConfig::bsdf_fraction", f64::from(self.bsdf_fraction))
    }

    /// `bsdf_fraction` as used: in `[0, 1]`, NaN as 0.5.
    pub(crate) fn effective_bsdf_fraction(&self) -> f32 {
        if self.bsdf_fraction.is_nan() {
            0.5
        } else {
            self.bsdf_fraction.clamp(0.0, 1.0)
        }
    }
}
