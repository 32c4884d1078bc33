//! [`Bucket`]: the emitters of one bucket of the binned split, the unit
//! both the split (`binned.rs`) and the heuristic's cost (`heuristic.rs`)
//! read.

use super::items::Item;
use crate::math::{Aabb, LightCone};
use core::f32::consts::PI;

/// The emitters of one bucket (or a run of buckets) on one axis. Under SAOH
/// it also bounds their cones (meaningful when `count > 0`), carrying
/// `theta_o` beside the cone so that `acos` is only taken when the cone
/// changes.
#[derive(Clone, Copy)]
pub(super) struct Bucket {
    pub(super) bounds: Aabb,
    pub(super) area: f64,
    pub(super) power: f64,
    pub(super) count: usize,
    pub(super) cone: LightCone,
    pub(super) theta_o: f32,
}

pub(super) const EMPTY_BUCKET: Bucket = Bucket {
    bounds: Aabb::EMPTY,
    area: 0.0,
    power: 0.0,
    count: 0,
    cone: LightCone::SPHERE,
    theta_o: PI,
};

impl Bucket {
    #[inline]
    pub(super) fn add<const SAOH: bool>(&mut self, it: &Item) {
        if SAOH {
            (self.cone, self.theta_o) = if self.count == 0 {
                (it.cone, it.theta_o)
            } else {
                self.cone
                    .union_with_angles(self.theta_o, &it.cone, it.theta_o)
            };
        }
        self.count += 1;
        self.bounds = self.bounds.union(&it.bounds);
        self.area += it.area as f64;
        self.power += it.power as f64;
    }

    #[inline]
    pub(super) fn merge<const SAOH: bool>(&self, o: &Bucket) -> Bucket {
        let (cone, theta_o) = if !SAOH || o.count == 0 {
            (self.cone, self.theta_o)
        } else if self.count == 0 {
            (o.cone, o.theta_o)
        } else {
            self.cone
                .union_with_angles(self.theta_o, &o.cone, o.theta_o)
        };
        Bucket {
            bounds: self.bounds.union(&o.bounds),
            area: self.area + o.area,
            power: self.power + o.power,
            count: self.count + o.count,
            cone,
            theta_o,
        }
    }
}
