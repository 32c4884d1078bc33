//! What the kernel reads per query and writes per answer (the WGSL
//! `Query` and `Answer` structs, word for word).

use bytemuck::{Pod, Zeroable};
use guiding::LightId;

/// The top bit of an answer's light word: an unbounded light.
const UNBOUNDED: u32 = 1 << 31;
/// An answer's light word when nothing was chosen.
const NOTHING: u32 = u32::MAX;

/// One query: a shading point, its normal (all zero: none), the uniform
/// number a sample draws with, and the light a pmf evaluation asks for.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Query {
    /// Position.
    pub p: [f32; 3],
    /// The uniform number in `[0, 1)` (sampling).
    pub u: f32,
    /// The normal, or zero.
    pub n: [f32; 3],
    /// The light asked for (pmf evaluation), as [`Query::light_word`]
    /// encodes it.
    pub light: u32,
}

impl Query {
    /// A sampling query at `p` with `normal` and number `u`.
    pub fn new(p: [f32; 3], normal: Option<[f32; 3]>, u: f32) -> Self {
        Self {
            p,
            u,
            n: normal.unwrap_or([0.0; 3]),
            light: NOTHING,
        }
    }

    /// This query asking for the pmf of `light`.
    pub fn with_light(self, light: LightId) -> Self {
        Self {
            light: Self::light_word(light),
            ..self
        }
    }

    /// How the kernel names a light: emitter `e` as `e`, unbounded light
    /// `i` as `1 << 31 | i`.
    pub fn light_word(light: LightId) -> u32 {
        match light {
            LightId::Emitter(e) => e & !UNBOUNDED,
            LightId::Unbounded(i) => UNBOUNDED | i,
        }
    }
}

/// One answer: the light chosen (or asked for), its pmf and the learned
/// visibility of its cluster.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Answer {
    /// The light word ([`Query::light_word`]; `u32::MAX`: nothing).
    pub light: u32,
    /// Its pmf.
    pub pmf: f32,
    /// The learned visibility of its cluster (sampling; 1 for pmf queries).
    pub visibility: f32,
    /// Unused.
    pub pad: u32,
}

impl Answer {
    /// The light, `None` when nothing was chosen.
    pub fn light(&self) -> Option<LightId> {
        match self.light {
            NOTHING => None,
            w if w & UNBOUNDED != 0 => Some(LightId::Unbounded(w & !UNBOUNDED)),
            w => Some(LightId::Emitter(w)),
        }
    }
}
