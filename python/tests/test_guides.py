"""Everything around the queries: two Python threads on one guide, save and
load, merge (a farm's step), the SD-tree's directions, and bad input,
which raises and never crashes or answers wrong."""

import copy
import threading

import numpy as np
import pytest

import guiding
from conftest import BOUNDS, floor_points, irradiance, small_scene, train


def record_round(guide, positions, powers, p, nrm, u):
    light, pmf = guide.sample(p, u, normals=nrm)
    e = irradiance(p, nrm, positions, powers)
    is_point = light < len(positions)
    value = np.zeros(len(p))
    value[is_point] = e[np.flatnonzero(is_point), light[is_point]] / pmf[is_point]
    return light, value


def test_two_threads_on_one_guide(scene, tree, trained_glt):
    """Sampling and recording from two threads at once: the samples equal
    one thread's, and with deterministic sums the learned state equals,
    byte for byte, what one thread recording everything learns."""
    _, positions, powers = scene
    p, nrm = floor_points(40_000, seed=30)
    u = np.random.default_rng(31).random(len(p))
    alone = trained_glt.sample(p, u, normals=nrm)
    results = [None, None]
    halves = [slice(0, 20_000), slice(20_000, 40_000)]

    def sample(k):
        s = halves[k]
        results[k] = trained_glt.sample(p[s], u[s], normals=nrm[s])

    threads = [threading.Thread(target=sample, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert np.array_equal(np.concatenate([r[0] for r in results]), alone[0])
    assert np.array_equal(np.concatenate([r[1] for r in results]), alone[1])

    one = guiding.Glt(tree, BOUNDS, deterministic=True)
    two = guiding.Glt(tree, BOUNDS, deterministic=True)
    light, value = record_round(one, positions, powers, p, nrm, u)
    assert one.record_light(p, light, value, normals=nrm) == len(p)

    def record(k):
        s = halves[k]
        for i in range(s.start, s.stop, 5000):
            j = slice(i, i + 5000)
            two.record_light(p[j], light[j], value[j], normals=nrm[j])

    threads = [threading.Thread(target=record, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert one.to_bytes() == two.to_bytes()
    one.refine()
    two.refine()
    assert one.to_bytes() == two.to_bytes()


def test_save_and_load(scene, tree, trained_glt):
    data = trained_glt.to_bytes()
    back = guiding.Glt.from_bytes(data, tree)
    assert back.to_bytes() == data
    assert back.iteration == trained_glt.iteration
    p, nrm = floor_points(5000, seed=32)
    u = np.random.default_rng(33).random(len(p))
    a, b = trained_glt.sample(p, u, normals=nrm), back.sample(p, u, normals=nrm)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    # Another light tree (other lights) is refused, as are damaged bytes.
    other = guiding.LightTree(small_scene(seed=7)[0])
    with pytest.raises(ValueError):
        guiding.Glt.from_bytes(data, other)
    with pytest.raises(ValueError):
        guiding.Glt.from_bytes(data[: len(data) // 2], tree)
    with pytest.raises(ValueError):
        guiding.Glt.from_bytes(b"not a guide", tree)


@pytest.mark.parametrize("kind", ["glt", "field", "sd_tree"])
def test_merged_shares_equal_one_guide(scene, tree, kind):
    """A farm's step: two workers' copies each record half, the merge
    equals one guide recording all (deterministic sums), then refines
    alike."""
    _, positions, powers = scene

    def make():
        if kind == "glt":
            return guiding.Glt(tree, BOUNDS, deterministic=True)
        if kind == "field":
            return guiding.GuidingField(tree, BOUNDS, deterministic=True, spatial_threshold=500)
        return guiding.SdTree(BOUNDS, deterministic=True, spatial_threshold=500)

    whole = make()
    rng = np.random.default_rng(34)
    p, nrm = floor_points(20_000, seed=35)
    u, u2 = rng.random(len(p)), rng.random((len(p), 2))

    def record(g, s):
        if kind != "sd_tree":
            light, value = record_round(g, positions, powers, p[s], nrm[s], u[s])
            g.record_light(p[s], light, value, normals=nrm[s])
        if kind != "glt":
            d, pdf = g.sample_direction(p[s], u2[s])
            g.record_radiance(p[s], d, np.abs(d[:, 0]), pdf)

    record(whole, slice(None))
    coordinator = make()
    worker = copy.deepcopy(coordinator)
    record(coordinator, slice(0, 10_000))
    record(worker, slice(10_000, None))
    coordinator.merge(worker)
    assert coordinator.to_bytes() == whole.to_bytes()
    coordinator.refine()
    whole.refine()
    assert coordinator.to_bytes() == whole.to_bytes()
    # Copies of different iterations are not a farm's shares.
    with pytest.raises(ValueError):
        coordinator.merge(make())


@pytest.mark.parametrize("kind", ["sd_tree", "field"])
def test_directions_carry_their_pdf_and_integrate_to_one(tree, kind):
    if kind == "sd_tree":
        g = guiding.SdTree(BOUNDS, spatial_threshold=500)
    else:
        g = guiding.GuidingField(tree, BOUNDS, spatial_threshold=500)
    rng = np.random.default_rng(36)
    for _ in range(3):
        p, _ = floor_points(20_000, seed=int(rng.integers(1 << 30)))
        d, pdf = g.sample_direction(p, rng.random((len(p), 2)))
        # Radiance from straight up: the quadtrees learn a peak.
        g.record_radiance(p, d, np.maximum(d[:, 1], 0.0) ** 8, pdf)
        g.refine()
    p, _ = floor_points(4, seed=37)
    for i in range(len(p)):
        pi = np.repeat(p[i : i + 1], 100_000, axis=0)
        d, pdf = g.sample_direction(pi, rng.random((len(pi), 2)))
        np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, rtol=1e-5)
        assert np.array_equal(g.direction_pdf(pi, d), pdf)
        # Integrated over the sphere (uniform directions): 1.
        w = rng.normal(size=(200_000, 3))
        uniform = np.repeat(p[i : i + 1], len(w), axis=0)
        integral = 4 * np.pi * g.direction_pdf(uniform, w).mean()
        assert abs(integral - 1) < 0.05
        # Control: a learned peak, not a uniform pdf (which would pass the
        # integral trivially).
        assert pdf.max() > 10 * pdf.min()
    s = g.bsdf_fraction(p)
    assert np.all((s >= 0) & (s <= 1))


BAD_CALLS = {
    "positions of two columns": lambda g: g.sample(np.zeros((4, 2)), np.zeros(4)),
    "u of another length": lambda g: g.sample(np.zeros((4, 3)), np.zeros(3)),
    "complex positions": lambda g: g.sample(np.zeros((4, 3), complex), np.zeros(4)),
    "string positions": lambda g: g.sample(np.array([["a", "b", "c"]]), np.zeros(1)),
    "NaN position": lambda g: g.sample(np.full((1, 3), np.nan), [0.5]),
    "infinite position": lambda g: g.sample(np.full((1, 3), np.inf), [0.5]),
    "u of 1": lambda g: g.sample(np.zeros((1, 3)), [1.0]),
    "negative u": lambda g: g.sample(np.zeros((1, 3)), [-0.1]),
    "NaN u": lambda g: g.sample(np.zeros((1, 3)), [np.nan]),
    "u rounding to 1 in float32": lambda g: g.sample(np.zeros((1, 3)), [1 - 1e-12]),
    "NaN normal": lambda g: g.sample(np.zeros((1, 3)), [0.5], normals=np.full((1, 3), np.nan)),
    "light out of range": lambda g: g.pmf(np.zeros((1, 3)), [g.light_count]),
    "negative light": lambda g: g.pmf(np.zeros((1, 3)), [-1]),
    "float light indices": lambda g: g.pmf(np.zeros((1, 3)), [0.5]),
    "negative record": lambda g: g.record_light(np.zeros((1, 3)), [0], [-1.0]),
    "NaN record": lambda g: g.record_light(np.zeros((1, 3)), [0], [np.nan]),
    "float64 record beyond float32": lambda g: g.record_light(np.zeros((1, 3)), [0], [1e300]),
}


@pytest.mark.parametrize("name", sorted(BAD_CALLS))
def test_bad_input_raises_and_changes_nothing(tree, name):
    g = guiding.Glt(tree, BOUNDS, unbounded_lights=1)
    before = g.to_bytes()
    with pytest.raises((ValueError, TypeError)):
        BAD_CALLS[name](g)
    assert g.to_bytes() == before
    assert g.dropped_records["total"] == 0


BAD_CONFIGS = {
    "sigma above 1": dict(sigma=1.5),
    "negative alpha": dict(alpha=-0.1),
    "NaN threshold": dict(spatial_threshold=float("nan")),
    "unknown keyword": dict(sigmaa=0.1),
    "a string for a number": dict(sigma="small"),
    "unknown filter": dict(light_filter="gaussian"),
    "probability without lights": dict(unbounded_probability=0.5),
    "probability of 1": dict(unbounded_lights=2, unbounded_probability=1.0),
}


@pytest.mark.parametrize("name", sorted(BAD_CONFIGS))
def test_bad_configuration_is_an_error_not_a_clamp(tree, name):
    with pytest.raises((ValueError, TypeError)):
        guiding.Glt(tree, BOUNDS, **BAD_CONFIGS[name])


def test_bad_sd_tree_and_field_configurations(tree):
    with pytest.raises(ValueError):
        guiding.SdTree(BOUNDS, rho=0.0)
    with pytest.raises(ValueError):
        guiding.SdTree(BOUNDS, bsdf_fraction=1.5)
    with pytest.raises(ValueError):
        guiding.SdTree(BOUNDS, max_depth=0)
    with pytest.raises(ValueError):
        guiding.GuidingField(tree, BOUNDS, directional_filter="tent")
    with pytest.raises(ValueError):
        guiding.Glt(tree, ([0, 0, 0], [np.nan, 1, 1]))
    with pytest.raises(ValueError):
        guiding.Glt(tree, ([0, 0, 0], [1, 1]))


def test_bad_emitters():
    lights = guiding.Emitters()
    with pytest.raises(ValueError):
        lights.add_points(np.zeros((2, 3)), [1.0, -1.0])
    with pytest.raises(ValueError):
        lights.add_points(np.zeros((2, 3)), [1.0])
    with pytest.raises(ValueError):
        lights.add_spots(np.zeros((1, 3)), np.zeros((1, 3)), [0.9], [0.8], [1.0])
    with pytest.raises(ValueError):
        lights.add_spots(np.zeros((1, 3)), [[0, 0, 1]], [1.5], [0.8], [1.0])
    with pytest.raises(ValueError):
        lights.add_triangles(np.zeros((2, 3, 2)), [1.0, 1.0])
    with pytest.raises(ValueError):
        guiding.LightTree(lights, heuristic="best")
    assert len(lights) == 0  # a refused batch adds nothing


def test_every_emitter_kind_and_the_hard_cases():
    lights = guiding.Emitters()
    assert lights.add_points([[0, 1, 0]], [1.0]) == 0
    assert lights.add_spheres([[1, 1, 0]], [0.1], [2.0]) == 1
    assert lights.add_spots([[2, 1, 0]], [[0, -1, 0]], [0.9], [0.8], [3.0]) == 2
    assert lights.add_triangles(np.array([[[3, 1, 0], [4, 1, 0], [3, 1, 1]]]), [4.0], two_sided=True) == 3
    assert lights.add_quads([[5, 1, 0]], [[1, 0, 0]], [[0, 0, 1]], [5.0]) == 4
    assert lights.add_disks([[6, 1, 0]], [[0, -1, 0]], [0.5], [6.0]) == 5
    assert lights.add_points(np.zeros((2, 3)), [0.0, 1e30]) == 6  # zero and huge powers
    tree = guiding.LightTree(lights)
    assert tree.emitter_count == 8
    glt = guiding.Glt(tree, ([-1, -1, -1], [8, 2, 2]))
    # Points far outside the bounds are clamped onto them, not refused.
    p = np.array([[0.5, 0, 0.5], [1e6, -1e6, 3.0], [7, 0, 0]])
    light, pmf = glt.sample(p, [0.3, 0.6, 0.9], normals=np.tile([0, 1, 0], (3, 1)))
    assert np.all(np.isfinite(pmf)) and np.array_equal(glt.pmf(p, light, normals=np.tile([0, 1, 0], (3, 1))), pmf)
    # One light and no lights.
    one = guiding.Emitters()
    one.add_points([[0, 0, 0]], [1.0])
    g1 = guiding.Glt(guiding.LightTree(one), ([-1, -1, -1], [1, 1, 1]))
    assert g1.sample([[0.5, 0.5, 0.5]], [0.7]) == (np.array([0]), np.array([1.0], np.float32))
    g0 = guiding.Glt(guiding.LightTree(guiding.Emitters()), ([-1, -1, -1], [1, 1, 1]))
    light, pmf = g0.sample(np.zeros((2, 3)), [0.1, 0.2])
    assert list(light) == [-1, -1] and list(pmf) == [0.0, 0.0]
    # Empty batches are batches.
    light, pmf = glt.sample(np.zeros((0, 3)), np.zeros(0))
    assert light.shape == (0,) and pmf.shape == (0,)
