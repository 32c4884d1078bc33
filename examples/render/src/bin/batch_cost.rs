//! The Rust half of `python/bench/batch_cost.py`: loads the light tree,
//! the trained GLT and the batch of shading points that the Python bindings
//! were timed on, times the same batch through the Rust front (one thread,
//! `glt.vertex(&ctx)` then `sample(u)` per point, as the bindings do), and
//! checks that every light and pmf equals the bindings' bit for bit.
//!
//! ```text
//! python python/bench/batch_cost.py     # runs this at the end
//! cargo run --release --bin batch_cost -- out/batch_cost
//! ```

use guiding::glam::Vec3;
use guiding::{Glt, LightChoice, LightTree, ShadingContext};
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

fn floats(dir: &Path, name: &str) -> Result<Vec<f32>, String> {
    let bytes = std::fs::read(dir.join(name)).map_err(|e| format!("{name}: {e}"))?;
    Ok(bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}

fn run(dir: &Path, reps: usize) -> Result<(), String> {
    let read = |name: &str| std::fs::read(dir.join(name)).map_err(|e| format!("{name}: {e}"));
    let tree = LightTree::from_bytes(&read("tree.bin")?).map_err(|e| e.to_string())?;
    let glt = Glt::from_bytes(&read("glt.bin")?, &tree).map_err(|e| e.to_string())?;
    let (p, n, u) = (
        floats(dir, "points.f32")?,
        floats(dir, "normals.f32")?,
        floats(dir, "u.f32")?,
    );
    let python_pmfs = floats(dir, "pmfs.f32")?;
    let python_lights: Vec<i64> = read("lights.i64")?
        .chunks_exact(8)
        .map(|b| i64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
    let count = u.len();
    let emitters = guiding::LightHierarchy::emitter_count(&tree) as u32;
    let contexts: Vec<ShadingContext> = (0..count)
        .map(|i| {
            let at = |a: &[f32]| Vec3::new(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
            ShadingContext::on_surface(at(&p), at(&n))
        })
        .collect();
    let batch = |out: &mut Vec<(i64, f32)>| {
        out.clear();
        out.extend(contexts.iter().zip(&u).map(|(ctx, &u)| {
            glt.vertex(ctx)
                .and_then(|v| v.sample(u))
                .map_or((-1, 0.0), |s| (i64::from(s.light.index(emitters)), s.pmf))
        }));
    };
    let mut out = Vec::with_capacity(count);
    batch(&mut out);
    let mismatches = out
        .iter()
        .zip(python_lights.iter().zip(&python_pmfs))
        .filter(|((l, p), (pl, pp))| l != *pl || p.to_bits() != pp.to_bits())
        .count();
    let mut times = Vec::with_capacity(reps);
    for _ in 0..reps {
        let t = Instant::now();
        batch(&mut out);
        times.push(t.elapsed().as_secs_f64());
        std::hint::black_box(&out);
    }
    times.sort_by(f64::total_cmp);
    let median = times[reps / 2];
    println!(
        "rust: {count} points, median of {reps}: {:.3} ms, {:.1} ns per point (one thread); \
         {mismatches} of {count} samples differ from the bindings'",
        median * 1e3,
        median * 1e9 / count as f64
    );
    if mismatches > 0 {
        return Err("the Rust front and the bindings chose differently".into());
    }
    Ok(())
}

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let dir = args.next().unwrap_or_else(|| "out/batch_cost".into());
    let reps = args.next().and_then(|r| r.parse().ok()).unwrap_or(21);
    match run(Path::new(&dir), reps) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("batch_cost: {e}");
            ExitCode::FAILURE
        }
    }
}
