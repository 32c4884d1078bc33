//! Instructions per light choice through the C API and through the Rust
//! front, counted by callgrind (repeatable on a noisy machine, where
//! `benches/call_cost.rs`'s times are not): each loop runs 100,000 calls
//! on the same trained GLT and shading points.
//!
//! ```text
//! cargo build --release -p guiding-c --example call_counts
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!     '--toggle-collect=call_counts::*_loop' target/release/examples/call_counts
//! callgrind_annotate ... | grep _loop     # or read the totals per function
//! ```
//!
//! Without valgrind it prints what each loop returned (a checksum).

#[path = "../benches/common/scene.rs"]
mod scene;

use guiding::glam::Vec3;
use guiding::{LightChoice, LightId, ShadingContext};
use guiding_c::*;
use std::hint::black_box;

const CALLS: usize = 100_000;

type Points = Vec<(GuidingShadingContext, f32)>;

#[inline(never)]
fn rust_sample_loop(
    glt: &guiding::Glt<std::sync::Arc<guiding::LightTree>>,
    points: &Points,
) -> f64 {
    let mut sum = 0.0;
    for (c, u) in points {
        let ctx = ShadingContext::on_surface(Vec3::from(c.position), Vec3::from(c.normal));
        sum += glt
            .vertex(&ctx)
            .and_then(|v| v.sample(*u))
            .map_or(0.0, |s| f64::from(s.pmf));
    }
    sum
}

#[inline(never)]
fn c_sample_loop(glt: *const GuidingGlt, points: &Points) -> f64 {
    let mut sum = 0.0;
    for (c, u) in points {
        let mut out = GuidingLightSample { light: 0, pmf: 0.0 };
        // SAFETY: a live handle and valid pointers.
        unsafe { guiding_glt_sample(glt, c, *u, &mut out) };
        sum += f64::from(out.pmf);
    }
    sum
}

#[inline(never)]
fn rust_pmf_loop(glt: &guiding::Glt<std::sync::Arc<guiding::LightTree>>, points: &Points) -> f64 {
    let mut sum = 0.0;
    for (i, (c, _)) in points.iter().enumerate() {
        let ctx = ShadingContext::on_surface(Vec3::from(c.position), Vec3::from(c.normal));
        let light = LightId::Emitter((i % 10_000) as u32);
        sum += glt.vertex(&ctx).map_or(0.0, |v| f64::from(v.pmf(light)));
    }
    sum
}

#[inline(never)]
fn c_pmf_loop(glt: *const GuidingGlt, points: &Points) -> f64 {
    let mut sum = 0.0;
    for (i, (c, _)) in points.iter().enumerate() {
        let mut p = 0.0;
        // SAFETY: a live handle and valid pointers.
        unsafe { guiding_glt_pmf(glt, c, (i % 10_000) as u32, &mut p) };
        sum += f64::from(p);
    }
    sum
}

#[inline(never)]
fn c_sample_batch_loop(glt: *const GuidingGlt, points: &Points) -> f64 {
    let (contexts, us): (Vec<GuidingShadingContext>, Vec<f32>) = points.iter().copied().unzip();
    let mut out = vec![GuidingLightSample { light: 0, pmf: 0.0 }; points.len()];
    // SAFETY: a live handle; arrays of `points.len()` elements.
    unsafe {
        guiding_glt_sample_batch(
            glt,
            contexts.as_ptr(),
            us.as_ptr(),
            us.len(),
            out.as_mut_ptr(),
        )
    };
    out.iter().map(|s| f64::from(s.pmf)).sum()
}

fn main() {
    let (tree, glt) = scene::scene();
    let mut r = scene::Lcg(9);
    let points: Points = (0..CALLS)
        .map(|_| {
            let c = GuidingShadingContext {
                position: [200.0 * r.next(), 0.0, 200.0 * r.next()],
                normal: [0.0, 1.0, 0.0],
                light_sets: GUIDING_ALL_LIGHTS,
                unbounded_lights: GUIDING_ALL_LIGHTS,
            };
            (c, r.next().min(0.999_999))
        })
        .collect();
    let (tree_bytes, glt_bytes) = (tree.to_bytes(), glt.to_bytes());
    let (mut c_tree, mut c_glt) = (std::ptr::null_mut(), std::ptr::null_mut());
    // SAFETY: valid pointers and lengths; the handles are freed below.
    unsafe {
        assert_eq!(
            guiding_light_tree_load(tree_bytes.as_ptr(), tree_bytes.len(), &mut c_tree),
            GuidingStatus::Ok
        );
        assert_eq!(
            guiding_glt_load(c_tree, glt_bytes.as_ptr(), glt_bytes.len(), &mut c_glt),
            GuidingStatus::Ok
        );
    }
    let sums = [
        ("rust sample", rust_sample_loop(&glt, black_box(&points))),
        ("c sample", c_sample_loop(c_glt, black_box(&points))),
        (
            "c sample batch",
            c_sample_batch_loop(c_glt, black_box(&points)),
        ),
        ("rust pmf", rust_pmf_loop(&glt, black_box(&points))),
        ("c pmf", c_pmf_loop(c_glt, black_box(&points))),
    ];
    for (name, sum) in sums {
        println!("{name}: {CALLS} calls, pmf sum {sum:.6}");
    }
    // SAFETY: the handles from the loads above, freed once.
    unsafe {
        guiding_glt_free(c_glt);
        guiding_light_tree_free(c_tree);
    }
}
