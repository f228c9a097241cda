"""Issue 17 item 4: a tile grid synthesized by a real Dask distributed
cluster (two worker processes, each tile a task) equals the single-process
synthesis of the whole world byte for byte."""

import os
import pathlib
import sys

import numpy as np
import pytest

import terrasynth

import dask.array as da  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "examples"))
import dask_tiles  # noqa: E402

WORLD = (512, 512)
TILE = (128, 128)
SEED = 17


@pytest.fixture(scope="module")
def client(db):  # db: the cache is built before the workers start
    with LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
    ) as cluster, Client(cluster) as c:
        yield c


def test_distributed_tiles_equal_the_single_process_world(client, db, tmp_path):
    info = client.scheduler_info()
    assert len(info["workers"]) == 2
    whole = terrasynth.synthesize(db, WORLD, seed=SEED)

    heights, windows = dask_tiles.world_array(WORLD, TILE, seed=SEED)
    assert isinstance(heights, da.Array) and len(windows) == 16
    assert heights.chunks == ((128,) * 4, (128,) * 4)
    out = heights.compute()
    assert out.dtype == np.float32 and out.shape == (512, 512)
    assert out.tobytes() == whole.tobytes()

    # The tiles really ran on the worker processes, and both took part.
    futures = dask_tiles.submit_tiles(client, WORLD, TILE, seed=SEED)
    client.gather(futures)
    holders = {a for f in futures for a in client.who_has([f])[f.key]}
    assert holders == set(info["workers"])
    mosaic = terrasynth.tiling.assemble(WORLD, windows, client.gather(futures))
    assert mosaic.tobytes() == whole.tobytes()


def test_example_writes_the_world(client, db, tmp_path):
    out = tmp_path / "world.tif"
    dask_tiles.main(["--world", "256x192", "--tile", "100", "--seed", "3", "-o", str(out)], client=client)
    got, cell, georef = terrasynth.read_heightfield(out)
    assert cell == db.cell_size() and georef is not None
    assert got.tobytes() == terrasynth.synthesize(db, (256, 192), seed=3).tobytes()
    npy = tmp_path / "world.npy"
    dask_tiles.main(["--world", "256x192", "--tile", "64x80", "--seed", "3", "-o", str(npy)], client=client)
    assert np.load(npy).tobytes() == got.tobytes()
