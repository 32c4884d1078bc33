//! The guides' configurations as plain C structs: start from a
//! `guiding_*_config_default`, change fields, and the constructor checks
//! them (`GUIDING_STATUS_INVALID_CONFIG` for a value out of range, never a
//! silent clamp).

use crate::status::{Failure, GuidingStatus, guard, put};
use guiding::{
    Accumulation, CutConfig, DirectionalFilter, FieldConfig, GltConfig, SdTreeConfig,
    SpatialFilter, UnboundedLights,
};

/// A spatial filter: a record goes to its point's cell.
pub const GUIDING_FILTER_NEAREST: u32 = 0;
/// A spatial filter: a record goes to one cell picked within a cell-sized
/// box around it.
pub const GUIDING_FILTER_STOCHASTIC_BOX: u32 = 1;
/// A spatial filter: a record is spread over the cells a cell-sized box
/// around it overlaps.
pub const GUIDING_FILTER_BOX: u32 = 2;
/// A directional filter: a record goes to the quadtree leaf of its
/// direction.
pub const GUIDING_DIRECTIONAL_NEAREST: u32 = 0;
/// A directional filter: a record is spread over the leaves a leaf-sized
/// box around its direction overlaps.
pub const GUIDING_DIRECTIONAL_BOX: u32 = 1;

/// The learned cut's configuration (the Rust `CutConfig`'s
/// renderer-facing fields), shared by the GLT and the field.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingCutConfig {
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
}

/// The GLT's configuration.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingGltConfig {
    /// The cuts'.
    pub cut: GuidingCutConfig,
    /// Records a spatial cell takes before it splits.
    pub spatial_threshold: f64,
    /// The most bytes the spatial tree's cells may take; 0 for no limit.
    pub max_bytes: usize,
    /// Where a light record goes: a `GUIDING_FILTER_*`.
    pub light_filter: u32,
    /// Learned state bit for bit the same whatever the thread count.
    pub deterministic: bool,
}

/// The SD-tree's configuration (Practical Path Guiding's).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingSdTreeConfig {
    /// Records a spatial cell takes before it splits (PPG's c).
    pub spatial_threshold: f64,
    /// The most bytes the tree may take; 0 for no limit.
    pub max_bytes: usize,
    /// A quadtree leaf splits above this share of its energy (PPG's rho).
    pub rho: f32,
    /// The quadtrees' deepest level.
    pub max_depth: u32,
    /// Where a radiance record goes in space: a `GUIDING_FILTER_*`.
    pub spatial_filter: u32,
    /// ... and in direction: a `GUIDING_DIRECTIONAL_*`.
    pub directional_filter: u32,
    /// The probability of sampling the BSDF rather than the guide (the
    /// starting value when it is learned).
    pub bsdf_fraction: f32,
    /// Learn the BSDF fraction per cell (from fraction records).
    pub learn_bsdf_fraction: bool,
    /// Optimisation steps of the learned fraction per record.
    pub fraction_steps: u32,
    /// Learned state bit for bit the same whatever the thread count.
    pub deterministic: bool,
}

/// The combined field's configuration: its SD-tree's (whose spatial
/// threshold and `deterministic` the whole field follows) and its cuts'.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingFieldConfig {
    /// The SD-tree's (`deterministic` sets both halves).
    pub sd: GuidingSdTreeConfig,
    /// The cuts'.
    pub cut: GuidingCutConfig,
    /// Where a light record goes: a `GUIDING_FILTER_*`.
    pub light_filter: u32,
}

fn invalid(e: impl ToString) -> Failure {
    Failure::new(GuidingStatus::InvalidConfig, e.to_string())
}

fn spatial(f: u32, name: &str) -> Result<SpatialFilter, Failure> {
    Ok(match f {
        GUIDING_FILTER_NEAREST => SpatialFilter::Nearest,
        GUIDING_FILTER_STOCHASTIC_BOX => SpatialFilter::StochasticBox,
        GUIDING_FILTER_BOX => SpatialFilter::Box,
        _ => return Err(invalid(format!("{name} = {f} is not a GUIDING_FILTER_*"))),
    })
}

fn spatial_code(f: SpatialFilter) -> u32 {
    match f {
        SpatialFilter::StochasticBox => GUIDING_FILTER_STOCHASTIC_BOX,
        SpatialFilter::Box => GUIDING_FILTER_BOX,
        _ => GUIDING_FILTER_NEAREST,
    }
}

fn accumulation(deterministic: bool) -> Accumulation {
    if deterministic {
        Accumulation::Deterministic
    } else {
        Accumulation::Fast
    }
}

fn is_deterministic(a: Accumulation) -> bool {
    matches!(a, Accumulation::Deterministic)
}

impl GuidingCutConfig {
    fn from_rust(c: &CutConfig) -> Self {
        Self {
            sigma: c.sigma,
            alpha: c.alpha,
            min_records: c.min_records,
            visibility: c.visibility,
            unbounded_lights: c.unbounded.count,
            unbounded_probability: c.unbounded.probability,
        }
    }

    fn to_rust(self, deterministic: bool) -> Result<CutConfig, Failure> {
        let unbounded = if self.unbounded_lights == 0 {
            UnboundedLights::default()
        } else {
            UnboundedLights::new(self.unbounded_lights, self.unbounded_probability)
                .map_err(invalid)?
        };
        Ok(CutConfig {
            sigma: self.sigma,
            alpha: self.alpha,
            min_records: self.min_records,
            visibility: self.visibility,
            unbounded,
            accumulation: accumulation(deterministic),
            ..CutConfig::default()
        })
    }
}

