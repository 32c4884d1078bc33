//! `SdTree`: Practical Path Guiding's SD-tree, numpy-batched.

use crate::config::{Kwargs, sd_tree_config};
use crate::direction_ops::{self, DirectionSamples};
use crate::error::value_error;
use crate::glt::bounds;
use crate::guide_class::guide_class;
use crate::light_ops;
use crate::state::State;
use guiding::ShadingContext;
use guiding::glam::Vec3;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Practical Path Guiding's SD-tree: a spatial binary tree over the
/// scene's `bounds` whose cells learn the incident radiance's directions
/// in quadtrees. Batched like every guide; sampling and recording may run
/// from many threads at once.
#[pyclass(module = "guiding._guiding", frozen)]
pub struct SdTree {
    state: State<guiding::SdTree>,
}

impl SdTree {
    fn with_state(&self, state: State<guiding::SdTree>) -> Self {
        Self { state }
    }
}

guide_class!(SdTree, {
    /// An SD-tree over `bounds` ((lower, upper) corners). Keywords, each
    /// the crate's default (PPG's paper setup) when left out: `improved`
    /// (start from the later recommendations instead), `spatial_threshold`,
    /// `max_bytes`, `rho`, `max_depth`, `spatial_filter`,
    /// `directional_filter`, `bsdf_fraction`, `learn_bsdf_fraction`,
    /// `fraction_steps`, `deterministic`.
    #[new]
    #[pyo3(signature = (bounds, **config))]
    fn new(bounds: &Bound<'_, PyAny>, config: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut kw = Kwargs::new(config, "SdTree");
        let config = sd_tree_config(&mut kw)?;
        kw.finish()?;
        let inner = guiding::SdTree::new(self::bounds(bounds)?, config).map_err(value_error)?;
        Ok(Self {
            state: State::new(inner),
        })
    }

    /// An SD-tree saved by `to_bytes`; `ValueError` for bytes that are
    /// not one.
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let inner = py
            .detach(|| guiding::SdTree::from_bytes(data))
            .map_err(value_error)?;
        Ok(Self {
            state: State::new(inner),
        })
    }

    /// The cell holding each position (n, 3): int64 (n,).
    fn lookup<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let at = light_ops::points(positions, None)?;
        let cells = self.state.read(py, |g| {
            crate::batch::map(at.len(), |i| {
                let ctx = ShadingContext::at(Vec3::from(at.positions[i]));
                g.vertex(&ctx).map_or(-1, |v| i64::from(v.cell().0))
            })
        })?;
        Ok(PyArray1::from_vec(py, cells))
    }

    /// One guided direction per point from `u` (n, 2) in [0, 1):
    /// `(directions, pdfs)`, unit float32 (n, 3) and their solid-angle
    /// pdfs (n,), each exactly `direction_pdf` of its direction.
    fn sample_direction<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<DirectionSamples<'py>> {
        direction_ops::py_sample_direction(py, &self.state, positions, u)
    }

    /// The guiding distribution's solid-angle pdf of `directions[i]` (any
    /// length but 0) at point `i`.
    fn direction_pdf<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        direction_ops::py_direction_pdf(py, &self.state, positions, directions)
    }

    /// The probability of sampling the BSDF rather than the guiding
    /// distribution at each point.
    fn bsdf_fraction<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        direction_ops::py_bsdf_fraction(py, &self.state, positions)
    }

    /// PPG's records: `radiance[i]` (one scalar, e.g. luminance) arrived
    /// along `directions[i]` at point `i`, sampled with solid-angle pdf
    /// `pdfs[i]` (the mixture's). Returns how many were taken.
    fn record_radiance(
        &self,
        py: Python<'_>,
        positions: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        radiance: &Bound<'_, PyAny>,
        pdfs: &Bound<'_, PyAny>,
    ) -> PyResult<usize> {
        direction_ops::py_record_radiance(py, &self.state, positions, directions, radiance, pdfs)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let (cells, it) = self.state.read(py, |g| (g.cell_count(), g.iteration()))?;
        Ok(format!("SdTree({cells} cells, iteration {it})"))
    }
});
