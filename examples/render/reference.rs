//! Reference images: a long run of an unbiased method, cached on disk per
//! scene, resolution and scene fingerprint, with its per-pixel variance so
//! error estimates can discount the reference's own noise.

use crate::film::{read_exr, write_exr};
use crate::methods::Method;
use crate::run::{Budget, Settings, render};
use crate::scene::Scene;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// A reference image.
pub struct Reference {
    /// Linear RGB.
    pub image: Vec<Vec3>,
    /// Per-pixel variance of `image` (per channel).
    pub variance: Vec<Vec3>,
    /// Mean luminance.
    pub mean: f64,
    /// Method, samples per pixel and seconds it took (from the cache's
    /// metadata when loaded).
    pub provenance: String,
    /// True when it came from the cache.
    pub cached: bool,
}

/// The cache files' common stem:
/// `<out>/references/<scene>-<w>x<h>-<method>-<hash>`.
pub fn cache_stem(out: &Path, scene: &Scene, width: u32, height: u32, method: Method) -> PathBuf {
    out.join("references").join(format!(
        "{}-{}x{}-{}-{:08x}",
        scene.name,
        width,
        height,
        method.name(),
        scene.fingerprint as u32
    ))
}

/// A line saying how trustworthy `reference` is against the best of the
/// compared methods' relMSE `best` (reached by `name`): its own relMSE
/// `floor` should be below a tenth of it, and if it is not, about how
/// long a reference would have to render (its error falls as 1 / time).
pub fn trust_line(floor: f64, best: f64, name: &str, reference_seconds: Option<f64>) -> String {
    let ratio = floor / best;
    let mut line = format!(
        "reference: own relMSE {floor:.2e} = {ratio:.3} of the best method's ({name}, {best:.2e})"
    );
    if ratio <= 0.1 {
        line.push_str(": trustworthy (below 1/10)");
    } else {
        line.push_str(": NOT below 1/10");
        if let Some(s) = reference_seconds {
            let need = s * ratio / 0.1;
            line.push_str(&format!("; about --reference-seconds {need:.0} would be"));
        }
    }
    line
}

/// The seconds a reference took, from its provenance (`... <s> s`).
pub fn seconds_of(reference: &Reference) -> Option<f64> {
    let mut words = reference.provenance.split_whitespace().rev();
    (words.next() == Some("s")).then(|| words.next()?.parse().ok())?
}

/// Loads the cached reference, or renders it with `method` for `budget` and
/// caches it. `rebuild` ignores the cache.
pub fn load_or_render(
    scene: &Scene,
    out: &Path,
    settings: &Settings,
    method: Method,
    budget: Budget,
    rebuild: bool,
) -> Result<Reference, String> {
    let stem = cache_stem(out, scene, settings.width, settings.height, method);
    let (img_path, var_path, meta_path) = (
        stem.with_extension("exr"),
        PathBuf::from(format!("{}-variance.exr", stem.display())),
        stem.with_extension("txt"),
    );
    if !rebuild && img_path.exists() && var_path.exists() {
        let (w, h, image) = read_exr(&img_path)?;
        let (vw, vh, variance) = read_exr(&var_path)?;
        if (w, h) == (settings.width, settings.height) && (vw, vh) == (w, h) {
            let provenance = std::fs::read_to_string(&meta_path).unwrap_or_default();
            let mean = mean_luminance(&image);
            return Ok(Reference {
                image,
                variance,
                mean,
                provenance: provenance.trim().to_string(),
                cached: true,
            });
        }
    }
    let mut s = settings.clone();
    s.budget = budget;
    s.seed ^= 0x0005_eed0_f4ef;
    let r = render(scene, method, &s);
    std::fs::create_dir_all(stem.parent().unwrap_or(out)).map_err(|e| e.to_string())?;
    write_exr(&img_path, r.width, r.height, &r.image)?;
    write_exr(&var_path, r.width, r.height, &r.variance)?;
    let provenance = format!("{} {} spp {:.1} s", method.name(), r.spp, r.seconds);
    std::fs::write(&meta_path, format!("{provenance}\n")).map_err(|e| e.to_string())?;
    Ok(Reference {
        mean: r.mean,
        image: r.image,
        variance: r.variance,
        provenance,
        cached: false,
    })
}

fn mean_luminance(px: &[Vec3]) -> f64 {
    px.iter()
        .map(|p| f64::from(crate::lights::luminance(*p)))
        .sum::<f64>()
        / px.len().max(1) as f64
}
