"""terrasynth: controllable, example-based terrain synthesis.

Heightfields are numpy ``float32`` arrays of shape (rows, columns), row 0
north, in metres, NaN = nodata. Any window of a world (up to 1048576 pixels
a side) is byte for byte the same crop of the whole synthesis, so tiles
computed anywhere -- threads, processes, a Dask cluster -- join seamlessly
(see :mod:`terrasynth.tiling` and ``examples/dask_tiles.py``).

>>> import terrasynth
>>> db = terrasynth.Database.default()
>>> tile = terrasynth.synthesize(db, world=(65536, 65536), window=(4096, 0, 512, 512), seed=7)
>>> tile.shape, tile.dtype
((512, 512), dtype('float32'))
"""

from ._native import (
    Database,
    TerrasynthError,
    __version__,
    erode,
    eval,
    mesh,
    novelty,
    read_heightfield,
    synthesize,
    synthesize_scene,
    water,
    write_heightfield,
)

__all__ = [
    "Database",
    "TerrasynthError",
    "__version__",
    "erode",
    "eval",
    "mesh",
    "novelty",
    "read_heightfield",
    "synthesize",
    "synthesize_scene",
    "water",
    "write_heightfield",
]
