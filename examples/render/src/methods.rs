//! The rendering methods compared, and the crate objects each one needs:
//! which light sampler drives next-event estimation, and whether a Guiding
//! Light Tree and/or an SD-tree is trained.

use crate::scene::Scene;
use guiding::cut::{BelowCut, CutConfig, ImportanceBound, Modulation, Prior};
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::{ImportanceTreeSampler, PowerSampler, UniformSampler, WithUnbounded};
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::SpatialFilter;
use guiding::{LightSampler, LightTree};

/// A way to render: a light sampler for NEE, optionally with PPG's
/// directional guiding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Path tracing, NEE choosing emitters uniformly.
    PtUniform,
    /// Path tracing, NEE by emitter power.
    PtPower,
    /// Path tracing, NEE by the light BVH's importance (Estevez-Kulla /
    /// pbrt-v4).
    PtBvh,
    /// Path tracing, NEE by the Guiding Light Tree (no directional guiding).
    PtGlt,
    /// Practical Path Guiding (SD-tree) with uniform NEE: the paper's
    /// baseline.
    Ppg,
    /// Practical Path Guiding with GLT NEE, the paper's method: one
    /// spatial tree whose cells hold a quadtree and a cut
    /// (`guiding::field::GuidingField`).
    PpgGlt,
    /// PPG's own SD-tree for directions beside a GLT on its own spatial
    /// tree for NEE (two lookups per vertex): what the combined field's
    /// one subdivision costs or saves.
    PpgAndGlt,
}

impl Method {
    /// Every method, in table order.
    pub const ALL: [Method; 7] = [
        Method::PtUniform,
        Method::PtPower,
        Method::PtBvh,
        Method::PtGlt,
        Method::Ppg,
        Method::PpgGlt,
        Method::PpgAndGlt,
    ];

    /// The methods a run without arguments compares.
    pub const MAIN: [Method; 4] = [Method::PtBvh, Method::PtGlt, Method::Ppg, Method::PpgGlt];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Method::PtUniform => "pt-uniform",
            Method::PtPower => "pt-power",
            Method::PtBvh => "pt-bvh",
            Method::PtGlt => "pt-glt",
            Method::Ppg => "ppg",
            Method::PpgGlt => "ppg-glt",
            Method::PpgAndGlt => "ppg+glt",
        }
    }

    /// The method called `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Trains a Guiding Light Tree on its own spatial tree.
    pub fn uses_glt(self) -> bool {
        matches!(self, Method::PtGlt | Method::PpgAndGlt)
    }

    /// Trains an SD-tree for directional guiding.
    pub fn uses_sd_tree(self) -> bool {
        matches!(self, Method::Ppg | Method::PpgAndGlt)
    }

    /// Trains the combined field (quadtree and cut per cell).
    pub fn uses_field(self) -> bool {
        matches!(self, Method::PpgGlt)
    }

    /// Renders in training iterations (PPG's schedule).
    pub fn is_trained(self) -> bool {
        self.uses_glt() || self.uses_sd_tree() || self.uses_field()
    }
}

/// Parameters of the learned structures.
#[derive(Clone, Copy, Debug)]
pub struct GuideParams {
    /// The GLT's split threshold sigma.
    pub sigma: f64,
    /// PPG's spatial split threshold `c` (radiance records), for the
    /// SD-tree and the combined field.
    pub spatial_threshold: f64,
    /// The spatial split threshold of the GLT's own tree (light records).
    pub glt_spatial_threshold: f64,
    /// The GLT's rule below its cut.
    pub below_cut: BelowCut,
    /// The fewest non-zero light records a cut rebuilds from.
    pub min_records: u32,
    /// The weight of the GLT's defensive mixture with the power prior.
    pub alpha: f64,
    /// Whether the GLT's cut probabilities vary inside a cell.
    pub modulation: Modulation,
    /// The bound the GLT's importance rules weigh children by.
    pub importance_bound: ImportanceBound,
    /// Light records carry `f cos Le w / p` (else the paper's `Le w / p`).
    pub contribution_records: bool,
    /// The spatial filter of the light records (`pt-glt`'s GLT and
    /// `ppg-glt`'s field).
    pub glt_filter: SpatialFilter,
    /// The GLT's defensive prior.
    pub prior: Prior,
    /// Whether the cuts learn each cluster's visibility from the NEE
    /// records ([`CutConfig::visibility`]).
    pub visibility: bool,
    /// Candidates of resampled NEE for the GLT methods, resampled with the
    /// light the next direction finds (0: none, plain NEE with MIS).
    pub resample: usize,
    /// Resample at the first this-many non-specular vertices (0: all).
    pub resample_vertices: u32,
    /// Light samples per vertex (without resampling), averaged.
    pub nee_samples: u32,
    /// Take `nee_samples` at the first this-many non-specular vertices
    /// (0: all).
    pub nee_samples_vertices: u32,
}

