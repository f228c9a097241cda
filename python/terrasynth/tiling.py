"""Tiles of one world, for process pools and clusters (Dask, Ray, ...).

Every window of a world is the same crop of the whole synthesis, so a world
can be cut into a grid of tiles computed independently -- one task each, on
any worker of any machine -- and pasted together without seams. The helpers
here are plain functions of picklable arguments (a database is named by its
path, None = the embedded one) so task schedulers can ship them; each worker
process opens a database once and reuses it.
"""

from __future__ import annotations

import functools
import os
from typing import Iterator, List, Optional, Tuple, Union

import numpy as np

from ._native import Database, synthesize

Window = Tuple[int, int, int, int]
PathLike = Union[str, "os.PathLike[str]"]


def tile_windows(world: Tuple[int, int], tile: Tuple[int, int]) -> List[Window]:
    """The windows (x, y, w, h) of a grid of ``tile``-sized tiles covering
    ``world`` (width, height), row by row; the last column and row are
    narrower where the world is not a multiple of the tile."""
    (width, height), (tw, th) = world, tile
    if width < 1 or height < 1 or tw < 1 or th < 1:
        raise ValueError(f"world {world} and tile {tile} must be positive")
    return [
        (x, y, min(tw, width - x), min(th, height - y))
        for y in range(0, height, th)
        for x in range(0, width, tw)
    ]


@functools.lru_cache(maxsize=4)
def open_database(path: Optional[str] = None) -> Database:
    """The database at ``path`` (None: the embedded one), opened once per
    process."""
    return Database.default() if path is None else Database.open(path)


def synthesize_tile(
    world: Tuple[int, int],
    window: Window,
    seed: int = 1,
    db_path: Optional[PathLike] = None,
    **params: object,
) -> np.ndarray:
    """One tile: ``synthesize(db, world, window, seed=seed, **params)`` with
    the database at ``db_path`` (None: the embedded one). ``params`` are
    ``synthesize``'s keywords (jitter, passes, start_exemplar,
    height_prior)."""
    db = open_database(None if db_path is None else os.fspath(db_path))
    return synthesize(db, tuple(world), tuple(window), seed=seed, **params)  # type: ignore[arg-type]


def assemble(
    world: Tuple[int, int], windows: List[Window], tiles: List[np.ndarray]
) -> np.ndarray:
    """Pastes tiles (in the order of ``windows``) into one (height, width)
    float32 array."""
    out = np.empty((world[1], world[0]), dtype=np.float32)
    for (x, y, w, h), t in zip(windows, tiles):
        if t.shape != (h, w):
            raise ValueError(f"tile at ({x}, {y}) is {t.shape[::-1]}, not {(w, h)}")
        out[y : y + h, x : x + w] = t
    return out


def iter_tiles(
    world: Tuple[int, int], tile: Tuple[int, int], seed: int = 1, db_path: Optional[PathLike] = None, **params: object
) -> Iterator[Tuple[Window, np.ndarray]]:
    """Each window of the grid with its heights, computed here, in order
    (for worlds larger than memory: write each tile as it comes)."""
    for win in tile_windows(world, tile):
        yield win, synthesize_tile(world, win, seed, db_path, **params)
