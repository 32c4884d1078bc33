//! The three material models the scenes call for: Lambertian diffuse, one
//! glossy model (GGX microfacet reflection with Schlick's Fresnel, sampled by
//! visible normals) and a smooth dielectric.

use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// A surface's scattering model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection (`albedo` 0 absorbs: used for emitters and
    /// dark occluders).
    Diffuse {
        /// Reflectance.
        albedo: Vec3,
    },
    /// GGX microfacet reflection.
    Glossy {
        /// Normal-incidence reflectance (Schlick's `F0`).
        specular: Vec3,
        /// GGX `alpha` (roughness squared).
        alpha: f32,
    },
    /// A smooth dielectric interface; the geometric normal points to the
    /// outside (index 1).
    Dielectric {
        /// Index of refraction of the inside.
        ior: f32,
    },
}

/// Which effect a material needs, for the scenes' effect declarations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialKind {
    /// [`Material::Diffuse`].
    Diffuse,
    /// [`Material::Glossy`].
    Glossy,
    /// [`Material::Dielectric`].
    Dielectric,
}

/// A sampled direction.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The incident direction (world space, unit).
    pub wi: Vec3,
    /// `f * |cos| / pdf`.
    pub weight: Vec3,
    /// Solid-angle pdf (for the dielectric: the discrete probability of
    /// the chosen lobe).
    pub pdf: f32,
}

impl Material {
    /// The effect this material needs.
    pub fn kind(&self) -> MaterialKind {
        match self {
            Self::Diffuse { .. } => MaterialKind::Diffuse,
            Self::Glossy { .. } => MaterialKind::Glossy,
            Self::Dielectric { .. } => MaterialKind::Dielectric,
        }
    }

    /// True when it only scatters into discrete directions.
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(self, Self::Dielectric { .. })
    }

    /// True when it never scatters light (the path can stop).
    #[inline]
    pub fn is_black(&self) -> bool {
        match self {
            Self::Diffuse { albedo } => albedo.max_element() <= 0.0,
            Self::Glossy { specular, .. } => specular.max_element() <= 0.0,
            Self::Dielectric { .. } => false,
        }
    }

    /// `f(wo, wi) |cos(wi)|` and the pdf with which [`Material::sample`]
    /// draws `wi`, for non-delta materials. `n` is the shading normal turned
    /// towards `wo`.
    #[inline]
    pub fn eval(&self, n: Vec3, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let cos_i = n.dot(wi);
        let cos_o = n.dot(wo);
        if cos_i <= 0.0 || cos_o <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        match *self {
            Self::Diffuse { albedo } => (albedo * (FRAC_1_PI * cos_i), cos_i * FRAC_1_PI),
            Self::Glossy { specular, alpha } => {
                let h = (wo + wi).normalize();
                let cos_h = n.dot(h);
                let d = ggx_d(cos_h, alpha);
                let g1o = ggx_g1(cos_o, alpha);
                let g = g1o * ggx_g1(cos_i, alpha);
                let f = schlick(specular, wi.dot(h));
                let value = f * (d * g / (4.0 * cos_o));
                let pdf = g1o * d / (4.0 * cos_o);
                (value, pdf)
            }
            Self::Dielectric { .. } => (Vec3::ZERO, 0.0),
        }
    }

    /// Draws an incident direction for `wo`. `n` is the shading normal (for
    /// diffuse and glossy turned towards `wo`; for the dielectric the
    /// geometric normal, pointing outside).
    #[inline]
    pub fn sample(&self, n: Vec3, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        match *self {
            Self::Diffuse { albedo } => {
                let frame = Frame::new(n);
                let local = cosine_hemisphere(u);
                if local.z <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi: frame.to_world(local),
                    weight: albedo,
                    pdf: local.z * FRAC_1_PI,
                })
            }
            Self::Glossy { alpha, .. } => {
                let frame = Frame::new(n);
                let wo_l = frame.to_local(wo);
                if wo_l.z <= 0.0 {
                    return None;
                }
                let h = sample_ggx_vndf(wo_l, alpha, u);
                let wi_l = (2.0 * wo_l.dot(h)) * h - wo_l;
                if wi_l.z <= 0.0 {
                    return None;
                }
                let wi = frame.to_world(wi_l).normalize();
                let (value, pdf) = self.eval(n, wo, wi);
                if pdf <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    weight: value / pdf,
                    pdf,
                })
            }
            Self::Dielectric { ior } => {
                let cos_o = n.dot(wo);
                let (eta_i, eta_t, nn, cos_i) = if cos_o >= 0.0 {
                    (1.0, ior, n, cos_o)
                } else {
                    (ior, 1.0, -n, -cos_o)
                };
                let eta = eta_i / eta_t;
                let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
                let reflect = (2.0 * cos_i) * nn - wo;
                if sin2_t >= 1.0 {
                    return Some(BsdfSample {
                        wi: reflect,
                        weight: Vec3::ONE,
                        pdf: 1.0,
                    });
                }
                let cos_t = (1.0 - sin2_t).sqrt();
                let fresnel = fresnel_dielectric(cos_i, cos_t, eta_i, eta_t);
                if u_lobe < fresnel {
                    Some(BsdfSample {
                        wi: reflect,
                        weight: Vec3::ONE,
                        pdf: fresnel,
                    })
                } else {
                    let wi = (-eta * wo + (eta * cos_i - cos_t) * nn).normalize();
                    // Radiance is scaled by (eta_i / eta_t)^2 across the
                    // interface (camera paths carry importance the other way).
                    Some(BsdfSample {
                        wi,
                        weight: Vec3::splat(eta * eta),
                        pdf: 1.0 - fresnel,
                    })
                }
            }
        }
    }
}

/// Cosine-weighted direction around +z.
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (s, c) = phi.sin_cos();
    Vec3::new(r * c, r * s, (1.0 - u.x).max(0.0).sqrt())
}

/// GGX normal distribution.
#[inline]
fn ggx_d(cos_h: f32, alpha: f32) -> f32 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let c2 = cos_h * cos_h;
    let denom = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * denom * denom)
}

/// Smith's masking for GGX.
#[inline]
fn ggx_g1(cos: f32, alpha: f32) -> f32 {
    let c2 = cos * cos;
    let tan2 = (1.0 - c2).max(0.0) / c2.max(1e-12);
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// Schlick's Fresnel.
#[inline]
fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// Unpolarised Fresnel reflectance of a dielectric interface.
#[inline]
fn fresnel_dielectric(cos_i: f32, cos_t: f32, eta_i: f32, eta_t: f32) -> f32 {
    let rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    let rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    (0.5 * (rs * rs + rp * rp)).clamp(0.0, 1.0)
}

/// A GGX visible normal for `wo` (local, z up) (Heitz 2018).
#[inline]
fn sample_ggx_vndf(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (sp, cp) = phi.sin_cos();
    let p1 = r * cp;
    let mut p2 = r * sp;
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-6)).normalize()
}
