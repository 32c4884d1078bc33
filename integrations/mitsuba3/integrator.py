"""`glt_path`: Mitsuba 3 path tracing with next-event estimation whose light
choice is the crate's Guiding Light Tree (or, as a check, a uniform choice
over the same per-triangle lights).

A wavefront integrator: each bounce is one evaluated Dr.Jit kernel over
every path; the shading points go to the host as numpy arrays, the crate
chooses a light for each (one batched call, the GIL released), and the
chosen lights come back as indices. Triangles of emissive meshes are
sampled here (uniformly by area); every other emitter by Mitsuba's own
`sample_direction`. MIS (power heuristic) weighs NEE against BSDF samples
that hit emitters, with the light pmf the crate reports for the hit light.
No Russian roulette (`max_depth` bounds the paths, as in the comparison's
`path` runs with `rr_depth` past it).

Registered as `glt_path` (`mi.register_integrator`); `render_image`
renders with it and returns the image as numpy.
"""

from __future__ import annotations

import time

import drjit as dr
import mitsuba as mi
import numpy as np

import guiding
from lights import SceneLights


def _gather(lanes, *arrays):
    """The `lanes` of each array, evaluated: what goes to the host is only
    the paths that need the crate."""
    out = [dr.gather(type(a), a, lanes) for a in arrays]
    dr.eval(*out)
    return out


def _power_heuristic(a, b):
    a2, b2 = dr.square(a), dr.square(b)
    return dr.detach(dr.select(a2 + b2 > 0, a2 / (a2 + b2), 0))


class Timer:
    """Seconds spent per part of a bounce: Mitsuba's kernels, the host
    round trip (arrays to and from numpy) and the crate's calls."""

    def __init__(self):
        self.parts = {"mitsuba": 0.0, "round trip": 0.0, "crate": 0.0}
        self._t = time.perf_counter()

    def lap(self, part):
        if part == "mitsuba":
            # Dr.Jit's LLVM backend runs kernels asynchronously: wait for
            # them, or their time would land in the next part.
            dr.sync_thread()
        now = time.perf_counter()
        self.parts[part] += now - self._t
        self._t = now