impl Default for GuideParams {
    /// The crate's defaults, with the render example's spatial thresholds
    /// (see its `--spatial-threshold` and `--glt-spatial-threshold`).
    fn default() -> Self {
        let cut = CutConfig::default();
        Self {
            sigma: cut.sigma,
            spatial_threshold: 4000.0,
            glt_spatial_threshold: guiding::glt::GltConfig::default().spatial_threshold,
            below_cut: cut.below_cut,
            min_records: cut.min_records,
            alpha: cut.alpha,
            modulation: cut.modulation,
            importance_bound: cut.importance_bound,
            contribution_records: false,
            glt_filter: GltConfig::default().light_filter,
            prior: cut.prior,
            visibility: cut.visibility,
            resample: 0,
            resample_vertices: 1,
            nee_samples: 1,
            nee_samples_vertices: 0,
        }
    }
}

impl GuideParams {
    /// These parameters with the paper's GLT rules: power below the cut,
    /// one distribution per cell, the power prior at weight 0 (no
    /// defensive mixture), rebuild from any data, jittered light records.
    pub fn paper_rules(self) -> Self {
        let cut = CutConfig::default().with_paper_rules();
        Self {
            below_cut: cut.below_cut,
            modulation: cut.modulation,
            prior: cut.prior,
            alpha: 0.0,
            min_records: 0,
            glt_filter: SpatialFilter::StochasticBox,
            ..self
        }
    }
}

/// A fixed (untrained) light sampler for `method`, with the scene's
/// unbounded lights beside it; `None` for GLT methods.
pub fn fixed_sampler<'a>(
    scene: &'a Scene,
    method: Method,
) -> Option<Box<dyn LightSampler + Sync + 'a>> {
    fn wrap<'a, S: LightSampler + Sync + 'a>(
        s: S,
        scene: &Scene,
    ) -> Box<dyn LightSampler + Sync + 'a> {
        let valid = "the scene's share was validated when it was built";
        Box::new(WithUnbounded::new(s, scene.unbounded_lights).expect(valid))
    }
    match method {
        Method::PtUniform | Method::Ppg => {
            Some(wrap(UniformSampler::new(scene.lights.len()), scene))
        }
        Method::PtPower => Some(wrap(PowerSampler::new(&scene.emitters), scene)),
        Method::PtBvh => Some(wrap(ImportanceTreeSampler::new(&scene.light_tree), scene)),
        Method::PtGlt | Method::PpgGlt | Method::PpgAndGlt => None,
    }
}

/// The cuts' configuration: sigma, and the unbounded lights' prior.
fn cut_config(scene: &Scene, params: &GuideParams) -> CutConfig {
    CutConfig {
        sigma: params.sigma,
        below_cut: params.below_cut,
        min_records: params.min_records,
        alpha: params.alpha,
        modulation: params.modulation,
        importance_bound: params.importance_bound,
        prior: params.prior,
        unbounded: scene.unbounded_lights,
        visibility: params.visibility,
        ..CutConfig::default()
    }
}

/// Müller's improved SD-tree configuration (stochastic box filter, box
/// directional filter, learned BSDF fraction) with the given spatial
/// threshold.
fn sd_config(params: &GuideParams) -> SdTreeConfig {
    SdTreeConfig {
        spatial_threshold: params.spatial_threshold,
        ..SdTreeConfig::improved()
    }
}

/// A fresh combined field over the scene, if `method` uses one.
pub fn new_field<'a>(
    scene: &'a Scene,
    method: Method,
    params: &GuideParams,
) -> Option<GuidingField<&'a LightTree>> {
    if !method.uses_field() {
        return None;
    }
    let config = FieldConfig {
        sd: sd_config(params),
        cut: cut_config(scene, params),
        light_filter: params.glt_filter,
    };
    Some(
        GuidingField::new(&scene.light_tree, scene.bounds, config)
            .expect("scene bounds are finite"),
    )
}

/// A fresh Guiding Light Tree over the scene, if `method` uses one.
pub fn new_glt<'a>(
    scene: &'a Scene,
    method: Method,
    params: &GuideParams,
) -> Option<Glt<&'a LightTree>> {
    if !method.uses_glt() {
        return None;
    }
    let config = GltConfig {
        cut: cut_config(scene, params),
        spatial_threshold: params.glt_spatial_threshold,
        max_bytes: None,
        light_filter: params.glt_filter,
    };
    Some(Glt::new(&scene.light_tree, scene.bounds, config).expect("scene bounds are finite"))
}

/// A fresh SD-tree over the scene, if `method` uses one (see `sd_config`).
pub fn new_sd_tree(scene: &Scene, method: Method, params: &GuideParams) -> Option<SdTree> {
    if !method.uses_sd_tree() {
        return None;
    }
    let config = sd_config(params);
    Some(SdTree::new(scene.bounds, config).expect("scene bounds are finite"))
}
