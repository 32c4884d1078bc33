//! Parameters of the guiding field.

use crate::glt::CutConfig;
use crate::math::Accumulation;
use crate::sd_tree::SdTreeConfig;
use crate::spatial::SpatialFilter;

/// Everything a [`GuidingField`](super::GuidingField) is configured with:
/// the SD-tree's parameters, the cuts' parameters and the filter of the
/// light splats. `Default` is PPG's paper setup with the GLT's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldConfig {
    /// The SD-tree's parameters. Its spatial threshold `c` drives every
    /// spatial split of the field (by the weight of the radiance splats, as
    /// in PPG; light splats do not count); its filters are those of
    /// [`GuidingField::splat_radiance`](super::GuidingField::splat_radiance);
    /// its `max_bytes` caps everything but the table the cells share
    /// ([`FieldMemory::capped`](super::FieldMemory::capped)).
    pub sd: SdTreeConfig,
    /// Every cell's cut.
    pub cut: CutConfig,
    /// The spatial filter of
    /// [`GuidingField::splat_light`](super::GuidingField::splat_light).
    /// Default [`SpatialFilter::Nearest`], as
    /// [`GltConfig::filter`](crate::glt::GltConfig::filter): a jittered
    /// splat carries light through walls into cells that cannot see it
    /// (measured in docs/experiments/light-selection.md, "The sealed dim
    /// room").
    /// [`SpatialFilter::StochasticBox`] draws its jitter as the GLT does
    /// (one `next_u64` per splat).
    pub light_filter: SpatialFilter,
}

impl Default for FieldConfig {
    fn default() -> Self {
        Self {
            sd: SdTreeConfig::default(),
            cut: CutConfig::default(),
            light_filter: SpatialFilter::Nearest,
        }
    }
}

impl FieldConfig {
    /// Checks the SD-tree's ([`SdTreeConfig::validate`]) and the cuts'
    /// ([`CutConfig::validate`]) fields.
    pub fn validate(&self) -> Result<(), crate::ConfigError> {
        self.sd.validate()?;
        self.cut.validate()
    }

    /// The configuration with both the SD-tree's and the cuts' training
    /// sums in `mode` ([`Accumulation::Deterministic`] makes the whole
    /// learned field bit-identical whatever the thread count).
    pub fn with_accumulation(mut self, mode: Accumulation) -> Self {
        self.sd.accumulation = mode;
        self.cut.accumulation = mode;
        self
    }
}
