use glam::Vec3;

/// An axis-aligned bounding box. The empty box has `min > max` and is the
/// identity of [`Aabb::union`]; a point is a valid (degenerate) box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box: contains nothing, `union` with it is the identity.
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box spanned by two corners, in any order.
    #[inline]
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The degenerate box holding one point.
    #[inline]
    pub fn from_point(p: Vec3) -> Self {
        Self { min: p, max: p }
    }

    /// True when the box holds no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.cmple(self.max).all())
    }

    /// True when both corners are finite (the empty box is not).
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The smallest box holding `self` and `p`.
    #[inline]
    pub fn extend(&self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The box's centre.
    #[inline]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// `max - min` (zero for a point, negative for the empty box).
    #[inline]
    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }

    /// Surface area; 0 for empty and degenerate boxes.
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Volume; 0 for empty and degenerate boxes.
    #[inline]
    pub fn volume(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        d.x * d.y * d.z
    }

    /// The axis (0, 1, 2) along which the box is longest.
    #[inline]
    pub fn longest_axis(&self) -> usize {
        let d = self.diagonal();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    }

    /// True when `p` lies inside or on the boundary.
    #[inline]
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The point of the box nearest to `p`.
    #[inline]
    pub fn clamp(&self, p: Vec3) -> Vec3 {
        p.clamp(self.min, self.max)
    }

    /// The box where both overlap (empty when they do not).
    #[inline]
    pub fn intersection(&self, other: &Self) -> Self {
        Self {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        }
    }

    /// `p` mapped to `[0, 1]^3` inside the box (0 along a flat axis).
    #[inline]
    pub fn offset(&self, p: Vec3) -> Vec3 {
        let d = self.diagonal();
        let o = p - self.min;
        Vec3::new(
            if d.x > 0.0 { o.x / d.x } else { 0.0 },
            if d.y > 0.0 { o.y / d.y } else { 0.0 },
            if d.z > 0.0 { o.z / d.z } else { 0.0 },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_is_identity_of_union() {
        let b = Aabb::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.0, 5.0));
        assert_eq!(Aabb::EMPTY.union(&b), b);
        assert!(Aabb::EMPTY.is_empty());
        assert!(!Aabb::EMPTY.is_finite());
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        assert_eq!(b.min, Vec3::new(-1.0, 0.0, 3.0));
    }

    #[test]
    fn point_box_is_degenerate_not_empty() {
        let p = Aabb::from_point(Vec3::ONE);
        assert!(!p.is_empty());
        assert_eq!(p.surface_area(), 0.0);
        assert!(p.contains(Vec3::ONE));
        assert_eq!(p.offset(Vec3::ONE), Vec3::ZERO);
    }

    #[test]
    fn measures() {
        let b = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(b.surface_area(), 22.0);
        assert_eq!(b.volume(), 6.0);
        assert_eq!(b.longest_axis(), 2);
        assert_eq!(b.clamp(Vec3::splat(9.0)), b.max);
        let i = b.intersection(&Aabb::new(Vec3::splat(0.5), Vec3::splat(5.0)));
        assert_eq!(i.volume(), 0.5 * 1.5 * 2.5);
        assert!(
            b.intersection(&Aabb::from_point(Vec3::splat(-1.0)))
                .is_empty()
        );
    }
}
