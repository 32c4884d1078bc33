"""Guiding Light Trees and Practical Path Guiding's SD-tree for path tracers.

The Python face of the Rust crate `guiding`: numpy-batched, one call per
wavefront of shading points, the GIL released while the crate works.

    import numpy as np
    import guiding

    lights = guiding.Emitters()
    lights.add_points(np.random.rand(1000, 3) * 10, np.ones(1000))
    tree = guiding.LightTree(lights)
    glt = guiding.Glt(tree, bounds=([0, 0, 0], [10, 10, 10]))
    p = np.random.rand(4096, 3) * 10
    light, pmf = glt.sample(p, np.random.rand(4096))
    assert np.array_equal(glt.pmf(p, light), pmf)

Light indices count the emitters in the order they were added, then the
unbounded lights (`unbounded_lights=` of a guide); -1 where no light could
be chosen. Every array argument is float32 or float64 (light indices any
integer type) of the documented shape; anything else, and any NaN or value
out of range, raises `TypeError` or `ValueError` naming the argument.
"""

from ._guiding import (
    PARALLEL_FROM,
    Emitters,
    Glt,
    GuidingField,
    LightTree,
    SdTree,
)

__all__ = [
    "PARALLEL_FROM",
    "Emitters",
    "Glt",
    "GuidingField",
    "LightTree",
    "SdTree",
]
