//! The side-by-side comparison sheet: the reference and every method's
//! tone-mapped image in a grid, each labelled with its name, RMSE and spp,
//! with a chart (the convergence curves) beside them.

use crate::film::tone_map;
use crate::raster::{Canvas, Viewport};
use glam::Vec3;
use std::path::Path;

/// One panel of the sheet.
pub struct Panel<'a> {
    /// Linear RGB.
    pub image: &'a [Vec3],
    /// Label lines.
    pub lines: Vec<String>,
}

/// Draws a chart into the viewport it is given.
pub type Chart<'a> = &'a dyn Fn(Viewport<'_>) -> Result<(), String>;

/// The labels' em size in pixels.
const FONT: f32 = 14.0;
/// The labels' line height in pixels.
const LINE: usize = 18;

/// Writes the panels (each `width x height`) as a grid of at most four
/// columns, tone mapped with `exposure`, and `chart` (if any) in a column
/// beside them as tall as the grid and at least 480 pixels wide.
pub fn write_sheet(
    path: &Path,
    width: u32,
    height: u32,
    exposure: f32,
    panels: &[Panel],
    chart: Option<Chart<'_>>,
) -> Result<(), String> {
    let (w, h) = (width as usize, height as usize);
    let cols = panels.len().clamp(1, 4);
    let rows = panels.len().div_ceil(cols).max(1);
    let label = panels.iter().map(|p| p.lines.len()).max().unwrap_or(0) * LINE + 4;
    let gap = 4;
    let grid_w = cols * (w + gap) + gap;
    let ch = rows * (h + label + gap) + gap;
    let chart_size = (480.max(ch) as u32, (ch - 2 * gap) as u32);
    let cw = grid_w + chart.map_or(0, |_| chart_size.0 as usize + gap);
    let mut canvas = Canvas::new(cw, ch, 24);
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
            let at = (x0 + 2, y0 + h + 2 + k * LINE);
            canvas.text(at, x0 + w, FONT, [235; 3], line);
        }
    }
    if let Some(draw) = chart {
        draw(Viewport::new(&mut canvas, (grid_w, gap), chart_size))?;
    }
    canvas.write_png(path)
}
