//! Text for the plots and the comparison sheet: DejaVu Sans (a subset
//! committed in `fonts/`, its licence beside it) laid out with its
//! advances and kerning and rasterised with anti-aliasing by `ab_glyph`,
//! so the PNGs need no system fonts.

use ab_glyph::{Font, FontRef, GlyphId, PxScale, ScaleFont, point};
use std::sync::OnceLock;

/// The font file, compiled in.
const DEJAVU_SANS: &[u8] = include_bytes!("../fonts/DejaVuSans-subset.ttf");

/// The parsed font.
fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(DEJAVU_SANS).expect("the committed font parses"))
}

/// The `ab_glyph` scale of an em of `size` pixels (the CSS meaning of a
/// font size, which the SVG plots use too; `ab_glyph`'s own scale is the
/// ascent-to-descent height).
fn scale(size: f32) -> PxScale {
    let f = font();
    let em = f.units_per_em().unwrap_or(2048.0);
    PxScale::from(size * f.height_unscaled() / em)
}

/// The glyphs of `s` at `size` with their pen positions (left edge, on
/// the baseline), and the laid-out box's width and height in pixels.
fn layout(s: &str, size: f32) -> (Vec<(GlyphId, f32)>, f32, f32) {
    let f = font().as_scaled(scale(size));
    let mut glyphs = Vec::with_capacity(s.len());
    let mut pen = 0.0;
    let mut previous: Option<GlyphId> = None;
    for c in s.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = previous {
            pen += f.kern(p, id);
        }
        glyphs.push((id, pen));
        pen += f.h_advance(id);
        previous = Some(id);
    }
    (glyphs, pen, f.ascent() - f.descent())
}

/// The size in whole pixels of the box `s` takes at an em of `size`
/// pixels: its advance width, and the font's ascent-to-descent height.
pub fn measure(s: &str, size: f32) -> (u32, u32) {
    let (_, w, h) = layout(s, size);
    (w.ceil() as u32, h.ceil() as u32)
}

/// Every pixel `s` touches at an em of `size` pixels, relative to the
/// top-left corner of its box (see [`measure`]), with the fraction of it
/// the glyphs cover.
pub fn coverage(s: &str, size: f32) -> Vec<(i32, i32, f32)> {
    let font = font();
    let px = scale(size);
    let ascent = font.as_scaled(px).ascent();
    let (glyphs, _, _) = layout(s, size);
    let mut out = Vec::new();
    for (id, x) in glyphs {
        let glyph = id.with_scale_and_position(px, point(x, ascent));
        if let Some(outline) = font.outline_glyph(glyph) {
            let min = outline.px_bounds().min;
            outline.draw(|gx, gy, c| {
                if c > 0.0 {
                    out.push((min.x as i32 + gx as i32, min.y as i32 + gy as i32, c));
                }
            });
        }
    }
    out
}
