//! A GLT configuration to measure, from a `key=value` list.

use crate::cli;
use crate::methods::GuideParams;
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
    /// below=power|importance, modulation=none|importance,
    /// bound=children|grandchildren,
    /// record=radiance|contribution, filter=nearest|jitter,
    /// prior=power|importance, rules=paper (the paper's rules, see the
    /// render example's `--paper-rules`), min-records, threshold,
    /// train-spp) applied in order to the defaults.
    pub fn parse(spec: &str, train_spp: u64) -> Result<Self, String> {
        Self::defaults(train_spp).with(spec)
    }

    /// This configuration with the settings of `spec` (as
    /// [`GltVariant::parse`] reads them) applied in order, named for them.
    pub fn with(self, spec: &str) -> Result<Self, String> {
        let mut v = self;
        for kv in spec.split_whitespace() {
            let (k, val) = kv
                .split_once('=')
                .ok_or_else(|| format!("`{kv}`: expected key=value"))?;
            let in_kv = |e: String| format!("`{kv}`: {e}");
            let num = || val.parse::<f64>().map_err(|e| in_kv(e.to_string()));
            match k {
                "sigma" => v.params.sigma = num()?,
                "alpha" => v.params.alpha = num()?,
                "threshold" => v.params.glt_spatial_threshold = num()?,
                // The render example's own parsers: one list of names.
                "prior" => v.params.prior = cli::parse_prior(val).map_err(in_kv)?,
                "below" => v.params.below_cut = cli::parse_below_cut(val).map_err(in_kv)?,
                "modulation" => v.params.modulation = cli::parse_modulation(val).map_err(in_kv)?,
                "bound" => {
                    v.params.importance_bound = cli::parse_importance_bound(val).map_err(in_kv)?
                }
                "record" => {
                    v.params.contribution_records =
                        pick(kv, val, [("radiance", false), ("contribution", true)])?
                }
                "filter" => {
                    v.params.glt_filter = pick(
                        kv,
                        val,
                        [
                            ("nearest", SpatialFilter::Nearest),
                            ("jitter", SpatialFilter::StochasticBox),
                        ],
                    )?
                }
                "rules" => {
                    if pick(kv, val, [("paper", true), ("default", false)])? {
                        v.params = v.params.paper_rules();
                    }
                }
                "resample" => v.params.resample = num()? as usize,
                "visibility" => {
                    v.params.visibility = pick(kv, val, [("on", true), ("off", false)])?
                }
                "min-records" => v.params.min_records = num()? as u32,
                "train-spp" => v.train_spp = num()? as u64,
                _ => return Err(format!("`{kv}`: unknown key {k:?}")),
            }
        }
        v.name = format!("glt {}", spec.trim());
        Ok(v)
    }
}

/// The value named `val` among `choices` (`kv` is the whole setting, for
/// the error).
fn pick<T: Copy, const N: usize>(
    kv: &str,
    val: &str,
    choices: [(&str, T); N],
) -> Result<T, String> {
    choices
        .iter()
        .find(|(name, _)| *name == val)
        .map(|&(_, t)| t)
        .ok_or_else(|| {
            let names: Vec<&str> = choices.iter().map(|(n, _)| *n).collect();
            format!("`{kv}`: expected {}", names.join(" or "))
        })
}
