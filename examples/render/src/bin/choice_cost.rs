//! `choice_cost`: what one light choice costs, per operation, on the render
//! example's scenes, for every light sampler the render example compares.
//!
//! At first non-specular hits of camera rays it runs, for the GLT of
//! `pt-glt` and the combined field of `ppg-glt` (both trained as the render
//! example trains them), pbrt-v4's light BVH, power and uniform:
//!
//! - `lookup`: the one lookup per vertex (`Glt::vertex`, `GuidingField::vertex`;
//!   `LightSampler::at` for the fixed samplers);
//! - `sample`: one light sample at a looked-up vertex;
//! - `pmf-sampled`: the pmf of the light just sampled;
//! - `pmf-hit`: the pmf of a light a cosine-sampled BSDF ray hit;
//! - `candidates`: 8 resampling candidates at one vertex, one
//!   `sample_with_visibility` each;
//! - `candidates-shared`: the same 8 in one `sample_candidates` call (as
//!   `guiding::resample` draws them: a guide's walks share their common
//!   steps; checked equal, bit for bit, to `candidates`' choices);
//! - `record`: one light record (the guides only).
//!
//! It prints the median time per operation over `--reps` repetitions
//! (noisy on a shared machine: compare ratios from one run), and with
//! `--callgrind` the instructions per operation, counted by valgrind in a
//! child process that loads the guides trained here (repeatable whatever
//! else the machine runs):
//!
//! ```text
//! cargo run --release --bin choice_cost -- --scene city,ring,torus --callgrind
//! ```
//!
//! How the cost grows with the number of emitters: the city on grids of 2
//! to 61 blocks (1k to 1M emitters), `--scene city:2,city:6,city:20,city:61`.
//!
//! Each operation is its own `#[inline(never)]` function per sampler
//! (`choice_cost::glt::sample`, ...), so callgrind's inclusive count of a
//! function divided by the operations it ran is the cost of one.

use clap::Parser;
use guiding::config::ImportanceBound;
use guiding::field::GuidingField;
use guiding::glt::Glt;
use guiding::{LightChoice, LightId, LightSample, LightSampler, LightTree, ShadingContext};
use guiding_render::geometry::{Frame, NO_EMITTER, offset_origin};
use guiding_render::glt_variant::GltVariant;
use guiding_render::materials::cosine_hemisphere;
use guiding_render::methods::{self, Method};
use guiding_render::scene::Scene;
use guiding_render::{cli, rng, run, scenes, shading_points};
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

/// The number of resampling candidates `candidates` draws per vertex.
const CANDIDATES: usize = 8;

