//! [`LightVertex`]: a located cell's learned light choice, the one
//! cut-based [`LightChoice`], serving every light query and record at a
//! path vertex for the GLT and the guiding field alike.

use super::cut_rules::CutRules;
use super::guiding_cut::GuidingCut;
use super::octants::{OctantRecords, octant_of};
use crate::dropped::{DropCounters, DropReason};
use crate::light_sampler::ShadingContext;
use crate::light_sampler::{LightChoice, LightId, LightSample};
use crate::light_tree::LightHierarchy;
use crate::math::Aabb;
use crate::record::RecordOutcome;
use crate::spatial::{BinaryTree, CellId, Located, SpatialFilter, SpatialTree, record_offset};
use glam::Vec3;

/// Where a light vertex's records go: the cells of a [`Glt`](crate::Glt)
/// or of a [`GuidingField`](crate::GuidingField) (a stochastic filter may
/// carry a record into a neighbouring cell), and their drop counter.
pub(crate) trait LightCells {
    /// The GLT's record of the estimate `value` for `light` made at a
    /// located point, with the configured filter; counts a drop.
    fn record_light(&self, at: Located, light: LightId, value: f32) -> RecordOutcome;

    /// The counters of dropped records.
    fn dropped(&self) -> &DropCounters;
}

/// The cells light records spread over: a spatial tree of cells holding a
/// cut and its per-octant counts, its light filter, and its drop counters.
pub(crate) type Cells<'a, C> = (&'a BinaryTree<C>, SpatialFilter, &'a DropCounters);

/// The salt of a light record's stochastic-box offset
/// (`src/spatial/jitter.rs`): which light it is.
#[inline]
pub(crate) fn light_salt(light: LightId) -> [u32; 3] {
    match light {
        LightId::Emitter(e) => [e, 0x4c45_4d49, 0],
        LightId::Unbounded(i) => [i, 0x4c55_4e42, 1],
    }
}

/// A path vertex's light choice: the cut of the cell of a
/// [`Glt`](crate::Glt) ([`Glt::vertex`](crate::Glt::vertex)) or of a
/// [`GuidingField`](crate::GuidingField)
/// ([`FieldVertex::light`](crate::FieldVertex::light)) found by the one
/// lookup, sampled by the GLT's sampling rule (`src/cut/sampling.rs`), and
/// the records that teach it.
///
/// It is the [`LightChoice`] at the shading point it was made for: it
/// keeps the context (position, normal, light links), so `sample`, `pmf`
/// and the records take none. At each vertex a renderer chooses a light
/// with `sample`, weighs BSDF samples that hit an emitter with `pmf`, and
/// records what each light sample found with [`LightVertex::record_light`]
/// (and, to learn each cluster's visibility,
/// [`LightVertex::record_visibility`]).
#[derive(Clone, Copy)]
pub struct LightVertex<'a, H: LightHierarchy> {
    rules: &'a CutRules<H>,
    cut: &'a GuidingCut,
    ctx: ShadingContext,
    /// The cells records go to and where the vertex is in them; `None`
    /// for a lone cut ([`CutRules::vertex`]).
    cells: Option<(&'a dyn LightCells, (CellId, Aabb))>,
}

impl<H: LightHierarchy> core::fmt::Debug for LightVertex<'_, H> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("LightVertex")
            .field("position", &self.ctx.position)
            .field("cell", &self.cells.map(|c| c.1.0))
            .field("cut", &self.cut)
            .finish_non_exhaustive()
    }
}

impl<'a, H: LightHierarchy> LightVertex<'a, H> {
    /// The vertex for `ctx`, located at `at` in `cells`, whose cut is
    /// `cut`.
    #[inline]
    pub(crate) fn new(
        rules: &'a CutRules<H>,
        cut: &'a GuidingCut,
        ctx: &ShadingContext,
        at: (CellId, Aabb),
        cells: &'a dyn LightCells,
    ) -> Self {
        Self {
            rules,
            cut,
            ctx: *ctx,
            cells: Some((cells, at)),
        }
    }

    /// The point this vertex was located from.
    #[inline]
    pub fn position(&self) -> Vec3 {
        self.ctx.position
    }

