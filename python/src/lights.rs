//! `Emitters` (a scene's emitters, added in batches of one kind) and
//! `LightTree` (the global light tree over them, shared by the guides).

use crate::arrays::{Range, float_rows, floats};
use crate::error::value_error;
use guiding::glam::Vec3;
use guiding::{BuildHeuristic, Emitter};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::sync::Arc;

/// A scene's emitters, in the order their light indices count: each
/// `add_*` call appends a batch of one kind from arrays with one row per
/// emitter and returns the index of the first. Powers are the emitters'
/// flux (any unit, the same for all): finite and >= 0.
#[pyclass(module = "guiding._guiding")]
#[derive(Default)]
pub struct Emitters {
    pub list: Vec<Emitter>,
}

impl Emitters {
    fn push(&mut self, batch: impl Iterator<Item = Emitter>) -> PyResult<usize> {
        let first = self.list.len();
        self.list.extend(batch);
        if self.list.len() > u32::MAX as usize - 1 {
            self.list.truncate(first);
            return Err(PyValueError::new_err("more than 2^32 - 2 emitters"));
        }
        Ok(first)
    }
}

fn v(a: [f32; 3]) -> Vec3 {
    Vec3::from(a)
}

#[pymethods]
impl Emitters {
    /// An empty list.
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// The number of emitters.
    fn __len__(&self) -> usize {
        self.list.len()
    }

    fn __repr__(&self) -> String {
        format!("Emitters({} emitters)", self.list.len())
    }

    /// Isotropic point lights: `positions` (n, 3), `powers` (n,).
    fn add_points(
        &mut self,
        positions: &Bound<'_, PyAny>,
        powers: &Bound<'_, PyAny>,
    ) -> PyResult<usize> {
        let p = float_rows::<3>(positions, "positions", None, Range::Finite)?;
        let w = floats(powers, "powers", Some(p.len()), Range::NonNegative)?;
        self.push(p.into_iter().zip(w).map(|(p, w)| Emitter::point(v(p), w)))
    }

    /// Spherical emitters: `centers` (n, 3), `radii` (n,), `powers` (n,).
    fn add_spheres(
        &mut self,
        centers: &Bound<'_, PyAny>,
        radii: &Bound<'_, PyAny>,
        powers: &Bound<'_, PyAny>,
    ) -> PyResult<usize> {
        let c = float_rows::<3>(centers, "centers", None, Range::Finite)?;
        let r = floats(radii, "radii", Some(c.len()), Range::NonNegative)?;
        let w = floats(powers, "powers", Some(c.len()), Range::NonNegative)?;
        self.push((0..c.len()).map(|i| Emitter::sphere(v(c[i]), r[i], w[i])))
    }

    /// Spot lights (pbrt's): `positions` (n, 3), `directions` (n, 3) they
    /// shine along, full intensity within the angle whose cosine is
    /// `cos_falloff_start` (n,), dark beyond `cos_falloff_end` (n,),
    /// `powers` (n,).
    fn add_spots(
        &mut self,
        positions: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        cos_falloff_start: &Bound<'_, PyAny>,
        cos_falloff_end: &Bound<'_, PyAny>,
        powers: &Bound<'_, PyAny>,
    ) -> PyResult<usize> {
        let p = float_rows::<3>(positions, "positions", None, Range::Finite)?;
        let n = Some(p.len());
        let d = float_rows::<3>(directions, "directions", n, Range::Finite)?;
        let start = floats(cos_falloff_start, "cos_falloff_start", n, Range::Finite)?;
        let end = floats(cos_falloff_end, "cos_falloff_end", n, Range::Finite)?;
        let w = floats(powers, "powers", n, Range::NonNegative)?;
        for (i, d) in d.iter().enumerate() {
            if v(*d) == Vec3::ZERO {
                return Err(PyValueError::new_err(format!("directions[{i}] is zero")));
            }
        }
        for (i, (&s, &e)) in start.iter().zip(&end).enumerate() {
            if !(-1.0..=1.0).contains(&s) || !(-1.0..=1.0).contains(&e) {
                return Err(PyValueError::new_err(format!(
                    "cos_falloff_start[{i}] = {s}, cos_falloff_end[{i}] = {e}: cosines must be in [-1, 1]"
                )));
            }
        }
        self.push((0..p.len()).map(|i| Emitter::spot(v(p[i]), v(d[i]), start[i], end[i], w[i])))
    }

    /// Lambertian triangles: `vertices` (n, 3, 3) or (n, 9), each emitting
    /// on the side of `(p1 - p0) x (p2 - p0)`, both sides when
    /// `two_sided`; `powers` (n,).
    #[pyo3(signature = (vertices, powers, two_sided = false))]
    fn add_triangles(
        &mut self,
        vertices: &Bound<'_, PyAny>,
        powers: &Bound<'_, PyAny>,
        two_sided: bool,
    ) -> PyResult<usize> {
        let flat = vertices
            .call_method1("reshape", ((-1i64, 9i64),))
            .map_err(|_| {
                PyValueError::new_err("vertices: expected an array of shape (N, 3, 3) or (N, 9)")
            });
        let t = float_rows::<9>(&flat?, "vertices", None, Range::Finite)?;
        let w = floats(powers, "powers", Some(t.len()), Range::NonNegative)?;
        self.push(t.iter().zip(w).map(|(t, w)| {
            let p = [
                Vec3::new(t[0], t[1], t[2]),
                Vec3::new(t[3], t[4], t[5]),
                Vec3::new(t[6], t[7], t[8]),
            ];
            Emitter::triangle(p, w, two_sided)
        }))
    }

