//! The trained GLT that `benches/call_cost.rs` and
//! `examples/call_counts.rs` time: 10,000 quads over a 200 x 200 street,
//! four training iterations of 100,000 light records.

use guiding::glam::Vec3;
use guiding::{Aabb, Emitter, Glt, GltConfig, LightChoice, LightTree, ShadingContext};
use std::sync::Arc;

/// A small deterministic generator.
pub struct Lcg(pub u64);
impl Lcg {
    /// The next float in [0, 1).
    pub fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / 16_777_216.0
    }
}

/// The light tree and the trained GLT.
pub fn scene() -> (Arc<LightTree>, Glt<Arc<LightTree>>) {
    let mut r = Lcg(3);
    let lights: Vec<Emitter> = (0..10_000)
        .map(|i| {
            let c = Vec3::new(200.0 * r.next(), 5.0 + 40.0 * r.next(), 200.0 * r.next());
            Emitter::quad(c, Vec3::X * 0.5, Vec3::Y * 0.5, 1.0 + (i % 13) as f32, true)
        })
        .collect();
    let tree = Arc::new(LightTree::build(&lights, Default::default()).expect("tree"));
    let bounds = Aabb::new(Vec3::ZERO, Vec3::new(200.0, 50.0, 200.0));
    let mut glt = Glt::new(Arc::clone(&tree), bounds, GltConfig::default()).expect("glt");
    for _ in 0..4 {
        for _ in 0..100_000 {
            let ctx = ShadingContext::on_surface(
                Vec3::new(200.0 * r.next(), 0.0, 200.0 * r.next()),
                Vec3::Y,
            );
            if let Some(v) = glt.vertex(&ctx) {
                if let Some(s) = v.sample(r.next().min(0.999_999)) {
                    let d = lights[s.light.index(10_000) as usize].bounds.center() - ctx.position;
                    v.record_light(s.light, 1.0 / (d.length_squared().max(1.0) * s.pmf));
                }
            }
        }
        glt.refine();
    }
    (tree, glt)
}
