//! [`Strategy`]: a light sampler chosen by name, as pbrt's
//! `lightsamplestrategy`, owning everything it needs.

use crate::emitter::Emitters;
use crate::error::Error;
use crate::glt::{Glt, GltConfig};
use crate::light_sampler::ShadingContext;
use crate::light_sampler::{
    ImportanceTreeSampler, LightChoice, LightId, LightSample, LightSampler, PowerSampler,
    UnboundedLights, UniformSampler, WithUnbounded,
};
use crate::light_tree::{BuildHeuristic, LightTree};
use crate::math::Aabb;

/// A light-selection strategy by name: `"uniform"`, `"power"`,
/// `"importance"` (the light BVH of Estevez-Kulla and pbrt-v4) or `"glt"`
/// (the Guiding Light Tree, with its training side through
/// [`Strategy::glt`] and [`Strategy::glt_mut`]). It owns its light tree, is `Send + Sync`, and
/// samples exactly as the sampler it wraps, the scene's unbounded lights
/// (distant, infinite) beside the emitters.
///
/// ```
/// use guiding::{glam::Vec3, Aabb, Emitter, LightId, LightSampler};
/// use guiding::{ShadingContext, Strategy, UnboundedLights};
/// let lights = [Emitter::point(Vec3::Y, 1.0), Emitter::point(Vec3::X, 3.0)];
/// let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
/// let sun = UnboundedLights::new(1, 0.2)?;
/// let s = Strategy::new("power", &lights[..], sun, scene)?;
/// let ctx = ShadingContext::at(Vec3::ZERO);
/// assert_eq!(s.pmf(&ctx, LightId::Emitter(1)), 0.6);
/// assert_eq!(s.pmf(&ctx, LightId::Unbounded(0)), 0.2);
/// assert!(Strategy::new("bvh-2000", &lights[..], sun, scene).is_err());
/// # Ok::<(), guiding::Error>(())
/// ```
#[derive(Debug)]
pub enum Strategy {
    /// Every emitter equally (in proportion to their weights, if any).
    Uniform(WithUnbounded<UniformSampler>),
    /// In proportion to power.
    Power(WithUnbounded<PowerSampler>),
    /// Descending the light tree by importance at the shading point.
    Importance(WithUnbounded<ImportanceTreeSampler<LightTree>>),
    /// The Guiding Light Tree (learns; refine it between iterations).
    Glt(alloc::boxed::Box<Glt<LightTree>>),
}

impl Strategy {
    /// The names [`Strategy::new`] accepts.
    pub const NAMES: [&'static str; 4] = ["uniform", "power", "importance", "glt"];

    /// The strategy called `name` over `emitters` and the scene's
    /// `unbounded` lights ([`UnboundedLights::NONE`] for none); `scene`
    /// bounds the shading points (used by `"glt"`, with
    /// [`GltConfig::default`] and `unbounded` as its cuts' prior). Errors
    /// for an unknown name, an invalid `unbounded`, and emitters a light
    /// tree cannot be built from (`"importance"`, `"glt"`).
    pub fn new<E: Emitters + ?Sized>(
        name: &str,
        emitters: &E,
        unbounded: UnboundedLights,
        scene: Aabb,
    ) -> Result<Self, Error> {
        let tree = || LightTree::build(emitters, BuildHeuristic::default()).map_err(Error::Build);
        let u = unbounded;
        Ok(match name {
            "uniform" => Self::Uniform(WithUnbounded::new(UniformSampler::weighted(emitters), u)?),
            "power" => Self::Power(WithUnbounded::new(PowerSampler::new(emitters), u)?),
            "importance" => {
                Self::Importance(WithUnbounded::new(ImportanceTreeSampler::new(tree()?), u)?)
            }
            "glt" => {
                let mut config = GltConfig::default();
                config.cut.unbounded = unbounded;
                Self::Glt(alloc::boxed::Box::new(Glt::new(tree()?, scene, config)?))
            }
            _ => {
                return Err(Error::UnknownStrategy {
                    known: &Self::NAMES,
                });
            }
        })
    }

    /// Its name (one of [`Strategy::NAMES`]).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Uniform(_) => "uniform",
            Self::Power(_) => "power",
            Self::Importance(_) => "importance",
            Self::Glt(_) => "glt",
        }
    }

    /// The GLT, to record through its vertices
    /// ([`Glt::vertex`](crate::Glt::vertex)); `None` for the
    /// strategies that do not learn. As a [`LightSampler`] the strategy
    /// looks the GLT's cell up on every query; a renderer that records
    /// locates the vertex once here and samples through it.
    pub fn glt(&self) -> Option<&Glt<LightTree>> {
        match self {
            Self::Glt(g) => Some(g),
            _ => None,
        }
    }

    /// The GLT, to refine it; `None` for the strategies that do not learn.
    pub fn glt_mut(&mut self) -> Option<&mut Glt<LightTree>> {
        match self {
            Self::Glt(g) => Some(&mut **g),
            _ => None,
        }
    }
}

/// Calls `$call` on the chosen sampler at the point, as a
/// [`LightChoice`] (a `match`, not a virtual call: this runs per sample).
macro_rules! inner {
    ($self:ident, $ctx:expr, $c:ident => $call:expr, $none:expr) => {
        match $self {
            Strategy::Uniform(s) => {
                let $c = s.at($ctx);
                $call
            }
            Strategy::Power(s) => {
                let $c = s.at($ctx);
                $call
            }
            Strategy::Importance(s) => {
                let $c = s.at($ctx);
                $call
            }
            // By position: one lookup per call (a renderer that also
            // records locates the vertex once, through `Strategy::glt`).
            Strategy::Glt(g) => match g.vertex_uncounted($ctx) {
                Some($c) => $call,
                None => $none,
            },
        }
    };
}

impl LightSampler for Strategy {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        inner!(self, ctx, c => c.sample(u), None)
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        inner!(self, ctx, c => c.pmf(light), 0.0)
    }

    fn is_empty(&self) -> bool {
        match self {
            Strategy::Uniform(s) => s.is_empty(),
            Strategy::Power(s) => s.is_empty(),
            Strategy::Importance(s) => s.is_empty(),
            Strategy::Glt(g) => g.cut_rules().is_empty(),
        }
    }

    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        inner!(self, ctx, c => c.is_empty(), true)
    }

    #[inline]
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        inner!(self, ctx, c => c.sample_exact(u), None)
    }

    #[inline]
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        inner!(self, ctx, c => c.pmf_exact(light), 0.0)
    }

    fn visibility(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        inner!(self, ctx, c => c.visibility(light), 1.0)
    }

    fn sample_with_visibility(&self, ctx: &ShadingContext, u: f32) -> Option<(LightSample, f32)> {
        inner!(self, ctx, c => c.sample_with_visibility(u), None)
    }
}