    /// Lambertian parallelograms `corner + s edge_u + t edge_v`: `corners`,
    /// `edges_u`, `edges_v` (n, 3), emitting on the side of
    /// `edge_u x edge_v` (both sides when `two_sided`); `powers` (n,).
    #[pyo3(signature = (corners, edges_u, edges_v, powers, two_sided = false))]
    fn add_quads(
        &mut self,
        corners: &Bound<'_, PyAny>,
        edges_u: &Bound<'_, PyAny>,
        edges_v: &Bound<'_, PyAny>,
        powers: &Bound<'_, PyAny>,
        two_sided: bool,
    ) -> PyResult<usize> {
        let c = float_rows::<3>(corners, "corners", None, Range::Finite)?;
        let n = Some(c.len());
        let eu = float_rows::<3>(edges_u, "edges_u", n, Range::Finite)?;
        let ev = float_rows::<3>(edges_v, "edges_v", n, Range::Finite)?;
        let w = floats(powers, "powers", n, Range::NonNegative)?;
        self.push((0..c.len()).map(|i| Emitter::quad(v(c[i]), v(eu[i]), v(ev[i]), w[i], two_sided)))
    }

    /// Lambertian disks: `centers`, `normals` (n, 3), `radii` (n,),
    /// emitting on the side of the normal (both when `two_sided`);
    /// `powers` (n,).
    #[pyo3(signature = (centers, normals, radii, powers, two_sided = false))]
    fn add_disks(
        &mut self,
        centers: &Bound<'_, PyAny>,
        normals: &Bound<'_, PyAny>,
        radii: &Bound<'_, PyAny>,
        powers: &Bound<'_, PyAny>,
        two_sided: bool,
    ) -> PyResult<usize> {
        let c = float_rows::<3>(centers, "centers", None, Range::Finite)?;
        let n = Some(c.len());
        let nn = float_rows::<3>(normals, "normals", n, Range::Finite)?;
        let r = floats(radii, "radii", n, Range::NonNegative)?;
        let w = floats(powers, "powers", n, Range::NonNegative)?;
        self.push((0..c.len()).map(|i| Emitter::disk(v(c[i]), v(nn[i]), r[i], w[i], two_sided)))
    }
}

/// The global light tree over a scene's emitters (a BVH, one emitter a
/// leaf), shared by every guide built over it. Immutable.
#[pyclass(module = "guiding._guiding", frozen)]
pub struct LightTree {
    pub tree: Arc<guiding::LightTree>,
}

fn heuristic(name: &str) -> PyResult<BuildHeuristic> {
    match name {
        "balanced" => Ok(BuildHeuristic::Balanced),
        "sah" => Ok(BuildHeuristic::Sah),
        "sarh" => Ok(BuildHeuristic::Sarh),
        "saoh" => Ok(BuildHeuristic::Saoh),
        _ => Err(PyValueError::new_err(format!(
            "heuristic: '{name}' is not one of 'balanced', 'sah', 'sarh', 'saoh'"
        ))),
    }
}

#[pymethods]
impl LightTree {
    /// Builds the tree over `emitters` (the GIL released) with the split
    /// `heuristic`: 'sarh' (the default), 'sah', 'saoh' or 'balanced'.
    #[new]
    #[pyo3(signature = (emitters, heuristic = "sarh"))]
    fn new(py: Python<'_>, emitters: &Emitters, heuristic: &str) -> PyResult<Self> {
        let h = self::heuristic(heuristic)?;
        let list = emitters.list.as_slice();
        let tree = py
            .detach(|| guiding::LightTree::build(list, h))
            .map_err(value_error)?;
        Ok(Self {
            tree: Arc::new(tree),
        })
    }

    /// The number of emitters.
    #[getter]
    fn emitter_count(&self) -> usize {
        guiding::LightHierarchy::emitter_count(&*self.tree)
    }

    /// The deepest leaf's level (the root is 0).
    #[getter]
    fn depth(&self) -> usize {
        self.tree.depth()
    }

    /// The emitters' total power.
    #[getter]
    fn total_power(&self) -> f32 {
        self.tree.total_power()
    }

    /// The box around every emitter, as `(lower, upper)` corners.
    #[getter]
    fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let b = self.tree.scene_bounds();
        (b.min.to_array(), b.max.to_array())
    }

    /// Bytes the tree takes.
    #[getter]
    fn nbytes(&self) -> usize {
        self.tree.bytes()
    }

    /// The tree as bytes (`LightTree.from_bytes` reads them back): what a
    /// farm sends its workers once, instead of the emitters to rebuild from.
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.tree.to_bytes())
    }

    /// A tree saved by `to_bytes`; `ValueError` for bytes that are not one.
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let tree = py
            .detach(|| guiding::LightTree::from_bytes(data))
            .map_err(value_error)?;
        Ok(Self {
            tree: Arc::new(tree),
        })
    }

    /// Pickling (dask, multiprocessing) goes through the bytes.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let from_bytes = slf.get_type().getattr("from_bytes")?;
        Ok((from_bytes, (slf.get().to_bytes(slf.py()),)))
    }

    fn __repr__(&self) -> String {
        format!(
            "LightTree({} emitters, depth {})",
            self.emitter_count(),
            self.tree.depth()
        )
    }
}
