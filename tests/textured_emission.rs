//! Emissive triangles with textured emission: the power a renderer passes
//! ([`Emitter::triangle`]) is `pi` times the integral of the emitted
//! radiance over the triangle (per emitting side). Checked against brute
//! force twice: that power is the flux that reaches a sphere far around the
//! triangle, and direct light estimated through a light tree built from
//! such powers converges to the irradiance integrated over the triangles.

use glam::Vec3;
use guiding::light_sampler::ImportanceTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};
use std::f64::consts::PI;

mod common;
use common::Rand;

/// A textured triangle: its corners and the radiance its texture emits at
/// barycentric `(b1, b2)` (a gradient times a checkerboard).
struct Textured {
    p: [Vec3; 3],
    scale: f64,
}

impl Textured {
    fn radiance(&self, b1: f64, b2: f64) -> f64 {
        let checker = if ((b1 * 8.0) as i32 + (b2 * 8.0) as i32) % 2 == 0 {
            1.0
        } else {
            0.2
        };
        self.scale * (0.5 + 3.0 * b1) * checker
    }

    fn area(&self) -> f64 {
        0.5 * (self.p[1] - self.p[0])
            .cross(self.p[2] - self.p[0])
            .length() as f64
    }

    fn normal(&self) -> Vec3 {
        (self.p[1] - self.p[0])
            .cross(self.p[2] - self.p[0])
            .normalize()
    }

    fn point(&self, b1: f64, b2: f64) -> Vec3 {
        let (b1, b2) = (b1 as f32, b2 as f32);
        self.p[0] * (1.0 - b1 - b2) + self.p[1] * b1 + self.p[2] * b2
    }

    /// Midpoints of an `n x n` subdivision of the triangle in barycentric
    /// coordinates (`n^2` cells of equal area), each with its radiance.
    fn cells(&self, n: usize) -> impl Iterator<Item = (Vec3, f64)> + '_ {
        (0..n).flat_map(move |i| {
            (0..n - i).flat_map(move |j| {
                let up = (
                    (i as f64 + 1.0 / 3.0) / n as f64,
                    (j as f64 + 1.0 / 3.0) / n as f64,
                );
                let down = (
                    (i as f64 + 2.0 / 3.0) / n as f64,
                    (j as f64 + 2.0 / 3.0) / n as f64,
                );
                let mut cells = vec![up];
                if i + j + 1 < n {
                    cells.push(down);
                }
                cells
                    .into_iter()
                    .map(|(b1, b2)| (self.point(b1, b2), self.radiance(b1, b2)))
            })
        })
    }

    /// The documented power: `pi` times the radiance integrated over the
    /// triangle (one-sided Lambertian), by a fine quadrature.
    fn power(&self) -> f32 {
        let n = 256;
        let sum: f64 = self.cells(n).map(|(_, l)| l).sum();
        (PI * sum * self.area() / (n * n) as f64) as f32
    }

    fn emitter(&self) -> Emitter {
        Emitter::triangle(self.p, self.power(), false)
    }

    /// Irradiance at `x` (facing `n`) from the triangle, by quadrature.
    fn irradiance(&self, x: Vec3, n: Vec3, cells: usize) -> f64 {
        let normal = self.normal();
        let da = self.area() / (cells * cells) as f64;
        self.cells(cells)
            .map(|(y, l)| {
                let d = x - y;
                let r2 = d.length_squared() as f64;
                let w = d.normalize();
                let cos_e = normal.dot(w) as f64;
                let cos_x = (-w).dot(n) as f64;
                if cos_e > 0.0 && cos_x > 0.0 {
                    l * cos_e * cos_x / r2 * da
                } else {
                    0.0
                }
            })
            .sum()
    }
}

fn triangles(r: &mut Rand, n: usize) -> Vec<Textured> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(r.range(-5.0, 5.0), r.range(3.0, 6.0), r.range(-5.0, 5.0));
            let a = c + r.dir() * 0.6;
            let b = c + r.dir() * 0.6;
            // Facing down, towards the floor the points are on.
            let (a, b) = if (a - c).cross(b - c).y > 0.0 {
                (b, a)
            } else {
                (a, b)
            };
            Textured {
                p: [c, a, b],
                scale: 10f64.powf(r.f64() * 2.0 - 1.0),
            }
        })
        .collect()
}

#[test]
fn a_textured_triangles_power_is_its_flux() {
    let mut r = Rand::new(101);
    for t in triangles(&mut r, 3) {
        // The flux through a sphere of radius 200 around the triangle:
        // irradiance on the sphere (facing the centre) integrated over it.
        let centre = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        let radius = 200.0f32;
        let (rings, per_ring) = (90, 180);
        let mut flux = 0.0;
        for i in 0..rings {
            // Equal-area bands: cos(theta) uniform.
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / rings as f64;
            let s = (1.0 - z * z).sqrt();
            for j in 0..per_ring {
                let phi = 2.0 * PI * (j as f64 + 0.5) / per_ring as f64;
                let dir = Vec3::new((s * phi.cos()) as f32, z as f32, (s * phi.sin()) as f32);
                let x = centre + dir * radius;
                flux += t.irradiance(x, -dir, 48);
            }
        }
        let sphere = 4.0 * PI * (radius as f64).powi(2);
        let flux = flux * sphere / (rings * per_ring) as f64;
        let power = t.power() as f64;
        assert!(
            (flux - power).abs() < 0.01 * power,
            "flux {flux} vs power {power}"
        );
    }
}

#[test]
fn textured_triangles_are_estimated_without_bias() {
    let mut r = Rand::new(102);
    let tris = triangles(&mut r, 40);
    let emitters: Vec<Emitter> = tris.iter().map(Textured::emitter).collect();
    let tree = LightTree::build(emitters.as_slice(), BuildHeuristic::Sarh).unwrap();
    let sampler = ImportanceTreeSampler::new(&tree);
    for k in 0..4 {
        let x = Vec3::new(r.range(-4.0, 4.0), 0.0, r.range(-4.0, 4.0));
        let n = Vec3::Y;
        let truth: f64 = tris.iter().map(|t| t.irradiance(x, n, 64)).sum();
        // One light by the tree's pmf, one point uniformly on it.
        let ctx = ShadingContext::on_surface(x, n);
        let samples = 200_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..samples {
            let s = sampler.sample(&ctx, r.f()).unwrap();
            let LightId::Emitter(e) = s.light else {
                panic!()
            };
            let t = &tris[e as usize];
            let (mut b1, mut b2) = (r.f64(), r.f64());
            if b1 + b2 > 1.0 {
                (b1, b2) = (1.0 - b1, 1.0 - b2);
            }
            let y = t.point(b1, b2);
            let d = x - y;
            let w = d.normalize();
            let cos_e = t.normal().dot(w) as f64;
            let cos_x = (-w).dot(n) as f64;
            let f = if cos_e > 0.0 && cos_x > 0.0 {
                t.radiance(b1, b2) * cos_e * cos_x / d.length_squared() as f64 * t.area()
            } else {
                0.0
            };
            let v = f / s.pmf as f64;
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / samples as f64;
        let sigma = ((sum2 / samples as f64 - mean * mean) / samples as f64).sqrt();
        // The quadrature's own error is far below the estimate's.
        assert!(
            (mean - truth).abs() < 4.0 * sigma + 2e-3 * truth,
            "point {k}: estimate {mean} +- {sigma}, brute force {truth}"
        );
    }
}
