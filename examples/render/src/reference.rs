//! Reference images: a long run of an unbiased method, cached on disk per
//! scene, resolution and scene fingerprint, with its per-pixel variance so
//! error estimates can discount the reference's own noise.

use crate::film::{read_exr, write_exr, write_exr_half};
use crate::methods::Method;
use crate::report::Record;
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
    /// Whether it was cached, rendered or extended now.
    pub origin: Origin,
}

/// Where references committed to the repository live: the default scene's
/// at the default size, so a first run does not spend most of its time
/// rendering one (`references/README.md` there says how each was made).
pub const COMMITTED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/references");

/// The common stem of a reference's files in `dir`:
/// `<dir>/<scene>-<w>x<h>-<method>-<hash>` (`.exr`, `-variance.exr`,
/// `.txt` with the provenance on its first line). The hash is the scene's
/// fingerprint, so a reference of a scene that changed is never used.
pub fn stem_in(dir: &Path, scene: &Scene, width: u32, height: u32, method: Method) -> PathBuf {
    dir.join(format!(
        "{}-{}x{}-{}-{:08x}",
        scene.name,
        width,
        height,
        method.name(),
        scene.fingerprint as u32
    ))
}

/// The cache files' common stem: [`stem_in`] `<out>/references`.
pub fn cache_stem(out: &Path, scene: &Scene, width: u32, height: u32, method: Method) -> PathBuf {
    stem_in(&out.join("references"), scene, width, height, method)
}

/// The image, variance and provenance paths of a stem.
pub fn paths(stem: &Path) -> (PathBuf, PathBuf, PathBuf) {
    (
        stem.with_extension("exr"),
        PathBuf::from(format!("{}-variance.exr", stem.display())),
        stem.with_extension("txt"),
    )
}

/// A line saying how trustworthy `reference` is against the best of the
/// compared methods, `best`: the reference's own relMSE (`best`'s
/// `reference_relmse`) should be below a tenth of `best`'s at the end of
/// its curve. If it is not, the
/// line says up to when on the curves it is (where `best`'s relMSE is
/// still ten times `floor`) and about how long a reference would have to
/// render (its error falls as 1 / time).
pub fn trust_line(best: &Record, reference_seconds: Option<f64>) -> String {
    let floor = best.reference_relmse;
    let ratio = floor / best.relmse;
    let mut line = format!(
        "reference: own relMSE {floor:.2e} = {ratio:.3} of the best method's ({}, {:.2e})",
        best.method, best.relmse
    );
    if ratio <= 0.1 {
        line.push_str(": trustworthy (below 1/10)");
        return line;
    }
    line.push_str(": NOT below 1/10");
    if let Some(p) = best
        .curve
        .iter()
        .take_while(|p| p.relmse >= 10.0 * floor)
        .last()
    {
        line.push_str(&format!(" (it is up to {:.2} s of the curves)", p.seconds));
    }
    if let Some(s) = reference_seconds {
        let need = s * ratio / 0.1;
        line.push_str(&format!("; about --reference-seconds {need:.0} would be"));
    }
    line
}

/// The seconds a reference took, from its provenance.
pub fn seconds_of(reference: &Reference) -> Option<f64> {
    parse_provenance(&reference.provenance).map(|(_, seconds)| seconds)
}

/// Where a reference came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// Loaded from the cache as it was.
    Cached,
    /// Loaded from the references committed to the repository
    /// ([`COMMITTED`]), which hold at least what was asked for.
    Committed,
    /// Rendered now (no usable cache).
    Rendered,
    /// The cache held this many samples per pixel, fewer than asked for:
    /// more were rendered with fresh random streams and averaged in.
    Extended(u64),
}

/// A cached reference as read from disk.
struct Cache {
    image: Vec<Vec3>,
    variance: Vec<Vec3>,
    spp: u64,
    seconds: f64,
}

/// The samples per pixel and seconds in a provenance line
/// `<method> <spp> spp <seconds> s`.
fn parse_provenance(line: &str) -> Option<(u64, f64)> {
    let w: Vec<&str> = line.split_whitespace().collect();
    match w[..] {
        [_, spp, "spp", seconds, "s"] => Some((spp.parse().ok()?, seconds.parse().ok()?)),
        _ => None,
    }
}

/// The reference at `stem`, if its files are there, readable and of
/// `width` x `height`.
fn read_cache(stem: &Path, width: u32, height: u32) -> Option<Cache> {
    let (img, var, meta) = paths(stem);
    let (w, h, image) = read_exr(&img).ok()?;
    let (vw, vh, variance) = read_exr(&var).ok()?;
    let meta = std::fs::read_to_string(meta).ok()?;
    let (spp, seconds) = parse_provenance(meta.lines().next()?.trim())?;
    ((w, h) == (width, height) && (vw, vh) == (w, h)).then_some(Cache {
        image,
        variance,
        spp,
        seconds,
    })
}

