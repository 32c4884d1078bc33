//! [`PathRecorder`]: the bookkeeping every guided integrator repeats, in
//! one place. The renderer reports what happened along a path (the
//! scattering at each vertex, and every MIS-weighted radiance the path
//! found); the recorder keeps the pixel estimate and, at the end of the
//! path, the radiance that arrived at each vertex along the direction the
//! path left it in, which is what the SD-tree (PPG) learns from.
//!
//! ```text
//! recorder.clear();
//! loop {
//!     hit emitter   -> recorder.add_radiance(Le * w_bsdf)          // MIS-weighted
//!     NEE at vertex -> recorder.add_radiance(f cos Le * w_light / p)
//!     scatter       -> recorder.push_segment(vertex, wi, pdf, bsdf_pdf, guide_pdf, f cos / pdf)
//!     specular      -> recorder.scatter_unrecorded(f cos / pdf)
//! }
//! recorder.finish();   // each vertex's radiance and fraction records
//! let pixel = recorder.estimate();
//! ```
//!
//! The radiance arriving at vertex `i` is computed at the end by one
//! backward pass, `L_i = e_i + s_i w_(i+1) L_(i+1)` (`e_i` the radiance the
//! path found at the end of segment `i`, `w_(i+1)` the throughput factor
//! of the next recorded segment, `s_i` that of the specular scatterings
//! between them), without dividing by the path throughput: a colour channel
//! that the throughput zeroes loses nothing of the others.
//!
//! Light records (the GLT's) do not wait for the end of the path: the
//! renderer makes them where it finds direct light, through the vertex's
//! [`LightVertex::record_light`](crate::LightVertex::record_light).

use crate::math::luminance;
use crate::sd_tree::DirectionVertex;
use alloc::vec::Vec;
use glam::Vec3;

/// One scattering of a path: where it left from, in which direction, with
/// which pdfs and throughput factor, and (after [`PathRecorder::finish`])
/// the radiance that arrived back along it.
#[derive(Clone, Copy, Debug)]
pub struct PathSegment<'a> {
    /// The directional guiding of the vertex the path left from, which
    /// [`PathRecorder::finish`] records into; `None` for a vertex nothing
    /// learns at.
    pub vertex: Option<DirectionVertex<'a>>,
    /// The direction it left in (unit).
    pub direction: Vec3,
    /// The solid-angle pdf the direction was sampled with (the mixture of
    /// BSDF and guide sampling).
    pub pdf: f32,
    /// The BSDF's pdf of the direction.
    pub bsdf_pdf: f32,
    /// The guide's pdf of the direction (0 without a guide).
    pub guide_pdf: f32,
    /// The throughput factor `f cos / pdf` of the segment.
    pub weight: Vec3,
    /// MIS-weighted radiance found at the end of this segment (the
    /// emitter it hit, and what next-event estimation found there).
    pub found: Vec3,
    /// The radiance that arrived at the vertex along `direction`, filled
    /// by [`PathRecorder::finish`].
    pub incident: Vec3,
    /// The throughput of the unrecorded (specular) scatterings after this
    /// segment so far, applied to what is found after them.
    factor: Vec3,
}

/// The bookkeeping of one path at a time (reuse it between paths: its
/// storage is kept). See the module docs.
#[derive(Clone, Debug)]
pub struct PathRecorder<'a> {
    segments: Vec<PathSegment<'a>>,
    throughput: Vec3,
    estimate: Vec3,
}

impl Default for PathRecorder<'_> {
    fn default() -> Self {
        Self::new()
    }
}

impl<'a> PathRecorder<'a> {
    /// An empty recorder.
    pub fn new() -> Self {
        Self {
            segments: Vec::new(),
            throughput: Vec3::ONE,
            estimate: Vec3::ZERO,
        }
    }

    /// Starts a new path (keeps the storage).
    pub fn clear(&mut self) {
        self.segments.clear();
        self.throughput = Vec3::ONE;
        self.estimate = Vec3::ZERO;
    }

    /// The path throughput so far: the product of the segments' weights.
    #[inline]
    pub fn throughput(&self) -> Vec3 {
        self.throughput
    }

    /// Radiance the path found at its current end, MIS-weighted and not
    /// multiplied by the throughput (the recorder does that): an emitter
    /// hit `Le w`, or next-event estimation's `f cos Le w / p`. Non-finite
    /// values are ignored (they would poison the pixel and every record).
    #[inline]
    pub fn add_radiance(&mut self, radiance: Vec3) {
        if !radiance.is_finite() {
            return;
        }
        self.estimate += self.throughput * radiance;
        if let Some(last) = self.segments.last_mut() {
            last.found += last.factor * radiance;
        }
    }

    /// The path leaves `vertex` along `direction`, sampled with the
    /// mixture pdf `pdf` (BSDF pdf `bsdf_pdf`, guide pdf `guide_pdf`), with
    /// throughput factor `weight = f cos / pdf`. `vertex` is the
    /// directional guiding located there (`None`: nothing learns there).
    #[inline]
    pub fn push_segment(
        &mut self,
        vertex: Option<DirectionVertex<'a>>,
        direction: Vec3,
        pdf: f32,
        bsdf_pdf: f32,
        guide_pdf: f32,
        weight: Vec3,
    ) {
        self.throughput *= weight;
        self.segments.push(PathSegment {
            vertex,
            direction,
            pdf,
            bsdf_pdf,
            guide_pdf,
            weight,
            found: Vec3::ZERO,
            incident: Vec3::ZERO,
            factor: Vec3::ONE,
        });
    }

    /// A scattering that guiding does not learn from (a specular bounce):
    /// only the throughput changes. Radiance found after it still reaches
    /// the earlier segments, through `weight`.
    #[inline]
    pub fn scatter_unrecorded(&mut self, weight: Vec3) {
        self.throughput *= weight;
        if let Some(last) = self.segments.last_mut() {
            last.factor *= weight;
        }
    }

    /// The pixel estimate: every radiance found, times the throughput at
    /// the moment it was found.
    #[inline]
    pub fn estimate(&self) -> Vec3 {
        self.estimate
    }

    /// The recorded segments (their `incident` radiance is filled by
    /// [`PathRecorder::finish`]).
    pub fn segments(&self) -> &[PathSegment<'a>] {
        &self.segments
    }

    /// Computes the radiance that arrived along every segment and, for
    /// each one with a vertex and a finite value, makes that vertex's two
    /// records: [`DirectionVertex::record_radiance`] of
    /// `luminance(incident)` along the segment's direction with its pdf,
    /// and [`DirectionVertex::record_fraction`] with its two pdfs and
    /// `luminance(weight * incident)` (what the learned BSDF fraction
    /// optimises). The segments keep their `incident` radiance for a
    /// renderer that routes records elsewhere.
    pub fn finish(&mut self) {
        // L_i = found_i + factor_i w_(i+1) L_(i+1), from the last segment.
        let mut after = Vec3::ZERO;
        let mut next_weight = Vec3::ZERO;
        for s in self.segments.iter_mut().rev() {
            after = s.found + s.factor * next_weight * after;
            s.incident = after;
            next_weight = s.weight;
        }
        for s in &self.segments {
            if let Some(v) = &s.vertex
                && s.incident.is_finite()
            {
                v.record_radiance(s.direction, luminance(s.incident), s.pdf);
                v.record_fraction(s.bsdf_pdf, s.guide_pdf, luminance(s.weight * s.incident));
            }
        }
    }
}
