"""A guide trained on a dask.distributed LocalCluster (two worker
processes) equals, byte for byte, the guide one process trains on the same
shares (deterministic sums)."""

import sys

import numpy as np
import pytest

import guiding
import guiding.farm
from conftest import BOUNDS, floor_points, irradiance, small_scene

distributed = pytest.importorskip("dask.distributed")
cloudpickle = pytest.importorskip("cloudpickle")

SHARES = range(6)
ITERATIONS = 3


def render(guide, share, iteration):
    """One share of an iteration: NEE at 4,000 floor points of the small
    scene, recorded (and radiance records for a field)."""
    _, positions, powers = small_scene()
    seed = 1000 * iteration + share
    p, n = floor_points(4000, seed=seed)
    rng = np.random.default_rng(seed)
    light, pmf = guide.sample(p, rng.random(len(p)), normals=n)
    e = irradiance(p, n, positions, powers)
    is_point = light < len(positions)
    value = np.zeros(len(p))
    value[is_point] = e[np.flatnonzero(is_point), light[is_point]] / pmf[is_point]
    guide.record_light(p, light, value, normals=n)
    if hasattr(guide, "record_radiance"):
        d, pdf = guide.sample_direction(p, rng.random((len(p), 2)))
        guide.record_radiance(p, d, np.maximum(d[:, 1], 0.0), pdf)


@pytest.fixture(scope="module")
def client():
    # The workers unpickle `render` and the scene helpers by value: the
    # test modules are not importable in their processes.
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    cloudpickle.register_pickle_by_value(sys.modules["conftest"])
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


@pytest.mark.parametrize("kind", ["glt", "field"])
def test_the_farm_equals_one_process(client, kind):
    tree = guiding.LightTree(small_scene()[0])

    def make():
        if kind == "glt":
            return guiding.Glt(tree, BOUNDS, deterministic=True, min_records=16)
        return guiding.GuidingField(
            tree, BOUNDS, deterministic=True, min_records=16, spatial_threshold=2000
        )

    alone = make()
    for iteration in range(ITERATIONS):
        for share in SHARES:
            render(alone, share, iteration)
        alone.refine()
    farmed = guiding.farm.train(client, make(), render, SHARES, ITERATIONS, tree=tree)
    assert farmed.iteration == ITERATIONS
    assert farmed.to_bytes() == alone.to_bytes()
    # Control: a farm that lost one share's records in the last iteration
    # does not equal it.
    lossy = guiding.farm.train(client, make(), render, SHARES, ITERATIONS - 1, tree=tree)
    for share in list(SHARES)[:-1]:
        render(lossy, share, ITERATIONS - 1)
    lossy.refine()
    assert lossy.to_bytes() != alone.to_bytes()


def test_the_light_tree_pickles():
    import pickle

    tree = guiding.LightTree(small_scene()[0])
    back = pickle.loads(pickle.dumps(tree))
    assert back.to_bytes() == tree.to_bytes()
    with pytest.raises(ValueError):
        guiding.LightTree.from_bytes(b"not a tree")


def test_train_refuses_what_is_not_a_guide(client):
    with pytest.raises(TypeError):
        guiding.farm.train(client, object(), render, SHARES, 1)
    with pytest.raises(ValueError):
        tree = guiding.LightTree(small_scene()[0])
        guiding.farm.train(client, guiding.Glt(tree, BOUNDS), render, SHARES, 1)