#[derive(Parser, Debug, Clone)]
#[command(about = "Instructions and time per light-choice operation")]
struct Args {
    /// Scenes, comma-separated; `city:<blocks>` is the city on a
    /// `blocks` x `blocks` grid (`city` is `city:20`, about 108k emitters;
    /// `city:2,city:6,city:20,city:61` spans 1k to 1M).
    #[arg(long, default_value = "city,ring,torus", value_delimiter = ',')]
    scene: Vec<String>,
    /// Shading points.
    #[arg(long, default_value_t = 4096)]
    points: usize,
    /// Samples per pixel the guides train with (at --width x --height).
    #[arg(long, default_value_t = 32)]
    train_spp: u64,
    /// Training image width.
    #[arg(long, default_value_t = 128)]
    width: u32,
    /// Training image height.
    #[arg(long, default_value_t = 96)]
    height: u32,
    /// Timed repetitions of each operation (the median is printed).
    #[arg(long, default_value_t = 15)]
    reps: usize,
    /// Also count instructions per operation under valgrind's callgrind.
    #[arg(long)]
    callgrind: bool,
    /// Samplers, comma-separated (glt, field, bvh, power, uniform).
    #[arg(
        long,
        default_value = "glt,field,bvh,power,uniform",
        value_delimiter = ','
    )]
    samplers: Vec<String>,
    /// Operations, comma-separated (lookup, sample, pmf-sampled, pmf-hit,
    /// candidates, candidates-shared, record).
    #[arg(
        long,
        default_value = "lookup,sample,pmf-sampled,pmf-hit,candidates,candidates-shared,record",
        value_delimiter = ','
    )]
    ops: Vec<String>,
    /// The bound the trained guides' importance rules weigh children by
    /// (`children` or `grandchildren`, the crate's default).
    #[arg(long, default_value = "grandchildren", value_parser = cli::parse_importance_bound)]
    importance_bound: ImportanceBound,
    /// The trained guides' rules, as `light_limit --glt` takes them
    /// (space-separated `key=value`, e.g. `below=power prior=power` or
    /// `rules=paper`), applied after `--importance-bound`: what each rule
    /// costs, beside what `light_limit` says it is worth.
    #[arg(long, default_value = "")]
    glt: String,
    /// Where the trained guides are kept for the callgrind child.
    #[arg(long, default_value = "out/choice_cost")]
    out: PathBuf,
    /// Also print the mean walk length of sampled lights, inside and
    /// below the cut.
    #[arg(long)]
    stats: bool,
    /// Also plot each sampler's cost per `sample` and per `pmf-hit`
    /// against the scenes' emitter counts (instructions with --callgrind,
    /// else time), log-log, to `<PLOT>-sample.svg` and `<PLOT>-pmf-hit.svg`
    /// (and `.png`).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// (Internal) load the guides from --out instead of training: the
    /// callgrind child.
    #[arg(long, hide = true)]
    child: bool,
}

/// The operations, in table order.
const OPS: [&str; 7] = [
    "lookup",
    "sample",
    "pmf-sampled",
    "pmf-hit",
    "candidates",
    "candidates-shared",
    "record",
];

/// What the measured operations need at each point.
struct Inputs {
    contexts: Vec<ShadingContext>,
    /// One number per point for `sample`.
    u: Vec<f32>,
    /// `CANDIDATES` numbers per point.
    uc: Vec<f32>,
    /// (point, light) pairs where a BSDF ray from the point hit an emitter.
    hits: Vec<(usize, LightId)>,
}

impl Inputs {
    fn new(scene: &Scene, points: usize, seed: u64) -> Self {
        let size = scenes::DEFAULT_SIZE;
        let picked = shading_points::pick(scene, points, 1, size, seed);
        let mut s = rng::Sampler::new(seed, 0xc057, 0);
        let contexts: Vec<ShadingContext> = picked
            .iter()
            .map(|t| ShadingContext::on_surface(t.p, t.n))
            .collect();
        let u = (0..contexts.len()).map(|_| s.next()).collect();
        let uc = (0..contexts.len() * CANDIDATES).map(|_| s.next()).collect();
        // Up to 64 cosine-sampled rays per point until one hits an emitter.
        let mut hits = Vec::new();
        for (i, t) in picked.iter().enumerate() {
            for _ in 0..64 {
                let wi = Frame::new(t.n).to_world(cosine_hemisphere(s.next2()));
                let o = offset_origin(t.p, t.n, wi);
                let Some(hit) = scene.intersect(o, wi) else {
                    continue;
                };
                let e = scene.primitive(&hit).emitter;
                if e != NO_EMITTER {
                    hits.push((i, LightId::Emitter(e)));
                    break;
                }
            }
        }
        Self {
            contexts,
            u,
            uc,
            hits,
        }
    }
}

/// A light sampler as the measured operations see it.
trait Chooser {
    /// Its choice at one point.
    type Vertex<'a>: LightChoice
    where
        Self: 'a;
    /// The lookup.
    fn lookup(&self, ctx: &ShadingContext) -> Option<Self::Vertex<'_>>;
    /// A light record (nothing for a sampler that does not learn).
    fn record<'a>(&'a self, v: &Self::Vertex<'a>, light: LightId, value: f32);
    /// Whether it learns (records are measured).
    const LEARNS: bool;
}

