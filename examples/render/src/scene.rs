//! A renderable scene: geometry in a BVH, materials, emitters, camera, and
//! the effects it declares (the integrator simulates exactly those).

use crate::bvh::{Bvh, Hit};
use crate::camera::Camera;
use crate::geometry::{NO_EMITTER, Primitive};
use crate::lights::{Light, LightKind, Unbounded};
use crate::materials::{Material, MaterialKind};
use glam::Vec3;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{Emitter, LightTree, UnboundedLights};

/// The light-transport effects a scene needs. Building a scene checks that
/// it uses nothing it did not declare; the integrator implements exactly
/// this set (no media, spectra or textures).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Effects {
    /// Lambertian surfaces.
    pub diffuse: bool,
    /// GGX glossy reflection.
    pub glossy: bool,
    /// Smooth dielectric interfaces.
    pub dielectric: bool,
    /// Quad emitters.
    pub quad_lights: bool,
    /// Sphere emitters.
    pub sphere_lights: bool,
    /// Triangle (mesh) emitters.
    pub triangle_lights: bool,
    /// A constant environment light (a sky).
    pub sky: bool,
    /// A distant delta light (a sun).
    pub sun: bool,
    /// Maximum number of path segments from the camera.
    pub max_depth: u32,
}

impl Effects {
    /// One line naming the declared effects.
    pub fn describe(&self) -> String {
        let mut v = Vec::new();
        let flags = [
            (self.diffuse, "diffuse"),
            (self.glossy, "glossy"),
            (self.dielectric, "dielectric"),
            (self.quad_lights, "quad lights"),
            (self.sphere_lights, "sphere lights"),
            (self.triangle_lights, "triangle lights"),
            (self.sky, "sky"),
            (self.sun, "sun"),
        ];
        for (on, name) in flags {
            if on {
                v.push(name.to_string());
            }
        }
        v.push(format!("depth {}", self.max_depth));
        v.join(", ")
    }

    fn allows_material(&self, kind: MaterialKind) -> bool {
        match kind {
            MaterialKind::Diffuse => self.diffuse,
            MaterialKind::Glossy => self.glossy,
            MaterialKind::Dielectric => self.dielectric,
        }
    }

    fn allows_light(&self, kind: LightKind) -> bool {
        match kind {
            LightKind::Quad => self.quad_lights,
            LightKind::Triangle => self.triangle_lights,
            LightKind::Sphere => self.sphere_lights,
        }
    }
}

/// Everything the integrator needs about a scene.
pub struct Scene {
    /// Name (as on the command line).
    pub name: String,
    /// Declared effects.
    pub effects: Effects,
    /// Geometry.
    pub bvh: Bvh,
    /// Materials, indexed by [`Primitive::material`].
    pub materials: Vec<Material>,
    /// Emitters, indexed by [`Primitive::emitter`] and by the crate's
    /// `LightId::Emitter`.
    pub lights: Vec<Light>,
    /// The emitters as the crate sees them.
    pub emitters: Vec<Emitter>,
    /// The global light tree, built once.
    pub light_tree: LightTree,
    /// The unbounded lights (sky, sun): the crate's
    /// `LightId::Unbounded(i)` is `unbounded[i]`.
    pub unbounded: Vec<Unbounded>,
    /// Camera.
    pub camera: Camera,
    /// Bounds of all geometry.
    pub bounds: Aabb,
    /// The unbounded lights as the crate sees them: how many, and the
    /// probability fixed light samplers choose one with (the GLT's prior
    /// for them).
    pub unbounded_lights: UnboundedLights,
    /// A hash of the scene's content, part of the reference cache key.
    pub fingerprint: u64,
    /// False when emitters seen directly by the camera (also through
    /// specular reflection or refraction) are left out of the image, as in
    /// the paper's RMSE insets: tiny lights hit by camera rays only add
    /// pixel-sampling noise that no light sampler can change.
    pub camera_sees_emitters: bool,
}

