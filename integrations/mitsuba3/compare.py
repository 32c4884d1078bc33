"""The GLT inside Mitsuba 3 against Mitsuba's own light choice.

For each scene: a long reference from Mitsuba's `path` (with each emitter's
`sampling_weight` set to its power, Mitsuba's better choice), then at equal
samples and at equal time:

- `path`: Mitsuba's `path`, emitters chosen uniformly (its default);
- `path-power`: Mitsuba's `path`, `sampling_weight` = each emitter's power;
- `glt`: `glt_path` (integrator.py), the crate's GLT over every emissive
  triangle, trained for a few passes first (their time counted);
- `glt-ppg`: `glt_path` with a `GuidingField`: the same GLT light choice,
  and the path's directions from PPG's SD-tree in the same field (trained
  in the same passes);
- `glt-uniform`: `glt_path` choosing uniformly among the same lights, the
  wavefront's own check (its mean must agree too).

Prints the relMSE against the reference, each image's mean with its error,
the efficiency (1 / (relMSE x seconds)) and its ratio to `path-power` and
`path`, and where `glt`'s time goes per bounce (Mitsuba's kernels, the host
round trip, the crate). Writes a comparison sheet per scene (`--sheet`).

    python compare.py --quick            # a few minutes: one line per scene
    python compare.py --seconds 60       # the full comparison
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import drjit as dr
import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_rgb")

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import integrator as glt_integrator  # noqa: E402
import scenes  # noqa: E402
from lights import SceneLights, luminance  # noqa: E402

TRAIN_SPP = (1, 2, 4, 8)


def relmse(image, reference):
    eps = 0.01 * reference.mean() ** 2
    return float(np.mean((image - reference) ** 2 / (reference**2 + eps)))


def with_power_weights(scene_dict, work_dir):
    """The scene dict with every emitter's `sampling_weight` set to its
    power (as the crate's light tree counts it)."""
    scene = mi.load_dict(scene_dict)
    lights = SceneLights(scene)
    powers = {}
    for shape in scene.shapes():
        e = shape.emitter()
        if e is None:
            continue
        params = mi.traverse(e)
        le = luminance(np.array(params["radiance.value"]).reshape(-1)[:3] * np.ones(3))[0]
        powers[shape.id()] = np.pi * float(shape.surface_area()[0]) * le
    d = dict(scene_dict)
    for key, value in scene_dict.items():
        if not isinstance(value, dict):
            continue
        if "emitter" in value and key in powers:
            v = dict(value)
            v["emitter"] = dict(value["emitter"], sampling_weight=max(powers[key], 1e-12))
            d[key] = v
        elif value.get("type") == "point":
            i = luminance(value["intensity"]["value"])[0]
            d[key] = dict(value, sampling_weight=4 * np.pi * i)
        elif value.get("type") == "spot":
            i = luminance(value["intensity"]["value"])[0]
            c0 = np.cos(np.radians(value["beam_width"]))
            c1 = np.cos(np.radians(value["cutoff_angle"]))
            d[key] = dict(value, sampling_weight=2 * np.pi * i * (1 - 0.5 * (c0 + c1)))
    del lights
    return d


class Method:
    """Renders chunks of samples; `run` until a time or sample budget."""

    def __init__(self, name, scene, render):
        self.name, self.scene, self._render = name, scene, render
        self.prepare_seconds = 0.0

    def prepare(self):
        pass

    def run(self, spp=None, seconds=None, chunk=4, seed=1000):
        """Renders `spp` samples, or chunks until `seconds` (the
        preparation included); returns (image, seconds, spp, chunk means)."""
        t0 = time.perf_counter()
        self.prepare()
        total, done, means = None, 0, []
        k = 0
        while True:
            img = self._render(chunk, seed + k)
            k += 1
            total = img * chunk if total is None else total + img * chunk
            done += chunk
            means.append(img.mean())
            elapsed = time.perf_counter() - t0 + self.prepare_seconds
            if spp is not None and done >= spp:
                break
            if seconds is not None and elapsed >= seconds:
                break
        return total / done, elapsed, done, np.array(means)


class Mitsuba(Method):
    def __init__(self, name, scene):
        super().__init__(name, scene, lambda spp, seed: np.array(mi.render(scene, spp=spp, seed=seed)))


class Glt(Method):
    def __init__(self, name, scene, choice):
        props = mi.Properties()
        props["max_depth"] = scenes.MAX_DEPTH
        props["choice"] = choice
        self.integ = glt_integrator.GltPathIntegrator(props)
        super().__init__(name, scene, lambda spp, seed: self.integ.render_image(scene, spp, seed))
        self.trained = False

    def prepare(self):
        if self.trained:
            return
        # Dr.Jit compiles each kernel on its first use (and caches it on
        # disk): a throwaway training pass first, so that the timed training
        # counts the work, as the other methods' warm-up excludes theirs.
        self.integ.attach(self.scene)
        self.integ.render_image(self.scene, 1, seed=1, record=True)
        self.integ.render_image(self.scene, 1, seed=2)
        t0 = time.perf_counter()
        self.integ.attach(self.scene)
        if self.integ.choice != "uniform":
            for i, spp in enumerate(TRAIN_SPP):
                self.integ.render_image(self.scene, spp, seed=10 + i, record=True)
                self.integ.guide.refine()
        self.trained = True
        self.prepare_seconds = time.perf_counter() - t0


REFERENCES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "references")


