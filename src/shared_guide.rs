//! [`SharedGuide`]: a guiding structure a renderer's worker threads render
//! and record with while any of them refines it, through `&self`, for
//! renderers that render all their samples in one pass of a thread pool
//! (no separate training loop, no `&mut` between passes). Needs `std`.

use crate::field::GuidingField;
use crate::glt::Glt;
use crate::light_tree::LightHierarchy;
use crate::math::Counter;
use crate::sd_tree::SdTree;
use crate::spatial::RefineOutcome;
use std::sync::{RwLock, RwLockReadGuard, TryLockError};

/// A guiding structure that refines: [`SdTree`], [`Glt`] and
/// [`GuidingField`] (what [`SharedGuide`] holds).
pub trait Refine {
    /// Turns what was recorded into the distributions sampled next (the
    /// structure's own `refine`).
    fn refine(&mut self) -> RefineOutcome;
}

impl Refine for SdTree {
    fn refine(&mut self) -> RefineOutcome {
        SdTree::refine(self)
    }
}

impl<H: LightHierarchy> Refine for Glt<H> {
    fn refine(&mut self) -> RefineOutcome {
        Glt::refine(self)
    }
}

impl<H: LightHierarchy> Refine for GuidingField<H> {
    fn refine(&mut self) -> RefineOutcome {
        GuidingField::refine(self)
    }
}

/// A guide shared by a renderer's threads: each takes [`SharedGuide::read`]
/// for a unit of work (a tile, a row, a batch of paths), samples and
/// records through it as through the structure itself (queries and
/// records take `&self`), and drops it; any thread may call
/// [`SharedGuide::refine`] (waits for the units in flight to end, then
/// refines in place) or [`SharedGuide::try_refine`] (refines only if no
/// unit is in flight, never waits).
///
/// Nothing is copied and no record is lost: the refinement runs on the one
/// structure while no thread reads it, so a deterministic-mode structure
/// learns exactly what one thread recording the same records would have
/// (`tests/shared_guide.rs`). The lock is taken once per unit of work, not
/// per query.
///
/// A thread must not call `refine` while it holds a guard from `read`
/// (it would wait for itself); `try_refine` returns `None` then.
///
/// ```
/// use guiding::{glam::Vec3, Aabb, Emitter, Glt, GltConfig, LightTree};
/// use guiding::{LightChoice, ShadingContext, SharedGuide};
/// let lights = [Emitter::point(Vec3::Y, 1.0), Emitter::point(Vec3::X, 3.0)];
/// let tree = LightTree::build(&lights[..], Default::default())?;
/// let scene = Aabb::new(Vec3::splat(-2.0), Vec3::splat(2.0));
/// let guide = SharedGuide::new(Glt::new(tree, scene, GltConfig::default())?);
/// std::thread::scope(|s| {
///     for t in 0..4 {
///         let guide = &guide;
///         s.spawn(move || {
///             for tile in 0..8 {
///                 let glt = guide.read(); // one tile
///                 let ctx = ShadingContext::at(Vec3::new(0.1 * t as f32, 0.0, 0.1));
///                 let v = glt.vertex(&ctx).unwrap();
///                 let x = v.sample(0.5).unwrap();
///                 v.record_light(x.light, 1.0 / x.pmf);
///                 drop(glt);
///                 if tile == 3 && t == 0 {
///                     guide.refine(); // mid-render, from a worker
///                 }
///             }
///         });
///     }
/// });
/// assert_eq!(guide.refinements(), 1);
/// # Ok::<(), guiding::Error>(())
/// ```
#[derive(Debug)]
pub struct SharedGuide<F> {
    guide: RwLock<F>,
    /// Refinements run; a [`Counter`] works on targets without 64-bit
    /// atomics too.
    refinements: Counter,
}

impl<F: Refine> SharedGuide<F> {
    /// Shares `guide`.
    pub fn new(guide: F) -> Self {
        Self {
            guide: RwLock::new(guide),
            refinements: Counter::new(),
        }
    }

    /// The guide for one unit of work: sample, evaluate and record through
    /// it; drop it when the unit ends. A refinement waits for it.
    pub fn read(&self) -> RwLockReadGuard<'_, F> {
        // A panic in another thread while it refined leaves the guide as
        // that refinement left it: every structure's refine keeps its
        // invariants at each step, so the state is still usable.
        self.guide.read().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits until no unit of work is in flight, then refines (units that
    /// start meanwhile wait, or go first, as the platform's `RwLock`
    /// decides).
    pub fn refine(&self) -> RefineOutcome {
        let mut guide = self.guide.write().unwrap_or_else(|e| e.into_inner());
        self.refinements.bump();
        guide.refine()
    }

    /// Refines now if no unit of work is in flight; else `None`, at once.
    pub fn try_refine(&self) -> Option<RefineOutcome> {
        let mut guide = match self.guide.try_write() {
            Ok(g) => g,
            Err(TryLockError::Poisoned(e)) => e.into_inner(),
            Err(TryLockError::WouldBlock) => return None,
        };
        self.refinements.bump();
        Some(guide.refine())
    }

    /// How many refinements ran.
    pub fn refinements(&self) -> u64 {
        self.refinements.get()
    }

    /// The guide, for `&mut` access when no thread shares it.
    pub fn get_mut(&mut self) -> &mut F {
        self.guide.get_mut().unwrap_or_else(|e| e.into_inner())
    }

    /// Unshares the guide.
    pub fn into_inner(self) -> F {
        self.guide.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}
