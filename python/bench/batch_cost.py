"""What a batched GLT sample costs through Python, against the Rust call.

Builds a city-sized scene (100,000 quads in a 200 x 50 x 200 box, powers
over three decades), trains a GLT on it for four passes, then times
`glt.sample` on 65,536 shading points (median of 21 calls; inputs float32
and contiguous, so the bindings' one copy is a check-and-copy, not a
conversion) on one thread and on every thread. It saves the tree, the
guide, the points and the samples to `out/batch_cost`, and runs the render
example's `batch_cost` binary, which times the same points through the
Rust front on one thread and checks every sample equals the bindings'.

    python python/bench/batch_cost.py [--threads 1]

(from the repository's root, with the bindings installed; `--threads`
sets RAYON_NUM_THREADS for the bindings' pool, read once at import).
"""

import argparse
import os
import subprocess
import sys
import time

ap = argparse.ArgumentParser()
ap.add_argument("--threads", type=int, default=1)
ap.add_argument("--points", type=int, default=65536)
ap.add_argument("--out", default="out/batch_cost")
args = ap.parse_args()
os.environ["RAYON_NUM_THREADS"] = str(args.threads)

import numpy as np  # noqa: E402

import guiding  # noqa: E402

rng = np.random.default_rng(1)
n = 100_000
corners = rng.uniform([0, 0, 0], [200, 50, 200], size=(n, 3))
lights = guiding.Emitters()
lights.add_quads(corners, np.tile([0.5, 0, 0], (n, 1)), np.tile([0, 0, 0.5], (n, 1)), 10 ** rng.uniform(-1, 2, n))
tree = guiding.LightTree(lights)
glt = guiding.Glt(tree, ([0, 0, 0], [200, 50, 200]))


def points(k, seed):
    r = np.random.default_rng(seed)
    p = r.uniform([0, 0, 0], [200, 0, 200], size=(k, 3)).astype(np.float32)
    return p, np.tile(np.float32([0, 1, 0]), (k, 1))


for it in range(4):
    p, nrm = points(200_000, 10 + it)
    u = rng.random(len(p), dtype=np.float32)
    light, pmf = glt.sample(p, u, normals=nrm)
    d = corners[light] - p
    value = 1.0 / np.maximum(np.sum(d * d, axis=1), 1.0) / pmf  # a stand-in for what NEE found
    glt.record_light(p, light, value, normals=nrm)
    glt.refine()

p, nrm = points(args.points, 99)
u = rng.random(args.points, dtype=np.float32)
times = []
for _ in range(21):
    t = time.perf_counter()
    light, pmf = glt.sample(p, u, normals=nrm)
    times.append(time.perf_counter() - t)
median = sorted(times)[10]
print(
    f"python: {args.points} points, {args.threads} thread(s), median of 21: {median * 1e3:.3f} ms, "
    f"{median * 1e9 / args.points:.1f} ns per point"
)

os.makedirs(args.out, exist_ok=True)
for name, data in {
    "tree.bin": tree.to_bytes(),
    "glt.bin": glt.to_bytes(),
    "points.f32": p.astype("<f4").tobytes(),
    "normals.f32": nrm.astype("<f4").tobytes(),
    "u.f32": u.astype("<f4").tobytes(),
    "lights.i64": light.astype("<i8").tobytes(),
    "pmfs.f32": pmf.astype("<f4").tobytes(),
}.items():
    with open(os.path.join(args.out, name), "wb") as f:
        f.write(data)
sys.exit(subprocess.call(["cargo", "run", "--release", "-q", "--bin", "batch_cost", "--", args.out]))
