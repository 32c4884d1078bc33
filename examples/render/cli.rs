//! The command line.

use clap::Parser;
use std::path::PathBuf;

/// Renders the paper's scene analogues with every light-sampling and
/// guiding method at equal time or equal samples, and measures their error
/// against a cached reference.
///
/// Without arguments: the default scene with the main methods at equal
/// time (reference included on the first run), then a table.
#[derive(Parser, Debug, Clone)]
#[command(name = "render", version)]
pub struct Args {
    /// Scenes, comma separated: ring, city, pool, torus, occlusion,
    /// few-lights, box, or `all`.
    #[arg(long, value_delimiter = ',', default_value = crate::scenes::DEFAULT)]
    pub scene: Vec<String>,
    /// Methods, comma separated: pt-uniform, pt-power, pt-bvh, pt-glt, ppg,
    /// ppg-glt, or `all` [default: pt-bvh,pt-glt,ppg,ppg-glt].
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
    #[arg(long, default_value_t = 256)]
    pub width: u32,
    /// Image height.
    #[arg(long, default_value_t = 192)]
    pub height: u32,
    /// Output directory (images, comparison sheets, reference cache).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Write one JSON record per scene and method here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// The GLT's split threshold sigma.
    #[arg(long, default_value_t = 0.01)]
    pub sigma: f64,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// PPG's spatial split threshold c for the SD-tree and the GLT's spatial
    /// tree [default: 4000 scaled by the pixel count relative to 1280x720,
    /// at least 250].
    #[arg(long)]
    pub spatial_threshold: Option<f64>,
    /// Method that renders references.
    #[arg(long, default_value = "ppg-glt")]
    pub reference_method: String,
    /// Seconds a reference renders for [default: 4x --seconds, or 80].
    #[arg(long)]
    pub reference_seconds: Option<f64>,
    /// Samples per pixel for a reference (instead of seconds).
    #[arg(long, conflicts_with = "reference_seconds")]
    pub reference_spp: Option<u64>,
    /// Re-render references even when cached.
    #[arg(long)]
    pub rebuild_reference: bool,
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
}

impl Args {
    /// PPG's spatial threshold for this resolution.
    pub fn spatial_threshold(&self) -> f64 {
        self.spatial_threshold.unwrap_or_else(|| {
            let pixels = f64::from(self.width) * f64::from(self.height);
            (4000.0 * pixels / (1280.0 * 720.0)).max(250.0)
        })
    }
}
