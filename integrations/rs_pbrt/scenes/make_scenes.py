#!/usr/bin/env python3
"""Writes the integration's test scenes (pbrt-v3 format) into this folder.

    python3 make_scenes.py

Deterministic (fixed seeds): running it again rewrites the committed files
byte for byte. Each scene is described in README.md beside this script.
"""
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))


def num(x):
    """A short decimal: 3 places at most, no trailing zeros."""
    s = f"{x:.3f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def nums(xs):
    return " ".join(num(x) for x in xs)


def header(out, eye, look, fov, res, name, spp=64):
    out.append(f"LookAt {nums(eye)}  {nums(look)}  0 1 0")
    out.append(f'Camera "perspective" "float fov" [{num(fov)}]')
    out.append(f'Film "image" "integer xresolution" [{res[0]}] "integer yresolution" [{res[1]}] "string filename" "{name}.png"')
    out.append(f'Sampler "random" "integer pixelsamples" [{spp}]')
    out.append('Integrator "path" "integer maxdepth" [5] "string lightsamplestrategy" "spatial"')
    out.append("WorldBegin")


class Mesh:
    """Quads gathered into one trianglemesh."""

    def __init__(self):
        self.p, self.i = [], []

    def quad(self, c, u, v):
        """corner c, edges u and v (emits, for lights, on the side of u x v)"""
        k = len(self.p)
        self.p += [c, add(c, u), add(add(c, u), v), add(c, v)]
        self.i += [k, k + 1, k + 2, k, k + 2, k + 3]

    def strip(self, c, u, v, cells):
        """`cells` quads side by side from corner c along u (each u long,
        v high), sharing their edges (emits on the side of u x v)"""
        k = len(self.p)
        for j in range(cells + 1):
            b = tuple(x + j * y for x, y in zip(c, u))
            self.p += [b, add(b, v)]
        for j in range(cells):
            a = k + 2 * j
            self.i += [a, a + 2, a + 3, a, a + 3, a + 1]

    def box(self, lo, hi):
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        dx, dy, dz = (x1 - x0, 0, 0), (0, y1 - y0, 0), (0, 0, z1 - z0)
        self.quad((x0, y0, z0), dz, dx)  # bottom, facing -y
        self.quad((x0, y1, z0), dx, dz)  # top, +y
        self.quad((x0, y0, z0), dx, dy)  # -z
        self.quad((x0, y0, z1), dy, dx)  # +z
        self.quad((x0, y0, z0), dy, dz)  # -x
        self.quad((x1, y0, z0), dz, dy)  # +x

    def write(self, out):
        if not self.p:
            return
        out.append(f'Shape "trianglemesh" "integer indices" [{" ".join(map(str, self.i))}]')
        out.append(f'  "point P" [{" ".join(nums(p) for p in self.p)}]')

    def triangles(self):
        return len(self.i) // 3


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sphere_light(out, p, r, rgb):
    out.append("AttributeBegin")
    out.append(f'  AreaLightSource "diffuse" "rgb L" [{nums(rgb)}]')
    out.append(f"  Translate {nums(p)}")
    out.append(f'  Shape "sphere" "float radius" [{num(r)}]')
    out.append("AttributeEnd")


def two_rooms():
    """Two rooms side by side, a wall with a doorway between them; 100 dim
    lights in the room the camera is in, 100 twenty times brighter in the
    other."""
    rng = random.Random(1)
    out = ["# Two rooms split by a wall with a doorway (make_scenes.py)."]
    header(out, (-7.2, 1.6, 3.2), (0, 1.2, 0), 60, (160, 120), "two_rooms")
    out.append('Material "matte" "rgb Kd" [0.6 0.6 0.6]')
    m = Mesh()
    m.box((-8.2, -0.2, -4.2), (8.2, 0, 4.2))  # floor
    m.box((-8.2, 4, -4.2), (8.2, 4.2, 4.2))  # ceiling
    m.box((-8.2, 0, -4.2), (8.2, 4, -4))  # back
    m.box((-8.2, 0, 4), (8.2, 4, 4.2))  # front
    m.box((-8.2, 0, -4), (-8, 4, 4))  # left end
    m.box((8, 0, -4), (8.2, 4, 4))  # right end
    m.box((-0.1, 0, -4), (0.1, 4, -0.8))  # the wall, doorway at |z| < 0.8
    m.box((-0.1, 0, 0.8), (0.1, 4, 4))
    m.box((-0.1, 2.5, -0.8), (0.1, 4, 0.8))
    m.write(out)
    for room, scale in ((-1, 1.0), (1, 20.0)):
        for _ in range(100):
            x = room * rng.uniform(0.5, 7.5)
            p = (x, rng.uniform(2.6, 3.8), rng.uniform(-3.6, 3.6))
            c = rng.uniform(0.5, 2.0) * scale
            sphere_light(out, p, 0.04, (4 * c, 3.6 * c, 3 * c))
    out.append("WorldEnd")
    return out


