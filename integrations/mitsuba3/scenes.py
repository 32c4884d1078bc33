"""Three many-light scenes written with Mitsuba 3's scene-dict API.

- `city`: a grid of buildings whose windows are 12,288 small emissive
  quads (24,576 triangles), in 16 emissive meshes of one brightness each,
  every mesh's windows scattered over the whole city (as a renderer that
  groups lights by material sees them), a street between, a camera on it.
- `corridor`: a long hall of rooms behind walls with doorways, 2,048 ceiling
  lamps (4,096 triangles) in 8 meshes of powers spread over 3 decades:
  most lamps are behind a wall from any point.
- `mixed`: every kind of light the conversion handles: emissive quads,
  emissive spheres, point and spot lights, and an environment map.

Emissive meshes are written as binary PLY files into `work_dir` (Mitsuba
loads meshes from files; its `rectangle` shapes would make each window an
emitter of its own, and the JIT compile time grows with the number of
emitters: 12 s for 1,000 rectangles, 129 s for 10,000, measured).
Geometry is diffuse. Every scene sets Mitsuba's `path` integrator (`rr_depth`
past `max_depth`, as the wavefront integrator has no Russian roulette) and
a box pixel filter, so images of both integrators compare pixel by pixel.
"""

from __future__ import annotations

import os

import mitsuba as mi
import numpy as np

T = mi.ScalarTransform4f
MAX_DEPTH = 4


def write_ply(path, vertices, faces):
    """A binary little-endian PLY of float vertices and triangle faces."""
    vertices = np.asarray(vertices, dtype="<f4").reshape(-1, 3)
    faces = np.asarray(faces, dtype="<i4").reshape(-1, 3)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rows["n"] = 3
    rows["i"] = faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vertices.tobytes())
        f.write(rows.tobytes())


def quads_mesh(corners, edge_u, edge_v):
    """Vertices and faces of quads `corner + s edge_u + t edge_v`, emitting
    on the side of `edge_u x edge_v` (faces wound that way)."""
    c = np.asarray(corners, np.float64)
    eu = np.broadcast_to(edge_u, c.shape)
    ev = np.broadcast_to(edge_v, c.shape)
    v = np.stack([c, c + eu, c + eu + ev, c + ev], axis=1).reshape(-1, 3)
    base = 4 * np.arange(len(c))[:, None]
    f = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]], axis=1).reshape(-1, 3)
    return v, f


def _base(width, height, spp, origin, target, fov=60):
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH, "rr_depth": MAX_DEPTH + 1},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "to_world": T().look_at(origin=origin, target=target, up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }


def _box(center, size, bsdf="gray"):
    c, s = np.asarray(center, float), np.asarray(size, float) / 2
    return {
        "type": "cube",
        "to_world": T().translate(c.tolist()).scale(s.tolist()),
        "bsdf": {"type": "ref", "id": bsdf},
    }


def _gray(value=0.5):
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": [value] * 3}}


def _emissive_groups(d, work_dir, name, corners, edge_u, edge_v, radiance, groups, rng):
    """Adds the quads as `groups` emissive meshes of one radiance each,
    each quad assigned to a random group (scattered over the scene)."""
    group = rng.integers(groups, size=len(corners))
    for g in range(groups):
        sel = group == g
        if not sel.any():
            continue
        eu = np.asarray(edge_u)[sel] if np.ndim(edge_u) == 2 else edge_u
        ev = np.asarray(edge_v)[sel] if np.ndim(edge_v) == 2 else edge_v
        v, f = quads_mesh(np.asarray(corners)[sel], eu, ev)
        path = os.path.join(work_dir, f"{name}-{g}.ply")
        write_ply(path, v, f)
        d[f"{name}{g}"] = {
            "type": "ply",
            "filename": path,
            "face_normals": True,
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": radiance[g]}},
            "bsdf": {"type": "ref", "id": "gray"},
        }


