//! [`Glt::vertex`], the one lookup per path vertex, and where the
//! [`LightVertex`]'s records go (the cell's cut, through the light filter).

use super::Glt;
use crate::cut::{LightCells, LightVertex};
use crate::dropped::{DropCounters, DropReason};
use crate::light_sampler::{LightId, ShadingContext};
use crate::light_tree::LightHierarchy;
use crate::record::RecordOutcome;
use crate::spatial::{CellId, Located, SpatialTree};
use glam::Vec3;

impl<H: LightHierarchy> Glt<H> {
    /// The cell holding `p`, `None` for a non-finite point.
    pub fn locate(&self, p: Vec3) -> Option<CellId> {
        self.spatial.locate(p)
    }

    /// The one lookup per path vertex: the cell holding `ctx.position`
    /// (clamped onto the root cube), through which light selection and
    /// light records at that point go. `None` for a non-finite position
    /// (counted in [`DroppedRecords::position`](crate::DroppedRecords::position): nothing can be recorded
    /// there).
    #[inline]
    pub fn vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, H>> {
        let Some(v) = self.vertex_uncounted(ctx) else {
            self.dropped.count(DropReason::Position);
            return None;
        };
        Some(v)
    }

    /// [`Glt::vertex`] without counting a non-finite position (for
    /// [`Strategy`](crate::Strategy)'s queries by position).
    #[inline]
    pub(crate) fn vertex_uncounted(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, H>> {
        let at = self.spatial.locate_with_bounds(ctx.position)?;
        let cut = &self.spatial.data(at.0).cut;
        Some(LightVertex::new(&self.rules, cut, ctx, at, self))
    }
}

impl<H: LightHierarchy> LightCells for Glt<H> {
    #[inline]
    fn record_light(&self, at: Located, light: LightId, value: f32) -> RecordOutcome {
        let cells = (&self.spatial, self.config.light_filter, &self.dropped);
        self.rules.record_in_cells(cells, at, light, value)
    }

    #[inline]
    fn dropped(&self) -> &DropCounters {
        &self.dropped
    }
}
