//! `GuidingGlt`: the Guiding Light Tree behind a C handle: build, query
//! (sample, pmf), record, refine, save, load, merge.

use crate::buffer::GuidingBuffer;
use crate::context::{
    GUIDING_NO_LIGHT, GuidingLightSample, GuidingRecordOutcome, GuidingShadingContext, unit,
};
use crate::light_tree::GuidingLightTree;
use crate::status::{Failure, GuidingStatus, get, guard, put, slice, vec3};
use guiding::{
    Aabb, Accumulation, GltConfig, LightChoice, LightHierarchy, LightId, LightTree, SpatialFilter,
    UnboundedLights,
};
use std::sync::{Arc, RwLock, RwLockReadGuard, RwLockWriteGuard};

/// `light_filter` of `GuidingGltConfig`: a record goes to its point's cell.
pub const GUIDING_FILTER_NEAREST: u32 = 0;
/// A record goes to one cell picked within a cell-sized box around it.
pub const GUIDING_FILTER_STOCHASTIC_BOX: u32 = 1;
/// A record is spread over the cells a cell-sized box around it overlaps.
pub const GUIDING_FILTER_BOX: u32 = 2;

/// The GLT's configuration (the Rust `GltConfig`'s renderer-facing
/// fields). Start from `guiding_glt_config_default`; `guiding_glt_new`
/// refuses values out of range with `GUIDING_STATUS_INVALID_CONFIG`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingGltConfig {
    /// The cut's refinement threshold (the paper's sigma).
    pub sigma: f64,
    /// The weight of the learned estimate against the prior (alpha).
    pub alpha: f64,
    /// Records a cut needs before it trusts what it learned.
    pub min_records: u32,
    /// Learn each light's visibility as well (records' zeros).
    pub visibility: bool,
    /// How many unbounded lights (sun, sky) follow the emitters' indices.
    pub unbounded_lights: u32,
    /// The probability of choosing one of them (with `unbounded_lights` > 0).
    pub unbounded_probability: f64,
    /// Learned state bit for bit the same whatever the thread count.
    pub deterministic: bool,
    /// Records a spatial cell takes before it splits.
    pub spatial_threshold: f64,
    /// The most bytes the spatial tree's cells may take; 0 for no limit.
    pub max_bytes: usize,
    /// Where a light record goes: a `GUIDING_FILTER_*`.
    pub light_filter: u32,
}

/// A Guiding Light Tree (opaque).
pub struct GuidingGlt {
    glt: RwLock<guiding::Glt<Arc<LightTree>>>,
    emitters: u32,
    unbounded: u32,
}

type Inner = guiding::Glt<Arc<LightTree>>;

impl GuidingGlt {
    fn wrap(glt: Inner) -> Self {
        let emitters = glt.light_tree().emitter_count() as u32;
        let unbounded = glt.config().cut.unbounded.count;
        Self {
            glt: RwLock::new(glt),
            emitters,
            unbounded,
        }
    }

    fn read(&self) -> Result<RwLockReadGuard<'_, Inner>, Failure> {
        self.glt.read().map_err(|_| poisoned())
    }

    fn write(&self) -> Result<RwLockWriteGuard<'_, Inner>, Failure> {
        self.glt.write().map_err(|_| poisoned())
    }

    fn light(&self, index: u32) -> Result<LightId, Failure> {
        if index < self.emitters.saturating_add(self.unbounded) {
            Ok(LightId::from_index(index, self.emitters))
        } else {
            Err(Failure::invalid(format!(
                "light = {index}: the guide has {} emitters and {} unbounded lights",
                self.emitters, self.unbounded
            )))
        }
    }
}

fn poisoned() -> Failure {
    Failure::new(
        GuidingStatus::Panic,
        "the guide panicked in an earlier call; free it",
    )
}

