"""A Mitsuba 3 scene's emitters as the crate's lights.

Every triangle of an emissive mesh is a light of its own (Mitsuba samples
a mesh emitter as one light, by area over all of its triangles); a sphere
with an area emitter, a point and a spot light are one light each; the
environment (`constant`, `envmap`) is the crate's unbounded light. The
light indices count the triangles of the emissive meshes first, then the
other emitters, then the environment, as `guiding` counts emitters, then
unbounded lights.

`SceneLights` keeps what the integrator needs to sample a chosen light
and to find the light a BSDF sample hit: the triangles as Dr.Jit arrays,
and maps between light indices and Mitsuba's emitters.
"""

from __future__ import annotations

import math

import drjit as dr
import mitsuba as mi
import numpy as np

import guiding


def luminance(rgb):
    rgb = np.asarray(rgb, dtype=np.float64).reshape(-1, 3)
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def _uniform_color(params, key, what):
    if key not in params:
        raise NotImplementedError(f"{what}: only uniform ('rgb' or 'spectrum' value) emission is converted")
    return np.array(params[key], dtype=np.float64).reshape(-1)[:3] * np.ones(3)


def _registry_id(emitter) -> int:
    return int(dr.reinterpret_array(mi.UInt32, mi.EmitterPtr(emitter))[0])


class SceneLights:
    """The lights of a loaded Mitsuba scene, converted once."""

    def __init__(self, scene: "mi.Scene"):
        emitters = list(scene.emitters())
        # An emitter's shape as the scene holds it (`Emitter.get_shape`
        # gives the base class, without the mesh's buffers).
        shape_of = {
            _registry_id(s.emitter()): s for s in scene.shapes() if s.emitter() is not None
        }
        self.emitters = guiding.Emitters()
        # Emissive meshes' triangles: vertices, radiance.
        tri_p, tri_le, mesh_of = [], [], []
        others, environment = [], []
        for e in emitters:
            name = e.class_name()
            shape = shape_of.get(_registry_id(e))
            if name == "AreaLight" and shape is not None and shape.is_mesh():
                v = np.array(shape.vertex_positions_buffer(), dtype=np.float64).reshape(-1, 3)
                f = np.array(shape.faces_buffer(), dtype=np.int64).reshape(-1, 3)
                tri_p.append(v[f])
                le = _uniform_color(mi.traverse(e), "radiance.value", f"emitter on {shape.id()}")
                tri_le.append(np.tile(le, (len(f), 1)))
                mesh_of.append((e, len(f)))
            elif e.is_environment():
                environment.append(e)
            else:
                others.append(e)
        if len(environment) > 1:
            raise NotImplementedError("more than one environment emitter")
        # 1. The triangles.
        self.triangle_count = sum(n for _, n in mesh_of)
        if self.triangle_count:
            p = np.concatenate(tri_p)
            le = np.concatenate(tri_le)
            e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
            cross = np.cross(e1, e2)
            area = 0.5 * np.linalg.norm(cross, axis=1)
            power = math.pi * area * luminance(le)
            self.emitters.add_triangles(p, power)
            normal = cross / np.maximum(2 * area, 1e-30)[:, None]
            self.tri_p0 = mi.Point3f(*[mi.Float(p[:, 0, k]) for k in range(3)])
            self.tri_e1 = mi.Vector3f(*[mi.Float(e1[:, k]) for k in range(3)])
            self.tri_e2 = mi.Vector3f(*[mi.Float(e2[:, k]) for k in range(3)])
            self.tri_n = mi.Normal3f(*[mi.Float(normal[:, k]) for k in range(3)])
            self.tri_area = mi.Float(area)
            self.tri_le = mi.Color3f(*[mi.Float(le[:, k]) for k in range(3)])
        # 2. The other emitters, one light each.
        for e in others:
            name = e.class_name()
            params = mi.traverse(e)
            if name == "PointLight":
                i = _uniform_color(params, "intensity.value", "point light")
                pos = np.array(params["position"], dtype=np.float64).reshape(1, 3)
                self.emitters.add_points(pos, [4 * math.pi * luminance(i)[0]])
            elif name == "SpotLight":
                i = _uniform_color(params, "intensity.value", "spot light")
                m = np.array(params["to_world"].matrix, dtype=np.float64).reshape(4, 4)
                pos, axis = m[:3, 3], m[:3, 2]
                cos_start = math.cos(math.radians(float(params["beam_width"][0])))
                cos_end = math.cos(math.radians(float(params["cutoff_angle"][0])))
                power = luminance(i)[0] * 2 * math.pi * (1 - 0.5 * (cos_start + cos_end))
                self.emitters.add_spots([pos], [axis], [cos_start], [cos_end], [power])
            elif name == "AreaLight" and _registry_id(e) in shape_of:
                shape = shape_of[_registry_id(e)]
                le = _uniform_color(params, "radiance.value", f"emitter on {shape.id()}")
                box = shape.bbox()
                lo, hi = np.array(box.min).reshape(3), np.array(box.max).reshape(3)
                radius = float(np.max(hi - lo)) / 2
                power = math.pi * float(shape.surface_area()[0]) * luminance(le)[0]
                self.emitters.add_spheres([(lo + hi) / 2], [radius], [power])
            else:
                raise NotImplementedError(f"emitter {name} is not converted")
        self.emitter_count = len(self.emitters)
        self.unbounded = len(environment)
        # Light index -> the Mitsuba emitter that samples it (a mesh's
        # triangles: the mesh's, sampled by the integrator itself).
        order = [e for e, n in mesh_of for _ in range(n)] + others + environment
        self.mitsuba_emitters = mi.EmitterPtr(order) if order else None
        self.is_triangle = np.zeros(len(order), dtype=bool)
        self.is_triangle[: self.triangle_count] = True
        # Registry id of a Mitsuba emitter -> its first light index; a hit's
        # light is that plus the hit triangle's index for meshes.
        ids = [_registry_id(e) for e in emitters]
        size = max(ids, default=0) + 1
        first = np.full(size, -1, dtype=np.int64)
        per_mesh = np.zeros(size, dtype=bool)
        start = 0
        for e, n in mesh_of:
            first[_registry_id(e)] = start
            per_mesh[_registry_id(e)] = True
            start += n
        for k, e in enumerate(others + environment):
            first[_registry_id(e)] = self.triangle_count + k
        self.first_light = mi.Int32(first.astype(np.int32))
        self.per_triangle = mi.Bool(per_mesh)
        self.light_count = len(order)

    def hit_light(self, si: "mi.SurfaceInteraction3f", emitter) -> "mi.Int32":
        """The light index of what a ray hit (the environment for an escaped
        ray), -1 where it hit no emitter."""
        rid = dr.reinterpret_array(mi.UInt32, emitter)
        known = (rid > 0) & (rid < dr.width(self.first_light))
        first = dr.gather(mi.Int32, self.first_light, rid, known)
        tri = dr.gather(mi.Bool, self.per_triangle, rid, known)
        idx = first + dr.select(tri & si.is_valid(), mi.Int32(si.prim_index), 0)
        return dr.select(known & (first >= 0), idx, -1)

    def tree(self) -> guiding.LightTree:
        return guiding.LightTree(self.emitters)