def sun_sky():
    """A street at dusk: a low sun (distant light) and a sky (infinite
    light) over rows of buildings, 300 street lamps along the street."""
    rng = random.Random(2)
    out = ["# A street at dusk: sun, sky and 300 street lamps (make_scenes.py)."]
    header(out, (0, 1.7, -28), (0, 3, 20), 55, (160, 120), "sun_sky")
    out.append('Material "matte" "rgb Kd" [0.5 0.5 0.5]')
    m = Mesh()
    m.box((-60, -0.2, -40), (60, 0, 80))  # ground
    for side in (-1, 1):
        z = -30.0
        while z < 70:
            w, h = rng.uniform(6, 12), rng.uniform(6, 25)
            x0 = side * 9
            m.box((min(x0, x0 + side * 10), 0, z), (max(x0, x0 + side * 10), h, z + w))
            z += w + rng.uniform(0.5, 3)
    m.write(out)
    out.append('LightSource "distant" "point from" [0 0 0] "point to" [-0.6 -0.12 0.8] "rgb L" [2.2 1.1 0.5]')
    out.append('LightSource "infinite" "rgb L" [0.05 0.07 0.12]')
    for k in range(150):
        z = -30 + k * (100 / 150)
        for side in (-1, 1):
            p = (side * rng.uniform(6.5, 7.5), rng.uniform(3.5, 4.5), z + rng.uniform(-0.2, 0.2))
            c = rng.uniform(0.5, 1.5)
            sphere_light(out, p, 0.08, (30 * c, 24 * c, 14 * c))
    out.append("WorldEnd")
    return out


def city():
    """Night over a city of 10 x 10 blocks: every building's windows are
    emissive: a band of 0.5 m cells round every floor (two triangles a
    cell, a light per triangle), over 100,000 emissive triangles in all."""
    rng = random.Random(3)
    out = ["# A city at night, >= 100k emissive window triangles (make_scenes.py)."]
    header(out, (-20, 60, -20), (60, 0, 60), 60, (160, 120), "city")
    out.append('Material "matte" "rgb Kd" [0.4 0.4 0.4]')
    ground, buildings = Mesh(), Mesh()
    ground.box((-40, -0.2, -40), (160, 0, 160))
    lit = []
    for bx in range(10):
        for bz in range(10):
            x0, z0 = bx * 12.0, bz * 12.0
            w, d, h = 8.0, 8.0, 3.0 * rng.randint(4, 14)
            buildings.box((x0, 0, z0), (x0 + w, h, z0 + d))
            win = Mesh()
            floors = int(h / 3)
            e = 0.02  # the window bands stand off the facade
            n = int(w / 0.5)  # cells of 0.5 m per band and facade
            for f in range(floors):
                y = f * 3 + 1.0
                up = (0, 1.2, 0)
                # a band of windows round the floor, each cell facing out
                win.strip((x0 + w, y, z0 - e), (-0.5, 0, 0), up, n)
                win.strip((x0 + w + e, y, z0 + d), (0, 0, -0.5), up, n)
                win.strip((x0, y, z0 + d + e), (0.5, 0, 0), up, n)
                win.strip((x0 - e, y, z0), (0, 0, 0.5), up, n)
            warm = rng.random() < 0.7
            c = rng.uniform(0.3, 3.0)
            rgb = (3 * c, 2.4 * c, 1.5 * c) if warm else (1.6 * c, 2.0 * c, 3 * c)
            lit.append((rgb, win))
    ground.write(out)
    buildings.write(out)
    total = 0
    for rgb, win in lit:
        out.append("AttributeBegin")
        out.append(f'  AreaLightSource "diffuse" "rgb L" [{nums(rgb)}]')
        win.write(out)
        out.append("AttributeEnd")
        total += win.triangles()
    out.insert(1, f"# {total} emissive triangles")
    out.append("WorldEnd")
    return out


def tiny():
    """The check mode's scene: one room, 12 small spheres, a spot, a point
    light and a sun (every kind of light the glue describes but emissive
    triangles), 32 x 24 pixels."""
    rng = random.Random(4)
    out = ["# The --check scene: a box and 12 small lights (make_scenes.py)."]
    header(out, (0, 1, -3.5), (0, 1, 0), 60, (32, 24), "tiny", spp=4)
    out.append('Material "matte" "rgb Kd" [0.6 0.6 0.6]')
    m = Mesh()
    m.box((-2, -0.1, -4), (2, 0, 2))
    m.box((-2, 2, -4), (2, 2.1, 2))
    m.box((-2, 0, 2), (2, 2, 2.1))
    m.box((-2.1, 0, -4), (-2, 2, 2))
    m.box((2, 0, -4), (2.1, 2, 2))
    m.box((-0.5, 0, -0.5), (0.5, 0.8, 0.5))
    m.write(out)
    for _ in range(12):
        p = (rng.uniform(-1.8, 1.8), rng.uniform(1.2, 1.9), rng.uniform(-1, 1.8))
        sphere_light(out, p, 0.05, (8, 7, 6))
    out.append('LightSource "distant" "point from" [0 0 0] "point to" [0.3 -1 0.2] "rgb L" [0.5 0.5 0.5]')
    out.append('LightSource "spot" "point from" [1.5 1.8 -3] "point to" [0 0 0] "float coneangle" [25] "rgb I" [6 6 6]')
    out.append('LightSource "point" "point from" [-1.5 1.5 -3] "rgb I" [1 1 1]')
    out.append("WorldEnd")
    return out


if __name__ == "__main__":
    for name, make in (("two_rooms", two_rooms), ("sun_sky", sun_sky), ("city", city), ("tiny", tiny)):
        path = os.path.join(HERE, f"{name}.pbrt")
        with open(path, "w") as f:
            f.write("\n".join(make()) + "\n")
        print(f"{path}: {os.path.getsize(path)} bytes")
