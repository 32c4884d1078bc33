//! The one-number stochastic descent every tree in the crate uses.
//!
//! A descent picks a child at each node with probability proportional to two
//! weights, using one uniform number `u` for the whole root-to-leaf walk: at a
//! node with left probability `f`, it goes left iff `u < f` and rescales
//! `u' = u / f`, else right with `u' = (u - f) / (1 - f)`. This is exactly the
//! inverse of the leaves' cumulative distribution, so a QMC sample stays
//! stratified over the leaves.
//!
//! The rescaling and the running pmf are kept in `f64`. An `f32` rescaling
//! loses about one bit per level and stops moving after ~24 levels (the bug
//! of the paper's code and pbrt-v4 past depth 24); in `f64` the inverse CDF
//! stays exact to ~1e-16 relative at any depth, so the only limit left is the
//! resolution of the caller's `u` itself. The pmf product is also `f64`, so
//! probabilities down to 1e-300 compose without underflow before the final
//! conversion.
//!
//! `pmf` evaluation replays the same arithmetic with [`Descent::follow`], so a
//! sampled pmf and an evaluated pmf agree bit for bit.

/// The largest `f64` below one: where rescaled numbers are clamped.
const ONE_MINUS_EPS: f64 = 1.0 - f64::EPSILON / 2.0;

/// Which child a descent takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The first child.
    Left = 0,
    /// The second child.
    Right = 1,
}

impl Side {
    /// `0` for left, `1` for right.
    #[inline]
    pub fn index(self) -> usize {
        self as usize
    }
}

/// State of a root-to-leaf walk: the rescaled uniform number and the
/// probability of the choices made so far.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Descent {
    u: f64,
    pmf: f64,
}

impl Descent {
    /// Starts a sampling walk from `u` in `[0, 1)`. Values outside are
    /// clamped into it and NaN counts as 0, so a bad sampler cannot produce
    /// an out-of-range choice.
    #[inline]
    pub fn new(u: f32) -> Self {
        Self::from_f64(u as f64)
    }

    /// Like [`Descent::new`] from an `f64` number (more bits than an `f32`).
    #[inline]
    pub fn from_f64(u: f64) -> Self {
        let u = if u >= 0.0 { u.min(ONE_MINUS_EPS) } else { 0.0 };
        Self { u, pmf: 1.0 }
    }

    /// Starts a pmf evaluation: no random number, probability 1.
    #[inline]
    pub fn evaluate() -> Self {
        Self { u: 0.0, pmf: 1.0 }
    }

    /// The probability of the choices made so far.
    #[inline]
    pub fn pmf(&self) -> f64 {
        self.pmf
    }

    /// The rescaled uniform number for what comes next.
    #[inline]
    pub fn u(&self) -> f64 {
        self.u
    }

    /// The probabilities of left and right for weights `left` and `right`;
    /// `None` when they do not sum to a positive finite number.
    #[inline]
    pub fn probabilities(left: f64, right: f64) -> Option<(f64, f64)> {
        let total = left + right;
        if !(total > 0.0 && total.is_finite() && left >= 0.0 && right >= 0.0) {
            return None;
        }
        Some((left / total, right / total))
    }

    /// Chooses a side with weights `left` and `right` and rescales `u`.
    /// `None` when neither side can be chosen.
    #[inline]
    pub fn choose(&mut self, left: f64, right: f64) -> Option<Side> {
        let (pl, pr) = Self::probabilities(left, right)?;
        Some(self.choose_with(pl, pr))
    }

    /// Chooses left with probability `pl` and right with `pr` (`pl + pr`
    /// should be 1; callers pass the pair [`Descent::probabilities`] or a
    /// stored fraction gave).
    #[inline]
    pub fn choose_with(&mut self, pl: f64, pr: f64) -> Side {
        if self.u < pl {
            self.u = (self.u / pl).min(ONE_MINUS_EPS);
            self.pmf *= pl;
            Side::Left
        } else {
            // pr > 0 here unless the caller's pair is inconsistent; guard so
            // the state never becomes NaN.
            self.u = if pr > 0.0 {
                ((self.u - pl) / pr).clamp(0.0, ONE_MINUS_EPS)
            } else {
                0.0
            };
            self.pmf *= pr;
            Side::Right
        }
    }

