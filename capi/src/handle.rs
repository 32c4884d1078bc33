//! What the three guides' handles share: the guide behind a read-write
//! lock (queries and records read, refinement and merging write), the
//! light count, and the calls every guide answers the same way (refine,
//! clear_records, merge, save, iteration, dropped records), written once.

use crate::buffer::GuidingBuffer;
use crate::glt::GuidingRefineOutcome;
use crate::status::{Failure, GuidingStatus, put};
use guiding::{
    DirectionVertex, GuidingField, LightHierarchy, LightId, LightTree, LightVertex, RefineOutcome,
    SdTree, ShadingContext,
};
use std::sync::{Arc, RwLock, RwLockReadGuard, RwLockWriteGuard};

// No type aliases here: cbindgen reads every item of the crate and would
// take `guiding::Glt<..>` in a handle for an alias of that last name.

/// A guide behind its lock, with how many lights it chooses among.
pub(crate) struct Handle<G> {
    guide: RwLock<G>,
    pub emitters: u32,
    pub unbounded: u32,
}

impl<G: Learned> Handle<G> {
    pub fn new(guide: G) -> Self {
        let (emitters, unbounded) = guide.light_count();
        Self {
            guide: RwLock::new(guide),
            emitters,
            unbounded,
        }
    }

    pub fn read(&self) -> Result<RwLockReadGuard<'_, G>, Failure> {
        self.guide.read().map_err(|_| poisoned())
    }

    pub fn write(&self) -> Result<RwLockWriteGuard<'_, G>, Failure> {
        self.guide.write().map_err(|_| poisoned())
    }

    /// `index` as a light of this guide, or an invalid-argument failure.
    pub fn light(&self, index: u32) -> Result<LightId, Failure> {
        if index < self.emitters.saturating_add(self.unbounded) {
            Ok(LightId::from_index(index, self.emitters))
        } else {
            Err(Failure::invalid(format!(
                "light = {index}: the guide has {} emitters and {} unbounded lights",
                self.emitters, self.unbounded
            )))
        }
    }

    pub fn refine(&self, outcome: *mut GuidingRefineOutcome) -> Result<(), Failure> {
        let r = self.write()?.refine();
        if !outcome.is_null() {
            let o = GuidingRefineOutcome {
                splits: r.splits,
                refused_by_budget: r.refused_by_budget,
                refused_by_precision: r.refused_by_precision,
            };
            // SAFETY: non-null, writable by the exported caller's promise.
            unsafe { put(outcome, o, "outcome") }?;
        }
        Ok(())
    }

    pub fn clear_records(&self) -> Result<(), Failure> {
        self.write()?.clear_records();
        Ok(())
    }

    pub fn merge(&self, other: &Self) -> Result<(), Failure> {
        if std::ptr::eq(self, other) {
            return Err(Failure::invalid(
                "merge: the two handles are the same guide",
            ));
        }
        let theirs = other.read()?;
        if self.write()?.merge(&theirs) {
            Ok(())
        } else {
            Err(Failure::new(
                GuidingStatus::Incompatible,
                "merge: the guides are not copies of one guide after the same refinements",
            ))
        }
    }

    pub fn save(&self, out: *mut GuidingBuffer) -> Result<(), Failure> {
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let bytes = self.read()?.to_bytes();
        // SAFETY: checked non-null, writable by the exported caller's promise.
        unsafe { put(out, GuidingBuffer::from_vec(bytes), "out") }
    }

    pub fn iteration(&self) -> u32 {
        self.read().map_or(0, |g| g.iteration())
    }

    pub fn dropped_records(&self) -> u64 {
        self.read().map_or(0, |g| g.dropped_records())
    }
}

fn poisoned() -> Failure {
    Failure::new(
        GuidingStatus::Panic,
        "the guide panicked in an earlier call; free it",
    )
}

/// What every guide does between and around passes.
pub(crate) trait Learned {
    fn refine(&mut self) -> RefineOutcome;
    fn clear_records(&mut self);
    fn merge(&mut self, other: &Self) -> bool;
    fn to_bytes(&self) -> Vec<u8>;
    fn iteration(&self) -> u32;
    fn dropped_records(&self) -> u64;
    /// (emitters, unbounded lights); (0, 0) for a guide of directions.
    fn light_count(&self) -> (u32, u32);
}

macro_rules! learned {
    ($t:ty, |$g:ident| $count:expr) => {
        impl Learned for $t {
            fn refine(&mut self) -> RefineOutcome {
                <$t>::refine(self)
            }
            fn clear_records(&mut self) {
                <$t>::clear_records(self)
            }
            fn merge(&mut self, other: &Self) -> bool {
                <$t>::merge(self, other)
            }
            fn to_bytes(&self) -> Vec<u8> {
                <$t>::to_bytes(self)
            }
            fn iteration(&self) -> u32 {
                <$t>::iteration(self)
            }
            fn dropped_records(&self) -> u64 {
                <$t>::dropped_records(self).total()
            }
            fn light_count(&self) -> (u32, u32) {
                let $g = self;
                $count
            }
        }
    };
}

learned!(guiding::Glt<Arc<LightTree>>, |g| (
    g.light_tree().emitter_count() as u32,
    g.config().cut.unbounded.count
));
learned!(GuidingField<Arc<LightTree>>, |f| (
    f.light_tree().emitter_count() as u32,
    f.config().cut.unbounded.count
));
learned!(SdTree, |_s| (0, 0));

/// A guide that chooses lights.
pub(crate) trait LightGuide {
    fn light_vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, Arc<LightTree>>>;
}

impl LightGuide for guiding::Glt<Arc<LightTree>> {
    fn light_vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, Arc<LightTree>>> {
        self.vertex(ctx)
    }
}

impl LightGuide for GuidingField<Arc<LightTree>> {
    fn light_vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, Arc<LightTree>>> {
        self.vertex(ctx).map(|v| v.light)
    }
}

/// A guide that samples directions.
pub(crate) trait DirectionGuide {
    fn direction_vertex(&self, ctx: &ShadingContext) -> Option<DirectionVertex<'_>>;
}

impl DirectionGuide for SdTree {
    fn direction_vertex(&self, ctx: &ShadingContext) -> Option<DirectionVertex<'_>> {
        self.vertex(ctx)
    }
}

impl DirectionGuide for GuidingField<Arc<LightTree>> {
    fn direction_vertex(&self, ctx: &ShadingContext) -> Option<DirectionVertex<'_>> {
        self.vertex(ctx).map(|v| v.direction)
    }
}