    /// The shading context this vertex answers for.
    #[inline]
    pub fn context(&self) -> &ShadingContext {
        &self.ctx
    }

    /// The located cell's cut.
    #[inline]
    pub fn cut(&self) -> &'a GuidingCut {
        self.cut
    }

    /// Records a light sample's estimate: `value` is what the sample of
    /// `light` contributed, MIS-weighted and divided by its pdf, without
    /// the BSDF and the cosine (from NEE, `Le * T * w_mis / (pmf *
    /// pdf_solid_angle)`; from a BSDF sample that hit an emitter, `Le *
    /// w_mis / pdf_direction`; one scalar, e.g. luminance;
    /// [`mis::DirectLight::estimate`](crate::DirectLight::estimate)
    /// gives it). Occluded samples record 0 ([`RecordOutcome::Zero`]): a
    /// valid observation. It goes to the cut of the vertex's cell (or,
    /// with a jittering filter configured, of the cell at the jittered
    /// point), into the first slot on `light`'s path that ends the cut.
    /// Dropped and counted: a negative or non-finite value, an emitter out
    /// of range or without power, an unbounded light beyond the configured
    /// count. `&self`: any number of threads at once, no update lost.
    #[inline]
    pub fn record_light(&self, light: LightId, value: f32) -> RecordOutcome {
        match self.cells {
            Some((cells, at)) => cells.record_light((self.ctx.position, at), light, value),
            None => self
                .rules
                .record_from(self.cut, self.ctx.position, light, value),
        }
    }

    /// Records what a next-event sample of `light` saw, for the learned
    /// visibility ([`CutConfig::visibility`](super::CutConfig::visibility)):
    /// `shadowed` is the value recorded for it (0 when the shadow ray was
    /// blocked) and `unshadowed` the value it would have been without
    /// occluders. It goes to the vertex's own cell (visibility is never
    /// carried into neighbouring cells). [`RecordOutcome::Ignored`] when
    /// no visibility is learned; dropped and counted: values negative, not
    /// finite or with `shadowed > unshadowed`, lights out of range.
    #[inline]
    pub fn record_visibility(
        &self,
        light: LightId,
        shadowed: f32,
        unshadowed: f32,
    ) -> RecordOutcome {
        let outcome = self
            .rules
            .record_visibility(self.cut, light, shadowed, unshadowed);
        if outcome == RecordOutcome::Dropped {
            if let Some((cells, _)) = self.cells {
                cells.dropped().count(DropReason::Light);
            }
        }
        outcome
    }
}

impl<H: LightHierarchy> CutRules<H> {
    /// `cut` as a vertex at `ctx.position`, for a renderer that keeps its
    /// own spatial structure: it samples by the GLT's rule and its records
    /// go to `cut` alone (nothing counts its drops: the outcome says).
    pub fn vertex<'a>(&'a self, cut: &'a GuidingCut, ctx: &ShadingContext) -> LightVertex<'a, H> {
        LightVertex {
            rules: self,
            cut,
            ctx: *ctx,
            cells: None,
        }
    }

    /// Records the estimate `value` for `light` made at `p` (located at
    /// `at` in `cells`) into the cuts of the cells that the cells' filter
    /// spreads the point over (each cell's part `value * weight`), the
    /// stochastic box's offset hashed from the record; every cell whose cut
    /// took its part ([`RecordOutcome::Recorded`] or
    /// [`RecordOutcome::Zero`]) counts it in the octant of its cell `p` lies
    /// in. A [`RecordOutcome::Dropped`] result is counted once. Shared by
    /// [`Glt`](crate::Glt) and the guiding field.
    #[inline]
    pub(crate) fn record_in_cells<C: AsRef<GuidingCut> + AsRef<OctantRecords>>(
        &self,
        (cells, filter, dropped): Cells<'_, C>,
        (p, at): Located,
        light: LightId,
        value: f32,
    ) -> RecordOutcome {
        let octant = octant_of(p, &at.1);
        let mut outcome = RecordOutcome::Zero;
        let jitter = || record_offset(p, light_salt(light));
        cells.spread_from(p, at, filter, jitter, |cell, weight| {
            let cell = cells.data(cell);
            let cut: &GuidingCut = cell.as_ref();
            match self.record_weighted_from(cut, p, weight, light, value * weight) {
                RecordOutcome::Dropped => outcome = RecordOutcome::Dropped,
                o => {
                    AsRef::<OctantRecords>::as_ref(cell).count(octant);
                    if o == RecordOutcome::Recorded && outcome != RecordOutcome::Dropped {
                        outcome = o;
                    }
                }
            }
        });
        if outcome == RecordOutcome::Dropped {
            dropped.count(DropReason::Light);
        }
        outcome
    }
}