fn filter(f: u32) -> Result<SpatialFilter, Failure> {
    Ok(match f {
        GUIDING_FILTER_NEAREST => SpatialFilter::Nearest,
        GUIDING_FILTER_STOCHASTIC_BOX => SpatialFilter::StochasticBox,
        GUIDING_FILTER_BOX => SpatialFilter::Box,
        _ => {
            return Err(Failure::new(
                GuidingStatus::InvalidConfig,
                format!("light_filter = {f} is not a GUIDING_FILTER_*"),
            ));
        }
    })
}

fn config_error(e: impl ToString) -> Failure {
    Failure::new(GuidingStatus::InvalidConfig, e.to_string())
}

impl GuidingGltConfig {
    fn from_rust(c: &GltConfig) -> Self {
        Self {
            sigma: c.cut.sigma,
            alpha: c.cut.alpha,
            min_records: c.cut.min_records,
            visibility: c.cut.visibility,
            unbounded_lights: c.cut.unbounded.count,
            unbounded_probability: c.cut.unbounded.probability,
            deterministic: matches!(c.cut.accumulation, Accumulation::Deterministic),
            spatial_threshold: c.spatial_threshold,
            max_bytes: c.max_bytes.unwrap_or(0),
            light_filter: match c.light_filter {
                SpatialFilter::StochasticBox => GUIDING_FILTER_STOCHASTIC_BOX,
                SpatialFilter::Box => GUIDING_FILTER_BOX,
                _ => GUIDING_FILTER_NEAREST,
            },
        }
    }

    fn to_rust(self) -> Result<GltConfig, Failure> {
        let mut c = GltConfig::default();
        c.cut.sigma = self.sigma;
        c.cut.alpha = self.alpha;
        c.cut.min_records = self.min_records;
        c.cut.visibility = self.visibility;
        c.cut.unbounded = if self.unbounded_lights == 0 {
            UnboundedLights::default()
        } else {
            UnboundedLights::new(self.unbounded_lights, self.unbounded_probability)
                .map_err(config_error)?
        };
        c.cut.accumulation = if self.deterministic {
            Accumulation::Deterministic
        } else {
            Accumulation::Fast
        };
        c.spatial_threshold = self.spatial_threshold;
        c.max_bytes = (self.max_bytes > 0).then_some(self.max_bytes);
        c.light_filter = filter(self.light_filter)?;
        c.validate().map_err(config_error)?;
        Ok(c)
    }
}

/// The crate's default configuration, written to `out`.
///
/// # Safety
/// `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_config_default(out: *mut GuidingGltConfig) -> GuidingStatus {
    // SAFETY: forwarded.
    guard(|| unsafe {
        put(
            out,
            GuidingGltConfig::from_rust(&GltConfig::default()),
            "out",
        )
    })
}

fn hand_out(glt: Inner, out: *mut *mut GuidingGlt) -> Result<(), Failure> {
    let handle = Box::into_raw(Box::new(GuidingGlt::wrap(glt)));
    // SAFETY: forwarded from the exported caller; the box is taken back on failure.
    unsafe { put(out, handle, "out") }.inspect_err(|_| {
        // SAFETY: `handle` came from Box::into_raw just above.
        drop(unsafe { Box::from_raw(handle) });
    })
}

/// A GLT over `tree` for shading points in the box `lower[3]`..`upper[3]`
/// (points outside are clamped onto it), with `config` (null: the
/// defaults), written to `out`.
///
/// # Safety
/// `tree` a live handle; `lower`, `upper` 3 floats each; `config` null or
/// readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_new(
    tree: *const GuidingLightTree,
    lower: *const f32,
    upper: *const f32,
    config: *const GuidingGltConfig,
    out: *mut *mut GuidingGlt,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (t, lo, hi) = unsafe {
            (
                get(tree, "tree")?,
                vec3(lower, "lower")?,
                vec3(upper, "upper")?,
            )
        };
        // SAFETY: forwarded.
        let config = match unsafe { config.as_ref() } {
            Some(c) => c.to_rust()?,
            None => GltConfig::default(),
        };
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let glt = guiding::Glt::new(Arc::clone(&t.tree), Aabb::new(lo, hi), config).map_err(
            |e| match e {
                guiding::Error::Config(c) => config_error(c),
                e => Failure::new(GuidingStatus::BuildFailed, e.to_string()),
            },
        )?;
        hand_out(glt, out)
    })
}

