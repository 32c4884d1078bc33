//! The errors of the guiding structures' constructors: an invalid
//! configuration ([`ConfigError`]) or scene bounds no spatial tree can
//! start from ([`SpatialError`]).

use crate::light_tree::BuildError;
use crate::spatial::SpatialError;

/// A configuration field outside its valid range. Constructors check every
/// field before building anything; nothing is clamped silently.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConfigError {
    /// The field, as `Type::field` (for example `"CutConfig::sigma"`).
    pub field: &'static str,
    /// The value given (as `f64`; integers convert exactly below 2^53).
    pub value: f64,
    /// What the field accepts (for example `"in (0, 1]"`).
    pub expected: &'static str,
}

impl ConfigError {
    /// This error as a load error at `offset` of a saved buffer (a saved
    /// configuration that does not validate).
    pub(crate) fn at(self, offset: usize) -> crate::persist::LoadError {
        crate::persist::Reader::invalid(self.field, offset)
    }
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} = {} is invalid: expected a value {}",
            self.field, self.value, self.expected
        )
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ConfigError {}

/// Why a guiding structure could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A configuration field is out of range.
    Config(ConfigError),
    /// The scene bounds are empty or not finite.
    Spatial(SpatialError),
    /// No light tree can be built from the emitters.
    Build(BuildError),
    /// A light sampling strategy was asked for by a name it does not
    /// know (`Strategy::new`); `known` lists the names it does.
    UnknownStrategy {
        /// The names that are known.
        known: &'static [&'static str],
    },
    /// A guide was handed a light tree of another shape than the one it
    /// learned over ([`Glt::set_light_tree`](crate::Glt::set_light_tree)):
    /// other lights, another order, or a rebuild rather than a refit.
    LightTreeShape,
}

impl From<ConfigError> for Error {
    fn from(e: ConfigError) -> Self {
        Self::Config(e)
    }
}

impl From<BuildError> for Error {
    fn from(e: BuildError) -> Self {
        Self::Build(e)
    }
}

impl From<SpatialError> for Error {
    fn from(e: SpatialError) -> Self {
        Self::Spatial(e)
    }
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Config(e) => e.fmt(f),
            Self::Spatial(e) => e.fmt(f),
            Self::Build(e) => e.fmt(f),
            Self::UnknownStrategy { known } => write!(
                f,
                "unknown light sampling strategy (expected one of {known:?})"
            ),
            Self::LightTreeShape => f.write_str(
                "the light tree has another shape than the one the guide learned over \
                 (refit the guide's tree rather than rebuilding it)",
            ),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Config(e) => Some(e),
            Self::Spatial(e) => Some(e),
            Self::Build(e) => Some(e),
            Self::UnknownStrategy { .. } | Self::LightTreeShape => None,
        }
    }
}

/// Checks that `value` satisfies `ok`; else the error for `field`.
#[inline]
pub(crate) fn check(
    field: &'static str,
    value: f64,
    ok: bool,
    expected: &'static str,
) -> Result<(), ConfigError> {
    if ok {
        Ok(())
    } else {
        Err(ConfigError {
            field,
            value,
            expected,
        })
    }
}

/// `value` is finite and in `[0, 1]`.
pub(crate) fn unit(field: &'static str, value: f64) -> Result<(), ConfigError> {
    check(field, value, (0.0..=1.0).contains(&value), "in [0, 1]")
}

/// `value` is finite and positive.
pub(crate) fn positive(field: &'static str, value: f64) -> Result<(), ConfigError> {
    check(
        field,
        value,
        value > 0.0 && value.is_finite(),
        "finite and > 0",
    )
}
