//! [`SharedGuide`]: a guiding structure a renderer's worker threads render
//! and record with while any of them refines it, through `&self`, for
//! renderers that render all their samples in one pass of a thread pool
//! (no separate training loop, no `&mut` between passes), and
//! [`RefineSchedule`], when it refines by itself for renderers that give
//! the integrator no hook but the path (tiles from a work queue, no
//! thread count). Needs `std`.

use crate::error::{ConfigError, Error};
use crate::field::GuidingField;
use crate::glt::Glt;
use crate::light_tree::LightHierarchy;
use crate::math::Counter;
use crate::sd_tree::SdTree;
use crate::spatial::RefineOutcome;
use std::sync::{Mutex, RwLock, RwLockReadGuard, TryLockError};
use std::time::{Duration, Instant};

/// A guiding structure that refines: [`SdTree`], [`Glt`] and
/// [`GuidingField`] (what [`SharedGuide`] holds).
pub trait Refine {
    /// Turns what was recorded into the distributions sampled next (the
    /// structure's own `refine`).
    fn refine(&mut self) -> RefineOutcome;

    /// When [`SharedGuide::refine_when_due`] refines it unless
    /// [`SharedGuide::with_schedule`] says otherwise.
    fn schedule(&self) -> RefineSchedule;
}

impl Refine for SdTree {
    fn refine(&mut self) -> RefineOutcome {
        SdTree::refine(self)
    }

    /// PPG's doubling, the first iteration as many paths as the spatial
    /// threshold (enough records for the root to split).
    fn schedule(&self) -> RefineSchedule {
        RefineSchedule::doubling_from(self.config().spatial_threshold)
    }
}

impl<H: LightHierarchy> Refine for Glt<H> {
    fn refine(&mut self) -> RefineOutcome {
        Glt::refine(self)
    }

    /// [`RefineSchedule::GLT`]: its cells refine each on records of its own.
    fn schedule(&self) -> RefineSchedule {
        RefineSchedule::GLT
    }
}

impl<H: LightHierarchy> Refine for GuidingField<H> {
    fn refine(&mut self) -> RefineOutcome {
        GuidingField::refine(self)
    }

    /// The SD-tree's doubling: the field's cells refine on PPG's clock.
    fn schedule(&self) -> RefineSchedule {
        RefineSchedule::doubling_from(self.config().sd.spatial_threshold)
    }
}

/// When [`SharedGuide::refine_when_due`] refines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RefineSchedule {
    /// Whenever the time since the last refinement ended is at least
    /// `ratio` times what that refinement took: the threads spend at most
    /// `1 / (ratio + 1)` of the render's wall time waiting for
    /// refinements, whatever their number. For the [`Glt`], whose cells
    /// each wait for 3/2 of their own last records, so that refining often
    /// refines each cell when its data says so (and the cells a tile in
    /// progress covers learn from its first samples).
    Amortized {
        /// At least 1.
        ratio: u32,
    },
    /// Practical Path Guiding's: the first refinement after `first` paths,
    /// each next one after twice the paths of the one before (after
    /// `first`, `3 first`, `7 first`, ... paths), for the [`SdTree`] and the
    /// [`GuidingField`], which rebuild every cell from what it collected
    /// since the last refinement. PPG's first iteration is one sample per
    /// pixel: pass the image's pixel count.
    Doubling {
        /// At least 1.
        first: u64,
    },
}

impl RefineSchedule {
    /// The [`Glt`]'s: amortized, at most 1/51 of the wall time refining.
    /// Measured in tile order, 2 threads, 3 seeds
    /// (docs/experiments/tile-order.md): the rs_pbrt rooms' relMSE 0.031
    /// against 0.045 refining after every wave of tiles and 0.117 never
    /// refining, the street's 0.019 against 0.024 and 0.074.
    pub const GLT: Self = Self::Amortized { ratio: 50 };

    fn doubling_from(paths: f64) -> Self {
        Self::Doubling {
            first: (paths.ceil() as u64).max(1),
        }
    }

    /// Checks the fields: `ratio` and `first` at least 1.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let (field, value) = match *self {
            Self::Amortized { ratio } => ("RefineSchedule::Amortized::ratio", ratio as u64),
            Self::Doubling { first } => ("RefineSchedule::Doubling::first", first),
        };
        match value {
            0 => Err(ConfigError {
                field,
                value: 0.0,
                expected: "at least 1",
            }),
            _ => Ok(()),
        }
    }
}