/// Frees `glt` (null is allowed and does nothing).
///
/// # Safety
/// `glt` null or a live handle, freed once, with no call on it running.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_free(glt: *mut GuidingGlt) {
    if !glt.is_null() {
        // SAFETY: a handle from Box::into_raw, freed once (the caller's promise).
        drop(unsafe { Box::from_raw(glt) });
    }
}

/// How many lights `glt` chooses among: its emitters, then its unbounded
/// lights (0 for null).
///
/// # Safety
/// `glt` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_light_count(glt: *const GuidingGlt) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(glt, "glt") }.map_or(0, |g| g.emitters + g.unbounded)
}

/// Chooses a light at `ctx` with `u` in [0, 1): its index and pmf in
/// `out` (`GUIDING_NO_LIGHT` and 0 when nothing can be sampled there).
///
/// # Safety
/// `glt` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_sample(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    u: f32,
    out: *mut GuidingLightSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (g, ctx) = unsafe { (get(glt, "glt")?, get(ctx, "ctx")?.to_rust()?) };
        let u = unit(u, "u")?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let sample = g.read()?.vertex(&ctx).and_then(|v| v.sample(u));
        let s = sample.map_or(
            GuidingLightSample {
                light: GUIDING_NO_LIGHT,
                pmf: 0.0,
            },
            |s| GuidingLightSample {
                light: s.light.index(g.emitters),
                pmf: s.pmf,
            },
        );
        // SAFETY: checked non-null, writable by the caller's promise.
        unsafe { put(out, s, "out") }
    })
}

/// The probability that `guiding_glt_sample` at `ctx` chooses `light`
/// (for MIS with a BSDF sample that hit it), in `out`.
///
/// # Safety
/// `glt` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_pmf(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    light: u32,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (g, ctx) = unsafe { (get(glt, "glt")?, get(ctx, "ctx")?.to_rust()?) };
        let light = g.light(light)?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let pmf = g.read()?.vertex(&ctx).map_or(0.0, |v| v.pmf(light));
        // SAFETY: checked non-null, writable by the caller's promise.
        unsafe { put(out, pmf, "out") }
    })
}

/// `guiding_glt_sample` for `count` shading points at once: `ctx[i]` with
/// `u[i]` into `out[i]` (a wavefront renderer's batch; the guide's lock is
/// taken once for the batch). Every input is checked before anything is
/// written: on failure `out` is untouched and the message names the first
/// bad element.
///
/// # Safety
/// `glt` a live handle; `ctx`, `u` `count` readable elements each; `out`
/// `count` writable elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_sample_batch(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    u: *const f32,
    count: usize,
    out: *mut GuidingLightSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (g, ctx, u) = unsafe {
            (
                get(glt, "glt")?,
                slice(ctx, count, "ctx")?,
                slice(u, count, "u")?,
            )
        };
        if count > 0 && out.is_null() {
            return Err(Failure::null("out"));
        }
        let contexts = ctx
            .iter()
            .zip(u)
            .enumerate()
            .map(|(i, (c, &u))| {
                let c = c
                    .to_rust()
                    .map_err(|f| Failure::invalid(format!("ctx[{i}]: {}", f.message)))?;
                if !(0.0..1.0).contains(&u) {
                    return Err(Failure::invalid(format!("u[{i}] = {u} is not in [0, 1)")));
                }
                Ok((c, u))
            })
            .collect::<Result<Vec<_>, Failure>>()?;
        let guide = g.read()?;
        for (i, (c, u)) in contexts.iter().enumerate() {
            let s = guide.vertex(c).and_then(|v| v.sample(*u)).map_or(
                GuidingLightSample {
                    light: GUIDING_NO_LIGHT,
                    pmf: 0.0,
                },
                |s| GuidingLightSample {
                    light: s.light.index(g.emitters),
                    pmf: s.pmf,
                },
            );
            // SAFETY: `out` holds `count` writable elements (the caller's promise), i < count.
            unsafe { out.add(i).write(s) };
        }
        Ok(())
    })
}

