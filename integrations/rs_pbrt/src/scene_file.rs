//! Reads the pbrt-v3 scene files of `scenes/` into rs_pbrt's scene and
//! camera, through rs_pbrt's public constructors (its own parser lives in
//! its binary, and its API state keeps the scene private until it renders
//! with its own integrators).
//!
//! The subset the scenes use: `LookAt`, `Camera "perspective"`, `Film`,
//! `Sampler` and `Integrator` (read for the resolution, `pixelsamples` and
//! `maxdepth`), `WorldBegin`/`WorldEnd`, `AttributeBegin`/`AttributeEnd`,
//! `Translate`, `Scale`, `Material "matte"` (`rgb Kd`), `AreaLightSource
//! "diffuse"` (`rgb L`, `bool twosided`), `LightSource` `point`, `spot`,
//! `distant` and `infinite` (constant `rgb L`), `Shape` `sphere` and
//! `trianglemesh`. Anything else is an error naming the directive.

use rs_pbrt::core::api::{make_accelerator, make_camera, make_film, make_filter};
use rs_pbrt::core::camera::Camera;
use rs_pbrt::core::geometry::{Bounds2f, Point2f, Point3f, Vector3f};
use rs_pbrt::core::light::Light;
use rs_pbrt::core::material::Material;
use rs_pbrt::core::medium::MediumInterface;
use rs_pbrt::core::paramset::ParamSet;
use rs_pbrt::core::pbrt::Spectrum;
use rs_pbrt::core::primitive::{GeometricPrimitive, Primitive};
use rs_pbrt::core::scene::Scene;
use rs_pbrt::core::shape::Shape;
use rs_pbrt::core::transform::{AnimatedTransform, Transform};
use rs_pbrt::lights::diffuse::DiffuseAreaLight;
use rs_pbrt::lights::distant::DistantLight;
use rs_pbrt::lights::infinite::InfiniteAreaLight;
use rs_pbrt::lights::point::PointLight;
use rs_pbrt::lights::spot::SpotLight;
use rs_pbrt::materials::matte::MatteMaterial;
use rs_pbrt::shapes::sphere::Sphere;
use rs_pbrt::shapes::triangle::{Triangle, TriangleMesh};
use rs_pbrt::textures::constant::ConstantTexture;
use std::collections::HashMap;
use std::sync::Arc;

/// A scene read from a file, ready to render.
pub struct Loaded {
    /// rs_pbrt's scene: the geometry's BVH and the lights, the bounded ones
    /// first (distant and infinite lights last, as the glue maps them).
    pub scene: Scene,
    /// The camera (its film holds the resolution).
    pub camera: Arc<Camera>,
    /// Width and height in pixels.
    pub resolution: (usize, usize),
    /// The file's `pixelsamples` and `maxdepth`.
    pub spp: u32,
    /// The path tracer's depth limit.
    pub max_depth: u32,
    /// For each light (by index in `scene.lights`), the address of the
    /// primitive that carries it (area lights), to tell a BSDF sample that
    /// hit that light.
    pub primitive_of: Vec<Option<usize>>,
}

/// One token of a scene file.
#[derive(Clone, Debug, PartialEq)]
enum Token {
    Word(String),
    Quoted(String),
    Open,
    Close,
}

fn tokens(text: &str) -> Vec<Token> {
    let mut out = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(&c) = chars.peek() {
        match c {
            '#' => while chars.next_if(|&c| c != '\n').is_some() {},
            '[' | ']' => {
                chars.next();
                out.push(if c == '[' { Token::Open } else { Token::Close });
            }
            '"' => {
                chars.next();
                out.push(Token::Quoted(
                    chars.by_ref().take_while(|&c| c != '"').collect(),
                ));
            }
            c if c.is_whitespace() => {
                chars.next();
            }
            _ => {
                let mut w = String::new();
                while let Some(c) = chars.next_if(|c| !c.is_whitespace() && !"[]\"#".contains(*c)) {
                    w.push(c);
                }
                out.push(Token::Word(w));
            }
        }
    }
    out
}

/// A directive's parameters: `"type name" value(s)`.
#[derive(Default)]
struct Params(HashMap<String, Vec<String>>);

