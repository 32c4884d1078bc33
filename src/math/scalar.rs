//! Scalar functions that work with and without `std` (libm backs them in
//! `no_std` builds), so the rest of the crate never cares which it is.

#[cfg(feature = "std")]
mod imp {
    #[inline]
    pub fn sqrt(x: f32) -> f32 {
        x.sqrt()
    }
    #[inline]
    pub fn cbrt(x: f32) -> f32 {
        x.cbrt()
    }
    #[inline]
    pub fn sqrt64(x: f64) -> f64 {
        x.sqrt()
    }
    #[inline]
    pub fn acos(x: f32) -> f32 {
        x.acos()
    }
    #[inline]
    pub fn cos(x: f32) -> f32 {
        x.cos()
    }
    #[inline]
    pub fn sin_cos(x: f32) -> (f32, f32) {
        x.sin_cos()
    }
    #[inline]
    pub fn atan2(y: f32, x: f32) -> f32 {
        y.atan2(x)
    }
    #[inline]
    pub fn floor(x: f32) -> f32 {
        x.floor()
    }
    #[inline]
    pub fn ceil(x: f32) -> f32 {
        x.ceil()
    }
    #[inline]
    pub fn exp64(x: f64) -> f64 {
        x.exp()
    }
    #[inline]
    pub fn ln64(x: f64) -> f64 {
        x.ln()
    }
}

#[cfg(not(feature = "std"))]
mod imp {
    #[inline]
    pub fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    #[inline]
    pub fn cbrt(x: f32) -> f32 {
        libm::cbrtf(x)
    }
    #[inline]
    pub fn sqrt64(x: f64) -> f64 {
        libm::sqrt(x)
    }
    #[inline]
    pub fn acos(x: f32) -> f32 {
        libm::acosf(x)
    }
    #[inline]
    pub fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
    #[inline]
    pub fn sin_cos(x: f32) -> (f32, f32) {
        libm::sincosf(x)
    }
    #[inline]
    pub fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
    #[inline]
    pub fn floor(x: f32) -> f32 {
        libm::floorf(x)
    }
    #[inline]
    pub fn ceil(x: f32) -> f32 {
        libm::ceilf(x)
    }
    #[inline]
    pub fn exp64(x: f64) -> f64 {
        libm::exp(x)
    }
    #[inline]
    pub fn ln64(x: f64) -> f64 {
        libm::log(x)
    }
}

pub use imp::*;

/// `sqrt(max(x, 0))`: never NaN for the slightly negative results of
/// `1 - cos^2` rounding.
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    sqrt(x.max(0.0))
}

/// `acos` of `x` clamped to `[-1, 1]`.
#[inline]
pub fn safe_acos(x: f32) -> f32 {
    acos(x.clamp(-1.0, 1.0))
}
