//! [`DirectionVertex`]: one located cell's directional guiding, serving
//! every directional query and record at a path vertex, for the SD-tree
//! and the guiding field alike.

use super::state::SdState;
use super::{SdCell, SdTree};
use crate::light_sampler::ShadingContext;
use crate::record::RecordOutcome;
use crate::spatial::{CellId, Located, SpatialTree};
use glam::Vec3;

/// Where a direction vertex's radiance records go: the cells of an
/// [`SdTree`] or of a [`GuidingField`](crate::GuidingField) (the spatial
/// filters may reach the neighbouring cells).
pub(crate) trait RadianceCells {
    /// PPG's record from a located point, with the configured filters.
    fn record_radiance(&self, at: Located, dir: Vec3, radiance: f32, pdf: f32) -> RecordOutcome;
}

impl RadianceCells for SdTree {
    #[inline]
    fn record_radiance(&self, at: Located, dir: Vec3, radiance: f32, pdf: f32) -> RecordOutcome {
        self.state
            .record_radiance(&self.spatial, at, dir, radiance, pdf)
    }
}

/// A path vertex's directional guiding: the cell of an [`SdTree`]
/// ([`SdTree::vertex`]) or of a [`GuidingField`](crate::GuidingField)
/// ([`FieldVertex::direction`](crate::FieldVertex::direction)) found by the
/// one lookup, through which the guided direction, its pdf, the BSDF
/// fraction and both records at that point go.
///
/// At each vertex a renderer samples its BSDF with probability
/// [`bsdf_fraction`](DirectionVertex::bsdf_fraction), else
/// [`sample_direction`](DirectionVertex::sample_direction), and weighs
/// with [`mixture_pdf`](DirectionVertex::mixture_pdf); once the path is
/// done it records the radiance that arrived along the sampled direction
/// ([`record_radiance`](DirectionVertex::record_radiance)) and, to learn
/// the fraction, the sample ([`record_fraction`](DirectionVertex::record_fraction)).
#[derive(Clone, Copy)]
pub struct DirectionVertex<'a> {
    state: &'a SdState,
    cell: &'a SdCell,
    at: Located,
    cells: &'a dyn RadianceCells,
}

impl core::fmt::Debug for DirectionVertex<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("DirectionVertex")
            .field("position", &self.at.0)
            .field("cell", &self.at.1.0)
            .finish_non_exhaustive()
    }
}

impl<'a> DirectionVertex<'a> {
    /// The vertex at `p`, located at `at` in the spatial tree of `cells`.
    #[inline]
    pub(crate) fn new(
        state: &'a SdState,
        cell: &'a SdCell,
        at: Located,
        cells: &'a dyn RadianceCells,
    ) -> Self {
        Self {
            state,
            cell,
            at,
            cells,
        }
    }

    /// The point this vertex was located from.
    #[inline]
    pub fn position(&self) -> Vec3 {
        self.at.0
    }

    /// The located cell's number.
    #[inline]
    pub fn cell(&self) -> CellId {
        self.at.1.0
    }

    /// The located cell's directional part (its quadtree and learned
    /// fraction).
    #[inline]
    pub fn sd(&self) -> &'a SdCell {
        self.cell
    }

    /// A direction drawn from the cell's guiding distribution with two
    /// uniform numbers, and its solid-angle pdf (equal to
    /// [`DirectionVertex::direction_pdf`] of it, bit for bit).
    #[inline]
    pub fn sample_direction(&self, u: [f32; 2]) -> (Vec3, f32) {
        self.cell.sample(u)
    }

    /// [`DirectionVertex::sample_direction`] with the two numbers drawn
    /// from a renderer's generator: two `next_u32`, each one's top 24 bits
    /// times `2^-24`, so the direction equals `sample_direction` of them.
    #[inline]
    pub fn sample_direction_with<R: rand_core::Rng + ?Sized>(&self, rng: &mut R) -> (Vec3, f32) {
        let u0 = crate::math::unit_f32(rng);
        self.sample_direction([u0, crate::math::unit_f32(rng)])
    }

    /// The solid-angle pdf of `dir` (any positive length) under the cell's
    /// guiding distribution; 0 for an invalid direction.
    #[inline]
    pub fn direction_pdf(&self, dir: Vec3) -> f32 {
        self.cell.pdf(dir)
    }

    /// The probability `s` of sampling the BSDF rather than the guiding
    /// distribution here (learned per cell, or the configured constant;
    /// fixed between refinements).
    #[inline]
    pub fn bsdf_fraction(&self) -> f32 {
        self.cell.bsdf_fraction()
    }

    /// The pdf of the one-sample mixture:
    /// `s * bsdf_pdf + (1 - s) * direction_pdf(dir)`.
    #[inline]
    pub fn mixture_pdf(&self, dir: Vec3, bsdf_pdf: f32) -> f32 {
        self.cell.mixture_pdf(dir, bsdf_pdf)
    }

    /// PPG's record: `radiance`, the incident radiance that arrived along
    /// `dir` (one scalar, e.g. luminance), sampled with the solid-angle
    /// `pdf` (the mixture's). The cell's quadtree gets `radiance / pdf`
    /// along `dir` and its statistical weight grows by 1, spread by the
    /// configured spatial and directional filters (the stochastic box's
    /// offset is a hash of the record, `src/spatial/jitter.rs`). Radiance
    /// 0 is valid: weight and no power ([`RecordOutcome::Zero`]). Dropped
    /// and counted: a NaN, infinite or zero-length direction, a NaN,
    /// infinite or negative radiance, a zero, negative or non-finite pdf,
    /// `radiance / pdf` overflowing `f32`. `&self`: any number of threads.
    #[inline]
    pub fn record_radiance(&self, dir: Vec3, radiance: f32, pdf: f32) -> RecordOutcome {
        self.cells.record_radiance(self.at, dir, radiance, pdf)
    }

    /// Reports one direction sample to the cell's BSDF-fraction learner:
    /// `bsdf_pdf` and `guiding_pdf` are the two techniques' solid-angle
    /// pdfs of the sampled direction, and `contribution` is the sample's
    /// estimate `|f_s cos| L_i / q` (one number, e.g. luminance), with `q`
    /// the mixture pdf it was drawn with ([`DirectionVertex::mixture_pdf`]).
    /// Do not report samples of delta BSDF lobes.
    ///
    /// Dropped and counted: a negative or non-finite contribution, a
    /// negative or non-finite pdf, both pdfs 0. [`RecordOutcome::Ignored`]
    /// when the configuration learns no fraction.
    #[inline]
    pub fn record_fraction(
        &self,
        bsdf_pdf: f32,
        guiding_pdf: f32,
        contribution: f32,
    ) -> RecordOutcome {
        self.state
            .record_fraction(self.cell, bsdf_pdf, guiding_pdf, contribution)
    }
}

impl SdTree {
    /// The one lookup per path vertex: the cell holding `ctx.position`
    /// (clamped into the scene), through which directional guiding and its
    /// records at that point go. `None` for a non-finite position (counted
    /// as a dropped record's position: nothing can be recorded there).
    #[inline]
    pub fn vertex(&self, ctx: &ShadingContext) -> Option<DirectionVertex<'_>> {
        let p = ctx.position;
        let Some(at) = self.spatial.locate_with_bounds(p) else {
            self.state
                .dropped
                .count(crate::dropped::DropReason::Position);
            return None;
        };
        Some(DirectionVertex::new(
            &self.state,
            self.spatial.data(at.0),
            (p, at),
            self,
        ))
    }
}
