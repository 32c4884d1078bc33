"""Shared scenes for the bindings' tests: small enough to brute-force."""

import numpy as np
import pytest

import guiding

BOUNDS = ([0.0, 0.0, 0.0], [10.0, 4.0, 10.0])


def small_scene(seed=1):
    """40 point lights and 8 downward quads under a 10 x 10 floor, powers
    spread over three decades: (emitters, their positions, their powers)."""
    rng = np.random.default_rng(seed)
    positions = rng.uniform([0, 2, 0], [10, 4, 10], size=(40, 3))
    powers = 10.0 ** rng.uniform(-1, 2, size=40)
    lights = guiding.Emitters()
    lights.add_points(positions, powers)
    corners = rng.uniform([0, 3.9, 0], [9, 3.9, 9], size=(8, 3))
    lights.add_quads(
        corners,
        np.tile([0.5, 0.0, 0.0], (8, 1)),
        np.tile([0.0, 0.0, 0.5], (8, 1)),
        np.full(8, 20.0),
    )
    return lights, positions, powers


def floor_points(n, seed=2):
    """`n` points on the floor y = 0, normals up."""
    rng = np.random.default_rng(seed)
    p = rng.uniform([0, 0, 0], [10, 0, 10], size=(n, 3))
    return p, np.tile([0.0, 1.0, 0.0], (n, 1))


def irradiance(p, n, positions, powers):
    """Each point light's unoccluded irradiance at `p` with normal `n`:
    power / (4 pi r^2) * cos, shape (len(p), len(positions))."""
    d = positions[None, :, :] - p[:, None, :]
    r2 = np.sum(d * d, axis=-1)
    cos = np.maximum(np.sum(d * n[:, None, :], axis=-1), 0.0) / np.sqrt(r2)
    return powers[None, :] / (4 * np.pi * r2) * cos


def train(guide, positions, powers, iterations=3, n=20000, seed=3):
    """Trains a light guide on floor points: NEE records of the point
    lights' irradiance (the quads contribute nothing, so the cut learns
    to prefer the points)."""
    rng = np.random.default_rng(seed)
    for _ in range(iterations):
        p, nrm = floor_points(n, seed=int(rng.integers(1 << 30)))
        light, pmf = guide.sample(p, rng.random(n), normals=nrm)
        value = np.zeros(n)
        is_point = (light >= 0) & (light < len(positions))
        e = irradiance(p, nrm, positions, powers)
        value[is_point] = e[np.flatnonzero(is_point), light[is_point]] / pmf[is_point]
        guide.record_light(p, light, value, normals=nrm)
        if hasattr(guide, "record_radiance"):
            # The field splits its cells on radiance records (PPG's rule).
            d, pdf = guide.sample_direction(p, rng.random((n, 2)))
            guide.record_radiance(p, d, np.maximum(d[:, 1], 0.0), pdf)
        guide.refine()
    return guide


@pytest.fixture(scope="module")
def scene():
    return small_scene()


@pytest.fixture(scope="module")
def tree(scene):
    return guiding.LightTree(scene[0])


@pytest.fixture(scope="module")
def trained_glt(scene, tree):
    _, positions, powers = scene
    glt = guiding.Glt(tree, BOUNDS, unbounded_lights=1, min_records=16)
    return train(glt, positions, powers)