def city(work_dir, width=128, height=96, spp=16, seed=1):
    rng = np.random.default_rng(seed)
    d = _base(width, height, spp, origin=[0, 1.7, -46], target=[0, 6, 40])
    d["gray"] = _gray()
    d["ground"] = {
        "type": "rectangle",
        "to_world": T().rotate([1, 0, 0], -90).scale(80),
        "bsdf": {"type": "ref", "id": "gray"},
    }
    corners, eu, ev = [], [], []
    k = 0
    for bx in range(-3, 4):
        for bz in range(-3, 4):
            if bx == 0:
                continue  # the street
            cx, cz = bx * 12.0, bz * 12.0
            h = float(rng.uniform(8, 30))
            d[f"building{k}"] = _box([cx, h / 2, cz], [8, h, 8])
            k += 1
            # Windows on the four facades, just outside the walls.
            for side in range(4):
                normal = np.array([[1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1]][side], float)
                tangent = np.array([[0, 0, -1], [0, 0, 1], [1, 0, 0], [-1, 0, 0]][side], float)
                face = np.array([cx, 0, cz]) + normal * 4.02
                for row in range(int(h // 3.0)):
                    for col in range(-3, 4):
                        if rng.random() < 0.35:
                            continue
                        c = face + tangent * (col * 1.1 - 0.3) + np.array([0, 1.0 + row * 3.0, 0])
                        corners.append(c)
                        # edge_u x edge_v = normal: windows face outwards.
                        eu.append(np.cross([0, 1.0, 0], normal) * 0.6)
                        ev.append([0, 1.2, 0])
    corners, eu, ev = np.array(corners), np.array(eu), np.array(ev)
    radiance = [[float(x)] * 3 for x in 10 ** rng.uniform(-1, 1, size=16)]
    _emissive_groups(d, work_dir, "windows", corners, eu, ev, radiance, 16, rng)
    return d


def corridor(work_dir, width=128, height=64, spp=16, seed=2):
    rng = np.random.default_rng(seed)
    d = _base(width, height, spp, origin=[0.5, 1.6, 1], target=[0, 1.0, 40], fov=70)
    d["gray"] = _gray(0.6)
    length, rooms = 128.0, 16
    d["floor"] = _box([0, -0.05, length / 2], [8, 0.1, length])
    d["ceiling"] = _box([0, 3.05, length / 2], [8, 0.1, length])
    d["left"] = _box([-4.05, 1.5, length / 2], [0.1, 3, length])
    d["right"] = _box([4.05, 1.5, length / 2], [0.1, 3, length])
    for r in range(1, rooms):
        z = r * length / rooms
        # A wall across the hall with a doorway off the centre.
        door = float(rng.uniform(-2.5, 2.5))
        d[f"wall{r}a"] = _box([(-4 + door - 0.6) / 2, 1.5, z], [door - 0.6 + 4, 3, 0.1])
        d[f"wall{r}b"] = _box([(door + 0.6 + 4) / 2, 1.5, z], [4 - door - 0.6, 3, 0.1])
    n = 2048
    x = rng.uniform(-3.8, 3.6, n)
    z = rng.uniform(0.2, length - 0.4, n)
    corners = np.stack([x, np.full(n, 2.99), z], axis=1)
    # Facing down: edge_u x edge_v = -y.
    radiance = [[float(v)] * 3 for v in 10 ** np.linspace(-1.5, 1.5, 8)]
    _emissive_groups(d, work_dir, "lamps", corners, [0.2, 0, 0], [0, 0, 0.2], radiance, 8, rng)
    return d


def mixed(work_dir, width=128, height=96, spp=16, seed=3):
    rng = np.random.default_rng(seed)
    d = _base(width, height, spp, origin=[0, 6, -14], target=[0, 0, 4])
    d["gray"] = _gray()
    d["floor"] = {
        "type": "rectangle",
        "to_world": T().rotate([1, 0, 0], -90).scale(20),
        "bsdf": {"type": "ref", "id": "gray"},
    }
    for i in range(6):
        d[f"pillar{i}"] = _box([rng.uniform(-8, 8), 1.5, rng.uniform(-4, 12)], [1, 3, 1])
    n = 1024
    corners = np.stack([rng.uniform(-10, 10, n), np.full(n, 4.0), rng.uniform(-6, 16, n)], axis=1)
    radiance = [[float(v), float(v) * 0.8, float(v) * 0.6] for v in 10 ** rng.uniform(0, 2, 4)]
    # Facing down.
    _emissive_groups(d, work_dir, "panels", corners, [0.15, 0, 0], [0, 0, 0.15], radiance, 4, rng)
    for i in range(16):
        d[f"bulb{i}"] = {
            "type": "sphere",
            "center": [float(rng.uniform(-9, 9)), float(rng.uniform(0.5, 3)), float(rng.uniform(-5, 15))],
            "radius": 0.08,
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [30.0, 20.0, 10.0]}},
        }
    for i in range(16):
        d[f"point{i}"] = {
            "type": "point",
            "position": [float(rng.uniform(-9, 9)), float(rng.uniform(0.5, 3)), float(rng.uniform(-5, 15))],
            "intensity": {"type": "rgb", "value": [float(rng.uniform(0.5, 5))] * 3},
        }
    for i in range(4):
        p = [float(rng.uniform(-8, 8)), 3.8, float(rng.uniform(-4, 14))]
        d[f"spot{i}"] = {
            "type": "spot",
            "to_world": T().look_at(origin=p, target=[p[0], 0, p[2]], up=[0, 0, 1]),
            "cutoff_angle": 35.0,
            "beam_width": 25.0,
            "intensity": {"type": "rgb", "value": [20.0, 20.0, 20.0]},
        }
    sky = np.ones((16, 32, 3), np.float32) * 0.02
    sky[:8] *= np.linspace(3, 1, 8)[:, None, None]
    d["sky"] = {"type": "envmap", "bitmap": mi.Bitmap(sky)}
    return d


SCENES = {"city": city, "corridor": corridor, "mixed": mixed}