/// [`SharedGuide::refine_when_due`]'s clock.
#[derive(Debug)]
struct Clock {
    /// When the last refinement ended and what it took (amortized).
    last_end: Instant,
    took: Duration,
    /// The path count at which the next one runs (doubling).
    next_paths: u64,
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
/// A thread must not call `refine` or `refine_when_due` while it holds a
/// guard from `read` (it would wait for itself); `try_refine` returns
/// `None` then.
///
/// ## A renderer that renders tiles from a work queue
///
/// A renderer whose integrator sees only paths (rs_pbrt, pbrt-v3: tiles
/// handed out from a queue, no tile hook, no thread count) takes the
/// guard for each path and calls [`SharedGuide::refine_when_due`] after
/// dropping it; the guide refines when its [`RefineSchedule`] says so,
/// from any thread. The guard and the call cost 25 ns a path on one
/// thread and 115 ns with a second thread doing the same in a loop (the
/// worst case: the lock's cache line moves at every path; `cargo bench
/// --bench shared_guide`), about 1% of the 10 microseconds a path takes in
/// the rs_pbrt scenes: fine for a handful of threads. With many more,
/// take the guard per tile or per batch of paths and pass their count. Refinements interleave with the records as the threads'
/// timing decides, so such a render's learned state is not reproducible
/// bit for bit; a renderer that needs it refines at its own pass
/// boundaries with [`SharedGuide::refine`].
///
/// A pbrt-v3-style estimator (one light sample and one BSDF sample of the
/// chosen light, MIS-weighted) records each sample as it comes: the
/// [`DirectLight`](crate::DirectLight) of each, from
/// [`Convention::PbrtV3`](crate::Convention::PbrtV3), gives the record of
/// that sample (zero when it was occluded or missed the light), and each
/// goes to the vertex's `record_light` for the chosen light. Their sum is
/// not a record: the records estimate the light's contribution each on
/// its own.
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
    schedule: RefineSchedule,
    /// Paths counted by [`SharedGuide::refine_when_due`].
    paths: Counter,
    clock: Mutex<Clock>,
}

impl<F: Refine> SharedGuide<F> {
    /// Shares `guide`; [`SharedGuide::refine_when_due`] follows the
    /// guide's own schedule ([`Refine::schedule`]).
    pub fn new(guide: F) -> Self {
        let schedule = guide.schedule();
        Self::shared(guide, schedule)
    }

    /// Shares `guide`; [`SharedGuide::refine_when_due`] follows `schedule`.
    /// An invalid schedule is an error.
    pub fn with_schedule(guide: F, schedule: RefineSchedule) -> Result<Self, Error> {
        schedule.validate().map_err(Error::Config)?;
        Ok(Self::shared(guide, schedule))
    }

    fn shared(guide: F, schedule: RefineSchedule) -> Self {
        let next_paths = match schedule {
            RefineSchedule::Doubling { first } => first,
            RefineSchedule::Amortized { .. } => 0,
        };
        Self {
            guide: RwLock::new(guide),
            refinements: Counter::new(),
            schedule,
            paths: Counter::new(),
            clock: Mutex::new(Clock {
                last_end: Instant::now(),
                took: Duration::ZERO,
                next_paths,
            }),
        }
    }

    /// The schedule [`SharedGuide::refine_when_due`] follows.
    pub fn schedule(&self) -> RefineSchedule {
        self.schedule
    }

    /// Counts `paths` finished paths (1 after each path; a tile's paths
    /// after a tile) and refines if the [`RefineSchedule`] says it is
    /// due, waiting for the paths in flight; `None` if it did not refine.
    /// Call it holding no guard. Cheap when not due: an atomic add and
    /// one lock tried (another thread checking or refining at that moment
    /// makes it return `None` at once, its paths counted all the same).
    pub fn refine_when_due(&self, paths: u64) -> Option<RefineOutcome> {
        self.paths.add(paths);
        let mut clock = match self.clock.try_lock() {
            Ok(c) => c,
            Err(TryLockError::Poisoned(e)) => e.into_inner(),
            Err(TryLockError::WouldBlock) => return None,
        };
        let due = match self.schedule {
            RefineSchedule::Amortized { ratio } => {
                clock.last_end.elapsed() >= clock.took.saturating_mul(ratio)
            }
            RefineSchedule::Doubling { .. } => self.paths.get() >= clock.next_paths,
        };
        if !due {
            return None;
        }
        let start = Instant::now();
        let outcome = self.refine();
        clock.last_end = Instant::now();
        clock.took = clock.last_end - start;
        if let RefineSchedule::Doubling { first } = self.schedule {
            // After first, 3 first, 7 first, ...: each iteration twice the last.
            clock.next_paths = self.paths.get().saturating_mul(2).saturating_add(first);
        }
        Some(outcome)
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
