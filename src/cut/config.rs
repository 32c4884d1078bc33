//! Parameters of the Guiding Light Tree: the per-cell cut ([`CutConfig`]).

use crate::error::{self, ConfigError};
use crate::light_sampler::UnboundedLights;
use crate::math::Accumulation;

/// How the cut's sampling continues below the cut, inside the cluster a cut
/// slot stands for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BelowCut {
    /// By the light tree's subtree power, as the paper does (one read of
    /// the [`CutRules`](super::CutRules)'s split table per level);
    /// independent of the shading point.
    Power,
    /// By the Estevez-Kulla / pbrt-v4 importance (power x orientation /
    /// distance^2) at the shading point, the paper's suggestion for future
    /// work. Where both children have zero importance the step falls back to
    /// power, so the cut component stays a proper distribution.
    ///
    /// Lower variance than [`BelowCut::Power`] for a costlier walk below
    /// the cut (two importance evaluations per level); measured in
    /// docs/experiments/settings.md, "Defaults of the cut". The default, with the other
    /// importance rules (see [`CutConfig::with_importance`]).
    #[default]
    Importance,
}

/// Whether the cut's learned probabilities vary with the shading point
/// inside a cell.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Modulation {
    /// One distribution for the whole cell: at a cut node the left child
    /// has the learned probability `p_left`, wherever the shading point
    /// is (the paper).
    None,
    /// The learned quantity is a per-cluster correction factor on top of
    /// the analytic importance (`crate::light_sampler::importance`): at
    /// refinement each slot's learned weight is divided by its cluster's
    /// importance at the cell's anchor (the mean position of the records it
    /// learned from), and at a query point `x` the two children of a cut
    /// node are chosen in proportion to factor x importance at `x`:
    ///
    /// ```text
    /// p_left(x) = r I_l(x) / (r I_l(x) + (1 - r) I_r(x)),
    /// r = (W_l / I_l(a)) / (W_l / I_l(a) + W_r / I_r(a))
    /// ```
    ///
    /// (`W` the learned weights, `a` the anchor). At the anchor this is the
    /// learned distribution; elsewhere it follows how the clusters'
    /// distance and orientation change across the cell, which the paper's
    /// constant distribution cannot. The factor keeps what the analytic
    /// bound misses (visibility, the BSDF). Where both importances at `x`
    /// are zero the step falls back to `r`. Records must carry their
    /// position for the anchor ([`crate::Glt`] and the combined field
    /// do, [`crate::learned::CutRules::record_from`] does); a cut rebuilt
    /// without one (recorded only through
    /// [`crate::learned::CutRules::record`]) keeps plain learned
    /// probabilities. The initial cut has equal factors: it samples by the
    /// importance at the shading point until it has learned. The default.
    #[default]
    Importance,
}

/// The distribution of the defensive mixture's prior component (weight
/// [`CutConfig::alpha`]), which keeps every emitter that can contribute at
/// a non-zero pmf whatever the cut learned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Prior {
    /// Tree-by-power from the light tree's root: power sampling, the same
    /// at every shading point (the paper).
    Power,
    /// Tree-by-importance from the root (the Estevez-Kulla / pbrt-v4 rule
    /// of `ImportanceTreeSampler`, power where both children's
    /// importance vanishes). The importance bound is conservative, so an
    /// emitter that can reach the point keeps a non-zero pmf. With
    /// [`Modulation::Importance`] and [`BelowCut::Importance`] the walk
    /// evaluates these importances anyway, so the better prior is free.
    /// The default.
    #[default]
    Importance,
}

/// How a slot that is split for the first time shares its learned weight
/// between its two new children (they have no statistics of their own yet).
///
/// Either way a child whose subtree has zero power gets nothing: its
/// emitters can never receive a record, and giving it weight would only lead
/// the cut into lights that cannot be sampled below it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SplitPrior {
    /// Half each, as the paper and its code do. The default: a fresh split
    /// that ignores power explores dim but near clusters sooner, which
    /// helps most when cells have little data (measured in
    /// docs/experiments/settings.md, "Defaults of the cut").
    #[default]
    Half,
    /// In the ratio of the children's subtree powers: a freshly split
    /// cluster is sampled exactly as it was before the split (below the cut
    /// it was descended by power too), so a split alone never changes the
    /// distribution before the cluster has data.
    Power,
}

