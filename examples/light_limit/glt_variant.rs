//! A GLT configuration to measure, from a `key=value` list.

use crate::methods::GuideParams;
use guiding::glt::{BelowCut, Modulation, Prior};
use guiding::spatial::SpatialFilter;

/// One GLT configuration and how long it trains.
#[derive(Clone, Debug)]
pub struct GltVariant {
    /// The method name in the table (`glt` for the defaults).
    pub name: String,
    /// The learned structure's parameters.
    pub params: GuideParams,
    /// Samples per pixel of training (the render schedule).
    pub train_spp: u64,
}

impl GltVariant {
    /// The crate's defaults, trained as the render example trains `pt-glt`.
    pub fn defaults(train_spp: u64) -> Self {
        Self {
            name: "glt".into(),
            params: GuideParams::default(),
            train_spp,
        }
    }

    /// Parses `spec`: space-separated `key=value` (sigma, alpha,
    /// below=energy|importance, modulation=none|importance,
    /// splat=radiance|contribution, filter=nearest|jitter,
    /// prior=energy|importance, min-splats,
    /// threshold, train-spp) applied
    /// to the defaults.
    pub fn parse(spec: &str, train_spp: u64) -> Result<Self, String> {
        let mut v = Self::defaults(train_spp);
        for kv in spec.split_whitespace() {
            let (k, val) = kv
                .split_once('=')
                .ok_or_else(|| format!("`{kv}`: expected key=value"))?;
            let num = || val.parse::<f64>().map_err(|e| format!("`{kv}`: {e}"));
            match k {
                "sigma" => v.params.sigma = num()?,
                "alpha" => v.params.alpha = num()?,
                "threshold" => v.params.glt_spatial_threshold = num()?,
                "prior" => {
                    v.params.prior = match val {
                        "energy" => Prior::Energy,
                        "importance" => Prior::Importance,
                        _ => return Err(format!("`{kv}`: energy or importance")),
                    }
                }
                "min-splats" => v.params.min_splats = num()? as u32,
                "train-spp" => v.train_spp = num()? as u64,
                "below" => {
                    v.params.below_cut = match val {
                        "energy" => BelowCut::Energy,
                        "importance" => BelowCut::Importance,
                        _ => return Err(format!("`{kv}`: energy or importance")),
                    }
                }
                "modulation" => {
                    v.params.modulation = match val {
                        "none" => Modulation::None,
                        "importance" => Modulation::Importance,
                        _ => return Err(format!("`{kv}`: none or importance")),
                    }
                }
                "splat" => {
                    v.params.contribution_splats = match val {
                        "radiance" => false,
                        "contribution" => true,
                        _ => return Err(format!("`{kv}`: radiance or contribution")),
                    }
                }
                "filter" => {
                    v.params.glt_filter = match val {
                        "nearest" => SpatialFilter::Nearest,
                        "jitter" => SpatialFilter::StochasticBox,
                        _ => return Err(format!("`{kv}`: nearest or jitter")),
                    }
                }
                _ => return Err(format!("`{kv}`: unknown key {k:?}")),
            }
        }
        v.name = format!("glt {}", spec.trim());
        Ok(v)
    }
}
