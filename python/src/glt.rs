//! `Glt`: the Guiding Light Tree, numpy-batched.

use crate::arrays::{Range, float_rows};
use crate::config::{Kwargs, glt_config};
use crate::error::value_error;
use crate::guide_class::guide_class;
use crate::light_ops::LightSamples;
use crate::light_ops::{self, LightCount};
use crate::lights::LightTree;
use crate::state::State;
use guiding::Aabb;
use guiding::glam::Vec3;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

type Inner = guiding::Glt<Arc<guiding::LightTree>>;

/// The Guiding Light Tree over a light tree, learning per region of the
/// scene's `bounds` which emitters matter. Every query takes a batch of
/// shading points; sampling and recording may run from many threads at
/// once.
#[pyclass(module = "guiding._guiding", frozen)]
pub struct Glt {
    state: State<Inner>,
    count: LightCount,
}

/// Scene bounds from `(lower, upper)` (a (2, 3) array-like).
pub fn bounds(obj: &Bound<'_, PyAny>) -> PyResult<Aabb> {
    let b = float_rows::<3>(obj, "bounds", Some(2), Range::Finite)?;
    Ok(Aabb::new(Vec3::from(b[0]), Vec3::from(b[1])))
}

impl Glt {
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

guide_class!(Glt, {
    /// A GLT over `tree` for shading points in `bounds` ((lower, upper)
    /// corners; points outside are clamped onto it). Keywords, each the
    /// crate's default when left out: `sigma`, `alpha`, `min_records`,
    /// `visibility`, `unbounded_lights`, `unbounded_probability`,
    /// `deterministic`, `spatial_threshold`, `max_bytes`, `light_filter`.
    #[new]
    #[pyo3(signature = (tree, bounds, **config))]
    fn new(
        tree: &LightTree,
        bounds: &Bound<'_, PyAny>,
        config: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut kw = Kwargs::new(config, "Glt");
        let config = glt_config(&mut kw)?;
        kw.finish()?;
        let inner =
            Inner::new(tree.tree.clone(), self::bounds(bounds)?, config).map_err(value_error)?;
        Ok(Self::from_inner(inner))
    }

    /// A guide saved by `to_bytes`, over `tree` (the one it learned over;
    /// another is refused). `ValueError` for bytes that are not such a
    /// guide.
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

    /// One light per shading point from `u` (n,) in [0, 1): `(lights,
    /// pmfs)`, int64 light indices (emitters first, then unbounded lights;
    /// -1 where no light can be chosen) and float32 pmfs, each exactly
    /// `pmf` of its light. `normals` (n, 3), where given, put the points
    /// on surfaces (a zero normal: none).
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

    /// The probability that `sample` chooses `lights[i]` at point `i`:
    /// float32 (n,). The MIS weight of a BSDF sample that hit an emitter
    /// needs it.
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

    /// Records what next-event estimation found: `values[i]` is the
    /// contribution of `lights[i]` at point `i` (0 when it was occluded)
    /// over its pmf, one scalar (e.g. luminance). Returns how many records
    /// were taken.
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

    /// The number of lights (emitters, then unbounded lights).
    #[getter]
    fn light_count(&self) -> u32 {
        self.count.total()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let it = self.state.read(py, |g| g.iteration())?;
        Ok(format!(
            "Glt({} lights, iteration {it})",
            self.count.total()
        ))
    }
});
