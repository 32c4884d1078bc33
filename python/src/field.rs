//! `GuidingField`: the SD-tree and the GLT in one spatial tree (one lookup
//! per vertex serves directions and lights), numpy-batched.

use crate::config::{Kwargs, field_config};
use crate::direction_ops::{self, DirectionSamples};
use crate::error::value_error;
use crate::glt::bounds;
use crate::guide_class::guide_class;
use crate::light_ops::LightSamples;
use crate::light_ops::{self, LightCount};
use crate::lights::LightTree;
use crate::state::State;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

type Inner = guiding::GuidingField<Arc<guiding::LightTree>>;

/// The combined field: every cell holds PPG's directional quadtree and a
/// guiding cut over `tree`, so `ppg-glt`'s two guides cost one lookup.
/// It has both the SD-tree's methods (`sample_direction`, ...) and the
/// GLT's (`sample`, `pmf`, `record_light`).
#[pyclass(module = "guiding._guiding", frozen)]
pub struct GuidingField {
    state: State<Inner>,
    count: LightCount,
}

impl GuidingField {
    fn from_inner(inner: Inner) -> Self {
        let count = LightCount::of(inner.light_tree(), inner.config().cut.unbounded);
        Self {
            state: State::new(inner),
            count,
        }
    }

    fn with_state(&self, state: State<Inner>) -> Self {
        Self {
            state,
            count: self.count,
        }
    }
}

guide_class!(GuidingField, {
    /// A field over `tree` for points in `bounds`. Keywords: the
    /// SD-tree's (`improved`, `spatial_threshold`, which drives every
    /// split, `max_bytes`, `rho`, `max_depth`, `spatial_filter`,
    /// `directional_filter`, `bsdf_fraction`, `learn_bsdf_fraction`,
    /// `fraction_steps`), the cuts' (`sigma`, `alpha`, `min_records`,
    /// `visibility`, `unbounded_lights`, `unbounded_probability`),
    /// `light_filter` and `deterministic` (both halves).
    #[new]
    #[pyo3(signature = (tree, bounds, **config))]
    fn new(
        tree: &LightTree,
        bounds: &Bound<'_, PyAny>,
        config: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut kw = Kwargs::new(config, "GuidingField");
        let config = field_config(&mut kw)?;
        kw.finish()?;
        let inner =
            Inner::new(tree.tree.clone(), self::bounds(bounds)?, config).map_err(value_error)?;
        Ok(Self::from_inner(inner))
    }

    /// A field saved by `to_bytes`, over `tree` (the one it learned over).
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8], tree: &LightTree) -> PyResult<Self> {
        let t = tree.tree.clone();
        let inner = py
            .detach(|| Inner::from_bytes(data, t))
            .map_err(value_error)?;
        Ok(Self::from_inner(inner))
    }

    /// The cell holding each position (n, 3): int64 (n,).
    fn lookup<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let at = light_ops::points(positions, None)?;
        let cells = self.state.read(py, |g| light_ops::lookup(g, &at))?;
        Ok(PyArray1::from_vec(py, cells))
    }

    /// As `Glt.sample`.
    #[pyo3(signature = (positions, u, normals = None))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
        normals: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<LightSamples<'py>> {
        light_ops::py_sample(py, &self.state, self.count, positions, u, normals)
    }

    /// As `Glt.pmf`.
    #[pyo3(signature = (positions, lights, normals = None))]
    fn pmf<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        lights: &Bound<'py, PyAny>,
        normals: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        light_ops::py_pmf(py, &self.state, self.count, positions, lights, normals)
    }

    /// As `Glt.record_light`.
    #[pyo3(signature = (positions, lights, values, normals = None))]
    fn record_light(
        &self,
        py: Python<'_>,
        positions: &Bound<'_, PyAny>,
        lights: &Bound<'_, PyAny>,
        values: &Bound<'_, PyAny>,
        normals: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<usize> {
        light_ops::py_record_light(
            py,
            &self.state,
            self.count,
            positions,
            lights,
            values,
            normals,
        )
    }

    /// As `SdTree.sample_direction`.
    fn sample_direction<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<DirectionSamples<'py>> {
        direction_ops::py_sample_direction(py, &self.state, positions, u)
    }

    /// As `SdTree.direction_pdf`.
    fn direction_pdf<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        direction_ops::py_direction_pdf(py, &self.state, positions, directions)
    }

    /// As `SdTree.bsdf_fraction`.
    fn bsdf_fraction<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        direction_ops::py_bsdf_fraction(py, &self.state, positions)
    }

    /// As `SdTree.record_radiance`.
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

    /// The number of lights (emitters, then unbounded lights).
    #[getter]
    fn light_count(&self) -> u32 {
        self.count.total()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let (cells, it) = self.state.read(py, |g| (g.cell_count(), g.iteration()))?;
        Ok(format!(
            "GuidingField({} lights, {cells} cells, iteration {it})",
            self.count.total()
        ))
    }
});
