//! An 8-bit RGB canvas, and a `plotters` backend drawing into a rectangle
//! of it with anti-aliased text (`text.rs`): the comparison sheet and the
//! PNG plots need no system fonts.

use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};
use std::path::Path;

/// An 8-bit RGB image.
pub struct Canvas {
    /// Width in pixels.
    pub w: usize,
    /// Height in pixels.
    pub h: usize,
    /// Row-major RGB bytes.
    pub px: Vec<u8>,
}

impl Canvas {
    /// A canvas filled with one grey level.
    pub fn new(w: usize, h: usize, grey: u8) -> Canvas {
        Canvas {
            w,
            h,
            px: vec![grey; 3 * w * h],
        }
    }

    /// Blends `rgb` with opacity `alpha` into pixel `(x, y)` (ignored
    /// outside the canvas).
    pub fn blend(&mut self, x: i64, y: i64, rgb: [u8; 3], alpha: f64) {
        if x < 0 || y < 0 || x as usize >= self.w || y as usize >= self.h {
            return;
        }
        let o = 3 * (y as usize * self.w + x as usize);
        let a = alpha.clamp(0.0, 1.0);
        for (dst, src) in self.px[o..o + 3].iter_mut().zip(rgb) {
            *dst = (f64::from(*dst) * (1.0 - a) + f64::from(src) * a).round() as u8;
        }
    }

    /// Draws `s` in `rgb` with its box's top-left corner at `(x0, y0)`,
    /// an em of `size` pixels, clipped at `x_end`.
    pub fn text(
        &mut self,
        (x0, y0): (usize, usize),
        x_end: usize,
        size: f32,
        rgb: [u8; 3],
        s: &str,
    ) {
        for (x, y, c) in crate::text::coverage(s, size) {
            let x = x0 as i64 + i64::from(x);
            if x < x_end as i64 {
                self.blend(x, y0 as i64 + i64::from(y), rgb, f64::from(c));
            }
        }
    }

    /// Writes the canvas as a PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), String> {
        crate::film::write_png(path, self.w as u32, self.h as u32, &self.px)
    }
}

/// The em in pixels of a `plotters` font size: plotters' fonts and its
/// SVG backend take a size to be 1.24 ems, so the PNG's text is as large
/// as the SVG's.
fn em(size: f64) -> f32 {
    (size / 1.24) as f32
}

/// A `plotters` backend drawing into the rectangle `origin`, `size` of a
/// [`Canvas`], text in DejaVu Sans.
pub struct Viewport<'a> {
    canvas: &'a mut Canvas,
    origin: (i64, i64),
    size: (u32, u32),
}

impl<'a> Viewport<'a> {
    /// The rectangle at `origin` of `size` pixels of `canvas`.
    pub fn new(canvas: &'a mut Canvas, origin: (usize, usize), size: (u32, u32)) -> Self {
        Viewport {
            canvas,
            origin: (origin.0 as i64, origin.1 as i64),
            size,
        }
    }
}

/// Never raised: drawing into memory cannot fail.
#[derive(Debug)]
pub struct NoError;

impl std::fmt::Display for NoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("no error")
    }
}

impl std::error::Error for NoError {}

impl DrawingBackend for Viewport<'_> {
    type ErrorType = NoError;

    fn get_size(&self) -> (u32, u32) {
        self.size
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<NoError>> {
        Ok(())
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<NoError>> {
        Ok(())
    }

    fn draw_pixel(
        &mut self,
        p: BackendCoord,
        c: BackendColor,
    ) -> Result<(), DrawingErrorKind<NoError>> {
        let (x, y) = (i64::from(p.0), i64::from(p.1));
        if x >= 0 && y >= 0 && x < i64::from(self.size.0) && y < i64::from(self.size.1) {
            let rgb = [c.rgb.0, c.rgb.1, c.rgb.2];
            self.canvas
                .blend(self.origin.0 + x, self.origin.1 + y, rgb, c.alpha);
        }
        Ok(())
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<NoError>> {
        let colour = style.color();
        if colour.alpha == 0.0 {
            return Ok(());
        }
        let size = em(style.size());
        let (w, h) = crate::text::measure(text, size);
        let (w, h) = (w as i32, h as i32);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -w,
            HPos::Center => -w / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -h / 2,
            VPos::Bottom => -h,
        };
        let transform = style.transform();
        for (x, y, c) in crate::text::coverage(text, size) {
            let (x, y) = transform.transform(x + dx, y + dy);
            let colour = BackendColor {
                alpha: colour.alpha * f64::from(c),
                rgb: colour.rgb,
            };
            self.draw_pixel((pos.0 + x, pos.1 + y), colour)?;
        }
        Ok(())
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<NoError>> {
        Ok(crate::text::measure(text, em(style.size())))
    }
}
