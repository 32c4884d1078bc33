//! The side-by-side comparison sheet: the reference and every method's
//! tone-mapped image in a grid, each labelled with its name, RMSE and spp
//! in a built-in 3x5 pixel font (no font files needed).

use crate::film::{tone_map, write_png};
use glam::Vec3;
use std::path::Path;

/// One panel of the sheet.
pub struct Panel<'a> {
    /// Linear RGB.
    pub image: &'a [Vec3],
    /// Label lines (upper-cased when drawn).
    pub lines: Vec<String>,
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

const SCALE: usize = 2;
const LINE: usize = 6 * SCALE + 2;

/// An 8-bit RGB canvas.
struct Canvas {
    w: usize,
    h: usize,
    px: Vec<u8>,
}

impl Canvas {
    /// Draws `s` at `(x0, y0)`, clipped at `x_end`.
    fn text(&mut self, x0: usize, y0: usize, x_end: usize, s: &str) {
        for (i, c) in s.chars().enumerate() {
            let g = glyph(c);
            for (row, bits) in g.iter().enumerate() {
                for col in 0..3 {
                    if bits & (4 >> col) == 0 {
                        continue;
                    }
                    for dy in 0..SCALE {
                        for dx in 0..SCALE {
                            let x = x0 + (i * 4 + col) * SCALE + dx;
                            let y = y0 + row * SCALE + dy;
                            if x < x_end.min(self.w) && y < self.h {
                                let o = 3 * (y * self.w + x);
                                self.px[o..o + 3].copy_from_slice(&[255, 255, 255]);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Writes the panels (each `width x height`) as a grid of at most four
/// columns, tone mapped with `exposure`.
pub fn write_sheet(
    path: &Path,
    width: u32,
    height: u32,
    exposure: f32,
    panels: &[Panel],
) -> Result<(), String> {
    let (w, h) = (width as usize, height as usize);
    let cols = panels.len().clamp(1, 4);
    let rows = panels.len().div_ceil(cols).max(1);
    let label = panels.iter().map(|p| p.lines.len()).max().unwrap_or(0) * LINE + 4;
    let gap = 4;
    let cw = cols * (w + gap) + gap;
    let ch = rows * (h + label + gap) + gap;
    let mut canvas = Canvas {
        w: cw,
        h: ch,
        px: vec![24; 3 * cw * ch],
    };
    for (i, p) in panels.iter().enumerate() {
        let x0 = gap + (i % cols) * (w + gap);
        let y0 = gap + (i / cols) * (h + label + gap);
        let rgb = tone_map(p.image, exposure);
        for y in 0..h {
            let src = &rgb[3 * y * w..3 * (y + 1) * w];
            let o = 3 * ((y0 + y) * cw + x0);
            canvas.px[o..o + 3 * w].copy_from_slice(src);
        }
        for (k, line) in p.lines.iter().enumerate() {
            canvas.text(x0 + 2, y0 + h + 3 + k * LINE, x0 + w, line);
        }
    }
    write_png(path, cw as u32, ch as u32, &canvas.px)
}