impl Scene {
    /// The sky (the one non-delta unbounded light) and its id, if any.
    pub fn sky(&self) -> Option<(guiding::LightId, &crate::lights::Environment)> {
        self.unbounded
            .iter()
            .enumerate()
            .find_map(|(i, u)| match u {
                Unbounded::Sky(sky) => Some((guiding::LightId::Unbounded(i as u32), sky)),
                Unbounded::Sun(_) => None,
            })
    }

    /// Closest hit.
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3) -> Option<Hit> {
        self.bvh.intersect(origin, dir, f32::INFINITY)
    }

    /// True when the segment is blocked by anything but the primitives of
    /// emitter `target` (pass `NO_EMITTER` to test everything).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32, target: u32) -> bool {
        self.bvh.occluded_except(origin, dir, tmax, target)
    }

    /// The primitive of a hit.
    #[inline]
    pub fn primitive(&self, hit: &Hit) -> &Primitive {
        &self.bvh.primitives()[hit.primitive as usize]
    }
}

/// Collects primitives, materials and lights, then checks them against the
/// declared effects and builds the acceleration structures.
#[derive(Default)]
pub struct SceneBuilder {
    prims: Vec<Primitive>,
    materials: Vec<Material>,
    lights: Vec<Light>,
    emitter_material: Option<u32>,
    hide_emitters: bool,
}

