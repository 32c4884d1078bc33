//! Parameters of the guiding field.

use crate::cut::CutConfig;
use crate::math::Accumulation;
use crate::sd_tree::SdTreeConfig;
use crate::spatial::SpatialFilter;

/// Everything a [`GuidingField`](super::GuidingField) is configured with:
/// the SD-tree's parameters, the cuts' parameters and the filter of the
/// light records. `Default` is PPG's paper setup with the GLT's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldConfig {
    /// The SD-tree's parameters. Its spatial threshold `c` drives every
    /// spatial split of the field (by the weight of the radiance records, as
    /// in PPG; light records do not count); its filters are those of
    /// [`DirectionVertex::record_radiance`](crate::DirectionVertex::record_radiance);
    /// its `max_bytes` caps everything but the table the cells share
    /// (`FieldMemory::capped`).
    pub sd: SdTreeConfig,
    /// Every cell's cut.
    pub cut: CutConfig,
    /// The spatial filter of light records
    /// ([`LightVertex::record_light`](crate::LightVertex::record_light)).
    /// Default [`SpatialFilter::Nearest`], as
    /// [`GltConfig::light_filter`](crate::GltConfig::light_filter): a
    /// jittered record carries light through walls into cells that cannot
    /// see it (measured in docs/experiments/light-selection.md, "The
    /// sealed dim room").
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
    pub fn validate(&self) -> Result<(), crate::error::ConfigError> {
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