def fingerprint(scene_dict, work_dir):
    """What a reference depends on: the scene dict and its mesh files."""
    import hashlib

    def portable(v):
        # The mesh files' folder is wherever the run put them.
        if isinstance(v, dict):
            return {k: os.path.basename(x) if k == "filename" else portable(x) for k, x in v.items()}
        return v

    h = hashlib.sha256(json.dumps(portable(scene_dict), sort_keys=True, default=str).encode())
    for name in sorted(os.listdir(work_dir)):
        if name.endswith(".ply"):
            with open(os.path.join(work_dir, name), "rb") as f:
                h.update(name.encode() + f.read())
    return h.hexdigest()[:16]


def reference(name, scene, scene_dict, args):
    """Mitsuba's `path` (power weights) at `args.reference_spp`: the
    committed one (references/) when it is of this very scene, else
    rendered (and cached in `args.out`). Returns (image, its own relMSE,
    where it came from)."""
    spp = args.reference_spp
    key = f"{name}-{args.width}x{args.height}-{spp}spp-{fingerprint(scene_dict, os.path.join(args.out, 'work', name))}"
    for folder in (REFERENCES, args.out):
        path = os.path.join(folder, key + ".npz")
        if os.path.exists(path):
            z = np.load(path)
            return z["image"].astype(np.float32), float(z["own_relmse"]), path
    halves = []
    for h in range(2):
        acc = None
        for k in range(0, spp // 2, 64):
            img = np.array(mi.render(scene, spp=64, seed=1_000_000 + 10_000 * h + k))
            acc = img if acc is None else acc + img
        halves.append(acc / (spp // 2 // 64))
    image = (halves[0] + halves[1]) / 2
    # Each half's relMSE against the other is twice a half's own: the full
    # reference's own is a quarter of it.
    own = relmse(halves[0], halves[1]) / 4
    path = os.path.join(REFERENCES if args.make_references else args.out, key + ".npz")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    np.savez_compressed(path, image=image.astype(np.float32), own_relmse=own)
    return image, own, path


def sheet(path, images, labels):
    """A row of tone-mapped images with their labels under them."""
    from PIL import Image, ImageDraw

    tiles = []
    for img, label in zip(images, labels):
        x = np.clip(img / (1 + img), 0, 1) ** (1 / 2.2)
        tile = Image.fromarray((x * 255).astype(np.uint8)).resize((img.shape[1] * 2, img.shape[0] * 2), Image.NEAREST)
        canvas = Image.new("RGB", (tile.width, tile.height + 18), "white")
        canvas.paste(tile, (0, 0))
        ImageDraw.Draw(canvas).text((4, tile.height + 3), label, fill="black")
        tiles.append(canvas)
    out = Image.new("RGB", (sum(t.width for t in tiles) + 4 * len(tiles), tiles[0].height), "white")
    x = 0
    for t in tiles:
        out.paste(t, (x, 0))
        x += t.width + 4
    out.save(path)


def bounce_timing(scene_dict, width, height, spp, choice="glt"):
    """Where a `glt_path` bounce's time goes at `width` x `height`: seconds
    per part over a render of `spp`, after a warm-up."""
    d = dict(scene_dict)
    d["sensor"] = dict(d["sensor"], film=dict(d["sensor"]["film"], width=width, height=height))
    scene = mi.load_dict(d)
    m = Glt(choice, scene, choice)
    m.prepare()
    m.integ.render_image(scene, spp, seed=1)
    m.integ.timer = glt_integrator.Timer()
    m.integ.render_image(scene, spp, seed=2)
    return m.integ.timer.parts


def compare(name, args):
    work = os.path.join(args.out, "work", name)
    os.makedirs(work, exist_ok=True)
    d = scenes.SCENES[name](work, width=args.width, height=args.height)
    uniform = mi.load_dict(d)
    power = mi.load_dict(with_power_weights(d, work))
    t = time.perf_counter()
    ref, ref_relmse, ref_path = reference(name, power, d, args)
    ref_seconds = time.perf_counter() - t
    if args.make_references:
        print(f"{name}: reference {ref_path} (own relMSE {ref_relmse:.2e}, {ref_seconds:.0f} s)")
        return None
    methods = [
        Mitsuba("path", uniform),
        Mitsuba("path-power", power),
        Glt("glt", uniform, "glt"),
        Glt("glt-ppg", uniform, "field"),
        Glt("glt-uniform", uniform, "uniform"),
    ]
    # Warm-up: Dr.Jit compiles each kernel once (and caches it on disk).
    for m in methods:
        m.prepare()
        m._render(1, 1)
    rows = {}
    for m in methods:
        img_s, sec_s, spp_s, means_s = m.run(spp=args.spp, chunk=min(args.spp, 16))
        img_t, sec_t, spp_t, means_t = m.run(seconds=args.seconds, chunk=16, seed=5000)
        rows[m.name] = dict(
            equal_spp=dict(spp=spp_s, seconds=sec_s, relmse=relmse(img_s, ref)),
            equal_time=dict(spp=spp_t, seconds=sec_t, relmse=relmse(img_t, ref)),
            mean=float(img_t.mean()),
            mean_err=float(means_t.std(ddof=1) / np.sqrt(len(means_t))) if len(means_t) > 1 else float("nan"),
            image=img_t,
        )
        v = rows[m.name]
        # Unbiased methods agree with the reference: within 5 errors of the
        # mean (from the chunks' means: heavy tails make it an estimate that
        # runs low), or 2% where that error is itself unreliable. Only the
        # wavefront integrator's are checked (Mitsuba's own are printed).
        # One chunk has no error estimate (NaN, which `max` would return
        # and every comparison refuse): the 2% alone then.
        err = v["mean_err"] if np.isfinite(v["mean_err"]) else 0.0
        v["agrees"] = bool(abs(v["mean"] - ref.mean()) <= max(5 * err, 0.02 * ref.mean()))
        r = rows[m.name]["equal_time"]
        r["efficiency"] = 1 / (max(r["relmse"] - ref_relmse, 0.1 * r["relmse"]) * r["seconds"])
    base, base2 = rows["path-power"]["equal_time"]["efficiency"], rows["path"]["equal_time"]["efficiency"]
    lights = SceneLights(uniform)
    report = dict(
        scene=name,
        lights=lights.light_count,
        emitters=len(uniform.emitters()),
        reference=dict(spp=args.reference_spp, mean=float(ref.mean()), own_relmse=ref_relmse, file=os.path.basename(ref_path)),
        methods={k: {kk: vv for kk, vv in v.items() if kk != "image"} for k, v in rows.items()},
        agree=all(v["agrees"] for k, v in rows.items() if k.startswith("glt")),
    )
    if not args.quick:
        report["bounce_seconds_256"] = {k: bounce_timing(d, 256, 256, 4, c) for k, c in (("glt", "glt"), ("glt-ppg", "field"))}
    if args.sheet:
        os.makedirs(args.sheet, exist_ok=True)
        sheet(
            os.path.join(args.sheet, f"mitsuba3-{name}.png"),
            [ref] + [rows[k]["image"] for k in ("path", "path-power", "glt", "glt-ppg")],
            [f"reference ({args.reference_spp} spp)"]
            + [f"{k}, {args.seconds:.0f} s" for k in ("path", "path-power", "glt", "glt-ppg")],
        )
    print(f"\n{name}: {lights.light_count} lights ({len(uniform.emitters())} Mitsuba emitters), "
          f"{args.width}x{args.height}, reference {os.path.basename(ref_path)} (mean {ref.mean():.5f}, own relMSE {ref_relmse:.2e})")
    print(f"{'method':<12} {'spp':>5} {'relMSE':>9} | {'spp':>5} {'s':>6} {'relMSE':>9} {'eff':>9} {'vs power':>8} {'vs path':>8} | mean +- err")
    for k, v in rows.items():
        s, t = v["equal_spp"], v["equal_time"]
        print(f"{k:<12} {s['spp']:>5} {s['relmse']:>9.3e} | {t['spp']:>5} {t['seconds']:>6.1f} {t['relmse']:>9.3e} "
              f"{t['efficiency']:>9.3g} {t['efficiency'] / base:>7.2f}x {t['efficiency'] / base2:>7.2f}x | "
              f"{v['mean']:.5f} +- {v['mean_err']:.5f}{'' if v['agrees'] else '  DISAGREES with the reference'}")
    if "bounce_seconds_256" in report:
        for method, parts in report["bounce_seconds_256"].items():
            total = sum(parts.values())
            print(f"{method} at 256x256, 4 spp: " + ", ".join(f"{k} {v:.2f} s ({100 * v / total:.0f}%)" for k, v in parts.items()))
    return report


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default="city,corridor,mixed")
    ap.add_argument("--quick", action="store_true", help="small budgets: a few minutes in all")
    ap.add_argument("--seconds", type=float, default=None, help="equal-time budget per method")
    ap.add_argument("--spp", type=int, default=None, help="equal-samples budget per method")
    ap.add_argument("--reference-spp", type=int, default=32768, help="the reference's samples (the committed ones: 32768)")
    ap.add_argument("--make-references", action="store_true", help="render the references into references/ and stop")
    ap.add_argument("--width", type=int, default=128)
    ap.add_argument("--height", type=int, default=96)
    ap.add_argument("--out", default="out/mitsuba3")
    ap.add_argument("--sheet", default=None, help="folder for the comparison sheets (PNG)")
    ap.add_argument("--json", default=None, help="write the numbers here")
    args = ap.parse_args()
    quick = args.quick
    args.seconds = args.seconds or (8.0 if quick else 60.0)
    args.spp = args.spp or (16 if quick else 64)
    os.makedirs(args.out, exist_ok=True)
    reports = [r for r in (compare(name, args) for name in args.scenes.split(",")) if r]
    if args.json:
        with open(args.json, "w") as f:
            json.dump(reports, f, indent=1)
    failed = [r["scene"] for r in reports if not r["agree"]]
    if quick:
        print()
        for r in reports:
            m = r["methods"]
            e = {k: v["equal_time"]["efficiency"] for k, v in m.items()}
            print(f"{r['scene']}: glt efficiency {e['glt'] / e['path-power']:.2f}x Mitsuba's path with power weights, "
                  f"{e['glt'] / e['path']:.2f}x with its uniform choice; glt-ppg {e['glt-ppg'] / e['path-power']:.2f}x, "
                  f"{e['glt-ppg'] / e['path']:.2f}x")
    if failed:
        sys.exit(f"means disagree with the reference on: {', '.join(failed)}")


if __name__ == "__main__":
    main()

