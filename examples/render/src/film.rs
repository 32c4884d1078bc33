//! Image output: linear EXR, tone-mapped 8-bit PNG, and reading EXRs back
//! (for the reference cache).

use glam::Vec3;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// Writes a linear RGB EXR.
pub fn write_exr(path: &Path, width: u32, height: u32, pixels: &[Vec3]) -> Result<(), String> {
    exr::prelude::write_rgb_file(path, width as usize, height as usize, |x, y| {
        let p = pixels[y * width as usize + x];
        (p.x, p.y, p.z)
    })
    .map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes a linear RGB EXR in half floats with lossless ZIP compression:
/// a quarter of [`write_exr`]'s size or less, for files committed to the
/// repository (half floats keep 11 significant bits, a relative rounding
/// of at most 2^-11, far below any error the example measures).
pub fn write_exr_half(path: &Path, width: u32, height: u32, pixels: &[Vec3]) -> Result<(), String> {
    use exr::prelude::*;
    let w = width as usize;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let c = pixels[p.y() * w + p.x()];
        (f16::from_f32(c.x), f16::from_f32(c.y), f16::from_f32(c.z))
    });
    Image::from_encoded_channels((w, height as usize), Encoding::SMALL_LOSSLESS, channels)
        .write()
        .to_file(path)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Reads an RGB EXR written by [`write_exr`] or [`write_exr_half`]: `(width, height, pixels)`.
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<Vec3>), String> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(|e| format!("{}: {e}", path.display()))?;
    let size = image.layer_data.size;
    let (_, px) = image.layer_data.channel_data.pixels;
    Ok((size.width() as u32, size.height() as u32, px))
}

/// Tone maps linear RGB: exposure, Reinhard on luminance-preserving scale,
/// sRGB encoding. Returns 8-bit RGB.
pub fn tone_map(pixels: &[Vec3], exposure: f32) -> Vec<u8> {
    let mut out = Vec::with_capacity(pixels.len() * 3);
    for p in pixels {
        let c = *p * exposure;
        let c = c / (Vec3::ONE + c);
        for v in c.to_array() {
            out.push((srgb(v) * 255.0 + 0.5).clamp(0.0, 255.0) as u8);
        }
    }
    out
}

/// The exposure that maps a mean luminance to middle grey.
pub fn auto_exposure(mean_luminance: f64) -> f32 {
    if mean_luminance > 0.0 {
        (0.3 / mean_luminance) as f32
    } else {
        1.0
    }
}

fn srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes 8-bit RGB as a PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let file = File::create(path).map_err(|e| err(&e))?;
    let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().map_err(|e| err(&e))?;
    writer.write_image_data(rgb).map_err(|e| err(&e))?;
    writer.finish().map_err(|e| err(&e))
}