/// `guiding_glt_pmf` for `count` shading points at once: the pmf of
/// `light[i]` at `ctx[i]` into `out[i]` (the lock taken once). Every input
/// is checked before anything is written.
///
/// # Safety
/// `glt` a live handle; `ctx`, `light` `count` readable elements each;
/// `out` `count` writable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_pmf_batch(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    light: *const u32,
    count: usize,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (g, ctx, light) = unsafe {
            (
                get(glt, "glt")?,
                slice(ctx, count, "ctx")?,
                slice(light, count, "light")?,
            )
        };
        if count > 0 && out.is_null() {
            return Err(Failure::null("out"));
        }
        let queries = ctx
            .iter()
            .zip(light)
            .enumerate()
            .map(|(i, (c, &l))| {
                let c = c
                    .to_rust()
                    .map_err(|f| Failure::invalid(format!("ctx[{i}]: {}", f.message)))?;
                let l = g
                    .light(l)
                    .map_err(|f| Failure::invalid(format!("light[{i}]: {}", f.message)))?;
                Ok((c, l))
            })
            .collect::<Result<Vec<_>, Failure>>()?;
        let guide = g.read()?;
        for (i, (c, l)) in queries.iter().enumerate() {
            let p = guide.vertex(c).map_or(0.0, |v| v.pmf(*l));
            // SAFETY: `out` holds `count` writable floats (the caller's promise), i < count.
            unsafe { out.add(i).write(p) };
        }
        Ok(())
    })
}

/// Records a light sample's estimate at `ctx`: `value` is what the sample
/// of `light` contributed, MIS-weighted and divided by its pdf, without the
/// BSDF and the cosine (from NEE `Le * T * w_mis / (pmf *
/// pdf_solid_angle)`, 0 when occluded; from a BSDF sample that hit the
/// emitter `Le * w_mis / pdf_direction`), one scalar such as luminance,
/// finite and >= 0. What the
/// record did goes to `outcome` (null allowed). A NaN, infinite or
/// negative `value` is `GUIDING_STATUS_INVALID_ARGUMENT`, and the guide
/// counts it among its dropped records.
///
/// # Safety
/// `glt` a live handle; `ctx` readable; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_record_light(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    light: u32,
    value: f32,
    outcome: *mut GuidingRecordOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (g, ctx) = unsafe { (get(glt, "glt")?, get(ctx, "ctx")?.to_rust()?) };
        let light = g.light(light)?;
        let guide = g.read()?;
        let Some(v) = guide.vertex(&ctx) else {
            return Err(Failure::invalid("ctx.position is not finite"));
        };
        let o = GuidingRecordOutcome::from(v.record_light(light, value));
        if !outcome.is_null() {
            // SAFETY: non-null, writable by the caller's promise.
            unsafe { put(outcome, o, "outcome") }?;
        }
        if o == GuidingRecordOutcome::Dropped {
            return Err(Failure::invalid(format!(
                "record_light: value = {value} for light {} was dropped (must be finite and >= 0, the light must have power)",
                light.index(g.emitters)
            )));
        }
        Ok(())
    })
}

/// What `guiding_glt_refine` did to the spatial tree.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct GuidingRefineOutcome {
    /// Cells split.
    pub splits: usize,
    /// Splits refused because the memory budget was reached.
    pub refused_by_budget: usize,
    /// Splits refused because a cell is too small to halve in `float`.
    pub refused_by_precision: usize,
}

