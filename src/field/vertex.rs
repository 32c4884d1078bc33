//! [`FieldVertex`]: one located cell of the guiding field, its directional
//! guiding and its light choice.

use super::{FieldCell, GuidingField};
use crate::cut::{LightCells, LightVertex};
use crate::dropped::{DropCounters, DropReason};
use crate::light_sampler::LightId;
use crate::light_sampler::ShadingContext;
use crate::light_tree::LightHierarchy;
use crate::record::RecordOutcome;
use crate::sd_tree::{DirectionVertex, RadianceCells};
use crate::spatial::{CellId, Located, SpatialTree};
use glam::Vec3;

/// A path vertex located in a [`GuidingField`] ([`GuidingField::vertex`]):
/// the one lookup serves directional guiding and light choice, each with
/// its records, through the same two types as the SD-tree's and the GLT's
/// vertices, so an integrator written for them drives the field too.
#[derive(Clone, Copy, Debug)]
pub struct FieldVertex<'f, H: LightHierarchy> {
    /// The cell's directional guiding (its quadtree and BSDF fraction).
    pub direction: DirectionVertex<'f>,
    /// The cell's light choice (its guiding cut).
    pub light: LightVertex<'f, H>,
}

impl<H: LightHierarchy> GuidingField<H> {
    /// The cell holding `p`, `None` for a non-finite point.
    #[inline]
    pub fn locate(&self, p: Vec3) -> Option<CellId> {
        self.spatial.locate(p)
    }

    /// The one lookup per path vertex: the cell holding `ctx.position`
    /// (clamped onto the root cube), through which all queries and records
    /// at that point go. `None` for a non-finite position (counted as a
    /// dropped record's position).
    #[inline]
    pub fn vertex(&self, ctx: &ShadingContext) -> Option<FieldVertex<'_, H>> {
        let p = ctx.position;
        let Some(at) = self.spatial.locate_with_bounds(p) else {
            self.sd.dropped.count(DropReason::Position);
            return None;
        };
        let cell: &FieldCell = self.spatial.data(at.0);
        Some(FieldVertex {
            direction: DirectionVertex::new(&self.sd, &cell.sd, (p, at), self),
            light: LightVertex::new(&self.rules, &cell.cut, ctx, at, self),
        })
    }
}

impl<H: LightHierarchy> RadianceCells for GuidingField<H> {
    #[inline]
    fn record_radiance(&self, at: Located, dir: Vec3, radiance: f32, pdf: f32) -> RecordOutcome {
        self.sd
            .record_radiance(&self.spatial, at, dir, radiance, pdf)
    }
}

impl<H: LightHierarchy> LightCells for GuidingField<H> {
    #[inline]
    fn record_light(&self, at: Located, light: LightId, value: f32) -> RecordOutcome {
        let cells = (&self.spatial, self.light_filter, &self.sd.dropped);
        self.rules.record_in_cells(cells, at, light, value)
    }

    #[inline]
    fn dropped(&self) -> &DropCounters {
        &self.sd.dropped
    }
}