    /// Records that `side` was taken at a node with weights `left`, `right`
    /// (pmf evaluation). Returns false when that side has probability 0.
    #[inline]
    pub fn follow(&mut self, left: f64, right: f64, side: Side) -> bool {
        match Self::probabilities(left, right) {
            Some((pl, pr)) => self.follow_with(pl, pr, side),
            None => {
                self.pmf = 0.0;
                false
            }
        }
    }

    /// Records that `side` was taken with the given pair of probabilities.
    #[inline]
    pub fn follow_with(&mut self, pl: f64, pr: f64, side: Side) -> bool {
        self.pmf *= match side {
            Side::Left => pl,
            Side::Right => pr,
        };
        self.pmf > 0.0
    }
}

/// Converts a final `f64` pmf to the `f32` the samplers return. A pmf that
/// rounds to zero in `f32` is reported as zero, and samplers then refuse the
/// draw, so `sample` and `pmf` still agree.
#[inline]
pub(crate) fn pmf_to_f32(pmf: f64) -> f32 {
    let p = pmf as f32;
    if p > 0.0 && p.is_finite() { p } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn follows_inverse_cdf_of_two_leaves() {
        let mut d = Descent::from_f64(0.2);
        assert_eq!(d.choose(1.0, 3.0), Some(Side::Left));
        assert!((d.u() - 0.8).abs() < 1e-15);
        assert_eq!(d.pmf(), 0.25);
        let mut d = Descent::new(0.25);
        assert_eq!(d.choose(1.0, 3.0), Some(Side::Right));
        assert_eq!(d.u(), 0.0);
        assert_eq!(d.pmf(), 0.75);
    }

    #[test]
    fn zero_weights_never_chosen() {
        for u in [0.0, 0.5, 1.0, -1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(Descent::new(u).choose(0.0, 1.0), Some(Side::Right));
            assert_eq!(Descent::new(u).choose(1.0, 0.0), Some(Side::Left));
            assert_eq!(Descent::new(u).choose(0.0, 0.0), None);
            assert_eq!(Descent::new(u).choose(f64::NAN, 1.0), None);
            assert_eq!(Descent::new(u).choose(-1.0, 2.0), None);
        }
    }

    #[test]
    fn sixty_four_halvings_keep_entropy() {
        // A chain where every node sends half of the mass right: the leaf at
        // depth k has probability 2^-(k+1) and owns [2^-(k+1), 2^-k). u in
        // [2^-41, 2^-40) walks left 40 times, then right.
        let u = 2f64.powi(-41) * 1.5;
        let mut d = Descent::from_f64(u);
        let mut depth = 0;
        while d.choose(1.0, 1.0) == Some(Side::Left) {
            depth += 1;
            assert!(depth < 64);
        }
        assert_eq!(depth, 40);
        assert_eq!(d.pmf(), 2f64.powi(-41));
    }

    #[test]
    fn follow_matches_choose_bit_for_bit() {
        let weights = [(3.0, 7.0), (1e-30, 1.0), (5.0, 5e-20), (0.1, 0.2)];
        for u in [0.0f32, 0.1, 0.3, 0.7, 0.99999994] {
            let mut s = Descent::new(u);
            let mut e = Descent::evaluate();
            for &(l, r) in &weights {
                let side = s.choose(l, r).unwrap();
                assert!(e.follow(l, r, side));
            }
            assert_eq!(s.pmf().to_bits(), e.pmf().to_bits());
        }
    }

    #[test]
    fn pmf_conversion_never_nan() {
        assert_eq!(pmf_to_f32(1e-60), 0.0);
        assert_eq!(pmf_to_f32(f64::NAN), 0.0);
        assert_eq!(pmf_to_f32(0.5), 0.5);
    }
}