impl<'t> Chooser for Glt<&'t LightTree> {
    type Vertex<'a>
        = guiding::LightVertex<'a, &'t LightTree>
    where
        Self: 'a;
    #[inline(always)]
    fn lookup(&self, ctx: &ShadingContext) -> Option<Self::Vertex<'_>> {
        self.vertex(ctx)
    }
    #[inline(always)]
    fn record<'a>(&'a self, v: &Self::Vertex<'a>, light: LightId, value: f32) {
        black_box(v.record_light(light, value));
    }
    const LEARNS: bool = true;
}

/// The combined field's light choice.
struct Field<'a>(GuidingField<&'a LightTree>);

impl<'t> Chooser for Field<'t> {
    type Vertex<'a>
        = guiding::LightVertex<'a, &'t LightTree>
    where
        Self: 'a;
    #[inline(always)]
    fn lookup(&self, ctx: &ShadingContext) -> Option<Self::Vertex<'_>> {
        self.0.vertex(ctx).map(|v| v.light)
    }
    #[inline(always)]
    fn record<'a>(&'a self, v: &Self::Vertex<'a>, light: LightId, value: f32) {
        black_box(v.record_light(light, value));
    }
    const LEARNS: bool = true;
}

/// A fixed sampler of the render example.
struct Fixed<'a>(Box<dyn LightSampler + Sync + 'a>);

impl<'t> Chooser for Fixed<'t> {
    type Vertex<'a>
        = guiding::SamplerAt<'a, dyn LightSampler + Sync + 't>
    where
        Self: 'a;
    #[inline(always)]
    fn lookup(&self, ctx: &ShadingContext) -> Option<Self::Vertex<'_>> {
        Some(guiding::SamplerAt::new(&*self.0, ctx))
    }
    #[inline(always)]
    fn record<'a>(&'a self, _: &Self::Vertex<'a>, _: LightId, _: f32) {}
    const LEARNS: bool = false;
}

/// The bodies of the operations, inlined into each sampler's named copy.
mod body {
    use super::*;

    #[inline(always)]
    pub fn lookup<C: Chooser>(c: &C, x: &Inputs) -> usize {
        for ctx in &x.contexts {
            black_box(c.lookup(black_box(ctx)).is_some());
        }
        x.contexts.len()
    }

