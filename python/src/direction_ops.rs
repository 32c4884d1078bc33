//! The batched directional guiding, shared by `SdTree` and
//! `GuidingField`: direction samples, their pdfs, the BSDF fraction and
//! radiance records over a batch of points, each point's vertex found once
//! (`guide.vertex(&ctx)`, then `sample_direction(u)`, `direction_pdf(dir)`,
//! `record_radiance(dir, radiance, pdf)`).

use crate::arrays::{Range, float_rows, floats};
use crate::batch::{Points, map};
use crate::light_ops::points;
use crate::state::State;
use guiding::glam::Vec3;
use guiding::{DirectionVertex, GuidingField, LightTree, RecordOutcome, SdTree, ShadingContext};
use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::Arc;

/// What a batched direction sample returns: directions (n, 3) and their
/// solid-angle pdfs.
pub type DirectionSamples<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray1<f32>>);

/// A guide that samples directions: its vertex at a point.
pub trait DirectionGuide: Sync {
    /// The direction vertex at `ctx`; `None` only for a non-finite
    /// position (refused before asking).
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

/// Pairs of random numbers (n, 2) in [0, 1).
pub fn unit_pairs(u: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<[f32; 2]>> {
    float_rows::<2>(u, "u", Some(n), Range::Unit)
}

/// Directions (n, 3): finite and not zero (any length).
pub fn directions(dirs: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<[f32; 3]>> {
    let d = float_rows::<3>(dirs, "directions", Some(n), Range::Finite)?;
    if let Some(i) = d.iter().position(|d| Vec3::from(*d) == Vec3::ZERO) {
        return Err(PyValueError::new_err(format!("directions[{i}] is zero")));
    }
    Ok(d)
}

/// One direction per point from `u[i]`: unit directions (n, 3) as a flat
/// row-major vector, and their solid-angle pdfs (n,).
pub fn sample_direction<G: DirectionGuide>(
    guide: &G,
    at: &Points,
    u: &[[f32; 2]],
) -> (Vec<f32>, Vec<f32>) {
    let samples = map(at.len(), |i| {
        guide
            .direction_vertex(&at.context(i))
            .map_or(([0.0; 3], 0.0), |v| {
                let (d, pdf) = v.sample_direction(u[i]);
                (d.to_array(), pdf)
            })
    });
    let mut dirs = Vec::with_capacity(3 * samples.len());
    let mut pdfs = Vec::with_capacity(samples.len());
    for (d, p) in samples {
        dirs.extend_from_slice(&d);
        pdfs.push(p);
    }
    (dirs, pdfs)
}

/// The guiding distribution's solid-angle pdf of `dirs[i]` at point `i`.
pub fn direction_pdf<G: DirectionGuide>(guide: &G, at: &Points, dirs: &[[f32; 3]]) -> Vec<f32> {
    map(at.len(), |i| {
        guide
            .direction_vertex(&at.context(i))
            .map_or(0.0, |v| v.direction_pdf(Vec3::from(dirs[i])))
    })
}

/// The BSDF sampling fraction at each point.
pub fn bsdf_fraction<G: DirectionGuide>(guide: &G, at: &Points) -> Vec<f32> {
    map(at.len(), |i| {
        guide
            .direction_vertex(&at.context(i))
            .map_or(0.0, |v| v.bsdf_fraction())
    })
}

/// PPG's records: `radiance[i]` arrived along `dirs[i]` at point `i`,
/// sampled with solid-angle pdf `pdfs[i]`. Returns how many were taken.
pub fn record_radiance<G: DirectionGuide>(
    guide: &G,
    at: &Points,
    dirs: &[[f32; 3]],
    radiance: &[f32],
    pdfs: &[f32],
) -> usize {
    map(at.len(), |i| {
        guide.direction_vertex(&at.context(i)).is_some_and(|v| {
            matches!(
                v.record_radiance(Vec3::from(dirs[i]), radiance[i], pdfs[i]),
                RecordOutcome::Recorded | RecordOutcome::Zero
            )
        })
    })
    .into_iter()
    .filter(|&taken| taken)
    .count()
}

/// Radiance (n,), finite and >= 0, and pdfs (n,), finite and > 0.
pub fn radiance_and_pdfs(
    radiance: &Bound<'_, PyAny>,
    pdfs: &Bound<'_, PyAny>,
    n: usize,
) -> PyResult<(Vec<f32>, Vec<f32>)> {
    let r = floats(radiance, "radiance", Some(n), Range::NonNegative)?;
    let p = floats(pdfs, "pdfs", Some(n), Range::NonNegative)?;
    if let Some(i) = p.iter().position(|&p| p == 0.0) {
        return Err(PyValueError::new_err(format!(
            "pdfs[{i}] = 0: a sampled direction has a positive pdf"
        )));
    }
    Ok((r, p))
}

/// `sample_direction` as the classes expose it: `(directions (n, 3),
/// pdfs (n,))`, float32.
pub fn py_sample_direction<'py, G: DirectionGuide + Send>(
    py: Python<'py>,
    state: &State<G>,
    positions: &Bound<'py, PyAny>,
    u: &Bound<'py, PyAny>,
) -> PyResult<DirectionSamples<'py>> {
    let at = points(positions, None)?;
    let u = unit_pairs(u, at.len())?;
    let (dirs, pdfs) = state.read(py, |g| sample_direction(g, &at, &u))?;
    let dirs = Array2::from_shape_vec((at.len(), 3), dirs).expect("three floats per point");
    Ok((
        PyArray2::from_owned_array(py, dirs),
        PyArray1::from_vec(py, pdfs),
    ))
}

/// `direction_pdf` as the classes expose it.
pub fn py_direction_pdf<'py, G: DirectionGuide + Send>(
    py: Python<'py>,
    state: &State<G>,
    positions: &Bound<'py, PyAny>,
    directions: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f32>>> {
    let at = points(positions, None)?;
    let dirs = self::directions(directions, at.len())?;
    let pdfs = state.read(py, |g| direction_pdf(g, &at, &dirs))?;
    Ok(PyArray1::from_vec(py, pdfs))
}

/// `bsdf_fraction` as the classes expose it.
pub fn py_bsdf_fraction<'py, G: DirectionGuide + Send>(
    py: Python<'py>,
    state: &State<G>,
    positions: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f32>>> {
    let at = points(positions, None)?;
    let s = state.read(py, |g| bsdf_fraction(g, &at))?;
    Ok(PyArray1::from_vec(py, s))
}

/// `record_radiance` as the classes expose it.
pub fn py_record_radiance<G: DirectionGuide + Send>(
    py: Python<'_>,
    state: &State<G>,
    positions: &Bound<'_, PyAny>,
    directions: &Bound<'_, PyAny>,
    radiance: &Bound<'_, PyAny>,
    pdfs: &Bound<'_, PyAny>,
) -> PyResult<usize> {
    let at = points(positions, None)?;
    let dirs = self::directions(directions, at.len())?;
    let (radiance, pdfs) = radiance_and_pdfs(radiance, pdfs, at.len())?;
    state.read(py, |g| record_radiance(g, &at, &dirs, &radiance, &pdfs))
}
