//! Reading numpy arguments: every batched call copies its arrays once,
//! under the GIL, into plain Rust vectors, checking dtype, shape and
//! values on the way; the work then runs with the GIL released on data no
//! Python thread can change under it.

use numpy::prelude::*;
use numpy::{PyArrayDyn, PyUntypedArray};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// An argument as a numpy array: an `ndarray` as it is, anything else
/// (a list, a tuple, a scalar) through `numpy.asarray`.
fn as_ndarray<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let asarray = obj.py().import("numpy")?.getattr("asarray")?;
    Ok(asarray.call1((obj,))?.cast_into::<PyUntypedArray>()?)
}

/// Which values an array of floats may hold.
#[derive(Clone, Copy)]
pub enum Range {
    /// Any finite value.
    Finite,
    /// Finite and at least 0.
    NonNegative,
    /// In `[0, 1)`: a uniform random number.
    Unit,
}

impl Range {
    fn check(self, name: &str, row: usize, v: f64) -> PyResult<()> {
        let ok = match self {
            Range::Finite => v.is_finite(),
            Range::NonNegative => v.is_finite() && v >= 0.0,
            Range::Unit => (0.0..1.0).contains(&v),
        };
        if ok {
            return Ok(());
        }
        let want = match self {
            Range::Finite => "finite",
            Range::NonNegative => "finite and >= 0",
            Range::Unit => "in [0, 1)",
        };
        Err(PyValueError::new_err(format!(
            "{name}[{row}] = {v} is not {want}"
        )))
    }
}

/// The shape an array must have: `rows` (when known) by `N` columns, the
/// column axis dropped for `N == 0` (a 1-D array of scalars).
fn check_shape(name: &str, shape: &[usize], cols: usize, rows: Option<usize>) -> PyResult<usize> {
    let want = match (cols, rows) {
        (0, Some(n)) => format!("({n},)"),
        (0, None) => "(N,)".to_string(),
        (c, Some(n)) => format!("({n}, {c})"),
        (c, None) => format!("(N, {c})"),
    };
    let got = match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let n = match (cols, shape) {
        (0, [n]) => *n,
        (c, [n, k]) if *k == c => *n,
        _ => {
            return Err(PyValueError::new_err(format!(
                "{name}: expected an array of shape {want}, got shape {got}"
            )));
        }
    };
    if let Some(want_rows) = rows
        && n != want_rows
    {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an array of shape {want} (one row per point), got shape {got}"
        )));
    }
    Ok(n)
}

/// Rows of `N` floats from a float32 or float64 array of shape `(n, N)`
/// (`(n,)` for `N == 1` when `flat`), every value in `range`; `rows`
/// fixes `n` when the batch's length is already known.
pub fn float_rows<const N: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    rows: Option<usize>,
    range: Range,
) -> PyResult<Vec<[f32; N]>> {
    read_floats::<N>(obj, name, rows, range, N)
}

/// One float per row, from a 1-D float32 or float64 array.
pub fn floats(
    obj: &Bound<'_, PyAny>,
    name: &str,
    rows: Option<usize>,
    range: Range,
) -> PyResult<Vec<f32>> {
    Ok(read_floats::<1>(obj, name, rows, range, 0)?
        .into_iter()
        .map(|[v]| v)
        .collect())
}

fn read_floats<const N: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    rows: Option<usize>,
    range: Range,
    cols: usize,
) -> PyResult<Vec<[f32; N]>> {
    let a = as_ndarray(obj)?;
    check_shape(name, a.shape(), cols, rows)?;
    let kind = a.dtype().kind();
    // Integers are exact numbers too (`bounds=([0, 0, 0], [10, 10, 10])`):
    // through float64, the one copy.
    let a = if kind == b'i' || kind == b'u' {
        a.call_method1("astype", ("float64",))?
            .cast_into::<PyUntypedArray>()?
    } else {
        a
    };
    if let Ok(a) = a.cast::<PyArrayDyn<f32>>() {
        let view = a.readonly();
        return collect::<N, f32>(view.as_array().iter().copied(), name, range, |v| v);
    }
    if let Ok(a) = a.cast::<PyArrayDyn<f64>>() {
        let view = a.readonly();
        // An f64 outside f32's range would become infinite: checked as
        // f64 first, then rounded (and a unit number that rounds to 1 is
        // refused by the check of the rounded value).
        return collect::<N, f64>(view.as_array().iter().copied(), name, range, |v| v as f32);
    }
    Err(PyTypeError::new_err(format!(
        "{name}: expected an array of floats (float32 or float64) or integers, got dtype {} (kind '{}')",
        a.dtype(),
        kind as char
    )))
}

fn collect<const N: usize, T: Copy + Into<f64>>(
    values: impl Iterator<Item = T>,
    name: &str,
    range: Range,
    to_f32: impl Fn(T) -> f32,
) -> PyResult<Vec<[f32; N]>> {
    let mut out = Vec::with_capacity(values.size_hint().0 / N);
    let mut row = [0.0f32; N];
    for (i, v) in values.enumerate() {
        range.check(name, i / N, v.into())?;
        let f = to_f32(v);
        range.check(name, i / N, f64::from(f))?;
        row[i % N] = f;
        if i % N == N - 1 {
            out.push(row);
        }
    }
    Ok(out)
}

/// Light indices (one list: the emitters, then the unbounded lights) from
/// a 1-D integer array, each below `count`.
pub fn light_indices(
    obj: &Bound<'_, PyAny>,
    name: &str,
    rows: Option<usize>,
    count: u32,
) -> PyResult<Vec<u32>> {
    let a = as_ndarray(obj)?;
    check_shape(name, a.shape(), 0, rows)?;
    if a.dtype().kind() != b'i' && a.dtype().kind() != b'u' {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected an integer array of light indices, got dtype {}",
            a.dtype()
        )));
    }
    // Any integer dtype, through int64 (uint64 beyond it fails the cast).
    let as_i64 = a.call_method1("astype", ("int64",))?;
    let a = as_i64.cast::<PyArrayDyn<i64>>()?;
    let view = a.readonly();
    view.as_array()
        .iter()
        .enumerate()
        .map(|(i, &l)| {
            if (0..i64::from(count)).contains(&l) {
                Ok(l as u32)
            } else {
                Err(PyValueError::new_err(format!(
                    "{name}[{i}] = {l} is not a light index in [0, {count})"
                )))
            }
        })
        .collect()
}
