//! Queries and records by position, through the vertex located there:
//! what a renderer writes in two lines (`vertex(&ctx)`, then the call),
//! in one, for tests that make many records at many points.

use glam::Vec3;
use guiding::field::GuidingField;
use guiding::glt::Glt;
use guiding::light_tree::LightHierarchy;
use guiding::sd_tree::SdTree;
use guiding::{
    DirectionVertex, LightChoice, LightId, LightSample, LightSampler, LightVertex, RecordOutcome,
    ShadingContext,
};

/// A GLT's or field's light vertex at a point, and the records made there
/// (a non-finite point, where no vertex exists, answers
/// [`RecordOutcome::Dropped`]).
pub trait LightsAt {
    /// The light hierarchy.
    type Lights: LightHierarchy;
    /// The light vertex for `ctx`.
    fn light_vertex_for(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, Self::Lights>>;
    /// The light vertex at `p` (no normal, every light).
    fn light_vertex(&self, p: Vec3) -> Option<LightVertex<'_, Self::Lights>> {
        self.light_vertex_for(&at(p))
    }
    /// The light vertex at `p` (panics where there is none).
    fn light_at(&self, p: Vec3) -> LightVertex<'_, Self::Lights> {
        self.light_vertex(p).expect("a finite point")
    }
    /// [`LightVertex::record_light`] at `p`.
    fn record_light_at(&self, p: Vec3, light: LightId, value: f32) -> RecordOutcome {
        self.light_vertex(p)
            .map_or(RecordOutcome::Dropped, |v| v.record_light(light, value))
    }
    /// [`LightVertex::record_visibility`] at `p`.
    fn record_visibility_at(
        &self,
        p: Vec3,
        light: LightId,
        shadowed: f32,
        unshadowed: f32,
    ) -> RecordOutcome {
        self.light_vertex(p).map_or(RecordOutcome::Dropped, |v| {
            v.record_visibility(light, shadowed, unshadowed)
        })
    }
}

/// An SD-tree's or field's direction vertex at a point, its queries and
/// the records made there (a non-finite point answers `None`, 0 or
/// [`RecordOutcome::Dropped`]).
pub trait DirectionsAt {
    /// The direction vertex at `p`.
    fn direction_vertex(&self, p: Vec3) -> Option<DirectionVertex<'_>>;
    /// The direction vertex at `p` (panics where there is none).
    fn direction_at(&self, p: Vec3) -> DirectionVertex<'_> {
        self.direction_vertex(p).expect("a finite point")
    }
    /// [`DirectionVertex::record_radiance`] at `p`.
    fn record_radiance_at(&self, p: Vec3, dir: Vec3, radiance: f32, pdf: f32) -> RecordOutcome {
        self.direction_vertex(p)
            .map_or(RecordOutcome::Dropped, |v| {
                v.record_radiance(dir, radiance, pdf)
            })
    }
    /// [`DirectionVertex::record_fraction`] at `p`.
    fn record_fraction_at(
        &self,
        p: Vec3,
        bsdf_pdf: f32,
        guiding_pdf: f32,
        contribution: f32,
    ) -> RecordOutcome {
        self.direction_vertex(p)
            .map_or(RecordOutcome::Dropped, |v| {
                v.record_fraction(bsdf_pdf, guiding_pdf, contribution)
            })
    }
    /// [`DirectionVertex::sample_direction`] at `p`.
    fn sample_direction_at(&self, p: Vec3, u: [f32; 2]) -> Option<(Vec3, f32)> {
        self.direction_vertex(p).map(|v| v.sample_direction(u))
    }
    /// [`DirectionVertex::direction_pdf`] at `p`.
    fn direction_pdf_at(&self, p: Vec3, dir: Vec3) -> f32 {
        self.direction_vertex(p)
            .map_or(0.0, |v| v.direction_pdf(dir))
    }
    /// [`DirectionVertex::bsdf_fraction`] at `p`.
    fn bsdf_fraction_at(&self, p: Vec3) -> f32 {
        self.direction_vertex(p)
            .map_or(f32::NAN, |v| v.bsdf_fraction())
    }
    /// [`DirectionVertex::mixture_pdf`] at `p`.
    fn mixture_pdf_at(&self, p: Vec3, dir: Vec3, bsdf_pdf: f32) -> f32 {
        self.direction_vertex(p)
            .map_or(0.0, |v| v.mixture_pdf(dir, bsdf_pdf))
    }
}

fn at(p: Vec3) -> ShadingContext {
    ShadingContext::at(p)
}

impl<H: LightHierarchy> LightsAt for Glt<H> {
    type Lights = H;
    fn light_vertex_for(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, H>> {
        self.vertex(ctx)
    }
}

impl<H: LightHierarchy> LightsAt for GuidingField<H> {
    type Lights = H;
    fn light_vertex_for(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, H>> {
        self.vertex(ctx).map(|v| v.light)
    }
}

impl<H: LightHierarchy> DirectionsAt for GuidingField<H> {
    fn direction_vertex(&self, p: Vec3) -> Option<DirectionVertex<'_>> {
        self.vertex(&at(p)).map(|v| v.direction)
    }
}

impl DirectionsAt for SdTree {
    fn direction_vertex(&self, p: Vec3) -> Option<DirectionVertex<'_>> {
        self.vertex(&at(p))
    }
}

/// A GLT or field as a [`LightSampler`] by position: every call locates
/// the vertex for `ctx` and answers through it (what
/// [`guiding::Strategy`] does for its GLT).
#[derive(Clone, Copy, Debug)]
pub struct ByPosition<'a, G>(pub &'a G);

macro_rules! by_position {
    ($g:ident, $ctx:ident, $v:ident => $call:expr, $none:expr) => {
        match $g.0.light_vertex_for(&$ctx) {
            Some($v) => $call,
            None => $none,
        }
    };
}

impl<G: LightsAt> LightSampler for ByPosition<'_, G> {
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        by_position!(self, ctx, v => v.sample(u), None)
    }
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        by_position!(self, ctx, v => v.pmf(light), 0.0)
    }
    fn is_empty(&self) -> bool {
        let ctx = at(Vec3::ZERO);
        by_position!(self, ctx, v => v.is_empty(), true)
    }
    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        by_position!(self, ctx, v => v.is_empty(), true)
    }
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        by_position!(self, ctx, v => v.sample_exact(u), None)
    }
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        by_position!(self, ctx, v => v.pmf_exact(light), 0.0)
    }
    fn visibility(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        by_position!(self, ctx, v => v.visibility(light), 1.0)
    }
    fn sample_with_visibility(&self, ctx: &ShadingContext, u: f32) -> Option<(LightSample, f32)> {
        by_position!(self, ctx, v => v.sample_with_visibility(u), None)
    }
}
