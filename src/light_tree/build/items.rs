//! The builder's input: each emitter checked (typed errors for bad
//! bounds, powers, areas and cones) and copied with what the build needs.

use crate::emitter::Emitters;
use crate::light_tree::BuildError;
use crate::light_tree::node::LEAF_BIT;
use crate::math::scalar::safe_acos;
use crate::math::{Aabb, LightCone};
use alloc::vec::Vec;
use glam::Vec3;

/// One emitter during the build, copied so partitioning stays local.
#[derive(Clone, Copy)]
pub(super) struct Item {
    pub(super) bounds: Aabb,
    pub(super) centroid: Vec3,
    pub(super) cone: LightCone,
    /// `safe_acos(cone.cos_theta_o)`, for SAOH's cone unions.
    pub(super) theta_o: f32,
    pub(super) power: f32,
    pub(super) area: f32,
    pub(super) emitter: u32,
    pub(super) two_sided: bool,
    /// The light sets it belongs to.
    pub(super) sets: u64,
}

pub(super) fn validate<E: Emitters + ?Sized>(emitters: &E) -> Result<Vec<Item>, BuildError> {
    let count = emitters.len();
    if count > (LEAF_BIT - 1) as usize {
        return Err(BuildError::TooManyEmitters { count });
    }
    let mut items = Vec::with_capacity(count);
    for i in 0..count {
        let bounds = emitters.bounds(i);
        if !bounds.is_finite() || bounds.is_empty() {
            return Err(BuildError::InvalidBounds { emitter: i });
        }
        let power = emitters.power(i);
        if !(power >= 0.0 && power.is_finite()) {
            return Err(BuildError::InvalidPower { emitter: i, power });
        }
        let weight = emitters.weight(i);
        if !(weight >= 0.0 && weight.is_finite()) {
            return Err(BuildError::InvalidWeight { emitter: i, weight });
        }
        // The tree chooses by power times weight (a product past f32 makes
        // the total overflow: `PowerOverflow` once every emitter is checked).
        let power = power * weight;
        let area = emitters.area(i);
        if !(area >= 0.0 && area.is_finite()) {
            return Err(BuildError::InvalidArea { emitter: i, area });
        }
        let cone = match emitters.cone(i) {
            None => LightCone::SPHERE,
            Some(c) => {
                if !(c.axis.is_finite() && c.cos_theta_o.is_finite() && c.cos_theta_e.is_finite()) {
                    return Err(BuildError::InvalidCone { emitter: i });
                }
                // Keep the caller's cosines (a cos/acos round trip would
                // narrow small cones); only the axis is normalised.
                match c.axis.try_normalize() {
                    Some(axis) => LightCone {
                        axis,
                        cos_theta_o: c.cos_theta_o.clamp(-1.0, 1.0),
                        cos_theta_e: c.cos_theta_e.clamp(-1.0, 1.0),
                    },
                    None => LightCone {
                        cos_theta_e: c.cos_theta_e.clamp(-1.0, 1.0),
                        ..LightCone::SPHERE
                    },
                }
            }
        };
        items.push(Item {
            bounds,
            // Halves first: `min + max` overflows for boxes near f32::MAX.
            centroid: bounds.min * 0.5 + bounds.max * 0.5,
            power,
            area,
            theta_o: safe_acos(cone.cos_theta_o),
            cone,
            two_sided: emitters.two_sided(i),
            sets: emitters.light_sets(i),
            emitter: i as u32,
        });
    }
    Ok(items)
}