impl Params {
    fn floats(&self, name: &str) -> Option<Vec<f32>> {
        self.0
            .get(name)
            .map(|v| v.iter().map(|s| s.parse().unwrap_or(f32::NAN)).collect())
    }
    fn float(&self, name: &str, default: f32) -> f32 {
        self.floats(name)
            .and_then(|v| v.first().copied())
            .unwrap_or(default)
    }
    /// An `rgb` parameter, or pbrt's default `default` (grey) without one.
    fn rgb(&self, name: &str, default: f32) -> Spectrum {
        match self.floats(name).as_deref() {
            Some([r, g, b]) => Spectrum::rgb(*r, *g, *b),
            _ => Spectrum::new(default),
        }
    }
    fn point(&self, name: &str, default: [f32; 3]) -> Point3f {
        let [x, y, z] = match self.floats(name).as_deref() {
            Some([x, y, z]) => [*x, *y, *z],
            _ => default,
        };
        Point3f { x, y, z }
    }
    fn flag(&self, name: &str) -> bool {
        self.0
            .get(name)
            .is_some_and(|v| v.first().is_some_and(|s| s == "true"))
    }
}

/// What attributes carry: the transform, the material, the area light.
#[derive(Clone)]
struct State {
    transform: Transform,
    material: Arc<Material>,
    area_light: Option<(Spectrum, bool)>,
}

fn matte(kd: Spectrum) -> Arc<Material> {
    let kd = Arc::new(ConstantTexture::new(kd));
    Arc::new(Material::Matte(Box::new(MatteMaterial::new(
        kd,
        Arc::new(ConstantTexture::new(0.0)),
        None,
    ))))
}

