//! `GuidingEmitters`: a scene's emitters, added one by one in the order
//! their light indices count, for `guiding_light_tree_build`.

use crate::status::{Failure, GuidingStatus, get, get_mut, guard, put, slice, vec3};
use guiding::Emitter;
use guiding::glam::Vec3;

/// A scene's emitters (opaque). Powers are the emitters' flux in any unit
/// (the same for all): finite and >= 0.
pub struct GuidingEmitters {
    pub(crate) list: Vec<Emitter>,
}

/// The most emitters a light tree indexes (its light indices are `u32`,
/// `GUIDING_NO_LIGHT` kept apart).
const MAX_EMITTERS: usize = u32::MAX as usize - 1;

fn power(w: f32) -> Result<f32, Failure> {
    if w.is_finite() && w >= 0.0 {
        Ok(w)
    } else {
        Err(Failure::invalid(format!(
            "power = {w}: must be finite and >= 0"
        )))
    }
}

fn length(x: f32, name: &str) -> Result<f32, Failure> {
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(Failure::invalid(format!(
            "{name} = {x}: must be finite and >= 0"
        )))
    }
}

/// Appends `e` to `emitters`, writing its index to `index` (which may be
/// null).
///
/// # Safety
/// `emitters` null or a live handle; `index` null or writable.
unsafe fn push(
    emitters: *mut GuidingEmitters,
    index: *mut u32,
    make: impl FnOnce() -> Result<Emitter, Failure>,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded from the caller.
        let e = unsafe { get_mut(emitters, "emitters") }?;
        if e.list.len() >= MAX_EMITTERS {
            return Err(Failure::invalid("more than 2^32 - 2 emitters"));
        }
        let emitter = make()?;
        if !index.is_null() {
            // SAFETY: non-null and writable by the caller's promise.
            unsafe { put(index, e.list.len() as u32, "index") }?;
        }
        e.list.push(emitter);
        Ok(())
    })
}

/// A new, empty list of emitters, written to `out`.
///
/// # Safety
/// `out` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_new(out: *mut *mut GuidingEmitters) -> GuidingStatus {
    guard(|| {
        let e = Box::into_raw(Box::new(GuidingEmitters { list: Vec::new() }));
        // SAFETY: forwarded; on failure the box is taken back.
        unsafe { put(out, e, "out") }.inspect_err(|_| {
            // SAFETY: `e` came from Box::into_raw just above.
            drop(unsafe { Box::from_raw(e) });
        })
    })
}

/// Frees `emitters` (null is allowed and does nothing).
///
/// # Safety
/// `emitters` null or a live handle from `guiding_emitters_new`, freed once.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_free(emitters: *mut GuidingEmitters) {
    if !emitters.is_null() {
        // SAFETY: a handle from Box::into_raw, freed once (the caller's promise).
        drop(unsafe { Box::from_raw(emitters) });
    }
}

/// How many emitters `emitters` holds (0 for null).
///
/// # Safety
/// `emitters` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_count(emitters: *const GuidingEmitters) -> usize {
    // SAFETY: forwarded.
    unsafe { get(emitters, "emitters") }.map_or(0, |e| e.list.len())
}

/// An isotropic point light at `position[3]`.
///
/// # Safety
/// `emitters` a live handle; `position` 3 floats; `index` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_add_point(
    emitters: *mut GuidingEmitters,
    position: *const f32,
    power_: f32,
    index: *mut u32,
) -> GuidingStatus {
    // SAFETY: forwarded.
    unsafe {
        push(emitters, index, || {
            Ok(Emitter::point(vec3(position, "position")?, power(power_)?))
        })
    }
}

/// A sphere of `radius` around `center[3]`.
///
/// # Safety
/// As for `guiding_emitters_add_point`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_add_sphere(
    emitters: *mut GuidingEmitters,
    center: *const f32,
    radius: f32,
    power_: f32,
    index: *mut u32,
) -> GuidingStatus {
    // SAFETY: forwarded.
    unsafe {
        push(emitters, index, || {
            let c = vec3(center, "center")?;
            Ok(Emitter::sphere(
                c,
                length(radius, "radius")?,
                power(power_)?,
            ))
        })
    }
}

