//! Keyword arguments to the crate's configurations. A keyword left out
//! keeps the crate's default (one place for the defaults: the Rust
//! `Default` impls); an unknown keyword is a `TypeError`, a value out of
//! range the crate's `ConfigError` as a `ValueError`. Nothing is clamped.

use crate::error::value_error;
use guiding::{
    Accumulation, CutConfig, DirectionalFilter, FieldConfig, GltConfig, SdTreeConfig,
    SpatialFilter, UnboundedLights,
};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The keywords of one constructor, taken one by one; [`Kwargs::finish`]
/// refuses any that nobody took.
pub struct Kwargs<'py> {
    dict: Option<Bound<'py, PyDict>>,
    taken: Vec<&'static str>,
    what: &'static str,
}

impl<'py> Kwargs<'py> {
    pub fn new(dict: Option<&Bound<'py, PyDict>>, what: &'static str) -> Self {
        Self {
            dict: dict.cloned(),
            taken: Vec::new(),
            what,
        }
    }

    /// The value of `key`, `None` when it was not given (or given as
    /// `None`).
    pub fn take<T: FromPyObjectOwned<'py>>(&mut self, key: &'static str) -> PyResult<Option<T>> {
        self.taken.push(key);
        let Some(dict) = &self.dict else {
            return Ok(None);
        };
        match dict.get_item(key)? {
            Some(v) if !v.is_none() => v.extract::<T>().map(Some).map_err(|e| {
                let e: PyErr = e.into();
                PyTypeError::new_err(format!("{}: {key}: {e}", self.what))
            }),
            _ => Ok(None),
        }
    }

    /// Refuses keywords that no configuration field took.
    pub fn finish(self) -> PyResult<()> {
        let Some(dict) = &self.dict else {
            return Ok(());
        };
        for key in dict.keys() {
            let key: String = key.extract()?;
            if !self.taken.contains(&key.as_str()) {
                let mut known = self.taken.clone();
                known.sort_unstable();
                return Err(PyTypeError::new_err(format!(
                    "{}: unknown keyword argument '{key}' (known: {})",
                    self.what,
                    known.join(", ")
                )));
            }
        }
        Ok(())
    }
}

fn set<T>(field: &mut T, value: Option<T>) {
    if let Some(v) = value {
        *field = v;
    }
}

fn spatial_filter(name: &str, key: &str) -> PyResult<SpatialFilter> {
    match name {
        "nearest" => Ok(SpatialFilter::Nearest),
        "stochastic_box" => Ok(SpatialFilter::StochasticBox),
        "box" => Ok(SpatialFilter::Box),
        _ => Err(PyValueError::new_err(format!(
            "{key}: '{name}' is not one of 'nearest', 'stochastic_box', 'box'"
        ))),
    }
}

fn directional_filter(name: &str) -> PyResult<DirectionalFilter> {
    match name {
        "nearest" => Ok(DirectionalFilter::Nearest),
        "box" => Ok(DirectionalFilter::Box),
        _ => Err(PyValueError::new_err(format!(
            "directional_filter: '{name}' is not one of 'nearest', 'box'"
        ))),
    }
}

fn accumulation(deterministic: bool) -> Accumulation {
    if deterministic {
        Accumulation::Deterministic
    } else {
        Accumulation::Fast
    }
}

/// The cut's keywords: `sigma`, `alpha`, `min_records`, `visibility`,
/// `unbounded_lights` with `unbounded_probability`, `deterministic`.
fn cut_config(kw: &mut Kwargs<'_>) -> PyResult<CutConfig> {
    let mut c = CutConfig::default();
    set(&mut c.sigma, kw.take("sigma")?);
    set(&mut c.alpha, kw.take("alpha")?);
    set(&mut c.min_records, kw.take("min_records")?);
    set(&mut c.visibility, kw.take("visibility")?);
    let count: Option<u32> = kw.take("unbounded_lights")?;
    let probability: Option<f64> = kw.take("unbounded_probability")?;
    match (count, probability) {
        (Some(n), p) if n > 0 => {
            c.unbounded = UnboundedLights::new(n, p.unwrap_or(0.25)).map_err(value_error)?;
        }
        (_, Some(_)) => {
            return Err(PyValueError::new_err(
                "unbounded_probability is given but unbounded_lights is 0",
            ));
        }
        _ => {}
    }
    Ok(c)
}