impl SceneBuilder {
    /// An empty scene.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a material and returns its index.
    pub fn material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }

    /// Leave emitters that camera rays hit directly out of the image.
    pub fn hide_emitters_from_camera(&mut self) {
        self.hide_emitters = true;
    }

    fn black(&mut self) -> u32 {
        match self.emitter_material {
            Some(m) => m,
            None => {
                let m = self.material(Material::Diffuse { albedo: Vec3::ZERO });
                self.emitter_material = Some(m);
                m
            }
        }
    }

    /// A triangle.
    pub fn triangle(&mut self, a: Vec3, b: Vec3, c: Vec3, material: u32) {
        self.prims
            .push(Primitive::triangle(a, b, c, material, NO_EMITTER));
    }

    /// A parallelogram `corner + s e1 + t e2` as two triangles (normal
    /// `e1 x e2`).
    pub fn quad(&mut self, corner: Vec3, e1: Vec3, e2: Vec3, material: u32) {
        self.triangle(corner, corner + e1, corner + e1 + e2, material);
        self.triangle(corner, corner + e1 + e2, corner + e2, material);
    }

    /// An axis-aligned box (faces facing outwards).
    pub fn cuboid(&mut self, min: Vec3, max: Vec3, material: u32) {
        let d = max - min;
        let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        self.quad(min, x, z, material);
        self.quad(min + y, z, x, material);
        self.quad(min, y, x, material);
        self.quad(min + z, x, y, material);
        self.quad(min, z, y, material);
        self.quad(min + x, y, z, material);
    }

    /// A box with centre `c` and half-axis vectors `a`, `b`, `d` (a right-handed,
    /// orthogonal set), faces facing outwards.
    pub fn oriented_box(&mut self, c: Vec3, a: Vec3, b: Vec3, d: Vec3, material: u32) {
        let lo = c - a - b - d;
        let (x, y, z) = (2.0 * a, 2.0 * b, 2.0 * d);
        self.quad(lo, x, z, material);
        self.quad(lo + y, z, x, material);
        self.quad(lo, y, x, material);
        self.quad(lo + z, x, y, material);
        self.quad(lo, z, y, material);
        self.quad(lo + x, y, z, material);
    }

    /// Triangles `[a, b, c]` with normals `(b - a) x (c - a)`.
    pub fn mesh(&mut self, tris: &[[Vec3; 3]], material: u32) {
        for t in tris {
            self.triangle(t[0], t[1], t[2], material);
        }
    }

    /// A sphere.
    pub fn sphere(&mut self, center: Vec3, radius: f32, material: u32) {
        self.prims
            .push(Primitive::sphere(center, radius, material, NO_EMITTER));
    }

    /// A one-sided quad emitter (emits along `e1 x e2`).
    pub fn quad_light(&mut self, corner: Vec3, e1: Vec3, e2: Vec3, radiance: Vec3) {
        let m = self.black();
        let id = self.lights.len() as u32;
        self.lights.push(Light {
            shape: crate::lights::LightShape::Quad { corner, e1, e2 },
            radiance,
        });
        let (a, b, c, d) = (corner, corner + e1, corner + e1 + e2, corner + e2);
        self.prims.push(Primitive::triangle(a, b, c, m, id));
        self.prims.push(Primitive::triangle(a, c, d, m, id));
    }

    /// A one-sided triangle emitter (emits along `(b - a) x (c - a)`).
    pub fn triangle_light(&mut self, a: Vec3, b: Vec3, c: Vec3, radiance: Vec3) {
        let m = self.black();
        let id = self.lights.len() as u32;
        self.lights.push(Light {
            shape: crate::lights::LightShape::Triangle {
                v0: a,
                e1: b - a,
                e2: c - a,
            },
            radiance,
        });
        self.prims.push(Primitive::triangle(a, b, c, m, id));
    }

    /// A spherical emitter.
    pub fn sphere_light(&mut self, center: Vec3, radius: f32, radiance: Vec3) {
        let m = self.black();
        let id = self.lights.len() as u32;
        self.lights.push(Light {
            shape: crate::lights::LightShape::Sphere { center, radius },
            radiance,
        });
        self.prims.push(Primitive::sphere(center, radius, m, id));
    }

    /// Checks the content against `effects` and builds the scene.
    ///
    /// # Panics
    /// When the scene uses an effect it did not declare, or the crate
    /// rejects its emitters: both are bugs in the scene's code.
    pub fn build(
        self,
        name: &str,
        effects: Effects,
        camera: Camera,
        unbounded: Vec<Unbounded>,
    ) -> Scene {
        for m in &self.materials {
            assert!(
                effects.allows_material(m.kind()),
                "scene {name} uses {:?} without declaring it",
                m.kind()
            );
        }
        for l in &self.lights {
            assert!(
                effects.allows_light(l.kind()),
                "scene {name} uses {:?} lights without declaring them",
                l.kind()
            );
        }
        let count = |sun| {
            let is = |u: &&Unbounded| matches!(u, Unbounded::Sun(_)) == sun;
            unbounded.iter().filter(is).count()
        };
        assert!(
            count(false) == usize::from(effects.sky) && (count(true) > 0) == effects.sun,
            "scene {name}: unbounded lights and their declaration disagree (one sky at most)"
        );
        let mut bounds = Aabb::EMPTY;
        for p in &self.prims {
            let (lo, hi) = p.bounds();
            bounds = bounds.union(&Aabb::new(lo, hi));
        }
        let emitters: Vec<Emitter> = self.lights.iter().map(|l| l.to_emitter()).collect();
        let light_tree = LightTree::build(&emitters, BuildHeuristic::default())
            .unwrap_or_else(|e| panic!("scene {name}: light tree: {e}"));
        let mut fingerprint = crate::rng::mix64(self.prims.len() as u64);
        for l in self.lights.iter().step_by(97) {
            fingerprint = crate::rng::mix64(
                fingerprint ^ u64::from(l.to_emitter().power.to_bits()) ^ (l.kind() as u64),
            );
        }
        for u in &unbounded {
            let (kind, v) = match u {
                Unbounded::Sky(sky) => (1, sky.radiance),
                Unbounded::Sun(sun) => (2, sun.radiance + sun.direction * 7.0),
            };
            for x in v.to_array() {
                fingerprint = crate::rng::mix64(fingerprint ^ kind ^ u64::from(x.to_bits()));
            }
        }
        for v in camera.eye.to_array() {
            fingerprint = crate::rng::mix64(fingerprint ^ u64::from(v.to_bits()));
        }
        let unbounded_lights = match unbounded.len() as u32 {
            0 => UnboundedLights::NONE,
            n => UnboundedLights::new(n, 0.25).expect("a valid share"),
        };
        Scene {
            name: name.to_string(),
            effects,
            bvh: Bvh::build(self.prims),
            materials: self.materials,
            lights: self.lights,
            emitters,
            light_tree,
            unbounded,
            camera,
            bounds,
            unbounded_lights,
            fingerprint,
            camera_sees_emitters: !self.hide_emitters,
        }
    }
}