/// The bound the importance rules weigh a node's two children by
/// (wherever a rule reads importance: [`Modulation::Importance`],
/// [`BelowCut::Importance`], [`Prior::Importance`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ImportanceBound {
    /// Each child by its own bound (Estevez-Kulla, as pbrt-v4's light
    /// BVH): two evaluations per level of a walk. A file saved before
    /// format version 6 loads with this bound, so it answers as it did.
    Children,
    /// At a node of even depth (the root at 0; over instances, the depth
    /// in the flattened tree, an instance's leaf standing for its mesh
    /// root) each child by the sum of its own two children's bounds (a
    /// leaf child by its own), at odd depth each child by its own bound.
    /// The grandchildren's boxes are smaller and their cones narrower, so
    /// the sum is the tighter bound, and their four evaluations go in four
    /// vector lanes, once per two levels (`src/cut/child_weights.rs`):
    /// 7-11% lower variance on city and torus and 6-9% fewer instructions
    /// than [`ImportanceBound::Children`] (docs/benchmarks.md, "Weighing a
    /// child by its children"). The default.
    #[default]
    Grandchildren,
}

/// The parameters of one guiding cut: how it is refined and sampled.
///
/// Constructors check it ([`CutConfig::validate`]): a value out of its
/// range is a [`ConfigError`], never clamped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutConfig {
    /// Split threshold: a slot whose share of its cell's learned total is
    /// above `sigma` is split (down to single emitters); slots at or below
    /// end the cut. Default 0.01, the paper's recommendation.
    pub sigma: f64,
    /// Weight of the defensive mixture with the prior ([`CutConfig::prior`],
    /// by default importance at the shading point):
    /// `pmf = (1 - alpha) * learned + alpha * prior`. Every emitter with
    /// non-zero power keeps a pmf of at least `alpha` times its prior pmf,
    /// so delta lights stay unbiased without MIS and the variance is never
    /// more than `1 / alpha` times that of prior sampling (Hesterberg's
    /// defensive importance sampling bound), while a perfectly learned
    /// distribution loses at most a factor `1 / (1 - alpha)` in variance.
    ///
    /// Default 0.2: cells learn from few samples, so clusters that matter
    /// but drew no record must be caught by the floor, and 0.2 costs at most
    /// 1.25x against a perfect guide (measured in docs/experiments/settings.md,
    /// "Defaults of the cut"). 0 gives the paper's behaviour (biased for
    /// delta lights the cut never learned).
    pub alpha: f64,
    /// How to continue below the cut. Default `BelowCut::Importance`.
    pub below_cut: BelowCut,
    /// Whether the cut's probabilities vary inside a cell. Default
    /// `Modulation::Importance`.
    pub modulation: Modulation,
    /// The prior component of the defensive mixture. Default
    /// `Prior::Importance`.
    pub prior: Prior,
    /// How a newly split slot's weight is shared. Default
    /// `SplitPrior::Half`.
    pub split_prior: SplitPrior,
    /// The bound the importance rules weigh children by. Default
    /// `ImportanceBound::Grandchildren`.
    pub importance_bound: ImportanceBound,
    /// The scene's unbounded lights (distant and infinite, beside the
    /// emitters) and their prior probability `q` together. Each one's
    /// learned share is its fraction of the recorded values in the cell,
    /// mixed with its prior share `q / count` by `alpha` like the emitters,
    /// so `alpha * q / count` is its floor. Default
    /// [`UnboundedLights::NONE`].
    pub unbounded: UnboundedLights,
    /// How the training sums accumulate. Default [`Accumulation::Fast`];
    /// [`Accumulation::Deterministic`] gives bit-identical learned cuts
    /// whatever the thread count (48 bytes per sum instead of 8).
    pub accumulation: Accumulation,
    /// The fewest non-zero records a cut rebuilds from. Below it,
    /// [`CutRules::refine`](crate::learned::CutRules::refine) keeps the cut as
    /// it is and lets its sums go on accumulating into the next iteration:
    /// a light record is an unbiased estimate whatever distribution drew it,
    /// so sums from several iterations add up. Without this floor a cell
    /// that drew a handful of records (cells of the combined field split on
    /// radiance records, not light records) rebuilds its cut around those
    /// few lights, and only `alpha` stands between it and the rest.
    /// `0` gives the paper's rule (rebuild from any data). Default 64,
    /// measured (docs/experiments/settings.md, "The cut's data floor").
    pub min_records: u32,
    /// Learn each cut cluster's visibility: the fraction of its unshadowed
    /// contribution that arrives, from next-event records that carry both
    /// (`record_visibility` of [`crate::Glt`], its vertex, the field and
    /// `CutRules::record_visibility`),
    /// shrunk towards what the cluster had before when it has few records
    /// and never below 1/64. It is the factor resampled light choice puts
    /// on its target ([`crate::LightSampler::visibility`],
    /// `crate::resampling`); sampling by the cut itself does not read
    /// it. Costs 20 bytes per cut slot (the value and two sums; 100 with
    /// [`Accumulation::Deterministic`]). Default false.
    pub visibility: bool,
}