/// A spot light (pbrt's) at `position[3]` shining along `direction[3]`:
/// full intensity within the angle whose cosine is `cos_falloff_start`,
/// dark beyond `cos_falloff_end` (both in [-1, 1]).
///
/// # Safety
/// As for `guiding_emitters_add_point`; `direction` 3 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_add_spot(
    emitters: *mut GuidingEmitters,
    position: *const f32,
    direction: *const f32,
    cos_falloff_start: f32,
    cos_falloff_end: f32,
    power_: f32,
    index: *mut u32,
) -> GuidingStatus {
    // SAFETY: forwarded.
    unsafe {
        push(emitters, index, || {
            let p = vec3(position, "position")?;
            let d = vec3(direction, "direction")?;
            if d == Vec3::ZERO {
                return Err(Failure::invalid("direction is zero"));
            }
            for (name, c) in [
                ("cos_falloff_start", cos_falloff_start),
                ("cos_falloff_end", cos_falloff_end),
            ] {
                if !(-1.0..=1.0).contains(&c) {
                    return Err(Failure::invalid(format!("{name} = {c} is not in [-1, 1]")));
                }
            }
            Ok(Emitter::spot(
                p,
                d,
                cos_falloff_start,
                cos_falloff_end,
                power(power_)?,
            ))
        })
    }
}

/// A Lambertian triangle, `vertices[9]` = p0, p1, p2, emitting on the side
/// of `(p1 - p0) x (p2 - p0)` (both sides when `two_sided`).
///
/// # Safety
/// As for `guiding_emitters_add_point`; `vertices` 9 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_add_triangle(
    emitters: *mut GuidingEmitters,
    vertices: *const f32,
    power_: f32,
    two_sided: bool,
    index: *mut u32,
) -> GuidingStatus {
    // SAFETY: forwarded.
    unsafe {
        push(emitters, index, || {
            let v = slice(vertices, 9, "vertices")?;
            let p = [
                crate::status::finite3([v[0], v[1], v[2]], "vertices[0..3]")?,
                crate::status::finite3([v[3], v[4], v[5]], "vertices[3..6]")?,
                crate::status::finite3([v[6], v[7], v[8]], "vertices[6..9]")?,
            ];
            Ok(Emitter::triangle(p, power(power_)?, two_sided))
        })
    }
}

/// A Lambertian parallelogram `corner + s edge_u + t edge_v`, emitting on
/// the side of `edge_u x edge_v` (both sides when `two_sided`).
///
/// # Safety
/// As for `guiding_emitters_add_point`; `corner`, `edge_u`, `edge_v` 3
/// floats each.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_add_quad(
    emitters: *mut GuidingEmitters,
    corner: *const f32,
    edge_u: *const f32,
    edge_v: *const f32,
    power_: f32,
    two_sided: bool,
    index: *mut u32,
) -> GuidingStatus {
    // SAFETY: forwarded.
    unsafe {
        push(emitters, index, || {
            let (c, u, v) = (
                vec3(corner, "corner")?,
                vec3(edge_u, "edge_u")?,
                vec3(edge_v, "edge_v")?,
            );
            Ok(Emitter::quad(c, u, v, power(power_)?, two_sided))
        })
    }
}

/// A Lambertian disk of `radius` at `center[3]` facing `normal[3]` (both
/// sides when `two_sided`).
///
/// # Safety
/// As for `guiding_emitters_add_point`; `center`, `normal` 3 floats each.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_emitters_add_disk(
    emitters: *mut GuidingEmitters,
    center: *const f32,
    normal: *const f32,
    radius: f32,
    power_: f32,
    two_sided: bool,
    index: *mut u32,
) -> GuidingStatus {
    // SAFETY: forwarded.
    unsafe {
        push(emitters, index, || {
            let (c, n) = (vec3(center, "center")?, vec3(normal, "normal")?);
            if n == Vec3::ZERO {
                return Err(Failure::invalid("normal is zero"));
            }
            Ok(Emitter::disk(
                c,
                n,
                length(radius, "radius")?,
                power(power_)?,
                two_sided,
            ))
        })
    }
}