/// A [`GltConfig`]: the cut's keywords and `spatial_threshold`,
/// `max_bytes`, `light_filter`.
pub fn glt_config(kw: &mut Kwargs<'_>) -> PyResult<GltConfig> {
    let mut c = GltConfig {
        cut: cut_config(kw)?,
        ..GltConfig::default()
    };
    if let Some(d) = kw.take::<bool>("deterministic")? {
        c.cut.accumulation = accumulation(d);
    }
    set(&mut c.spatial_threshold, kw.take("spatial_threshold")?);
    c.max_bytes = kw.take("max_bytes")?;
    if let Some(f) = kw.take::<String>("light_filter")? {
        c.light_filter = spatial_filter(&f, "light_filter")?;
    }
    c.validate().map_err(value_error)?;
    Ok(c)
}

/// An [`SdTreeConfig`]: `improved` (start from
/// [`SdTreeConfig::improved`]), `spatial_threshold`, `max_bytes`, `rho`,
/// `max_depth`, `spatial_filter`, `directional_filter`, `bsdf_fraction`,
/// `learn_bsdf_fraction`, `fraction_steps`.
fn sd_fields(kw: &mut Kwargs<'_>) -> PyResult<SdTreeConfig> {
    let mut c = if kw.take::<bool>("improved")?.unwrap_or(false) {
        SdTreeConfig::improved()
    } else {
        SdTreeConfig::default()
    };
    set(&mut c.spatial_threshold, kw.take("spatial_threshold")?);
    c.max_bytes = kw.take("max_bytes")?;
    set(&mut c.quadtree.rho, kw.take("rho")?);
    set(&mut c.quadtree.max_depth, kw.take("max_depth")?);
    if let Some(f) = kw.take::<String>("spatial_filter")? {
        c.spatial_filter = spatial_filter(&f, "spatial_filter")?;
    }
    if let Some(f) = kw.take::<String>("directional_filter")? {
        c.directional_filter = directional_filter(&f)?;
    }
    set(&mut c.bsdf_fraction, kw.take("bsdf_fraction")?);
    set(&mut c.learn_bsdf_fraction, kw.take("learn_bsdf_fraction")?);
    set(&mut c.fraction_steps, kw.take("fraction_steps")?);
    Ok(c)
}

/// An [`SdTreeConfig`] and `deterministic`.
pub fn sd_tree_config(kw: &mut Kwargs<'_>) -> PyResult<SdTreeConfig> {
    let mut c = sd_fields(kw)?;
    if let Some(d) = kw.take::<bool>("deterministic")? {
        c.accumulation = accumulation(d);
    }
    c.validate().map_err(value_error)?;
    Ok(c)
}

/// A [`FieldConfig`]: the SD-tree's keywords, the cut's, `light_filter`
/// and `deterministic` (both halves' sums).
pub fn field_config(kw: &mut Kwargs<'_>) -> PyResult<FieldConfig> {
    let mut c = FieldConfig {
        sd: sd_fields(kw)?,
        cut: cut_config(kw)?,
        ..FieldConfig::default()
    };
    if let Some(d) = kw.take::<bool>("deterministic")? {
        c = c.with_accumulation(accumulation(d));
    }
    if let Some(f) = kw.take::<String>("light_filter")? {
        c.light_filter = spatial_filter(&f, "light_filter")?;
    }
    c.validate().map_err(value_error)?;
    Ok(c)
}
