#!/usr/bin/env python3
"""A terrasynth world as a grid of tiles computed by a Dask cluster.

Every window of a world is byte for byte the same crop of the whole
synthesis (issue 17), so each tile is an independent task -- one
``terrasynth.synthesize(db, world, window)`` call on whichever worker Dask
picks -- and the tiles assemble without seams into a dask array, written
here to a GeoTIFF (.tif), a NumPy file (.npy, streamed tile by tile) or a
Zarr store (.zarr, needs ``pip install zarr``).

    # a local cluster of 2 worker processes:
    python examples/dask_tiles.py --world 4096x4096 --tile 1024 -o world.tif

    # an existing cluster (every worker needs `pip install .` of this repo):
    python examples/dask_tiles.py --scheduler tcp://scheduler:8786 \
        --world 65536x65536 --tile 4096 -o world.zarr

See README ("Python") for Slurm/PBS (dask-jobqueue) and Kubernetes
(dask-kubernetes).
"""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional, Sequence, Tuple

import dask
import dask.array as da
import numpy as np

import terrasynth
from terrasynth.tiling import Window, synthesize_tile, tile_windows


def world_array(
    world: Tuple[int, int],
    tile: Tuple[int, int],
    seed: int = 1,
    db_path: Optional[str] = None,
    **params: object,
) -> Tuple[da.Array, List[Window]]:
    """The world as a lazy (height, width) float32 dask array whose chunks
    are the tiles, each one task ``synthesize_tile(world, window, ...)``."""
    windows = tile_windows(world, tile)
    cols = -(-world[0] // tile[0])
    rows = []
    for r in range(0, len(windows), cols):
        row = []
        for win in windows[r : r + cols]:
            task = dask.delayed(synthesize_tile, pure=True)(
                world, win, seed, db_path, **params, dask_key_name=f"tile-{seed}-{world}-{win}"
            )
            row.append(da.from_delayed(task, shape=(win[3], win[2]), dtype=np.float32))
        rows.append(row)
    return da.block(rows), windows


def submit_tiles(client, world, tile, seed=1, db_path=None, **params):
    """The tiles as futures on ``client`` (for callers who want each tile
    as it is done, e.g. to write it to its own file)."""
    return [
        client.submit(synthesize_tile, world, win, seed, db_path, pure=False, **params)
        for win in tile_windows(world, tile)
    ]


def local_georef(world: Tuple[int, int], cell: float) -> dict:
    """terrasynth's local grid of a world (the CLI's windows use the same):
    metres, origin at the south-west corner."""
    return {
        "origin_x": 0.0,
        "origin_y": world[1] * cell,
        "pixel_x": cell,
        "pixel_y": cell,
        "pixel_is": "area",
        "crs": {
            "name": "terrasynth local grid (metres, no geographic location)",
            "units": "linear",
            "metres_per_unit": 1.0,
        },
    }


def write(client, heights: da.Array, path: str, world, tile, seed, db_path, cell: float) -> None:
    """Writes the world: .npy and .zarr stream the tiles (memory here: a
    few tiles); other formats (.tif, .exr, ...) gather the world into memory
    here first."""
    if path.endswith(".npy"):
        # The memory map lives in this process: tiles come here as they are
        # done, and each is written and dropped.
        from distributed import as_completed

        out = np.lib.format.open_memmap(path, mode="w+", dtype=np.float32, shape=heights.shape)
        futures = submit_tiles(client, world, tile, seed, db_path)
        where = {f.key: w for f, w in zip(futures, tile_windows(world, tile))}
        for f, t in as_completed(futures, with_results=True):
            x, y, w, h = where[f.key]
            out[y : y + h, x : x + w] = t
            f.release()
        out.flush()
        del out
    elif path.endswith(".zarr"):
        # Each worker writes its own chunks (the store must be reachable
        # from every worker: a shared file system or an object store URL).
        heights.to_zarr(path, overwrite=True)
    else:
        terrasynth.write_heightfield(path, heights.compute(), cell, local_georef(world, cell))


def size(s: str) -> Tuple[int, int]:
    w, _, h = s.partition("x")
    return int(w), int(h or w)


def main(argv: Optional[Sequence[str]] = None, client=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--world", type=size, default=(2048, 2048), help="WxH pixels (default 2048x2048)")
    p.add_argument("--tile", type=size, default=(512, 512), help="tile WxH or N (default 512)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--db", help="a .tsdb database (default: the embedded one); a path every worker can read")
    p.add_argument("--scheduler", help="address of an existing Dask scheduler, e.g. tcp://scheduler:8786")
    p.add_argument("--workers", type=int, default=2, help="worker processes of the local cluster")
    p.add_argument("-o", "--output", required=True, help=".tif/.exr/.png/... (gathered), .npy or .zarr (streamed)")
    a = p.parse_args(argv)

    from distributed import Client, LocalCluster

    cell = (terrasynth.Database.open(a.db) if a.db else terrasynth.Database.default()).cell_size()
    owned = []
    if client is None:
        if a.scheduler:
            client = Client(a.scheduler)
        else:
            cluster = LocalCluster(n_workers=a.workers, processes=True, threads_per_worker=1)
            owned.append(cluster)
            client = Client(cluster)
        owned.insert(0, client)
    try:
        heights, windows = world_array(a.world, a.tile, a.seed, a.db)
        with client.as_current():
            write(client, heights, a.output, a.world, a.tile, a.seed, a.db, cell)
        print(
            f"wrote {a.output}: {a.world[0]}x{a.world[1]} in {len(windows)} tiles of "
            f"{a.tile[0]}x{a.tile[1]} on {len(client.scheduler_info()['workers'])} workers",
            file=sys.stderr,
        )
    finally:
        for o in owned:
            o.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
