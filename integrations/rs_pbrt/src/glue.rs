//! The glue between rs_pbrt and `guiding`: rs_pbrt's lights described to the
//! crate, the GLT built over them, one shading point's light choice and records.

use crate::path_tracer::{LightAt, LightStrategy};
use guiding::glam::Vec3;
use guiding::{Aabb, Emitter, Glt, GltConfig, LightChoice, LightId, LightTree};
use guiding::{LightVertex, ShadingContext, UnboundedLights, luminance};
use rs_pbrt::core::{geometry::Point2f, interaction::SurfaceInteraction, light::Light};
use rs_pbrt::core::{scene::Scene, shape::Shape};

/// rs_pbrt's points, normals and vectors as the crate's.
macro_rules! v {
    ($p:expr) => {
        Vec3::new($p.x, $p.y, $p.z)
    };
}

/// An rs_pbrt light as an [`Emitter`] of its `power()`'s luminance; `None`
/// for distant and infinite lights, the crate's unbounded lights.
fn emitter(light: &Light) -> Option<Emitter> {
    let power = luminance(Vec3::from(light.power().c));
    Some(match light {
        Light::Point(l) => Emitter::point(v!(l.p_light), power),
        Light::GonioPhotometric(l) => Emitter::point(v!(l.p_light), power), // bounded as a point
        Light::Projection(l) => Emitter::point(v!(l.p_light), power),
        Light::Spot(l) => {
            let m = l.light_to_world.m.m; // its third column: where the spot points
            let axis = Vec3::new(m[0][2], m[1][2], m[2][2]);
            let (start, end) = (l.cos_falloff_start, l.cos_total_width);
            Emitter::spot(v!(l.p_light), axis, start, end, power)
        }
        Light::DiffuseArea(l) => {
            let b = l.shape.world_bound();
            let bounds = Aabb::new(v!(b.p_min), v!(b.p_max));
            let (center, radius) = (bounds.center(), 0.5 * bounds.diagonal().x);
            let on_it = l.shape.sample(Point2f::default(), &mut 0.0);
            let normal = match l.shape.as_ref() {
                Shape::Sphr(_) => return Some(Emitter::sphere(center, radius, power)),
                Shape::Trngl(_) | Shape::Dsk(_) => v!(on_it.n),
                _ => Vec3::ZERO, // curved: bounded by every direction
            };
            let mut e = Emitter::area(bounds, normal, l.area, power);
            e.two_sided = l.two_sided;
            e
        }
        Light::Distant(_) | Light::InfiniteArea(_) => return None,
    })
}

/// The GLT over an rs_pbrt scene's lights, which the scene lists emitters
/// first: light `i` is emitter `i`, then unbounded light `i - emitters`.
pub struct GltStrategy(Glt<LightTree>, u32);

impl GltStrategy {
    /// The GLT with the crate's defaults; a sun and sky take 10% until learned.
    pub fn new(scene: &Scene) -> Result<Self, Box<dyn std::error::Error>> {
        let described: Vec<Option<Emitter>> = scene.lights.iter().map(|l| emitter(l)).collect();
        if !described.is_sorted_by_key(Option::is_none) {
            return Err("list the scene's emitters before its distant and infinite lights".into());
        }
        let lights: Vec<Emitter> = described.into_iter().flatten().collect();
        let (n, all) = (lights.len() as u32, scene.lights.len() as u32);
        let mut config = GltConfig::default();
        config.cut.unbounded = UnboundedLights::new(all - n, if all > n { 0.1 } else { 0.0 })?;
        let world = Aabb::new(v!(scene.world_bound.p_min), v!(scene.world_bound.p_max));
        let tree = LightTree::build(&lights, Default::default())?;
        let glt = Glt::new(tree, world, config)?;
        Ok(Self(glt, n))
    }
}

impl GltStrategy {
    /// The GLT (for a tile renderer's threads to share through a
    /// [`SharedGuide`](guiding::SharedGuide)), and how many of the scene's lights are emitters.
    pub fn into_parts(self) -> (Glt<LightTree>, u32) {
        (self.0, self.1)
    }
}

/// The GLT through a borrow (a [`SharedGuide`](guiding::SharedGuide)'s read guard).
pub struct GltRef<'g>(pub &'g Glt<LightTree>, pub u32);

/// The GLT's view from one shading point: its vertex (one lookup; it
/// keeps the context).
pub struct GltAt<'a>(Option<LightVertex<'a, LightTree>>, u32);

fn glt_at<'a>(glt: &'a Glt<LightTree>, emitters: u32, it: &SurfaceInteraction) -> GltAt<'a> {
    let ctx = ShadingContext::facing(v!(it.common.p), v!(it.shading.n), v!(it.common.wo));
    GltAt(glt.vertex(&ctx), emitters)
}

impl LightStrategy for GltStrategy {
    type At<'a> = GltAt<'a>;

    fn at<'a>(&'a self, it: &SurfaceInteraction) -> GltAt<'a> {
        glt_at(&self.0, self.1, it)
    }

    fn refine(&mut self) {
        self.0.refine();
    }
}

impl LightStrategy for GltRef<'_> {
    type At<'a>
        = GltAt<'a>
    where
        Self: 'a;

    fn at<'a>(&'a self, it: &SurfaceInteraction) -> GltAt<'a> {
        glt_at(self.0, self.1, it)
    }
}

impl LightAt for GltAt<'_> {
    fn choose(&self, u: f32) -> Option<(usize, f32)> {
        let s = self.0.as_ref()?.sample(u)?;
        Some((s.light.index(self.1) as usize, s.pmf))
    }

    fn record(&self, light: usize, value: f32) {
        if let Some(v) = &self.0 {
            v.record_light(LightId::from_index(light as u32, self.1), value);
        }
    }
}