/// Ends an iteration: refines the cuts from their records and splits
/// cells. Waits for running queries on `glt`, and they for it. `outcome`
/// may be null.
///
/// # Safety
/// `glt` a live handle; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_refine(
    glt: *const GuidingGlt,
    outcome: *mut GuidingRefineOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let g = unsafe { get(glt, "glt") }?;
        let r = g.write()?.refine();
        if !outcome.is_null() {
            let o = GuidingRefineOutcome {
                splits: r.splits,
                refused_by_budget: r.refused_by_budget,
                refused_by_precision: r.refused_by_precision,
            };
            // SAFETY: non-null, writable by the caller's promise.
            unsafe { put(outcome, o, "outcome") }?;
        }
        Ok(())
    })
}

/// Forgets this iteration's records (what a farm's worker does after
/// loading the coordinator's guide), keeping what was learned.
///
/// # Safety
/// `glt` a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_clear_records(glt: *const GuidingGlt) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(glt, "glt") }?.write()?.clear_records();
        Ok(())
    })
}

/// Adds `other`'s records into `glt` (a farm: both copies of one guide
/// after the same refinements); `GUIDING_STATUS_INCOMPATIBLE` otherwise,
/// with `glt` unchanged.
///
/// # Safety
/// `glt`, `other` live handles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_merge(
    glt: *const GuidingGlt,
    other: *const GuidingGlt,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (g, o) = unsafe { (get(glt, "glt")?, get(other, "other")?) };
        if std::ptr::eq(g, o) {
            return Err(Failure::invalid("merge: glt and other are the same handle"));
        }
        let theirs = o.read()?;
        if g.write()?.merge(&theirs) {
            Ok(())
        } else {
            Err(Failure::new(
                GuidingStatus::Incompatible,
                "merge: the guides are not copies of one guide after the same refinements",
            ))
        }
    })
}

/// The refinements so far (0 for null).
///
/// # Safety
/// `glt` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_iteration(glt: *const GuidingGlt) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(glt, "glt") }
        .ok()
        .and_then(|g| g.read().ok().map(|g| g.iteration()))
        .unwrap_or(0)
}

/// The records dropped as bad input so far, every reason together (0 for
/// null).
///
/// # Safety
/// `glt` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_dropped_records(glt: *const GuidingGlt) -> u64 {
    // SAFETY: forwarded.
    unsafe { get(glt, "glt") }
        .ok()
        .and_then(|g| g.read().ok().map(|g| g.dropped_records().total()))
        .unwrap_or(0)
}

/// What `glt` learned, as bytes (`guiding_glt_load` reads them back over
/// the same light tree), into `out` (free it with `guiding_buffer_free`).
///
/// # Safety
/// `glt` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_save(
    glt: *const GuidingGlt,
    out: *mut GuidingBuffer,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let g = unsafe { get(glt, "glt") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let bytes = g.read()?.to_bytes();
        // SAFETY: checked non-null, writable by the caller's promise.
        unsafe { put(out, GuidingBuffer::from_vec(bytes), "out") }
    })
}

/// A GLT saved by `guiding_glt_save`, over `tree` (the light tree it was
/// saved over), from `len` bytes at `data`; `GUIDING_STATUS_LOAD_FAILED`
/// for bytes that are not one or another tree.
///
/// # Safety
/// `tree` a live handle; `data` `len` readable bytes; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_load(
    tree: *const GuidingLightTree,
    data: *const u8,
    len: usize,
    out: *mut *mut GuidingGlt,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (t, bytes) = unsafe { (get(tree, "tree")?, slice(data, len, "data")?) };
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let glt = guiding::Glt::from_bytes(bytes, Arc::clone(&t.tree))
            .map_err(|e| Failure::new(GuidingStatus::LoadFailed, e.to_string()))?;
        hand_out(glt, out)
    })
}
