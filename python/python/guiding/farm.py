"""Training one guide across the workers of a `dask.distributed` cluster.

Each iteration, every worker loads the coordinator's guide from its bytes,
clears its records (its share holds only its own), renders its share of the
iteration's work (your `render` function, recording into that copy) and
returns the copy's bytes; the client merges every share into the
coordinator's guide and refines it, and the next iteration starts from the
refined guide. With `deterministic=True` in the guide's configuration the
result is byte for byte what one process recording every share would learn,
whatever the number of workers and the order the shares come back in (the
crate's merge promise; `tests/test_farm.py` holds it).

You need it when one machine's cores are not enough to train a guide in
time (a farm renders an animation's frames or a still's tiles on many
machines); on one machine the guides already record from every thread.

    from dask.distributed import Client, LocalCluster
    import guiding, guiding.farm

    def render(guide, share, iteration):
        ...  # trace the paths of `share`, calling guide.sample / record_light

    with Client(LocalCluster(n_workers=4)) as client:
        glt = guiding.Glt(tree, bounds, deterministic=True)
        guiding.farm.train(client, glt, render, shares=range(16), iterations=6, tree=tree)

`render` and the shares are pickled to the workers (a module-level
function, plain data); the light tree is sent once per worker.
"""

from __future__ import annotations

from typing import Any, Callable, Iterable, Optional

from ._guiding import GuidingField, Glt, LightTree, SdTree

_KINDS = {"Glt": Glt, "GuidingField": GuidingField, "SdTree": SdTree}


def _load(kind: str, state: bytes, tree: Optional[LightTree]):
    cls = _KINDS[kind]
    if cls is SdTree:
        return SdTree.from_bytes(state)
    return cls.from_bytes(state, tree)


def render_share(
    kind: str,
    state: bytes,
    tree: Optional[LightTree],
    render: Callable[[Any, Any, int], Any],
    share: Any,
    iteration: int,
) -> bytes:
    """What a worker runs: the coordinator's guide from `state`, its
    records cleared, `render(guide, share, iteration)`, the guide's bytes."""
    guide = _load(kind, state, tree)
    guide.clear_records()
    render(guide, share, iteration)
    return guide.to_bytes()


def train(
    client,
    guide,
    render: Callable[[Any, Any, int], Any],
    shares: Iterable[Any],
    iterations: int,
    *,
    tree: Optional[LightTree] = None,
):
    """Trains `guide` (a `Glt`, `GuidingField` or `SdTree`, changed in
    place and returned) for `iterations` on `client`'s cluster: each
    iteration renders every share on some worker, merges the shares and
    refines. `tree` is the guide's light tree (not needed for an
    `SdTree`)."""
    from dask.distributed import as_completed

    kind = type(guide).__name__
    if kind not in _KINDS:
        raise TypeError(f"train: {kind} is not a guide (Glt, GuidingField or SdTree)")
    if kind != "SdTree" and tree is None:
        raise ValueError(f"train: a {kind} needs its light tree (tree=...)")
    shares = list(shares)
    # A key of its own (hash=False): a tree of equal bytes scattered by an
    # earlier call may still be being released under the same key.
    tree_on_workers = (
        client.scatter(tree, broadcast=True, hash=False) if tree is not None else None
    )
    for iteration in range(iterations):
        state = guide.to_bytes()
        futures = [
            client.submit(
                render_share, kind, state, tree_on_workers, render, share, iteration, pure=False
            )
            for share in shares
        ]
        for done in as_completed(futures):
            guide.merge(_load(kind, done.result(), tree))
        guide.refine()
    return guide