fn vector(p: Point3f) -> Vector3f {
    Vector3f {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Reads the scene file at `path`.
pub fn load(path: &std::path::Path) -> Result<Loaded, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let toks = tokens(&text);
    let mut i = 0;
    let mut state = State {
        transform: Transform::default(),
        material: matte(Spectrum::new(0.5)),
        area_light: None,
    };
    let mut stack: Vec<State> = Vec::new();
    let (mut camera_to_world, mut fov, mut resolution, mut spp, mut max_depth) =
        (Transform::default(), 90.0, (160, 120), 16, 5);
    let mut prims: Vec<Arc<Primitive>> = Vec::new();
    let mut lights: Vec<(Arc<Light>, Option<usize>)> = Vec::new();
    let number = |t: &Token| match t {
        Token::Word(w) => w.parse::<f32>().map_err(|_| format!("not a number: {w}")),
        t => Err(format!("not a number: {t:?}")),
    };
    while i < toks.len() {
        let Token::Word(directive) = &toks[i] else {
            return Err(format!("expected a directive, found {:?}", toks[i]));
        };
        i += 1;
        let args = |n: usize, i: &mut usize| -> Result<Vec<f32>, String> {
            let v = toks
                .get(*i..*i + n)
                .ok_or("file ends too early")?
                .iter()
                .map(number)
                .collect();
            *i += n;
            v
        };
        // Positional arguments, then a type (a quoted string) for some.
        match directive.as_str() {
            "LookAt" => {
                let a = args(9, &mut i)?;
                let p = |k: usize| Point3f {
                    x: a[k],
                    y: a[k + 1],
                    z: a[k + 2],
                };
                let look = Transform::look_at(&p(0), &p(3), &vector(p(6)));
                state.transform = state.transform * look;
                continue;
            }
            "Translate" => {
                let a = args(3, &mut i)?;
                state.transform = state.transform
                    * Transform::translate(&Vector3f {
                        x: a[0],
                        y: a[1],
                        z: a[2],
                    });
                continue;
            }
            "Scale" => {
                let a = args(3, &mut i)?;
                state.transform = state.transform * Transform::scale(a[0], a[1], a[2]);
                continue;
            }
            "WorldBegin" => {
                state.transform = Transform::default();
                continue;
            }
            "WorldEnd" => break,
            "AttributeBegin" => {
                stack.push(state.clone());
                continue;
            }
            "AttributeEnd" => {
                state = stack.pop().ok_or("AttributeEnd without AttributeBegin")?;
                continue;
            }
            _ => {}
        }
        let Some(Token::Quoted(kind)) = toks.get(i).cloned() else {
            return Err(format!("{directive}: no type"));
        };
        i += 1;
        let mut params = Params::default();
        while let Some(Token::Quoted(decl)) = toks.get(i) {
            let name = decl.split_whitespace().last().unwrap_or("").to_string();
            i += 1;
            let mut values = Vec::new();
            match toks.get(i) {
                Some(Token::Open) => {
                    i += 1;
                    while let Some(t) = toks.get(i).filter(|t| **t != Token::Close) {
                        values.push(match t {
                            Token::Word(w) | Token::Quoted(w) => w.clone(),
                            _ => return Err(format!("{directive}: bad value")),
                        });
                        i += 1;
                    }
                    i += 1;
                }
                Some(Token::Word(w) | Token::Quoted(w)) => {
                    values.push(w.clone());
                    i += 1;
                }
                _ => return Err(format!("{directive}: {name} has no value")),
            }
            // Numbers must be finite numbers, triples come in threes: a
            // bad file is an error naming the parameter, never a NaN.
            let ty = decl.split_whitespace().next().unwrap_or("");
            let numeric = [
                "float", "integer", "rgb", "color", "point", "normal", "vector",
            ];
            if numeric.contains(&ty) {
                if let Some(bad) = values
                    .iter()
                    .find(|v| !v.parse::<f32>().is_ok_and(f32::is_finite))
                {
                    return Err(format!("{directive}: {name}: not a finite number: {bad}"));
                }
                if ty != "float" && ty != "integer" && values.len() % 3 != 0 {
                    return Err(format!(
                        "{directive}: {name}: {} values, not triples",
                        values.len()
                    ));
                }
            }
            params.0.insert(name, values);
        }
        match (directive.as_str(), kind.as_str()) {
            ("Camera", "perspective") => {
                camera_to_world = Transform::inverse(&state.transform);
                fov = params.float("fov", 90.0);
            }
            ("Film", _) => {
                resolution = (
                    params.float("xresolution", 160.0) as usize,
                    params.float("yresolution", 120.0) as usize,
                )
            }
            ("Sampler", _) => spp = params.float("pixelsamples", 16.0) as u32,
            ("Integrator", _) => max_depth = params.float("maxdepth", 5.0) as u32,
            ("Material", "matte") => state.material = matte(params.rgb("Kd", 0.5)),
            ("AreaLightSource", "diffuse") => {
                state.area_light = Some((params.rgb("L", 1.0), params.flag("twosided")))
            }
            ("LightSource", light) => {
                let (t, mi) = (&state.transform, MediumInterface::default());
                let (from, to) = (
                    params.point("from", [0.0; 3]),
                    params.point("to", [0.0, 0.0, 1.0]),
                );
                let light = match light {
                    "point" => Light::Point(Box::new(PointLight::new(
                        &(*t * Transform::translate(&vector(from))),
                        &mi,
                        &params.rgb("I", 1.0),
                    ))),
                    "spot" => {
                        let dir = Transform::look_at(
                            &from,
                            &to,
                            &Vector3f {
                                x: 0.0,
                                y: 1.0,
                                z: 0.0,
                            },
                        );
                        let l2w = *t * Transform::inverse(&dir);
                        let (cone, delta) = (
                            params.float("coneangle", 30.0),
                            params.float("conedeltaangle", 5.0),
                        );
                        Light::Spot(Box::new(SpotLight::new(
                            &l2w,
                            &mi,
                            &params.rgb("I", 1.0),
                            cone,
                            cone - delta,
                        )))
                    }
                    "distant" => Light::Distant(Box::new(DistantLight::new(
                        t,
                        &params.rgb("L", 1.0),
                        &(from - to),
                    ))),
                    "infinite" => Light::InfiniteArea(Box::new(InfiniteAreaLight::new(
                        t,
                        &params.rgb("L", 1.0),
                        1,
                        String::new(),
                    ))),
                    other => return Err(format!("LightSource \"{other}\" is not read")),
                };
                lights.push((Arc::new(light), None));
            }
            ("Shape", shape) => {
                let t = state.transform;
                let shapes: Vec<Arc<Shape>> = match shape {
                    "sphere" => {
                        let r = params.float("radius", 1.0);
                        vec![Arc::new(Shape::Sphr(Sphere::new(
                            t,
                            Transform::inverse(&t),
                            false,
                            r,
                            -r,
                            r,
                            360.0,
                        )))]
                    }
                    "trianglemesh" => {
                        let p = params.floats("P").ok_or("trianglemesh without P")?;
                        // Read as integers: through `f32` an index past
                        // 2^24 would round to another vertex.
                        let idx: Vec<u32> = params
                            .0
                            .get("indices")
                            .ok_or("trianglemesh without indices")?
                            .iter()
                            .map(|s| s.parse().map_err(|_| format!("trianglemesh: index {s}")))
                            .collect::<Result<_, _>>()?;
                        let world: Vec<Point3f> = p
                            .chunks_exact(3)
                            .map(|c| {
                                t.transform_point(&Point3f {
                                    x: c[0],
                                    y: c[1],
                                    z: c[2],
                                })
                            })
                            .collect();
                        if idx.iter().any(|&k| k as usize >= world.len()) {
                            return Err("trianglemesh: an index past its points".into());
                        }
                        let n = (idx.len() / 3) as u32;
                        let mesh = Arc::new(TriangleMesh::new(
                            t,
                            Transform::inverse(&t),
                            false,
                            n,
                            idx,
                            world.len() as u32,
                            world,
                            vec![],
                            vec![],
                            vec![],
                            None,
                            None,
                        ));
                        (0..n)
                            .map(|k| Arc::new(Shape::Trngl(Triangle::new(mesh.clone(), k))))
                            .collect()
                    }
                    other => return Err(format!("Shape \"{other}\" is not read")),
                };
                for shape in shapes {
                    let light = state.area_light.map(|(l, two_sided)| {
                        let mi = MediumInterface::default();
                        Arc::new(Light::DiffuseArea(Box::new(DiffuseAreaLight::new(
                            &t,
                            &mi,
                            &l,
                            1,
                            shape.clone(),
                            two_sided,
                        ))))
                    });
                    let prim = Arc::new(Primitive::Geometric(Box::new(GeometricPrimitive::new(
                        shape,
                        Some(state.material.clone()),
                        light.clone(),
                        None,
                    ))));
                    if let Some(light) = light {
                        lights.push((light, Some(Arc::as_ptr(&prim) as usize)));
                    }
                    prims.push(prim);
                }
            }
            (d, k) => return Err(format!("{d} \"{k}\" is not read")),
        }
    }
    let aggregate = make_accelerator("bvh", &prims, &ParamSet::default()).ok_or("no BVH")?;
    // Bounded lights first, distant and infinite ones last: the order the
    // glue maps to the crate's emitters and unbounded lights.
    lights.sort_by_key(|(l, _)| matches!(**l, Light::Distant(_) | Light::InfiniteArea(_)));
    let primitive_of = lights.iter().map(|(_, p)| *p).collect();
    let scene = Scene::new(aggregate, lights.into_iter().map(|(l, _)| l).collect());
    let mut film_params = ParamSet::default();
    film_params.add_int("xresolution".into(), resolution.0 as i32);
    film_params.add_int("yresolution".into(), resolution.1 as i32);
    let filter = make_filter("box", &ParamSet::default()).ok_or("no filter")?;
    let crop = Bounds2f {
        p_min: Point2f { x: 0.0, y: 0.0 },
        p_max: Point2f { x: 1.0, y: 1.0 },
    };
    let film = make_film("image", &film_params, filter, &crop).ok_or("no film")?;
    let mut camera_params = ParamSet::default();
    camera_params.add_float("fov".into(), fov);
    let moving = AnimatedTransform::new(&camera_to_world, 0.0, &camera_to_world, 1.0);
    let camera =
        make_camera("perspective", &camera_params, moving, film, 0.0).ok_or("no camera")?;
    Ok(Loaded {
        scene,
        camera,
        resolution,
        spp,
        max_depth,
        primitive_of,
    })
}