impl GuidingGltConfig {
    fn from_rust(c: &GltConfig) -> Self {
        Self {
            cut: GuidingCutConfig::from_rust(&c.cut),
            spatial_threshold: c.spatial_threshold,
            max_bytes: c.max_bytes.unwrap_or(0),
            light_filter: spatial_code(c.light_filter),
            deterministic: is_deterministic(c.cut.accumulation),
        }
    }

    pub(crate) fn to_rust(self) -> Result<GltConfig, Failure> {
        let c = GltConfig {
            cut: self.cut.to_rust(self.deterministic)?,
            spatial_threshold: self.spatial_threshold,
            max_bytes: (self.max_bytes > 0).then_some(self.max_bytes),
            light_filter: spatial(self.light_filter, "light_filter")?,
        };
        c.validate().map_err(invalid)?;
        Ok(c)
    }
}

impl GuidingSdTreeConfig {
    fn from_rust(c: &SdTreeConfig) -> Self {
        Self {
            spatial_threshold: c.spatial_threshold,
            max_bytes: c.max_bytes.unwrap_or(0),
            rho: c.quadtree.rho,
            max_depth: c.quadtree.max_depth,
            spatial_filter: spatial_code(c.spatial_filter),
            directional_filter: match c.directional_filter {
                DirectionalFilter::Box => GUIDING_DIRECTIONAL_BOX,
                _ => GUIDING_DIRECTIONAL_NEAREST,
            },
            bsdf_fraction: c.bsdf_fraction,
            learn_bsdf_fraction: c.learn_bsdf_fraction,
            fraction_steps: c.fraction_steps,
            deterministic: is_deterministic(c.accumulation),
        }
    }

    fn fields(self) -> Result<SdTreeConfig, Failure> {
        let directional_filter = match self.directional_filter {
            GUIDING_DIRECTIONAL_NEAREST => DirectionalFilter::Nearest,
            GUIDING_DIRECTIONAL_BOX => DirectionalFilter::Box,
            f => {
                return Err(invalid(format!(
                    "directional_filter = {f} is not a GUIDING_DIRECTIONAL_*"
                )));
            }
        };
        if !self.bsdf_fraction.is_finite() {
            return Err(invalid(format!(
                "bsdf_fraction = {} is not finite",
                self.bsdf_fraction
            )));
        }
        let mut c = SdTreeConfig {
            spatial_threshold: self.spatial_threshold,
            max_bytes: (self.max_bytes > 0).then_some(self.max_bytes),
            spatial_filter: spatial(self.spatial_filter, "spatial_filter")?,
            directional_filter,
            bsdf_fraction: self.bsdf_fraction,
            learn_bsdf_fraction: self.learn_bsdf_fraction,
            fraction_steps: self.fraction_steps,
            accumulation: accumulation(self.deterministic),
            ..SdTreeConfig::default()
        };
        c.quadtree.rho = self.rho;
        c.quadtree.max_depth = self.max_depth;
        Ok(c)
    }

    pub(crate) fn to_rust(self) -> Result<SdTreeConfig, Failure> {
        let c = self.fields()?;
        c.validate().map_err(invalid)?;
        Ok(c)
    }
}

impl GuidingFieldConfig {
    fn from_rust(c: &FieldConfig) -> Self {
        Self {
            sd: GuidingSdTreeConfig::from_rust(&c.sd),
            cut: GuidingCutConfig::from_rust(&c.cut),
            light_filter: spatial_code(c.light_filter),
        }
    }

    pub(crate) fn to_rust(self) -> Result<FieldConfig, Failure> {
        let c = FieldConfig {
            sd: self.sd.fields()?,
            cut: self.cut.to_rust(self.sd.deterministic)?,
            light_filter: spatial(self.light_filter, "light_filter")?,
        };
        c.validate().map_err(invalid)?;
        Ok(c)
    }
}

/// The crate's default GLT configuration, written to `out`.
///
/// # Safety
/// `out` null or writable.
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

/// The crate's default SD-tree configuration (PPG's original settings),
/// written to `out`.
///
/// # Safety
/// `out` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_config_default(
    out: *mut GuidingSdTreeConfig,
) -> GuidingStatus {
    // SAFETY: forwarded.
    guard(|| unsafe {
        put(
            out,
            GuidingSdTreeConfig::from_rust(&SdTreeConfig::default()),
            "out",
        )
    })
}

/// Müller's improved SD-tree settings (c = 4,000, jittered records, a
/// learned BSDF fraction), written to `out`.
///
/// # Safety
/// `out` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_config_improved(
    out: *mut GuidingSdTreeConfig,
) -> GuidingStatus {
    // SAFETY: forwarded.
    guard(|| unsafe {
        put(
            out,
            GuidingSdTreeConfig::from_rust(&SdTreeConfig::improved()),
            "out",
        )
    })
}

/// The crate's default field configuration, written to `out`.
///
/// # Safety
/// `out` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_config_default(
    out: *mut GuidingFieldConfig,
) -> GuidingStatus {
    // SAFETY: forwarded.
    guard(|| unsafe {
        put(
            out,
            GuidingFieldConfig::from_rust(&FieldConfig::default()),
            "out",
        )
    })
}
