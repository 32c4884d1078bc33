//! Adding radiance to the building copy, from many threads through `&self`.

use super::cell::{Fixed, canonical_of, cell_size};
use super::config::DirectionalFilter;
use super::tree::DirectionalTree;
use glam::{Vec2, Vec3};

/// An axis-aligned rectangle of the canonical square, `[x0, x1] x [y0, y1]`.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl DirectionalTree {
    /// Adds `value` (radiance, already weighted as the caller's estimator
    /// wants) arriving from `dir` to the building copy, spread by `filter`.
    ///
    /// Lock-free and safe from many threads at once. Returns false, storing
    /// nothing, for a NaN, infinite or negative value or a zero, NaN or
    /// infinite direction; a direction of any positive length is normalised.
    /// A zero value is accepted and changes nothing.
    pub fn record(&self, dir: Vec3, value: f32, filter: DirectionalFilter) -> bool {
        if !(value >= 0.0 && value.is_finite()) {
            return false;
        }
        let Some(c) = canonical_of(dir) else {
            return false;
        };
        if value == 0.0 {
            return true;
        }
        let p = Fixed::from_canonical(c);
        let (mut n, mut level) = (0usize, 1u32);
        let q = loop {
            let q = p.quadrant(level);
            match self.links[n].child(q) {
                Some(child) => {
                    n = child;
                    level += 1;
                }
                None => break q,
            }
        };
        match filter {
            DirectionalFilter::Nearest => self.sums.add(4 * n + q, value),
            DirectionalFilter::Box => {
                self.record_box(c, cell_size(level), value);
                true
            }
        }
    }

    /// Spreads `value` over the square of side `size` centred on `c`,
    /// wrapped in `v` and clipped in `u` (see [`DirectionalFilter::Box`]).
    fn record_box(&self, c: Vec2, size: f64, value: f32) {
        let (cx, cy, h) = (c.x as f64, c.y as f64, 0.5 * size);
        let x0 = (cx - h).max(0.0);
        let x1 = (cx + h).min(1.0);
        let (y0, y1) = (cy - h, cy + h);
        let scale = value as f64 / ((x1 - x0) * size);
        let rect = |y0, y1| Rect { x0, x1, y0, y1 };
        if y0 < 0.0 {
            self.deposit(0, 1, 0, 0, rect(y0 + 1.0, 1.0), scale);
            self.deposit(0, 1, 0, 0, rect(0.0, y1), scale);
        } else if y1 > 1.0 {
            self.deposit(0, 1, 0, 0, rect(y0, 1.0), scale);
            self.deposit(0, 1, 0, 0, rect(0.0, y1 - 1.0), scale);
        } else {
            self.deposit(0, 1, 0, 0, rect(y0, y1), scale);
        }
    }

    /// Adds `scale * overlap area` to each quadrant of node `n` (at `level`,
    /// covering cell `(ox, oy)` of side `2^-(level - 1)`) that `r` overlaps:
    /// into a leaf, or onto an inner quadrant that `r` covers entirely (the
    /// refine spreads it evenly below), or recursively into the child.
    fn deposit(&self, n: usize, level: u32, ox: u32, oy: u32, r: Rect, scale: f64) {
        let s = cell_size(level);
        let link = self.links[n];
        for q in 0..4 {
            let (ix, iy) = (2 * ox + (q & 1) as u32, 2 * oy + (q >> 1) as u32);
            let (qx0, qy0) = (ix as f64 * s, iy as f64 * s);
            let (qx1, qy1) = (qx0 + s, qy0 + s);
            let w = r.x1.min(qx1) - r.x0.max(qx0);
            let h = r.y1.min(qy1) - r.y0.max(qy0);
            if !(w > 0.0 && h > 0.0) {
                continue;
            }
            let covered = r.x0 <= qx0 && qx1 <= r.x1 && r.y0 <= qy0 && qy1 <= r.y1;
            match link.child(q) {
                Some(child) if !covered => self.deposit(child, level + 1, ix, iy, r, scale),
                _ => {
                    let part = (scale * w * h).min(f32::MAX as f64) as f32;
                    self.sums.add(4 * n + q, part);
                }
            }
        }
    }
}
