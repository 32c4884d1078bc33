//! Error metrics against a reference. Each is corrected for the
//! reference's own noise: `E[(x - r)^2] = MSE(x) + Var(r)`, so the cached
//! per-pixel variance of the reference is subtracted (the raw values are
//! kept too).

use crate::reference::Reference;
use glam::Vec3;

/// Errors of one image.
#[derive(Clone, Copy, Debug, Default)]
pub struct Errors {
    /// Root mean squared error over pixels and channels, reference noise
    /// removed.
    pub rmse: f64,
    /// Relative MSE: mean of `(x - r)^2 / (r^2 + eps)` with
    /// `eps = 0.01 * mean(r)^2` (scale-free), reference noise removed.
    pub relmse: f64,
    /// RMSE without the correction.
    pub rmse_raw: f64,
    /// Relative MSE without the correction.
    pub relmse_raw: f64,
    /// The reference's own expected relative MSE (its noise floor).
    pub relmse_floor: f64,
}

/// The relative MSE (reference noise removed) of a flat RGB image, as a
/// render's convergence curve delivers it.
pub fn relmse_of_rgb(rgb: &[f32], reference: &Reference) -> f64 {
    let image: Vec<Vec3> = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
    errors(&image, reference).relmse
}

/// Errors of `image` against `reference`.
pub fn errors(image: &[Vec3], reference: &Reference) -> Errors {
    let eps = 0.01 * reference.mean * reference.mean;
    let (mut se, mut var, mut rel, mut rel_var) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for ((x, r), v) in image.iter().zip(&reference.image).zip(&reference.variance) {
        for c in 0..3 {
            let d = f64::from(x[c]) - f64::from(r[c]);
            let denom = f64::from(r[c]).powi(2) + eps;
            let v = f64::from(v[c]).max(0.0);
            se += d * d;
            var += v;
            rel += d * d / denom;
            rel_var += v / denom;
        }
    }
    let n = (3 * image.len()).max(1) as f64;
    let (mse_raw, relmse_raw) = (se / n, rel / n);
    // Never correct below a tenth of the raw value: where the reference is
    // as noisy as the image the estimate is unreliable anyway.
    let mse = (mse_raw - var / n).max(0.1 * mse_raw);
    let relmse = (relmse_raw - rel_var / n).max(0.1 * relmse_raw);
    Errors {
        rmse: mse.sqrt(),
        relmse,
        rmse_raw: mse_raw.sqrt(),
        relmse_raw,
        relmse_floor: rel_var / n,
    }
}

/// Monte Carlo efficiency: `1 / (relMSE * seconds)`.
pub fn efficiency(relmse: f64, seconds: f64) -> f64 {
    if relmse > 0.0 && seconds > 0.0 {
        1.0 / (relmse * seconds)
    } else {
        0.0
    }
}