impl<H: LightHierarchy> LightChoice for LightVertex<'_, H> {
    /// Applies the GLT's sampling rule with the located cell's cut.
    #[inline]
    fn sample(&self, u: f32) -> Option<LightSample> {
        self.rules.sample(self.cut, &self.ctx, u)
    }

    #[inline]
    fn pmf(&self, light: LightId) -> f32 {
        self.rules.pmf(self.cut, &self.ctx, light)
    }

    fn is_empty(&self) -> bool {
        self.rules.is_empty_at(&self.ctx)
    }

    #[inline]
    fn sample_exact(&self, u: f64) -> Option<(LightId, f64)> {
        self.rules.sample_exact(self.cut, &self.ctx, u)
    }

    #[inline]
    fn pmf_exact(&self, light: LightId) -> f64 {
        self.rules.pmf_exact(self.cut, &self.ctx, light)
    }

    /// The learned visibility of `light` in the located cell (1 where
    /// none is learned).
    fn visibility(&self, light: LightId) -> f32 {
        self.rules.visibility(self.cut, light)
    }

    /// One walk: the visibility is read where it leaves the cut.
    #[inline]
    fn sample_with_visibility(&self, u: f32) -> Option<(LightSample, f32)> {
        self.rules.sample_with_visibility(self.cut, &self.ctx, u)
    }

    /// The walks share their common steps
    /// ([`CutRules::sample_candidates`]).
    #[inline]
    fn sample_candidates(&self, u: &[f32], out: &mut [Option<(LightSample, f32)>]) {
        self.rules.sample_candidates(self.cut, &self.ctx, u, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Records of different lights at one point take different
    /// stochastic-box offsets (the salt names the light, emitter or
    /// unbounded), so a point's records spread over the box's cells rather
    /// than all landing in one; the same light at the same point, the same
    /// offset (learning is independent of thread order).
    #[test]
    fn each_light_salts_its_own_offset() {
        let ids = [
            LightId::Emitter(0),
            LightId::Emitter(1),
            LightId::Emitter(2),
            LightId::Unbounded(0),
            LightId::Unbounded(1),
        ];
        let p = Vec3::new(0.25, -3.0, 7.5);
        for (i, a) in ids.iter().enumerate() {
            assert_eq!(
                record_offset(p, light_salt(*a)),
                record_offset(p, light_salt(*a))
            );
            for b in &ids[i + 1..] {
                assert_ne!(light_salt(*a), light_salt(*b), "{a:?} {b:?}");
                let (oa, ob) = (
                    record_offset(p, light_salt(*a)),
                    record_offset(p, light_salt(*b)),
                );
                assert_ne!(oa, ob, "{a:?} {b:?}");
            }
        }
    }

    /// A vertex prints where it is, its cell and its cut (a renderer's
    /// logs show which cell a shading point was guided by).
    #[test]
    fn a_vertex_prints_where_it_is() {
        use crate::Emitter;
        use crate::cut::{CutConfig, CutRules};
        use crate::light_sampler::ShadingContext;
        use crate::light_tree::{BuildHeuristic, LightTree};
        let lights = [Emitter::point(Vec3::X, 1.0), Emitter::point(Vec3::Y, 2.0)];
        let tree = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
        let rules = CutRules::new(&tree, CutConfig::default()).unwrap();
        let cut = rules.new_cut();
        let p = Vec3::new(0.5, 1.5, -2.0);
        let text = alloc::format!("{:?}", rules.vertex(&cut, &ShadingContext::at(p)));
        for part in [
            "LightVertex",
            "position",
            "0.5",
            "cell: None",
            "cut: GuidingCut",
        ] {
            assert!(text.contains(part), "{part} not in {text}");
        }
    }
}
