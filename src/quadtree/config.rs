//! Refinement parameters, the directional record filters and the constants
//! that bound a directional tree.

use crate::math::SPHERE_MAP_JACOBIAN;

/// The pdf of the uniform distribution over the sphere, `1 / (4 pi)`.
pub const UNIFORM_PDF: f32 = 1.0 / SPHERE_MAP_JACOBIAN;

/// The deepest node level a tree refines to, whatever
/// [`QuadtreeConfig::max_depth`] says: a cell at level 24 is `2^-24` wide,
/// about the resolution of an `f32` direction mapped to canonical space, so
/// deeper cells could not be told apart by any direction.
pub(crate) const MAX_DEPTH: u32 = 24;

/// The smallest split threshold used; a smaller (or non-positive) `rho` is
/// raised to this. A tree has at most about `max_depth / rho` nodes, so this
/// bounds memory for a mistaken configuration.
pub(crate) const MIN_RHO: f32 = 1.0e-6;

/// The default weight of the uniform part of the density (the defensive
/// mixture). It costs one sample in a thousand and caps the sampling weight
/// `1 / pdf` at `4 pi / 0.001` where nothing was learned.
pub(crate) const DEFAULT_UNIFORM_FRACTION: f32 = 1.0e-3;

/// The smallest accepted uniform fraction: it keeps the pdf of every valid
/// direction positive in `f32`.
pub(crate) const MIN_UNIFORM_FRACTION: f32 = 1.0e-6;

/// How `DirectionalTree::refine` reshapes
/// the building copy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadtreeConfig {
    /// A quadrant whose share of the tree's total exceeds `rho` is split
    /// (becomes a node); a subtree whose share is at most `rho` is merged
    /// into one leaf. Default `0.01` (PPG). In `[MIN_RHO, 1]`
    /// ([`QuadtreeConfig::MIN_RHO`]).
    pub rho: f32,
    /// The deepest node level (the root is level 1, so leaves are at least
    /// `2^-max_depth` wide). Default `20` (PPG). In `1..=MAX_DEPTH`
    /// ([`QuadtreeConfig::MAX_DEPTH`]).
    pub max_depth: u32,
}

impl Default for QuadtreeConfig {
    fn default() -> Self {
        Self {
            rho: 0.01,
            max_depth: 20,
        }
    }
}

impl QuadtreeConfig {
    /// The deepest node level a tree refines to, whatever `max_depth`
    /// says: a cell at level 24 is `2^-24` wide, about the resolution of an
    /// `f32` direction mapped to canonical space, so deeper cells could not
    /// be told apart by any direction.
    pub const MAX_DEPTH: u32 = MAX_DEPTH;

    /// The smallest split threshold accepted. A tree has at most about
    /// `max_depth / rho` nodes, so this bounds memory.
    pub const MIN_RHO: f32 = MIN_RHO;

    /// Checks `rho` in `[MIN_RHO, 1]` and `max_depth` in `1..=MAX_DEPTH`.
    /// A `DirectionalTree` refined with an
    /// unchecked configuration uses the nearest valid values.
    pub fn validate(&self) -> Result<(), crate::error::ConfigError> {
        let rho = f64::from(self.rho);
        crate::error::check(
            "QuadtreeConfig::rho",
            rho,
            rho >= f64::from(MIN_RHO) && rho <= 1.0,
            "in [1e-6, 1]",
        )?;
        crate::error::check(
            "QuadtreeConfig::max_depth",
            f64::from(self.max_depth),
            (1..=MAX_DEPTH).contains(&self.max_depth),
            "in 1..=24",
        )
    }

    /// `rho` as used: at least [`QuadtreeConfig::MIN_RHO`].
    pub(crate) fn effective_rho(&self) -> f64 {
        if self.rho >= MIN_RHO {
            self.rho as f64
        } else {
            MIN_RHO as f64
        }
    }

    /// `max_depth` as used: in `1..=`[`QuadtreeConfig::MAX_DEPTH`].
    pub(crate) fn effective_max_depth(&self) -> u32 {
        self.max_depth.clamp(1, MAX_DEPTH)
    }
}

/// How a record is spread over the building copy's leaves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DirectionalFilter {
    /// All of the value goes to the leaf containing the direction.
    #[default]
    Nearest,
    /// The value is spread over a square in canonical space centred on the
    /// direction, as wide as the leaf containing it, in proportion to the
    /// area the square overlaps each leaf. The square wraps around in `v`
    /// (the azimuth is periodic, `phi = 0` and `2 pi` are the same meridian)
    /// and is clipped at `u = 0` and `u = 1` (the poles); the weights are
    /// divided by the area left inside the domain, so the total recorded is
    /// always the value (up to one `f32` rounding per leaf touched).
    Box,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn config_is_sanitised() {
        let c = QuadtreeConfig {
            rho: f32::NAN,
            max_depth: 99,
        };
        assert_eq!(c.effective_rho(), MIN_RHO as f64);
        assert_eq!(c.effective_max_depth(), MAX_DEPTH);
        let c = QuadtreeConfig {
            rho: -1.0,
            max_depth: 0,
        };
        assert_eq!(c.effective_rho(), MIN_RHO as f64);
        assert_eq!(c.effective_max_depth(), 1);
        let d = QuadtreeConfig::default();
        assert_eq!(d.effective_rho(), 0.01f32 as f64);
        assert_eq!(d.effective_max_depth(), 20);
    }
}
