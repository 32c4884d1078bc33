//! Sampling a direction and evaluating its pdf.
//!
//! Sampling uses one uniform pair for the whole walk, as the exact inverse of
//! the leaves' cumulative distribution: at each node `u.x` chooses the column
//! (`ix`) by the columns' marginal, then `u.y` the row within it, and both
//! are rescaled in `f64` ([`Descent`]) for the next level; what is left of
//! them places the point inside the leaf. A stratified or QMC pair therefore
//! stays stratified over the leaves, at any depth.
//!
//! The density of a leaf is the product over the path of
//! `4 * quadrant_probability`, evaluated by the same function in the same
//! order whether sampling or evaluating, so the two agree bit for bit.

use super::cell::{Fixed, canonical_of, cell_size};
use super::config::UNIFORM_PDF;
use super::node::quadrant_probability;
use super::tree::DirectionalTree;
use crate::math::{Descent, SPHERE_MAP_JACOBIAN, Side, canonical_to_dir};
use glam::{Vec2, Vec3};

/// The largest `f32` below one.
const ONE_MINUS_EPS_F32: f32 = 1.0 - f32::EPSILON / 2.0;
/// How often a sampled point is pulled toward its leaf's centre when the
/// `f32` direction it maps to falls just outside the leaf.
const ROUND_TRIP_TRIES: usize = 8;

impl DirectionalTree {
    /// Draws a unit direction from the sampling copy with the uniform pair
    /// `u` (clamped into `[0, 1)`; NaN counts as 0) and returns it with its
    /// solid-angle pdf, which is positive and equal to
    /// [`pdf`](Self::pdf)`(direction)`.
    ///
    /// A point that lands within `f32` rounding of its leaf's border, so that
    /// its direction would map back into the neighbouring leaf, is pulled
    /// toward the leaf's centre; if that still fails (cells near `2^-24`
    /// wide), the pdf reported is the one of the leaf the direction maps to.
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, f32) {
        if self.is_uniform() {
            let c = Vec2::new(clamp_unit(u[0]), clamp_unit(u[1]));
            return (canonical_to_dir(c), UNIFORM_PDF);
        }
        let a = self.uniform_fraction;
        let ux = clamp_unit(u[0]) as f64;
        let uy = clamp_unit(u[1]) as f64;
        if ux < a {
            // The defensive uniform part.
            let c = Vec2::new(clamp_unit((ux / a) as f32), uy as f32);
            let dir = canonical_to_dir(c);
            return (dir, self.pdf(dir));
        }
        let mut dx = Descent::from_f64((ux - a) / (1.0 - a));
        let mut dy = Descent::from_f64(uy);
        let (mut n, mut level) = (0usize, 1u32);
        let (mut cx, mut cy) = (0u32, 0u32);
        let mut density = 1.0f64;
        loop {
            let node = &self.nodes[n];
            let p = node.probs.map(f64::from);
            let ix = side_index(dx.choose(p[0] + p[2], p[1] + p[3]));
            let iy = side_index(dy.choose(p[ix], p[ix + 2]));
            let q = ix + 2 * iy;
            density *= 4.0 * quadrant_probability(&node.probs, q);
            cx = 2 * cx + ix as u32;
            cy = 2 * cy + iy as u32;
            match node.link.child(q) {
                Some(child) => {
                    n = child;
                    level += 1;
                }
                None => break,
            }
        }
        let size = cell_size(level);
        let (mut fx, mut fy) = (dx.u(), dy.u());
        let mut dir = Vec3::Z;
        for _ in 0..ROUND_TRIP_TRIES {
            let c = Vec2::new(
                ((cx as f64 + fx) * size) as f32,
                ((cy as f64 + fy) * size) as f32,
            );
            dir = canonical_to_dir(c);
            if let Some(back) = canonical_of(dir) {
                if Fixed::from_canonical(back).cell(level) == (cx, cy) {
                    return (dir, self.mix(density));
                }
            }
            fx = 0.5 + (fx - 0.5) * 0.5;
            fy = 0.5 + (fy - 0.5) * 0.5;
        }
        (dir, self.pdf(dir))
    }

    /// The solid-angle pdf with which [`sample`](Self::sample) draws `dir`.
    /// Any positive length is accepted (the direction is normalised); a
    /// zero, NaN or infinite vector gives 0. Positive for every valid
    /// direction.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let Some(c) = canonical_of(dir) else {
            return 0.0;
        };
        if self.is_uniform() {
            return UNIFORM_PDF;
        }
        self.mix(self.tree_density(Fixed::from_canonical(c)))
    }

    /// The tree part's density per unit canonical area at `p`.
    #[inline]
    fn tree_density(&self, p: Fixed) -> f64 {
        let (mut n, mut level) = (0usize, 1u32);
        let mut density = 1.0f64;
        loop {
            let node = &self.nodes[n];
            let q = p.quadrant(level);
            density *= 4.0 * quadrant_probability(&node.probs, q);
            match node.link.child(q) {
                Some(child) if density > 0.0 => {
                    n = child;
                    level += 1;
                }
                _ => return density,
            }
        }
    }

    /// The mixture with the uniform part, as a solid-angle pdf.
    #[inline]
    fn mix(&self, density: f64) -> f32 {
        let a = self.uniform_fraction;
        (((1.0 - a) * density + a) / SPHERE_MAP_JACOBIAN as f64) as f32
    }
}

#[inline]
fn side_index(side: Option<Side>) -> usize {
    match side {
        Some(Side::Right) => 1,
        _ => 0,
    }
}

/// `u` clamped into `[0, 1)`, NaN to 0.
#[inline]
fn clamp_unit(u: f32) -> f32 {
    if u >= 0.0 {
        u.min(ONE_MINUS_EPS_F32)
    } else {
        0.0
    }
}