/// What is still to render for `budget` when the cache holds `spp`
/// samples per pixel rendered in `seconds` (`None`: the cache suffices;
/// a cache within 2% of a time budget counts as meeting it).
fn still_to_render(budget: Budget, spp: u64, seconds: f64) -> Option<Budget> {
    match budget {
        Budget::Spp(n) => (n > spp).then(|| Budget::Spp(n - spp)),
        Budget::Seconds(s) => (seconds < 0.98 * s).then_some(Budget::Seconds(s - seconds)),
    }
}

/// Loads the cached reference if it holds at least `budget`, else the
/// committed one ([`COMMITTED`]) if there is one for this scene, size and
/// method that does; otherwise renders what is missing with `method`
/// (fresh random streams, so every part is independent), averages it with
/// the cache (or the committed reference) weighted by samples per pixel,
/// and writes the result to the cache. A reference therefore only grows:
/// asking for a longer one extends it. `rebuild` ignores both.
pub fn load_or_render(
    scene: &Scene,
    out: &Path,
    settings: &Settings,
    method: Method,
    budget: Budget,
    rebuild: bool,
) -> Result<Reference, String> {
    let stem = cache_stem(out, scene, settings.width, settings.height, method);
    let (img_path, var_path, meta_path) = paths(&stem);
    let (w, h) = (settings.width, settings.height);
    let read = |dir: &Path| {
        (!rebuild)
            .then(|| read_cache(&stem_in(dir, scene, w, h, method), w, h))
            .flatten()
    };
    // Start from whichever holds more samples.
    let cache = match (read(&out.join("references")), read(Path::new(COMMITTED))) {
        (Some(c), Some(k)) if k.spp > c.spp => Some((k, Origin::Committed)),
        (Some(c), _) => Some((c, Origin::Cached)),
        (None, Some(k)) => Some((k, Origin::Committed)),
        (None, None) => None,
    };
    let (have_spp, have_seconds) = cache.as_ref().map_or((0, 0.0), |c| (c.0.spp, c.0.seconds));
    let Some(more) = still_to_render(budget, have_spp, have_seconds) else {
        let (c, origin) = cache.expect("a budget is only met by a cache");
        return Ok(Reference {
            mean: mean_luminance(&c.image),
            image: c.image,
            variance: c.variance,
            provenance: format!("{} {} spp {:.1} s", method.name(), c.spp, c.seconds),
            origin,
        });
    };
    let cache = cache.map(|c| c.0);
    let mut s = settings.clone();
    s.budget = more;
    // Each part's streams depend on the samples already held, so an
    // extension never repeats a part (the first part keeps the seed the
    // cache has always used).
    s.seed ^= 0x0005_eed0_f4ef
        ^ if have_spp == 0 {
            0
        } else {
            crate::rng::mix64(have_spp)
        };
    let r = render(scene, method, &s);
    let (spp, seconds, image, variance, origin) = match cache {
        Some(c) if c.spp > 0 && r.spp > 0 => {
            let (n0, n1) = (c.spp as f32, r.spp as f32);
            let n = n0 + n1;
            let image = c
                .image
                .iter()
                .zip(&r.image)
                .map(|(a, b)| (*a * n0 + *b * n1) / n);
            let variance = c.variance.iter().zip(&r.variance);
            let variance = variance.map(|(a, b)| (*a * (n0 * n0) + *b * (n1 * n1)) / (n * n));
            (
                c.spp + r.spp,
                c.seconds + r.seconds,
                image.collect(),
                variance.collect(),
                Origin::Extended(c.spp),
            )
        }
        _ => (r.spp, r.seconds, r.image, r.variance, Origin::Rendered),
    };
    std::fs::create_dir_all(stem.parent().unwrap_or(out)).map_err(|e| e.to_string())?;
    write_exr(&img_path, r.width, r.height, &image)?;
    write_exr(&var_path, r.width, r.height, &variance)?;
    let provenance = format!("{} {spp} spp {seconds:.1} s", method.name());
    std::fs::write(&meta_path, format!("{provenance}\n")).map_err(|e| e.to_string())?;
    Ok(Reference {
        mean: mean_luminance(&image),
        image,
        variance,
        provenance,
        origin,
    })
}

fn mean_luminance(px: &[Vec3]) -> f64 {
    px.iter()
        .map(|p| f64::from(guiding::luminance(*p)))
        .sum::<f64>()
        / px.len().max(1) as f64
}

/// Writes `reference` to `dir` in half floats, named as the committed
/// references are ([`stem_in`]), with its provenance and `note` (how it was
/// made) in the text file: what `--export-reference` does to make a
/// reference to commit.
pub fn export(
    reference: &Reference,
    dir: &Path,
    scene: &Scene,
    (width, height): (u32, u32),
    method: Method,
    note: &str,
) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let stem = stem_in(dir, scene, width, height, method);
    let (img, var, meta) = paths(&stem);
    write_exr_half(&img, width, height, &reference.image)?;
    write_exr_half(&var, width, height, &reference.variance)?;
    std::fs::write(&meta, format!("{}\n{note}\n", reference.provenance))
        .map_err(|e| format!("{}: {e}", meta.display()))?;
    Ok(stem)
}
