//! The batched light choice, shared by `Glt` and `GuidingField`: lookup,
//! sample, pmf and record over a batch of shading points, each point's
//! vertex found once and queried as the Rust front does
//! (`guide.vertex(&ctx)`, then `sample(u)`, `pmf(light)`,
//! `record_light(light, value)`).

use crate::arrays::{Range, float_rows, floats, light_indices};
use crate::batch::{Points, map};
use crate::state::State;
use guiding::glam::Vec3;
use guiding::{
    GuidingField, LightChoice, LightId, LightTree, LightVertex, RecordOutcome, ShadingContext,
};
use numpy::PyArray1;
use pyo3::prelude::*;
use std::sync::Arc;

/// What a batched light sample returns: light indices and their pmfs.
pub type LightSamples<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f32>>);

/// A guide that chooses lights: its vertex at a shading point.
pub trait LightGuide: Sync {
    /// The light vertex at `ctx`; `None` only for a non-finite position
    /// (which the bindings refuse before asking).
    fn light_vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, Arc<LightTree>>>;
    /// The cell holding `p`.
    fn cell(&self, p: Vec3) -> Option<u32>;
}

impl LightGuide for guiding::Glt<Arc<LightTree>> {
    fn light_vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, Arc<LightTree>>> {
        self.vertex(ctx)
    }
    fn cell(&self, p: Vec3) -> Option<u32> {
        self.locate(p).map(|c| c.0)
    }
}

impl LightGuide for GuidingField<Arc<LightTree>> {
    fn light_vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, Arc<LightTree>>> {
        self.vertex(ctx).map(|v| v.light)
    }
    fn cell(&self, p: Vec3) -> Option<u32> {
        self.locate(p).map(|c| c.0)
    }
}

/// How many lights a guide chooses among: its emitters, then its unbounded
/// lights, in one list of indices.
#[derive(Clone, Copy)]
pub struct LightCount {
    pub emitters: u32,
    pub unbounded: u32,
}

impl LightCount {
    pub fn of(tree: &guiding::LightTree, unbounded: guiding::UnboundedLights) -> Self {
        Self {
            emitters: guiding::LightHierarchy::emitter_count(tree) as u32,
            unbounded: unbounded.count,
        }
    }
    pub fn total(self) -> u32 {
        self.emitters + self.unbounded
    }
    pub fn id(self, index: u32) -> LightId {
        LightId::from_index(index, self.emitters)
    }
    pub fn index(self, light: LightId) -> i64 {
        i64::from(light.index(self.emitters))
    }
}

/// Positions (n, 3) and optional normals (n, 3), checked.
pub fn points(
    positions: &Bound<'_, PyAny>,
    normals: Option<&Bound<'_, PyAny>>,
) -> PyResult<Points> {
    let positions = float_rows::<3>(positions, "positions", None, Range::Finite)?;
    let normals = normals
        .map(|n| float_rows::<3>(n, "normals", Some(positions.len()), Range::Finite))
        .transpose()?;
    Ok(Points { positions, normals })
}

/// The cell of every position.
pub fn lookup<G: LightGuide>(guide: &G, at: &Points) -> Vec<i64> {
    map(at.len(), |i| {
        guide
            .cell(Vec3::from(at.positions[i]))
            .map_or(-1, i64::from)
    })
}

/// Random numbers (n,) in [0, 1).
pub fn unit_numbers(u: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<f32>> {
    floats(u, "u", Some(n), Range::Unit)
}

/// Light indices (n,) below the guide's count.
pub fn lights(lights: &Bound<'_, PyAny>, n: usize, count: LightCount) -> PyResult<Vec<u32>> {
    light_indices(lights, "lights", Some(n), count.total())
}

/// One sample per point: the chosen light's index (-1 where none can be
/// chosen) and its pmf (0 there).
pub fn sample<G: LightGuide>(
    guide: &G,
    count: LightCount,
    at: &Points,
    u: &[f32],
) -> (Vec<i64>, Vec<f32>) {
    map(at.len(), |i| {
        guide
            .light_vertex(&at.context(i))
            .and_then(|v| v.sample(u[i]))
            .map_or((-1, 0.0), |s| (count.index(s.light), s.pmf))
    })
    .into_iter()
    .unzip()
}

/// The pmf of `lights[i]` at point `i`.
pub fn pmf<G: LightGuide>(guide: &G, count: LightCount, at: &Points, lights: &[u32]) -> Vec<f32> {
    map(at.len(), |i| {
        guide
            .light_vertex(&at.context(i))
            .map_or(0.0, |v| v.pmf(count.id(lights[i])))
    })
}

/// Records `values[i]` (the NEE estimate `contribution / pmf`, one scalar)
/// for `lights[i]` at point `i`; returns how many were taken (zeros
/// included: a zero is an observation).
pub fn record_light<G: LightGuide>(
    guide: &G,
    count: LightCount,
    at: &Points,
    lights: &[u32],
    values: &[f32],
) -> usize {
    map(at.len(), |i| {
        guide.light_vertex(&at.context(i)).is_some_and(|v| {
            matches!(
                v.record_light(count.id(lights[i]), values[i]),
                RecordOutcome::Recorded | RecordOutcome::Zero
            )
        })
    })
    .into_iter()
    .filter(|&taken| taken)
    .count()
}

/// Values (n,) to record: finite and >= 0.
pub fn values(values: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<f32>> {
    floats(values, "values", Some(n), Range::NonNegative)
}

/// `sample` as the classes expose it: read, run with the GIL released,
/// return numpy arrays.
pub fn py_sample<'py, G: LightGuide + Send>(
    py: Python<'py>,
    state: &State<G>,
    count: LightCount,
    positions: &Bound<'py, PyAny>,
    u: &Bound<'py, PyAny>,
    normals: Option<&Bound<'py, PyAny>>,
) -> PyResult<LightSamples<'py>> {
    let at = points(positions, normals)?;
    let u = unit_numbers(u, at.len())?;
    let (lights, pmfs) = state.read(py, |g| sample(g, count, &at, &u))?;
    Ok((PyArray1::from_vec(py, lights), PyArray1::from_vec(py, pmfs)))
}

/// `pmf` as the classes expose it.
pub fn py_pmf<'py, G: LightGuide + Send>(
    py: Python<'py>,
    state: &State<G>,
    count: LightCount,
    positions: &Bound<'py, PyAny>,
    lights: &Bound<'py, PyAny>,
    normals: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f32>>> {
    let at = points(positions, normals)?;
    let lights = self::lights(lights, at.len(), count)?;
    let pmfs = state.read(py, |g| pmf(g, count, &at, &lights))?;
    Ok(PyArray1::from_vec(py, pmfs))
}

/// `record_light` as the classes expose it.
pub fn py_record_light<G: LightGuide + Send>(
    py: Python<'_>,
    state: &State<G>,
    count: LightCount,
    positions: &Bound<'_, PyAny>,
    lights: &Bound<'_, PyAny>,
    values: &Bound<'_, PyAny>,
    normals: Option<&Bound<'_, PyAny>>,
) -> PyResult<usize> {
    let at = points(positions, normals)?;
    let lights = self::lights(lights, at.len(), count)?;
    let values = self::values(values, at.len())?;
    state.read(py, |g| record_light(g, count, &at, &lights, &values))
}
