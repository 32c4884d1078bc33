//! The command line.

use clap::Parser;
use guiding::cut::{BelowCut, ImportanceBound, Modulation, Prior};
use std::path::PathBuf;

/// Renders the paper's scene analogues with every light-sampling and
/// guiding method at equal time or equal samples, and measures their error
/// against a cached (or committed) reference.
///
/// Without arguments: the default scene (city-street) with the main
/// methods at equal time, against the reference committed for it, then a
/// table.
#[derive(Parser, Debug, Clone)]
#[command(name = "render", version)]
pub struct Args {
    /// Scenes, comma separated: ring, city, city-street, pool, torus, occlusion,
    /// few-lights, box, or `all`.
    #[arg(long, value_delimiter = ',', default_value = crate::scenes::DEFAULT)]
    pub scene: Vec<String>,
    /// Methods, comma separated: pt-uniform, pt-power, pt-bvh, pt-glt, ppg,
    /// ppg-glt, ppg+glt (PPG's SD-tree beside a GLT of its own), or `all`
    /// [default: pt-bvh,pt-glt,ppg,ppg-glt].
    #[arg(long, value_delimiter = ',')]
    pub method: Vec<String>,
    /// Samples per pixel per method (training included); exclusive with
    /// --seconds.
    #[arg(long, conflicts_with = "seconds")]
    pub spp: Option<u64>,
    /// Seconds per method (training included) [default: 20].
    #[arg(long)]
    pub seconds: Option<f64>,
    /// Image width.
    #[arg(long, default_value_t = crate::scenes::DEFAULT_SIZE.0)]
    pub width: u32,
    /// Image height.
    #[arg(long, default_value_t = crate::scenes::DEFAULT_SIZE.1)]
    pub height: u32,
    /// Output directory (images, comparison sheets, reference cache).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Write one JSON record per scene and method here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// The GLT's split threshold sigma. Several values (comma separated)
    /// make a sigma study: each GLT method renders once per value (as
    /// `pt-glt s=0.05`, ...), and `<out>/<scene>/sigma.svg` plots the final
    /// relMSE and the GLT's memory against sigma (the paper's Figure 3).
    #[arg(long, value_delimiter = ',', default_value = "0.01")]
    pub sigma: Vec<f64>,
    /// How the GLT chooses below its cut: `power` (the paper) or
    /// `importance` (Estevez-Kulla importance of the light tree's nodes;
    /// the crate's default).
    #[arg(long, default_value = "importance", value_parser = parse_below_cut)]
    pub below_cut: BelowCut,
    /// The fewest non-zero light records a cut rebuilds from
    /// (`guiding::cut::CutConfig::min_records`; 0 = the paper's rule).
    #[arg(long, default_value_t = guiding::cut::CutConfig::default().min_records)]
    pub min_records: u32,
    /// The GLT's defensive mixture weight alpha
    /// (`guiding::cut::CutConfig::alpha`).
    #[arg(long, default_value_t = guiding::cut::CutConfig::default().alpha)]
    pub alpha: f64,
    /// Whether the GLT's cut probabilities vary inside a cell: `none` (the
    /// paper) or `importance` (learned factor x importance at the point;
    /// the crate's default).
    #[arg(long, default_value = "importance", value_parser = parse_modulation)]
    pub modulation: Modulation,
    /// The bound the GLT's importance rules weigh a node's children by:
    /// `children` (their own) or `grandchildren` (their children's at
    /// even depths; the crate's default).
    #[arg(long, default_value = "grandchildren", value_parser = parse_importance_bound)]
    pub importance_bound: ImportanceBound,
    /// Light records carry the full contribution `f cos Le w / p` instead of
    /// the paper's `Le w / p`.
    #[arg(long)]
    pub contribution_records: bool,
    /// Light records (`pt-glt` and `ppg-glt`) jitter into neighbouring cells
    /// (PPG's stochastic box, as the paper does) instead of going to the
    /// shading point's own cell.
    #[arg(long)]
    pub glt_jitter: bool,
    /// The GLT's defensive prior: `power` (the paper's power sampling) or
    /// `importance` (the crate's default).
    #[arg(long, default_value = "importance", value_parser = parse_prior)]
    pub prior: Prior,
    /// `pt-glt` and `ppg-glt` choose each NEE light by resampling this many
    /// candidates of the GLT together with the light the path's next
    /// direction finds (`guiding::resampling`; at most 64); 0 samples the
    /// GLT directly and weighs the light the next direction finds by MIS
    /// (the default).
    #[arg(long, default_value_t = 0)]
    pub resample: usize,
    /// Resample at the first this-many non-specular vertices of a path
    /// (0: at every one); the others sample the GLT directly. The direct
    /// light at the first vertex is what a pixel sees most of.
    #[arg(long, default_value_t = 1)]
    pub resample_vertices: u32,
    /// Light samples per vertex for next-event estimation, averaged (MIS
    /// counts them all). Many of them approach a perfect light choice at
    /// the vertices they are taken at, so what error remains is what no
    /// light sampler can remove (an instrument, not a way to render;
    /// exclusive with `--resample`).
    #[arg(long, default_value_t = 1)]
    pub nee_samples: u32,
    /// Take `--nee-samples` at the first this-many non-specular vertices of
    /// a path (0: at every one); the others take one.
    #[arg(long, default_value_t = 0)]
    pub nee_samples_vertices: u32,
    /// The GLT's cuts learn each cluster's visibility from the NEE records
    /// (`CutConfig::visibility`), the factor resampling puts on its target.
    #[arg(long)]
    pub visibility: bool,
    /// Run `pt-glt` and `ppg-glt` exactly as the paper describes: power
    /// below the cut, one distribution per cell, no defensive mixture
    /// (alpha 0), rebuild from any data (min-records 0), jittered light
    /// records. Overrides `--below-cut`, `--modulation`, `--prior`,
    /// `--alpha`, `--min-records` and `--glt-jitter`.
    #[arg(long)]
    pub paper_rules: bool,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// PPG's spatial split threshold c (radiance records per cell) for the
    /// SD-tree of `ppg` and the combined field of `ppg-glt`. The default is
    /// Müller's improved PPG's, not rescaled for the resolution: at
    /// 256x192 a rescaled 250 doubled `ppg-glt`'s error on `ring` and took
    /// 15x the memory (docs/experiments/settings.md, "Spatial thresholds").
    #[arg(long, default_value_t = 4000.0)]
    pub spatial_threshold: f64,
    /// The same threshold for the GLT's own spatial tree (`pt-glt`), which
    /// counts light records: finer cells pay off there (the library's
    /// default).
    #[arg(long, default_value_t = guiding::glt::GltConfig::default().spatial_threshold)]
    pub glt_spatial_threshold: f64,
    /// Method that renders references: unbiased and unguided by default,
    /// so that no compared guided method is measured against its own
    /// noise (`pt-bvh`); cached per method.
    #[arg(long, default_value = "pt-bvh")]
    pub reference_method: String,
    /// Seconds a reference renders for [default: 40x --seconds, or 80]; a
    /// cached shorter reference is extended to this.
    #[arg(long)]
    pub reference_seconds: Option<f64>,
    /// Samples per pixel for a reference (instead of seconds).
    #[arg(long, conflicts_with = "reference_seconds")]
    pub reference_spp: Option<u64>,
    /// Only render (or extend) the references, then stop: how a long
    /// reference is made once and cached for later runs.
    #[arg(long)]
    pub reference_only: bool,
    /// Render nothing: read the records of an earlier `--json FILE` and
    /// redraw each scene's plots in `<out>/<scene>/` and print its tables
    /// (how the plots under docs/plots are redrawn from the data committed
    /// beside them).
    #[arg(long, value_name = "FILE")]
    pub replot: Option<PathBuf>,
    /// Re-render references even when cached (or committed).
    #[arg(long)]
    pub rebuild_reference: bool,
    /// Also write each scene's reference to DIR in half floats, named as
    /// the references committed to the repository are
    /// (`examples/render/references`): how a committed reference is made.
    #[arg(long, value_name = "DIR")]
    pub export_reference: Option<PathBuf>,
    /// Seed of every random stream.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Smaller scenes (fewer lights and objects), as the tests use.
    #[arg(long)]
    pub small: bool,
    /// Override the scenes' path depth (segments from the camera).
    #[arg(long)]
    pub max_depth: Option<u32>,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
    /// Save every trained method's learned guide (GLT, SD-tree or field)
    /// to `DIR/<scene>-<method>.guide` after rendering.
    #[arg(long, value_name = "DIR")]
    pub save_guide: Option<std::path::PathBuf>,
    /// Start every trained method from the guide saved in
    /// `DIR/<scene>-<method>.guide` (its schedule goes on from the saved
    /// iteration) instead of training from scratch.
    #[arg(long, value_name = "DIR")]
    pub load_guide: Option<std::path::PathBuf>,
    /// Do not record the convergence curves (relMSE, samples and memory
    /// at log-spaced sample counts, into the JSON and
    /// `<out>/<scene>/convergence.svg`); recording them is not counted
    /// as rendering time.
    #[arg(long)]
    pub no_curve: bool,
    /// Render in tile order (each 16x16 tile to completion, in Morton
    /// order, as pbrt-v3 and rs_pbrt do; needs --spp, draws no curves)
    /// with the guided methods refining by this rule: `never`,
    /// `doubling` (after 1, 3, 7, ... passes' worth of paths) or
    /// `every-wave` (after every wave of tiles). Without it: pass order
    /// (one sample per pixel per pass, PPG's iterations).
    #[arg(long, value_name = "RULE", value_parser = crate::tiles::Refinement::parse)]
    pub tiles: Option<crate::tiles::Refinement>,
    /// Render an animation of this many frames instead: the lights circling
    /// their places (neighbouring lights together, about 0.2% of the
    /// scene's diagonal per frame), the camera moving sideways. Each trained method
    /// renders every frame three ways at the same budget, from scratch,
    /// carrying its guide over with the first frame's light tree, and
    /// carrying it over with the light tree refitted to the frame; each
    /// frame against its own reference (`--reference-seconds`). Writes
    /// `<out>/<scene>/frames.md`.
    #[arg(long, default_value_t = 1)]
    pub frames: u32,
    /// Move the camera by `x,y,z` (the next frame of a camera move).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub camera_shift: Option<Vec<f32>>,
}

/// Parses `--modulation`.
pub fn parse_modulation(s: &str) -> Result<Modulation, String> {
    match s {
        "none" => Ok(Modulation::None),
        "importance" => Ok(Modulation::Importance),
        _ => Err(format!("`{s}`: expected `none` or `importance`")),
    }
}

/// Parses `--importance-bound`.
pub fn parse_importance_bound(s: &str) -> Result<ImportanceBound, String> {
    match s {
        "children" => Ok(ImportanceBound::Children),
        "grandchildren" => Ok(ImportanceBound::Grandchildren),
        _ => Err(format!("`{s}`: expected `children` or `grandchildren`")),
    }
}

/// Parses `--prior`.
pub fn parse_prior(s: &str) -> Result<Prior, String> {
    match s {
        "power" => Ok(Prior::Power),
        "importance" => Ok(Prior::Importance),
        _ => Err(format!("`{s}`: expected `power` or `importance`")),
    }
}

/// Parses `--below-cut`.
pub fn parse_below_cut(s: &str) -> Result<BelowCut, String> {
    match s {
        "power" => Ok(BelowCut::Power),
        "importance" => Ok(BelowCut::Importance),
        _ => Err(format!("`{s}`: expected `power` or `importance`")),
    }
}
