//! Procedural meshes the scenes are made of: torus, sphere caps, cylinders
//! and height fields, as triangle lists with outward normals.

use glam::{Quat, Vec3};
use std::f32::consts::{PI, TAU};

/// A torus around `axis` (through `center`), major radius `big`, minor
/// radius `small`, `nu x nv` quads split into `2 nu nv` triangles with
/// outward normals.
pub fn torus(
    center: Vec3,
    axis: Vec3,
    big: f32,
    small: f32,
    nu: usize,
    nv: usize,
) -> Vec<[Vec3; 3]> {
    let rot = Quat::from_rotation_arc(Vec3::Y, axis.normalize());
    let point = |i: usize, j: usize| {
        let u = TAU * i as f32 / nu as f32;
        let v = TAU * j as f32 / nv as f32;
        let ring = Vec3::new(u.cos(), 0.0, u.sin());
        let p = ring * (big + small * v.cos()) + Vec3::Y * (small * v.sin());
        center + rot * p
    };
    let mut tris = grid(nu, nv, point, true);
    let inv = rot.inverse();
    for t in &mut tris {
        let local = inv * ((t[0] + t[1] + t[2]) / 3.0 - center);
        let core = Vec3::new(local.x, 0.0, local.z).normalize_or_zero() * big;
        let n = inv * (t[1] - t[0]).cross(t[2] - t[0]);
        if n.dot(local - core) < 0.0 {
            t.swap(1, 2);
        }
    }
    tris
}

/// A quad grid `point(i, j)`, `i < nu`, `j < nv`, wrapping in both
/// directions when `wrap`, else with `nu + 1` x `nv + 1` vertices.
fn grid(nu: usize, nv: usize, point: impl Fn(usize, usize) -> Vec3, wrap: bool) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::with_capacity(2 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (i1, j1) = if wrap {
                ((i + 1) % nu, (j + 1) % nv)
            } else {
                (i + 1, j + 1)
            };
            let (a, b, c, d) = (point(i, j), point(i1, j), point(i1, j1), point(i, j1));
            tris.push([a, c, b]);
            tris.push([a, d, c]);
        }
    }
    tris
}

/// The upper half of a sphere (y >= center.y), normals pointing out of the
/// sphere when `outward`, else into it.
pub fn hemisphere(
    center: Vec3,
    radius: f32,
    nu: usize,
    nv: usize,
    outward: bool,
) -> Vec<[Vec3; 3]> {
    let point = |i: usize, j: usize| {
        let phi = TAU * i as f32 / nu as f32;
        let theta = 0.5 * PI * j as f32 / nv as f32;
        center
            + radius
                * Vec3::new(
                    theta.cos() * phi.cos(),
                    theta.sin(),
                    theta.cos() * phi.sin(),
                )
    };
    let mut tris = grid(nu, nv, |i, j| point(i % nu, j), false);
    orient(&mut tris, center, outward);
    tris
}

/// An open cylinder around the y axis through `base`, outward normals.
pub fn cylinder(base: Vec3, radius: f32, height: f32, n: usize) -> Vec<[Vec3; 3]> {
    let point = |i: usize, j: usize| {
        let phi = TAU * (i % n) as f32 / n as f32;
        base + Vec3::new(radius * phi.cos(), height * j as f32, radius * phi.sin())
    };
    let mut tris = grid(n, 1, point, false);
    let axis_mid = base + Vec3::Y * (0.5 * height);
    for t in &mut tris {
        let mid = (t[0] + t[1] + t[2]) / 3.0;
        let out = Vec3::new(mid.x - axis_mid.x, 0.0, mid.z - axis_mid.z);
        if (t[1] - t[0]).cross(t[2] - t[0]).dot(out) < 0.0 {
            t.swap(1, 2);
        }
    }
    tris
}

/// A disk facing +y.
pub fn disk(center: Vec3, radius: f32, n: usize) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|i| {
            let a = TAU * i as f32 / n as f32;
            let b = TAU * (i + 1) as f32 / n as f32;
            let pa = center + radius * Vec3::new(a.cos(), 0.0, a.sin());
            let pb = center + radius * Vec3::new(b.cos(), 0.0, b.sin());
            [center, pb, pa]
        })
        .collect()
}

/// A flat ring (annulus) around the y axis through `center`, facing +y.
pub fn annulus(center: Vec3, inner: f32, outer: f32, n: usize) -> Vec<[Vec3; 3]> {
    let at = |r: f32, i: usize| {
        let a = TAU * (i % n) as f32 / n as f32;
        center + r * Vec3::new(a.cos(), 0.0, a.sin())
    };
    let mut tris = Vec::with_capacity(2 * n);
    for i in 0..n {
        let (a, b, c, d) = (
            at(inner, i),
            at(outer, i),
            at(outer, i + 1),
            at(inner, i + 1),
        );
        tris.push([a, c, b]);
        tris.push([a, d, c]);
    }
    for t in &mut tris {
        if (t[1] - t[0]).cross(t[2] - t[0]).y < 0.0 {
            t.swap(1, 2);
        }
    }
    tris
}

/// A height field over `[x0, x1] x [z0, z1]` with `nx x nz` quads, normals
/// facing +y.
pub fn height_field(
    x: (f32, f32),
    z: (f32, f32),
    nx: usize,
    nz: usize,
    height: impl Fn(f32, f32) -> f32,
) -> Vec<[Vec3; 3]> {
    let point = |i: usize, j: usize| {
        let px = x.0 + (x.1 - x.0) * i as f32 / nx as f32;
        let pz = z.0 + (z.1 - z.0) * j as f32 / nz as f32;
        Vec3::new(px, height(px, pz), pz)
    };
    let mut tris = grid(nx, nz, point, false);
    for t in &mut tris {
        if (t[1] - t[0]).cross(t[2] - t[0]).y < 0.0 {
            t.swap(1, 2);
        }
    }
    tris
}

/// Turns every triangle to face away from (`outward`) or towards `center`.
fn orient(tris: &mut [[Vec3; 3]], center: Vec3, outward: bool) {
    for t in tris.iter_mut() {
        let mid = (t[0] + t[1] + t[2]) / 3.0;
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if (n.dot(mid - center) > 0.0) != outward {
            t.swap(1, 2);
        }
    }
}