impl Default for CutConfig {
    fn default() -> Self {
        Self {
            sigma: 0.01,
            alpha: 0.2,
            below_cut: BelowCut::Importance,
            modulation: Modulation::Importance,
            prior: Prior::Importance,
            split_prior: SplitPrior::Half,
            importance_bound: ImportanceBound::Grandchildren,
            unbounded: UnboundedLights::NONE,
            accumulation: Accumulation::Fast,
            min_records: 64,
            visibility: false,
        }
    }
}

impl CutConfig {
    /// This configuration with every importance-based rule on (the
    /// default): `Modulation::Importance`, `BelowCut::Importance` and
    /// `Prior::Importance`: the learned cut follows the shading point
    /// inside its cell. It costs two importance evaluations per level of
    /// every walk and chooses lights better per sample; in the render
    /// example it wins at equal time too on a quiet machine
    /// (docs/experiments/light-selection.md, "At equal time, and per path").
    pub fn with_importance(self) -> Self {
        Self {
            modulation: Modulation::Importance,
            below_cut: BelowCut::Importance,
            prior: Prior::Importance,
            ..self
        }
    }

    /// This configuration with the paper's rules: `Modulation::None`,
    /// `BelowCut::Power` and `Prior::Power`. One learned distribution
    /// per cell, continued below the cut by subtree power, independent of
    /// the shading point: the cheapest walk (one table read per level) and
    /// the configuration to compare against the paper with.
    pub fn with_paper_rules(self) -> Self {
        Self {
            modulation: Modulation::None,
            below_cut: BelowCut::Power,
            prior: Prior::Power,
            ..self
        }
    }

    /// Whether any rule evaluates the importance of light-tree nodes
    /// (`Modulation::Importance`, `BelowCut::Importance`,
    /// `Prior::Importance`).
    pub fn uses_importance(&self) -> bool {
        self.modulation == Modulation::Importance
            || self.below_cut == BelowCut::Importance
            || self.prior == Prior::Importance
    }

    /// Checks every field: `sigma` and `alpha` in `[0, 1]`, the unbounded
    /// lights' prior as [`UnboundedLights::validate`] says.
    pub fn validate(&self) -> Result<(), ConfigError> {
        error::unit("CutConfig::sigma", self.sigma)?;
        error::unit("CutConfig::alpha", self.alpha)?;
        self.unbounded.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two presets set exactly their three rules and keep every other
    /// field; importance is on by default and off under the paper's rules.
    #[test]
    fn presets_set_their_rules_and_keep_the_rest() {
        let mine = CutConfig {
            sigma: 0.3,
            alpha: 0.4,
            min_records: 7,
            visibility: true,
            split_prior: SplitPrior::Power,
            ..CutConfig::default()
        };
        let paper = mine.with_paper_rules();
        assert_eq!(
            (paper.modulation, paper.below_cut, paper.prior),
            (Modulation::None, BelowCut::Power, Prior::Power)
        );
        assert!(!paper.uses_importance());
        let back = paper.with_importance();
        assert_eq!(back, mine, "the importance rules are the default's");
        assert!(back.uses_importance());
        assert_eq!(
            (back.sigma, back.alpha, back.min_records, back.visibility),
            (0.3, 0.4, 7, true)
        );
        assert_eq!(back.split_prior, SplitPrior::Power);
        // Each rule alone makes the configuration use importance.
        for one in [
            CutConfig {
                modulation: Modulation::Importance,
                ..paper
            },
            CutConfig {
                below_cut: BelowCut::Importance,
                ..paper
            },
            CutConfig {
                prior: Prior::Importance,
                ..paper
            },
        ] {
            assert!(one.uses_importance(), "{one:?}");
        }
    }
}
