"""The light choice through Python: pmfs that sum to 1, samples that carry
their own pmf and follow it, an unbiased NEE estimate, for the GLT and the
combined field. Each property has a control: the plausible bug it exists
to catch, shown to fail it."""

import numpy as np
import pytest
from scipy_free_stats import chi_square_p

import guiding
from conftest import BOUNDS, floor_points, irradiance, train


def all_lights_at(points, normals, count):
    """Every (point, light) pair: points repeated per light, and lights."""
    k = len(points)
    return (
        np.repeat(points, count, axis=0),
        np.repeat(normals, count, axis=0),
        np.tile(np.arange(count), k),
    )


def pmf_table(guide, points, normals):
    count = guide.light_count
    p, n, lights = all_lights_at(points, normals, count)
    return guide.pmf(p, lights, normals=n).astype(np.float64).reshape(len(points), count)


@pytest.fixture(scope="module")
def trained_field(scene, tree):
    _, positions, powers = scene
    field = guiding.GuidingField(
        tree, BOUNDS, unbounded_lights=1, min_records=16, spatial_threshold=2000
    )
    return train(field, positions, powers)


@pytest.fixture(params=["glt", "field"])
def guide(request, trained_glt, trained_field):
    return trained_glt if request.param == "glt" else trained_field


def test_the_guide_has_learned(guide):
    assert guide.iteration == 3
    assert guide.dropped_records["total"] == 0


def test_pmfs_sum_to_one(guide):
    p, n = floor_points(64, seed=10)
    table = pmf_table(guide, p, n)
    assert np.all(table >= 0)
    np.testing.assert_allclose(table.sum(axis=1), 1.0, rtol=1e-5)
    # Control: a binding that dropped the unbounded lights from its index
    # list (emitters only) would sum short of 1.
    assert np.all(table[:, :-1].sum(axis=1) < 1 - 1e-4)


def test_samples_carry_their_pmf(guide):
    p, n = floor_points(50000, seed=11)
    u = np.random.default_rng(12).random(len(p))
    light, pmf = guide.sample(p, u, normals=n)
    assert np.all(light >= 0) and np.all(pmf > 0)
    # Exactly, bit for bit: the MIS weight of the BSDF sample uses `pmf`.
    assert np.array_equal(guide.pmf(p, light, normals=n), pmf)
    # Control: an off-by-one in the index conversion would not match.
    shifted = (light + 1) % guide.light_count
    assert not np.array_equal(guide.pmf(p, shifted, normals=n), pmf)
    # Without the normals the point is not on a surface: another choice.
    assert not np.array_equal(guide.pmf(p, light), pmf)


def test_draws_follow_the_pmf(guide):
    """Chi-square of 200,000 draws at one point against its pmf."""
    p, n = floor_points(1, seed=13)
    draws = 200_000
    u = np.random.default_rng(14).random(draws)
    light, _ = guide.sample(np.repeat(p, draws, axis=0), u, normals=np.repeat(n, draws, axis=0))
    counts = np.bincount(light, minlength=guide.light_count)
    expected = pmf_table(guide, p, n)[0] * draws
    assert chi_square_p(counts, expected) > 1e-4
    # Control: the same draws against the pmf of a neighbouring point
    # (a binding that queried the wrong row) fail.
    q, m = floor_points(1, seed=99)
    wrong = pmf_table(guide, q, m)[0] * draws
    assert chi_square_p(counts, wrong) < 1e-9


def test_nee_is_unbiased_against_brute_force(scene, guide):
    """The estimate f / pmf of the point lights' irradiance, averaged over
    samples, against the sum over every light (brute force)."""
    _, positions, powers = scene
    p, n = floor_points(8, seed=15)
    k = 40_000
    rng = np.random.default_rng(16)
    for i in range(len(p)):
        pi, ni = np.repeat(p[i : i + 1], k, axis=0), np.repeat(n[i : i + 1], k, axis=0)
        light, pmf = guide.sample(pi, rng.random(k), normals=ni)
        e = irradiance(p[i : i + 1], n[i : i + 1], positions, powers)[0]
        f = np.where(light < len(positions), e[np.minimum(light, len(positions) - 1)], 0.0)
        est = f / pmf
        truth = e.sum()
        err = est.std() / np.sqrt(k)
        assert abs(est.mean() - truth) < 5 * err + 1e-6 * truth
        # Control: dividing by the pmf of the next light (a mismatched MIS
        # pmf) is biased far beyond the error.
        other = guide.pmf(pi, (light + 1) % guide.light_count, normals=ni)
        biased = f / np.maximum(other, 1e-30)
        assert abs(biased.mean() - truth) > 5 * err


def test_a_large_batch_runs_in_parallel_and_equals_small_ones(guide):
    n_points = 3 * guiding.PARALLEL_FROM + 17
    p, n = floor_points(n_points, seed=17)
    u = np.random.default_rng(18).random(n_points)
    light, pmf = guide.sample(p, u, normals=n)
    step = guiding.PARALLEL_FROM // 2
    parts = [guide.sample(p[i : i + step], u[i : i + step], normals=n[i : i + step]) for i in range(0, n_points, step)]
    assert np.array_equal(light, np.concatenate([a for a, _ in parts]))
    assert np.array_equal(pmf, np.concatenate([b for _, b in parts]))


def test_float64_and_float32_inputs_agree(guide):
    p, n = floor_points(1000, seed=19)
    u = np.random.default_rng(20).random(1000)
    a = guide.sample(p.astype(np.float32), u.astype(np.float32), normals=n.astype(np.float32))
    b = guide.sample(p, u, normals=n)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    # Non-contiguous views are read as they are (no copy needed by the caller).
    wide = np.zeros((1000, 6))
    wide[:, ::2] = p
    c = guide.sample(wide[:, ::2], u, normals=n)
    assert np.array_equal(c[0], b[0])


def test_lookup_names_cells(guide):
    p, _ = floor_points(1000, seed=21)
    cells = guide.lookup(p)
    assert cells.dtype == np.int64 and np.all(cells >= 0)
    assert len(np.unique(cells)) > 1