    #[inline(always)]
    pub fn sample<C: Chooser>(v: &[Option<C::Vertex<'_>>], x: &Inputs) -> usize {
        for (v, &u) in v.iter().zip(&x.u) {
            if let Some(v) = v {
                black_box(v.sample(black_box(u)));
            }
        }
        v.len()
    }

    #[inline(always)]
    pub fn pmf_sampled<C: Chooser>(
        v: &[Option<C::Vertex<'_>>],
        s: &[Option<LightSample>],
    ) -> usize {
        for (v, s) in v.iter().zip(s) {
            if let (Some(v), Some(s)) = (v, s) {
                black_box(v.pmf(black_box(s.light)));
            }
        }
        v.len()
    }

    #[inline(always)]
    pub fn pmf_hit<C: Chooser>(v: &[Option<C::Vertex<'_>>], x: &Inputs) -> usize {
        for &(i, light) in &x.hits {
            if let Some(v) = &v[i] {
                black_box(v.pmf(black_box(light)));
            }
        }
        x.hits.len()
    }

    #[inline(always)]
    pub fn candidates<C: Chooser>(v: &[Option<C::Vertex<'_>>], x: &Inputs) -> usize {
        for (v, u) in v.iter().zip(x.uc.chunks_exact(CANDIDATES)) {
            if let Some(v) = v {
                for &u in u {
                    black_box(v.sample_with_visibility(black_box(u)));
                }
            }
        }
        v.len()
    }

    #[inline(always)]
    pub fn candidates_shared<C: Chooser>(v: &[Option<C::Vertex<'_>>], x: &Inputs) -> usize {
        let mut out = [None; CANDIDATES];
        for (v, u) in v.iter().zip(x.uc.chunks_exact(CANDIDATES)) {
            if let Some(v) = v {
                v.sample_candidates(black_box(u), &mut out);
                black_box(&out);
            }
        }
        v.len()
    }

    #[inline(always)]
    pub fn record<'a, C: Chooser>(
        c: &'a C,
        v: &[Option<C::Vertex<'a>>],
        s: &[Option<LightSample>],
    ) -> usize {
        for (v, s) in v.iter().zip(s) {
            if let (Some(v), Some(s)) = (v, s) {
                c.record(v, s.light, 0.5);
            }
        }
        v.len()
    }
}

/// One sampler's operations under names callgrind tells apart.
macro_rules! named_ops {
    ($name:ident, $ty:ty) => {
        mod $name {
            use super::*;
            #[inline(never)]
            pub fn lookup(c: &$ty, x: &Inputs) -> usize {
                body::lookup(c, x)
            }
            #[inline(never)]
            pub fn sample(v: &[Option<<$ty as Chooser>::Vertex<'_>>], x: &Inputs) -> usize {
                body::sample::<$ty>(v, x)
            }
            #[inline(never)]
            pub fn pmf_sampled(
                v: &[Option<<$ty as Chooser>::Vertex<'_>>],
                s: &[Option<LightSample>],
            ) -> usize {
                body::pmf_sampled::<$ty>(v, s)
            }
            #[inline(never)]
            pub fn pmf_hit(v: &[Option<<$ty as Chooser>::Vertex<'_>>], x: &Inputs) -> usize {
                body::pmf_hit::<$ty>(v, x)
            }
            #[inline(never)]
            pub fn candidates(v: &[Option<<$ty as Chooser>::Vertex<'_>>], x: &Inputs) -> usize {
                body::candidates::<$ty>(v, x)
            }
            #[inline(never)]
            pub fn candidates_shared(
                v: &[Option<<$ty as Chooser>::Vertex<'_>>],
                x: &Inputs,
            ) -> usize {
                body::candidates_shared::<$ty>(v, x)
            }
            #[inline(never)]
            pub fn record<'a>(
                c: &'a $ty,
                v: &[Option<<$ty as Chooser>::Vertex<'a>>],
                s: &[Option<LightSample>],
            ) -> usize {
                body::record::<$ty>(c, v, s)
            }
        }
    };
}

named_ops!(glt, Glt<&'static LightTree>);
named_ops!(field, Field<'static>);
named_ops!(bvh, Fixed<'static>);
named_ops!(power, Fixed<'static>);
named_ops!(uniform, Fixed<'static>);

/// Runs every operation of one sampler `reps` times; the median seconds
/// per operation and how many operations one repetition ran.
macro_rules! measure {
    ($m:ident, $c:expr, $x:expr, $args:expr) => {{
        let (c, x, reps, args_ops) = ($c, $x, $args.reps, &$args.ops);
        let vertices: Vec<_> = x.contexts.iter().map(|ctx| c.lookup(ctx)).collect();
        let sampled: Vec<Option<LightSample>> = vertices
            .iter()
            .zip(&x.u)
            .map(|(v, &u)| v.as_ref().and_then(|v| v.sample(u)))
            .collect();
        if !$args.child {
            println!(
                "  {:<8} digest {:016x}",
                stringify!($m),
                digest(&vertices, &sampled, x)
            );
        }
        let mut out: Vec<(&'static str, f64, usize)> = Vec::new();
        for op in OPS {
            if (op == "record" && !learns(c)) || !args_ops.iter().any(|o| o == op) {
                continue;
            }
            let mut times = Vec::with_capacity(reps);
            let mut n = 0;
            for _ in 0..reps.max(1) {
                let t = Instant::now();
                n = match op {
                    "lookup" => $m::lookup(c, x),
                    "sample" => $m::sample(&vertices, x),
                    "pmf-sampled" => $m::pmf_sampled(&vertices, &sampled),
                    "pmf-hit" => $m::pmf_hit(&vertices, x),
                    "candidates" => $m::candidates(&vertices, x) * CANDIDATES,
                    "candidates-shared" => $m::candidates_shared(&vertices, x) * CANDIDATES,
                    _ => $m::record(c, &vertices, &sampled),
                };
                times.push(t.elapsed().as_secs_f64());
            }
            times.sort_by(f64::total_cmp);
            out.push((op, times[times.len() / 2] / n.max(1) as f64, n));
        }
        out
    }};
}

/// A digest of every choice the measured operations make: each sampled
/// light and the bits of its pmf, the pmf of each light a BSDF ray hit,
/// and each candidate with its pmf and learned visibility. Two builds that
/// print the same digest chose the same lights with the same
/// probabilities, to the last bit (an optimisation that claims to change
/// no distribution shows it here).
fn digest<V: LightChoice>(
    vertices: &[Option<V>],
    sampled: &[Option<LightSample>],
    x: &Inputs,
) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325_u64;
    let mut eat = |word: u64| {
        for b in word.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    let id = |l: LightId| match l {
        LightId::Emitter(e) => u64::from(e),
        LightId::Unbounded(i) => u64::from(i) | 1 << 40,
    };
    for s in sampled.iter().flatten() {
        eat(id(s.light));
        eat(u64::from(s.pmf.to_bits()));
    }
    for &(i, light) in &x.hits {
        if let Some(v) = &vertices[i] {
            eat(u64::from(v.pmf(light).to_bits()));
        }
    }
    let mut shared = [None; CANDIDATES];
    for (v, u) in vertices.iter().zip(x.uc.chunks_exact(CANDIDATES)) {
        let Some(v) = v else { continue };
        v.sample_candidates(u, &mut shared);
        for (&u, shared) in u.iter().zip(&shared) {
            let each = v.sample_with_visibility(u);
            // Shared steps must not change a choice by a bit.
            let bits = |c: Option<(LightSample, f32)>| {
                c.map(|(s, v)| (s.light, s.pmf.to_bits(), v.to_bits()))
            };
            if bits(each) != bits(*shared) {
                eprintln!("candidates-shared differs from candidates: {shared:?} against {each:?}");
                std::process::exit(1);
            }
            if let Some((s, visibility)) = each {
                eat(id(s.light));
                eat(u64::from(s.pmf.to_bits()) << 32 | u64::from(visibility.to_bits()));
            }
        }
    }
    h
}

/// Whether `C` learns (its records are measured).
fn learns<C: Chooser>(_: &C) -> bool {
    C::LEARNS
}

fn guide_path(out: &Path, scene: &str, what: &str) -> PathBuf {
    out.join(format!("{scene}-{what}.guide"))
}

/// The trained GLT and field of `scene` (trained and saved, or loaded in
/// the callgrind child).
fn guides<'t>(
    args: &Args,
    name: &str,
    scene: &'t Scene,
) -> Result<(Glt<&'t LightTree>, GuidingField<&'t LightTree>), String> {
    let (gp, fp) = (
        guide_path(&args.out, name, "glt"),
        guide_path(&args.out, name, "field"),
    );
    if args.child {
        let read = |p: &Path| std::fs::read(p).map_err(|e| format!("{}: {e}", p.display()));
        let glt = Glt::from_bytes(&read(&gp)?, &scene.light_tree).map_err(|e| e.to_string())?;
        let field =
            GuidingField::from_bytes(&read(&fp)?, &scene.light_tree).map_err(|e| e.to_string())?;
        return Ok((glt, field));
    }
    let mut base = GltVariant::defaults(args.train_spp);
    base.params.importance_bound = args.importance_bound;
    let params = base.with(&args.glt)?.params;
    let settings = |_m: Method| run::Settings {
        width: args.width,
        height: args.height,
        budget: run::Budget::Spp(args.train_spp),
        params,
        seed: 1,
        progress: false,
        guide_files: Default::default(),
    };
    let (_, t) = run::render_trained(scene, Method::PtGlt, &settings(Method::PtGlt));
    let glt = t.glt.ok_or("pt-glt trains a GLT")?;
    let (_, t) = run::render_trained(scene, Method::PpgGlt, &settings(Method::PpgGlt));
    let field = t.field.ok_or("ppg-glt trains a field")?;
    std::fs::create_dir_all(&args.out).map_err(|e| e.to_string())?;
    std::fs::write(&gp, glt.to_bytes()).map_err(|e| e.to_string())?;
    std::fs::write(&fp, field.to_bytes()).map_err(|e| e.to_string())?;
    Ok((glt, field))
}

/// Prints the mean walk length of the GLT's sampled lights, in the cut
/// and below it, and the mean cut size.
fn walk_stats(name: &str, scene: &Scene, glt: &Glt<&LightTree>, x: &Inputs) {
    use guiding::LightHierarchy;
    use guiding::cut::Slot;
    let (mut inside, mut below, mut nodes, mut n) = (0usize, 0usize, 0usize, 0usize);
    for (ctx, &u) in x.contexts.iter().zip(&x.u) {
        let Some(v) = glt.vertex(ctx) else { continue };
        let Some(s) = v.sample(u) else { continue };
        let LightId::Emitter(e) = s.light else {
            continue;
        };
        let Some(path) = scene.light_tree.path(e) else {
            continue;
        };
        let cut = v.cut().nodes();
        let mut at = cut.first().copied();
        let mut k = 0;
        for &(_, side) in path.steps() {
            let Some(c) = at else { break };
            k += 1;
            at = match c.slot(side) {
                Slot::Child(i) => cut.get(i as usize).copied(),
                Slot::End(_) => None,
            };
        }
        inside += k;
        below += path.steps().len() - k;
        nodes += cut.len();
        n += 1;
    }
    let n = n.max(1) as f64;
    println!(
        "{name}: walk {:.1} levels, {:.1} in the cut, {:.1} below; {:.0} cut nodes",
        (inside + below) as f64 / n,
        inside as f64 / n,
        below as f64 / n,
        nodes as f64 / n
    );
}

/// One row per (sampler, op): seconds per op and ops per repetition.
type Rows = Vec<(String, &'static str, f64, usize)>;

fn measure_scene(args: &Args, name: &str) -> Result<(Rows, usize), String> {
    let scene = scenes::build(name, scenes::Size::Full).ok_or(format!("no scene {name}"))?;
    // The named copies take `'static` borrows: leak this scene's (the
    // process measures a few scenes and ends).
    let scene: &'static Scene = Box::leak(Box::new(scene));
    let (glt_guide, field_guide) = guides(args, name, scene)?;
    let (glt_guide, field_guide) = (
        &*Box::leak(Box::new(glt_guide)),
        &*Box::leak(Box::new(Field(field_guide))),
    );
    let x = Inputs::new(scene, args.points, 7);
    if !args.child {
        use guiding::LightHierarchy;
        println!("{name}: {} emitters", scene.light_tree.emitter_count());
    }
    if args.stats {
        walk_stats(name, scene, glt_guide, &x);
    }
    let mut rows = Rows::new();
    for s in &args.samplers {
        let fixed = |m| Fixed(methods::fixed_sampler(scene, m).expect("a fixed sampler"));
        let r = match s.as_str() {
            "glt" => measure!(glt, glt_guide, &x, args),
            "field" => measure!(field, field_guide, &x, args),
            "bvh" => measure!(bvh, &fixed(Method::PtBvh), &x, args),
            "power" => measure!(power, &fixed(Method::PtPower), &x, args),
            "uniform" => measure!(uniform, &fixed(Method::PtUniform), &x, args),
            other => return Err(format!("unknown sampler {other}")),
        };
        rows.extend(r.into_iter().map(|(op, t, n)| (s.clone(), op, t, n)));
    }
    use guiding::LightHierarchy;
    Ok((rows, scene.light_tree.emitter_count()))
}

/// The instructions per operation of each (sampler, op), from a callgrind
/// child run of this program on `name`.
fn callgrind(args: &Args, name: &str, rows: &Rows) -> Result<Vec<f64>, String> {
    let file = args.out.join(format!("{name}.callgrind"));
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let status = Command::new("valgrind")
        .arg("--tool=callgrind")
        .arg(format!("--callgrind-out-file={}", file.display()))
        .arg(&exe)
        .args(["--scene", name, "--reps", "1", "--child"])
        .args(["--points", &args.points.to_string()])
        .args(["--samplers", &args.samplers.join(",")])
        .args(["--ops", &args.ops.join(",")])
        .arg("--out")
        .arg(&args.out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .map_err(|e| format!("valgrind: {e}"))?;
    if !status.success() {
        return Err(format!("the callgrind child failed: {status}"));
    }
    let text = Command::new("callgrind_annotate")
        .args(["--inclusive=yes", "--threshold=100"])
        .arg(&file)
        .output()
        .map_err(|e| format!("callgrind_annotate: {e}"))?;
    let text = String::from_utf8_lossy(&text.stdout);
    // Lines like "1,234,567 (12.3%)  ???:choice_cost::glt::sample [...]".
    let inclusive = |func: &str| -> Option<f64> {
        text.lines().find_map(|l| {
            let (count, rest) = l.trim().split_once(' ')?;
            let f = rest.split(':').skip(1).collect::<Vec<_>>().join(":");
            let f = f.split_whitespace().next()?;
            (f == func).then(|| count.replace(',', "").parse().ok())?
        })
    };
    Ok(rows
        .iter()
        .map(|(s, op, _, n)| {
            let func = format!("choice_cost::{s}::{}", op.replace('-', "_"));
            inclusive(&func).map_or(f64::NAN, |c| c / *n.max(&1) as f64)
        })
        .collect())
}

/// A (sampler, op) pair's (emitters, cost) over the scenes, for --plot.
type Growth = (String, &'static str, Vec<(f64, f64)>);

fn main() -> ExitCode {
    let args = Args::parse();
    let mut growth: Vec<Growth> = Vec::new();
    for name in &args.scene {
        let (rows, emitters) = match measure_scene(&args, name) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("choice_cost: {e}");
                return ExitCode::FAILURE;
            }
        };
        if args.child {
            continue;
        }
        let instr = if args.callgrind {
            match callgrind(&args, name, &rows) {
                Ok(i) => Some(i),
                Err(e) => {
                    eprintln!("choice_cost: {e}");
                    return ExitCode::FAILURE;
                }
            }
        } else {
            None
        };
        println!("{name}: sampler op ns/op [instr/op] (ops per repetition)");
        for (k, (s, op, t, n)) in rows.iter().enumerate() {
            let i = instr
                .as_ref()
                .map_or(String::new(), |i| format!(" {:>9.0}", i[k]));
            println!("  {s:<8} {op:<12} {:>9.1}{i} ({n})", t * 1e9);
            let cost = instr.as_ref().map_or(t * 1e9, |i| i[k]);
            match growth.iter_mut().find(|(g, o, _)| g == s && o == op) {
                Some((_, _, points)) => points.push((emitters as f64, cost)),
                None => growth.push((s.clone(), op, vec![(emitters as f64, cost)])),
            }
        }
    }
    if let Some(stem) = &args.plot {
        let unit = if args.callgrind { "instructions" } else { "ns" };
        for op in ["sample", "pmf-hit"] {
            let lines: Vec<(String, Vec<(f64, f64)>)> = growth
                .iter()
                .filter(|(_, o, p)| *o == op && p.len() > 1)
                .map(|(s, _, p)| (s.clone(), p.clone()))
                .collect();
            if lines.is_empty() {
                continue;
            }
            let stem = stem.with_file_name(format!(
                "{}-{op}",
                stem.file_name()
                    .map_or("growth".into(), |f| f.to_string_lossy())
            ));
            let caption = format!("{unit} per {op} against the number of emitters");
            match guiding_render::plot::log_log(&stem, &caption, ("emitters", unit), &lines) {
                Ok([svg, _]) => println!("wrote {}", svg.display()),
                Err(e) => {
                    eprintln!("choice_cost: {e}");
                    return ExitCode::FAILURE;
                }
            }
        }
    }
    ExitCode::SUCCESS
}
