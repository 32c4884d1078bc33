//! An 8-bit RGB canvas with a built-in 3x5 pixel font, and a `plotters`
//! backend drawing into a rectangle of it: the comparison sheet and the
//! PNG plots need no font files and no system fonts.

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

    /// Draws `s` in white at `(x0, y0)`, `scale` canvas pixels per font
    /// pixel, clipped at `x_end`.
    pub fn text(&mut self, x0: usize, y0: usize, x_end: usize, scale: usize, s: &str) {
        for (x, y) in text_pixels(s, scale) {
            let (x, y) = (x0 + x as usize, y0 + y as usize);
            if x < x_end {
                self.blend(x as i64, y as i64, [255; 3], 1.0);
            }
        }
    }

    /// Writes the canvas as a PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), String> {
        crate::film::write_png(path, self.w as u32, self.h as u32, &self.px)
    }
}

/// The pixels `s` covers at `scale`, relative to its top-left corner:
/// each character is a 4x6 cell (3x5 glyph and a gap), upper-cased.
fn text_pixels(s: &str, scale: usize) -> impl Iterator<Item = (i32, i32)> + '_ {
    s.chars().enumerate().flat_map(move |(i, c)| {
        let g = glyph(c);
        (0..5).flat_map(move |row| {
            (0..3)
                .filter(move |col| g[row] & (4 >> col) != 0)
                .flat_map(move |col| {
                    (0..scale * scale).map(move |k| {
                        let x = (i * 4 + col) * scale + k % scale;
                        let y = row * scale + k / scale;
                        (x as i32, y as i32)
                    })
                })
        })
    })
}

/// The size in canvas pixels of `s` at `scale`.
fn text_size(s: &str, scale: usize) -> (u32, u32) {
    let n = s.chars().count();
    (
        (n * 4).saturating_sub(1) as u32 * scale as u32,
        5 * scale as u32,
    )
}

/// The font scale for a `plotters` font size in pixels.
fn scale_for(size: f64) -> usize {
    (size / 8.0).round().clamp(1.0, 4.0) as usize
}

/// A `plotters` backend drawing into the rectangle `origin`, `size` of a
/// [`Canvas`], text in the built-in font.
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
        let scale = scale_for(style.size());
        let (w, h) = text_size(text, scale);
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
        for (x, y) in text_pixels(text, scale) {
            let (x, y) = transform.transform(x + dx, y + dy);
            self.draw_pixel((pos.0 + x, pos.1 + y), colour)?;
        }
        Ok(())
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<NoError>> {
        Ok(text_size(text, scale_for(style.size())))
    }
}

/// Glyph rows, top to bottom, bit 2 = left column.
fn glyph(c: char) -> [u8; 5] {
    match c.to_ascii_uppercase() {
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [3, 4, 4, 4, 3],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 6, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [3, 4, 5, 5, 3],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 2],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [2, 5, 5, 5, 2],
        'P' => [6, 5, 6, 4, 4],
        'Q' => [2, 5, 5, 6, 3],
        'R' => [6, 5, 6, 5, 5],
        'S' => [3, 4, 2, 1, 6],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [6, 1, 2, 4, 7],
        '3' => [6, 1, 2, 1, 6],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 6, 1, 6],
        '6' => [3, 4, 6, 5, 2],
        '7' => [7, 1, 2, 2, 2],
        '8' => [2, 5, 2, 5, 2],
        '9' => [2, 5, 3, 1, 6],
        '.' => [0, 0, 0, 0, 2],
        '-' => [0, 0, 7, 0, 0],
        ':' => [0, 2, 0, 2, 0],
        '=' => [0, 7, 0, 7, 0],
        '+' => [0, 2, 7, 2, 0],
        '%' => [5, 1, 2, 4, 5],
        '/' => [1, 1, 2, 4, 4],
        '(' => [1, 2, 2, 2, 1],
        ')' => [4, 2, 2, 2, 4],
        _ => [0; 5],
    }
}
