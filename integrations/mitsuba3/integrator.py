"""`glt_path`: Mitsuba 3 path tracing with next-event estimation whose light
choice is the crate's Guiding Light Tree (or, as a check, a uniform choice
over the same per-triangle lights), and optionally Practical Path Guiding's
directions from the crate's combined field (`choice` = 'field').

A wavefront integrator: each bounce is one evaluated Dr.Jit kernel over
every path; the shading points go to the host as numpy arrays, the crate
chooses a light for each (one batched call, the GIL released), and the
chosen lights come back as indices. Triangles of emissive meshes are
sampled here (uniformly by area); every other emitter by Mitsuba's own
`sample_direction`. MIS (power heuristic) weighs NEE against BSDF samples
that hit emitters, with the light pmf the crate reports for the hit light.
No Russian roulette (`max_depth` bounds the paths, as in the comparison's
`path` runs with `rr_depth` past it).

With `choice` = 'field' the guide is a `GuidingField` (the SD-tree and the
GLT in one spatial tree): the light choice is its GLT's, and at every
diffuse vertex the path continues with PPG's one-sample mixture, the BSDF's
sample with the field's `bsdf_fraction` and the SD-tree's otherwise, both
directions and their pdfs computed on the host in the same round trip as
the light choice. The MIS weights between NEE and emitter hits use the
BSDF's pdf on both sides (they sum to one, so the estimate stays unbiased;
the mixture's pdf of an NEE direction would cost a second round trip per
bounce). A training pass records, besides the light records, PPG's: the
radiance that came back along each guided direction, from one backward
pass over the path's segments at the end (`L_k = e_k + w_(k+1) L_(k+1)`,
as the crate's `PathRecorder` does).

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
    `choice` ('glt'; 'field', the GLT's light choice and PPG's directions
    from one `GuidingField`; or 'uniform' over the same lights: a check of
    the wavefront's own correctness and cost)."""

    def __init__(self, props=mi.Properties()):
        super().__init__(props)
        self.max_depth = props.get("max_depth", 5)
        self.choice = props.get("choice", "glt")
        if self.choice not in ("glt", "field", "uniform"):
            raise ValueError(f"glt_path: choice must be 'glt', 'field' or 'uniform', not {self.choice!r}")
        self.lights = None
        self.guide = None
        self.timer = Timer()

    # The light choice on the host.

    def attach(self, scene, guide=None):
        """Converts `scene`'s lights; `guide` is the crate's guide to choose
        with (a `Glt`, or a `GuidingField` for 'field'; a new one over the
        scene's bounds when None)."""
        self.lights = SceneLights(scene)
        if self.choice != "uniform" and guide is None:
            box = scene.bbox()
            lo, hi = np.array(box.min).reshape(3), np.array(box.max).reshape(3)
            if self.choice == "field":
                # The field's cells hold the GLT's cuts too: the GLT's own
                # spatial threshold (250) rather than the SD-tree's 4,000
                # halves the light choice's error here (corridor, 16 spp:
                # relMSE 3.2e-2 against 4.9e-2; docs/results.md).
                guide = guiding.GuidingField(
                    self.lights.tree(), (lo, hi), unbounded_lights=self.lights.unbounded, spatial_threshold=250
                )
            else:
                guide = guiding.Glt(self.lights.tree(), (lo, hi), unbounded_lights=self.lights.unbounded)
        self.guide = guide
        return self

    def _choose(self, p, n, u):
        count = self.lights.light_count
        if self.choice != "uniform":
            return self.guide.sample(p, u, normals=n)
        light = np.minimum((u * count).astype(np.int64), count - 1)
        return light, np.full(len(u), 1.0 / count, np.float32)

    def _pmf(self, p, n, light):
        count = self.lights.light_count
        if self.choice != "uniform":
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
        field = self.choice == "field"
        ctx = mi.BSDFContext()
        throughput = mi.Spectrum(1.0)
        L = mi.Spectrum(0.0)
        active = mi.Bool(True)
        prev_si = dr.zeros(mi.SurfaceInteraction3f)
        prev_bsdf_pdf = mi.Float(1.0)
        prev_delta = mi.Bool(True)
        # PPG's records (a field's training pass): per vertex, what its
        # segment found at its end (`e`, not multiplied by the throughput)
        # and the guided segments leaving it.
        segments = [] if field and record else None
        for depth in range(self.max_depth):
            si = scene.ray_intersect(ray, active)
            found_here = mi.Spectrum(0.0)
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
                found_here += dr.select(hit, Le * mis, 0)
            active &= si.is_valid()
            if depth + 1 >= self.max_depth:
                L += throughput * found_here
                if segments is not None:
                    segments.append(dict(found=found_here))
                break
            bsdf = si.bsdf(ray)
            # Next-event estimation: the crate chooses, here the light is
            # sampled. With a field, the same round trip brings PPG's
            # directions.
            nee = active & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
            u_light = sampler.next_1d()
            u_point = sampler.next_2d()
            bs, bsdf_weight = bsdf.sample(ctx, si, sampler.next_1d(), sampler.next_2d(), active)
            lanes = dr.compress(nee)
            if field:
                u_pick, u_dir = sampler.next_1d(), sampler.next_2d()
                wo_bsdf = si.to_world(bs.wo)
                host = _gather(lanes, si.p, si.n, u_light, u_dir, wo_bsdf)
            else:
                host = _gather(lanes, si.p, si.n, u_light)
            self.timer.lap("mitsuba")
            p, nrm, u = (np.array(x) for x in host[:3])
            p, nrm = p.T, nrm.T
            u = np.minimum(u, np.float32(np.nextafter(np.float32(1), np.float32(0))))
            if field:
                u_dir_np, wo_bsdf_np = np.array(host[3]).T, np.array(host[4]).T
                u_dir_np = np.minimum(u_dir_np, np.float32(np.nextafter(np.float32(1), np.float32(0))))
            self.timer.lap("round trip")
            empty = len(u) == 0
            chosen, pmf = self._choose(p, nrm, u) if not empty else (np.zeros(0, np.int64), np.zeros(0, np.float32))
            if field:
                alpha = self.guide.bsdf_fraction(p) if not empty else np.zeros(0, np.float32)
                g_dir, g_pdf = self.guide.sample_direction(p, u_dir_np) if not empty else (np.zeros((0, 3), np.float32), np.zeros(0, np.float32))
                g_pdf_of_bsdf = self.guide.direction_pdf(p, wo_bsdf_np) if not empty else np.zeros(0, np.float32)
            self.timer.lap("crate")
            chosen_dr = dr.full(mi.Int32, -1, dr.width(nee))
            pmf_dr = dr.zeros(mi.Float, dr.width(nee))
            dr.scatter(chosen_dr, mi.Int32(chosen.astype(np.int32)), lanes)
            dr.scatter(pmf_dr, mi.Float(pmf), lanes)
            light_nee = nee & (chosen_dr >= 0)
            em_weight, wo, pdf_dir, delta = self._sample_light(scene, si, chosen_dr, u_point, light_nee)
            bsdf_val, bsdf_pdf = bsdf.eval_pdf(ctx, si, si.to_local(wo), light_nee)
            mis = dr.select(delta, 1.0, _power_heuristic(pmf_dr * pdf_dir, bsdf_pdf))
            found = dr.select(light_nee & (pmf_dr > 0), bsdf_val * em_weight / pmf_dr, 0)
            found_here += found * mis
            L += throughput * found_here
            if segments is not None:
                segments.append(dict(found=found_here))
            if record and self.choice != "uniform":
                (value,) = _gather(lanes, mi.luminance(found))
                self.timer.lap("mitsuba")
                v = np.array(value, dtype=np.float64)
                v = np.where(np.isfinite(v) & (v > 0), v, 0.0)
                self.timer.lap("round trip")
                keep = chosen >= 0
                self.guide.record_light(p[keep], chosen[keep], v[keep], normals=nrm[keep])
                self.timer.lap("crate")
            # The path continues: the BSDF's sample, or with a field PPG's
            # mixture of it and the SD-tree's.
            weight = bsdf_weight
            wo_next = si.to_world(bs.wo)
            next_bsdf_pdf = bs.pdf
            next_delta = mi.has_flag(bs.sampled_type, mi.BSDFFlags.Delta)
            if field:
                guided = nee & ~mi.has_flag(bsdf.flags(), mi.BSDFFlags.Delta)
                width = dr.width(nee)
                alpha_dr, g_pdf_dr, gb_pdf_dr = (dr.zeros(mi.Float, width) for _ in range(3))
                g_dir_dr = dr.zeros(mi.Vector3f, width)
                dr.scatter(alpha_dr, mi.Float(alpha), lanes)
                dr.scatter(g_pdf_dr, mi.Float(g_pdf), lanes)
                dr.scatter(gb_pdf_dr, mi.Float(g_pdf_of_bsdf), lanes)
                dr.scatter(g_dir_dr, mi.Vector3f(g_dir.T), lanes)
                by_guide = guided & (u_pick >= alpha_dr)
                f_guide, bsdf_pdf_guide = bsdf.eval_pdf(ctx, si, si.to_local(g_dir_dr), by_guide)
                f = dr.select(by_guide, f_guide, bsdf_weight * bs.pdf)
                p_bsdf = dr.select(by_guide, bsdf_pdf_guide, bs.pdf)
                p_guide = dr.select(by_guide, g_pdf_dr, gb_pdf_dr)
                mixture = alpha_dr * p_bsdf + (1 - alpha_dr) * p_guide
                weight = dr.select(guided, dr.select(mixture > 0, f / mixture, 0), bsdf_weight)
                wo_next = dr.select(by_guide, g_dir_dr, wo_next)
                next_bsdf_pdf = dr.select(guided, p_bsdf, next_bsdf_pdf)
                next_delta &= ~by_guide
                if segments is not None:
                    segments[-1].update(p=si.p, wo=wo_next, pdf=mixture, weight=weight, guided=guided & (mixture > 0))
            throughput *= weight
            prev_si = si
            prev_bsdf_pdf = next_bsdf_pdf
            prev_delta = next_delta
            ray = si.spawn_ray(wo_next)
            active &= dr.any(throughput != 0)
            dr.eval(throughput, L, active, ray, prev_bsdf_pdf, prev_delta)
        if segments is not None:
            self._record_directions(segments)
        return L

    def _record_directions(self, segments):
        """PPG's records from one training pass: the radiance that came back
        along every guided segment (`L_k = e_k + w_(k+1) L_(k+1)`, spectral,
        then its luminance), recorded with the segment's mixture pdf."""
        host = [{k: np.array(v) for k, v in s.items()} for s in segments]
        self.timer.lap("round trip")
        incident = np.zeros_like(host[-1]["found"].T, dtype=np.float64)
        records = []
        for k in range(len(host) - 2, -1, -1):
            # What arrived at vertex k along its segment: what the segment
            # found at its end, and what came back through the next segment.
            after = host[k + 1]
            carried = after["weight"].T * incident if "weight" in after else 0.0
            incident = after["found"].T + carried
            s = host[k]
            if "guided" not in s:
                continue
            keep = s["guided"].astype(bool)
            radiance = incident[keep] @ np.array([0.2126, 0.7152, 0.0722])
            ok = np.isfinite(radiance)
            records.append((s["p"].T[keep][ok], s["wo"].T[keep][ok], radiance[ok], s["pdf"][keep][ok]))
        for p, wo, radiance, pdf in records:
            if len(p):
                self.guide.record_radiance(p, wo, radiance, pdf)
        self.timer.lap("crate")

    def _sample_light(self, scene, si, light, u, active):
        """The chosen light sampled from `si`: (Le * G * V / pdf, the
        direction, its solid-angle pdf, whether the light is a delta). One
        shadow ray per path, whichever kind of light it chose."""
        lights = self.lights
        on_triangle = active & (light < lights.triangle_count)
        weight = mi.Spectrum(0.0)
        wo = mi.Vector3f(0, 0, 1)
        pdf = mi.Float(0.0)
        target = mi.Point3f(si.p)
        delta = mi.Bool(False)
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
            on_triangle &= cos_l > 0
            weight = dr.select(on_triangle, le * cos_l * area / dist2, 0)
            pdf = dr.select(on_triangle, dist2 / (cos_l * area), 0)
            wo = dr.select(on_triangle, w, wo)
            target = dr.select(on_triangle, y, target)
        other = active & (light >= lights.triangle_count)
        if lights.light_count > lights.triangle_count:
            k = mi.UInt32(dr.select(other, light, 0))
            emitter = dr.gather(mi.EmitterPtr, lights.mitsuba_emitters, k, other)
            ds, w_other = emitter.sample_direction(si, u, other)
            other &= ds.pdf > 0
            weight = dr.select(other, w_other, weight)
            wo = dr.select(other, ds.d, wo)
            pdf = dr.select(other, ds.pdf, pdf)
            target = dr.select(other, ds.p, target)
            delta = other & ds.delta
        shadowed = on_triangle | other
        occluded = scene.ray_test(si.spawn_ray_to(target), shadowed)
        weight = dr.select(shadowed & ~occluded, weight, 0)
        return weight, wo, pdf, delta


mi.register_integrator("glt_path", lambda props: GltPathIntegrator(props))
