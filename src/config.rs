//! The knobs of a guide's configuration that are not the configurations
//! themselves: how a cut samples below itself and inside itself, which
//! prior it mixes with, and how a split's prior is weighted
//! ([`CutConfig`](crate::CutConfig)'s fields). The configurations are at
//! the crate root ([`GltConfig`](crate::GltConfig),
//! [`CutConfig`](crate::CutConfig), [`SdTreeConfig`](crate::SdTreeConfig),
//! [`QuadtreeConfig`](crate::QuadtreeConfig),
//! [`FieldConfig`](crate::FieldConfig)); every default is measured
//! (docs/results.md) and a renderer rarely names these.
//!
//! ```
//! use guiding::config::{BelowCut, Modulation, Prior};
//! use guiding::{CutConfig, GltConfig};
//!
//! // The paper's rules: one distribution per cell, power below the cut.
//! let paper = CutConfig::default().with_paper_rules();
//! assert_eq!(paper.below_cut, BelowCut::Power);
//! assert_eq!(paper.modulation, Modulation::None);
//! assert_eq!(paper.prior, Prior::Power);
//! let config = GltConfig { cut: paper, ..GltConfig::default() };
//! assert!(config.validate().is_ok());
//! ```

pub use crate::cut::{BelowCut, ImportanceBound, Modulation, Prior, SplitPrior};