class GltPathIntegrator(mi.SamplingIntegrator):
    """NEE with the crate's light choice. Properties: `max_depth` (5),
    `choice` ('glt', or 'uniform' over the same lights: a check of the
    wavefront's own correctness and cost)."""

    def __init__(self, props=mi.Properties()):
        super().__init__(props)
        self.max_depth = props.get("max_depth", 5)
        self.choice = props.get("choice", "glt")
        self.lights = None
        self.guide = None
        self.timer = Timer()

    # The light choice on the host.

    def attach(self, scene, guide=None):
        """Converts `scene`'s lights; `guide` is the crate's guide to choose
        with (a `Glt` or `GuidingField`; a new GLT over the scene's bounds
        when None and `choice` is 'glt')."""
        self.lights = SceneLights(scene)
        if self.choice == "glt" and guide is None:
            box = scene.bbox()
            lo, hi = np.array(box.min).reshape(3), np.array(box.max).reshape(3)
            guide = guiding.Glt(
                self.lights.tree(), (lo, hi), unbounded_lights=self.lights.unbounded
            )
        self.guide = guide
        return self

    def _choose(self, p, n, u):
        count = self.lights.light_count
        if self.choice == "glt":
            return self.guide.sample(p, u, normals=n)
        light = np.minimum((u * count).astype(np.int64), count - 1)
        return light, np.full(len(u), 1.0 / count, np.float32)

    def _pmf(self, p, n, light):
        count = self.lights.light_count
        if self.choice == "glt":
            return self.guide.pmf(p, light, normals=n)
        return np.full(len(light), 1.0 / count, np.float32)

    # The wavefront.

    def render_image(self, scene, spp, seed=0, record=False, sensor=None):
        """Renders `spp` samples per pixel; returns the image (h, w, 3) as
        numpy. With `record`, every NEE sample is recorded into the guide
        (a training pass)."""
        sensor = sensor or scene.sensors()[0]
        film = sensor.film()
        w, h = film.crop_size()
        n = w * h * spp
        sampler = sensor.sampler().fork()
        sampler.set_sample_count(spp)
        sampler.set_samples_per_wavefront(spp)
        sampler.seed(seed, n)
        idx = dr.arange(mi.UInt32, n)
        pixel = idx // spp
        pos = mi.Vector2f(mi.Float(pixel % w), mi.Float(pixel // w)) + sampler.next_2d()
        ray, ray_weight = sensor.sample_ray(
            0.0, sampler.next_1d(), pos / mi.Vector2f(w, h), sampler.next_2d()
        )
        L = self._trace(scene, sampler, ray, record)
        L *= ray_weight
        dr.eval(L)
        self.timer.lap("mitsuba")
        rgb = np.array(L, dtype=np.float64).reshape(3, -1).T
        pix = np.array(pixel, dtype=np.int64)
        img = np.stack([np.bincount(pix, rgb[:, k], minlength=w * h) for k in range(3)], axis=1)
        self.timer.lap("round trip")
        return (img / spp).reshape(h, w, 3)

    def _trace(self, scene, sampler, ray, record):
        lights = self.lights
        ctx = mi.BSDFContext()
        throughput = mi.Spectrum(1.0)
        L = mi.Spectrum(0.0)
        active = mi.Bool(True)
        prev_si = dr.zeros(mi.SurfaceInteraction3f)
        prev_bsdf_pdf = mi.Float(1.0)
        prev_delta = mi.Bool(True)
        for depth in range(self.max_depth):
            si = scene.ray_intersect(ray, active)
            # Emission found by the camera ray or the BSDF sample, weighed
            # by MIS against the NEE that could have found it.
            emitter = si.emitter(scene, active)
            Le = emitter.eval(si, active)
            hit = active & (emitter != None) & dr.any(Le != 0)  # noqa: E711 (a Dr.Jit mask)
            if depth == 0:
                L += throughput * Le
            else:
                light = lights.hit_light(si, emitter)
                hit &= light >= 0
                lanes = dr.compress(hit)
                host = _gather(lanes, prev_si.p, prev_si.n, light)
                self.timer.lap("mitsuba")
                p_prev, n_prev, light_np = (np.array(x) for x in host)
                self.timer.lap("round trip")
                pmf = self._pmf(p_prev.T, n_prev.T, light_np) if len(light_np) else np.zeros(0, np.float32)
                self.timer.lap("crate")
                pmf_hit = dr.zeros(mi.Float, dr.width(hit))
                dr.scatter(pmf_hit, mi.Float(pmf), lanes)
                tri = dr.select(light < lights.triangle_count, light, 0)
                on_triangle = hit & (light < lights.triangle_count)
                cos_l = dr.abs(dr.dot(si.n, ray.d))
                area = dr.gather(mi.Float, lights.tri_area, mi.UInt32(tri), on_triangle) if lights.triangle_count else mi.Float(1)
                pdf_tri = dr.select(cos_l > 0, dr.square(si.t) / (cos_l * area), 0)
                ds = mi.DirectionSample3f(scene, si=si, ref=prev_si)
                pdf_other = emitter.pdf_direction(prev_si, ds, hit & ~on_triangle)
                pdf_light = pmf_hit * dr.select(on_triangle, pdf_tri, pdf_other)
                mis = dr.select(prev_delta, 1.0, _power_heuristic(prev_bsdf_pdf, pdf_light))
                L += dr.select(hit, throughput * Le * mis, 0)
            active &= si.is_valid()
            if depth + 1 >= self.max_depth:
                break
            bsdf = si.bsdf(ray)
            # Next-event estimation: the crate chooses, here the light is sampled.
            nee = active & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
            u_light = sampler.next_1d()
            u_point = sampler.next_2d()
            lanes = dr.compress(nee)
            host = _gather(lanes, si.p, si.n, u_light)
            self.timer.lap("mitsuba")
            p, nrm, u = (np.array(x) for x in host)
            p, nrm = p.T, nrm.T
            u = np.minimum(u, np.float32(np.nextafter(np.float32(1), np.float32(0))))
            self.timer.lap("round trip")
            chosen, pmf = self._choose(p, nrm, u) if len(u) else (np.zeros(0, np.int64), np.zeros(0, np.float32))
            self.timer.lap("crate")
            chosen_dr = dr.full(mi.Int32, -1, dr.width(nee))
            pmf_dr = dr.zeros(mi.Float, dr.width(nee))
            dr.scatter(chosen_dr, mi.Int32(chosen.astype(np.int32)), lanes)
            dr.scatter(pmf_dr, mi.Float(pmf), lanes)
            nee &= chosen_dr >= 0
            em_weight, wo, pdf_dir, delta = self._sample_light(scene, si, chosen_dr, u_point, nee)
            bsdf_val, bsdf_pdf = bsdf.eval_pdf(ctx, si, si.to_local(wo), nee)
            mis = dr.select(delta, 1.0, _power_heuristic(pmf_dr * pdf_dir, bsdf_pdf))
            found = dr.select(nee & (pmf_dr > 0), bsdf_val * em_weight / pmf_dr, 0)
            L += throughput * found * mis
            if record and self.choice == "glt":
                (value,) = _gather(lanes, mi.luminance(found))
                self.timer.lap("mitsuba")
                v = np.array(value, dtype=np.float64)
                v = np.where(np.isfinite(v) & (v > 0), v, 0.0)
                self.timer.lap("round trip")
                keep = chosen >= 0
                self.guide.record_light(p[keep], chosen[keep], v[keep], normals=nrm[keep])
                self.timer.lap("crate")
            # The BSDF sample continues the path.
            bs, bsdf_weight = bsdf.sample(ctx, si, sampler.next_1d(), sampler.next_2d(), active)
            throughput *= bsdf_weight
            prev_si = si
            prev_bsdf_pdf = bs.pdf
            prev_delta = mi.has_flag(bs.sampled_type, mi.BSDFFlags.Delta)
            ray = si.spawn_ray(si.to_world(bs.wo))
            active &= dr.any(throughput != 0)
            dr.eval(throughput, L, active, ray, prev_bsdf_pdf, prev_delta)
        return L

    def _sample_light(self, scene, si, light, u, active):
        """The chosen light sampled from `si`: (Le * G * V / pdf, the
        direction, its solid-angle pdf, whether the light is a delta)."""
        lights = self.lights
        on_triangle = active & (light < lights.triangle_count)
        weight = mi.Spectrum(0.0)
        wo = mi.Vector3f(0, 0, 1)
        pdf = mi.Float(0.0)
        if lights.triangle_count:
            t = mi.UInt32(dr.select(on_triangle, light, 0))
            p0 = dr.gather(mi.Point3f, lights.tri_p0, t, on_triangle)
            e1 = dr.gather(mi.Vector3f, lights.tri_e1, t, on_triangle)
            e2 = dr.gather(mi.Vector3f, lights.tri_e2, t, on_triangle)
            n = dr.gather(mi.Normal3f, lights.tri_n, t, on_triangle)
            area = dr.gather(mi.Float, lights.tri_area, t, on_triangle)
            le = dr.gather(mi.Color3f, lights.tri_le, t, on_triangle)
            s = dr.sqrt(u.x)
            y = p0 + e1 * (s * (1 - u.y)) + e2 * (s * u.y)
            d = y - si.p
            dist2 = dr.squared_norm(d)
            w = d * dr.rsqrt(dr.maximum(dist2, 1e-30))
            cos_l = -dr.dot(n, w)
            visible = on_triangle & (cos_l > 0) & ~scene.ray_test(si.spawn_ray_to(y), on_triangle)
            pdf_t = dr.select(cos_l > 0, dist2 / (cos_l * area), 0)
            weight = dr.select(visible, le * cos_l * area / dist2, 0)
            wo = dr.select(on_triangle, w, wo)
            pdf = dr.select(on_triangle, pdf_t, pdf)
        other = active & ~on_triangle
        k = mi.UInt32(dr.select(other, light, 0))
        emitter = dr.gather(mi.EmitterPtr, lights.mitsuba_emitters, k, other)
        ds, w_other = emitter.sample_direction(si, u, other)
        other_visible = other & (ds.pdf > 0) & ~scene.ray_test(si.spawn_ray_to(ds.p), other)
        weight = dr.select(other, dr.select(other_visible, w_other, 0), weight)
        wo = dr.select(other, ds.d, wo)
        pdf = dr.select(other, ds.pdf, pdf)
        delta = other & ds.delta
        return weight, wo, pdf, delta


mi.register_integrator("glt_path", lambda props: GltPathIntegrator(props))
