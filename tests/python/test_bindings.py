"""The Python bindings (python/): numpy in and out, windows, scenes, I/O,
eval and errors."""

import json

import numpy as np
import pytest

import terrasynth


def test_synthesis_is_float32_rows_by_columns_and_deterministic(db):
    a = terrasynth.synthesize(db, (96, 64), seed=3)
    assert a.dtype == np.float32 and a.shape == (64, 96)
    assert a.flags.c_contiguous and np.isfinite(a).all()
    assert np.array_equal(a, terrasynth.synthesize(db, (96, 64), seed=3))
    assert not np.array_equal(a, terrasynth.synthesize(db, (96, 64), seed=4))


@pytest.mark.parametrize(
    "window",
    [(0, 0, 200, 160), (37, 11, 61, 93), (129, 63, 71, 97), (0, 150, 200, 10), (199, 159, 1, 1)],
)
def test_window_is_the_crop_of_the_whole_synthesis(db, window):
    world = (200, 160)
    whole = terrasynth.synthesize(db, world, seed=11, jitter=0.3, passes=1)
    x, y, w, h = window
    win = terrasynth.synthesize(db, world, window, seed=11, jitter=0.3, passes=1)
    assert win.shape == (h, w)
    # Byte for byte, not merely close.
    assert win.tobytes() == whole[y : y + h, x : x + w].tobytes()


def test_window_of_a_huge_world_is_cheap(db):
    tile = terrasynth.synthesize(db, (65536, 65536), (40000, 1234, 64, 48), seed=5)
    assert tile.shape == (48, 64) and np.isfinite(tile).all()


def test_tiles_assemble_into_the_world(db):
    from terrasynth.tiling import assemble, synthesize_tile, tile_windows

    world = (150, 100)
    wins = tile_windows(world, (64, 64))
    assert len(wins) == 6 and wins[-1] == (128, 64, 22, 36)
    mosaic = assemble(world, wins, [synthesize_tile(world, w, seed=2) for w in wins])
    assert mosaic.tobytes() == terrasynth.synthesize(db, world, seed=2).tobytes()


@pytest.mark.parametrize("ext", ["tif", "exr", "r16"])
def test_heightfield_round_trip(tmp_path, ext):
    rng = np.random.default_rng(1)
    a = (rng.random((40, 56)) * 900 + 100).astype(np.float32)
    p = tmp_path / f"h.{ext}"
    terrasynth.write_heightfield(p, a, 12.5)
    b, cell, _georef = terrasynth.read_heightfield(p)
    assert b.dtype == np.float32 and b.shape == a.shape
    assert cell == 12.5
    if ext == "r16":  # 16-bit: quantized over the height range
        assert np.abs(b - a).max() <= (a.max() - a.min()) / 65535 * 0.51 + 1e-3
    else:
        assert b.tobytes() == a.tobytes()


def test_georef_and_nodata_round_trip(tmp_path, db):
    world = (300, 200)
    win = (100, 40, 64, 32)
    a = terrasynth.synthesize(db, world, win)
    a[0, 0] = np.nan
    georef = {
        "origin_x": 100 * 30.0,
        "origin_y": (200 - 40) * 30.0,
        "pixel_x": 30.0,
        "pixel_y": 30.0,
        "pixel_is": "area",
        "crs": {"epsg": 32611, "units": "linear", "metres_per_unit": 1.0},
    }
    p = tmp_path / "g.tif"
    terrasynth.write_heightfield(p, a.astype(np.float64), 30.0, georef)
    b, cell, g = terrasynth.read_heightfield(p)
    assert cell == 30.0 and np.isnan(b[0, 0])
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert b[~np.isnan(b)].tobytes() == a[~np.isnan(a)].tobytes()
    assert (g["origin_x"], g["origin_y"], g["pixel_x"]) == (3000.0, 4800.0, 30.0)
    assert g["crs"]["epsg"] == 32611
    # The dict read back writes back.
    terrasynth.write_heightfield(tmp_path / "h.tif", b, cell, g)
    assert terrasynth.read_heightfield(tmp_path / "h.tif")[2]["crs"]["epsg"] == 32611


def test_non_contiguous_input_is_read_in_logical_order(tmp_path):
    a = np.arange(12 * 10, dtype=np.float32).reshape(12, 10)
    view = a.T[::2]  # strided, Fortran-ordered
    terrasynth.write_heightfield(tmp_path / "v.exr", view, 1.0)
    b, _, _ = terrasynth.read_heightfield(tmp_path / "v.exr")
    assert np.array_equal(b, view)


def test_eval_reports_the_realism_ratio(db):
    world = (256, 256)
    a = terrasynth.synthesize(db, world, seed=1)
    b = terrasynth.synthesize(db, world, seed=2)
    r = terrasynth.eval(a, b, db.cell_size())
    assert set(r) >= {"ratio", "descriptors", "median_slope", "relief", "pits", "closed"}
    assert np.isfinite(r["ratio"]) and r["ratio"] > 0
    assert all({"id", "distance", "ratio"} <= set(d) for d in r["descriptors"])
    json.dumps(r)


def test_scene_window_is_the_crop_of_the_scene(root):
    scene = root / "data" / "scenes" / "coast_range.json"
    whole = terrasynth.synthesize_scene(scene)
    assert whole.shape == (512, 512)
    x, y, w, h = 200, 280, 97, 75  # across the river curve
    win = terrasynth.synthesize_scene(scene, (x, y, w, h))
    assert win.tobytes() == whole[y : y + h, x : x + w].tobytes()


def test_scene_matches_the_cli(root, tmp_path):
    import shutil
    import subprocess

    import os

    cli = root / "target" / "release" / "terrasynth"
    if not cli.exists():
        cli = shutil.which("terrasynth")
    if cli is None:
        if os.environ.get("TERRASYNTH_REQUIRE_CLI"):
            pytest.fail("TERRASYNTH_REQUIRE_CLI is set but no terrasynth CLI was found")
        pytest.skip("no terrasynth CLI built (cargo build --release)")
    scene = root / "data" / "scenes" / "coast_range.json"
    out = tmp_path / "cli.exr"
    subprocess.run([str(cli), "synth", "--scene", str(scene), "-o", str(out)], check=True, capture_output=True)
    ref, _, _ = terrasynth.read_heightfield(out)
    assert terrasynth.synthesize_scene(scene).tobytes() == ref.tobytes()


def test_errors_are_python_exceptions(db, tmp_path):
    with pytest.raises(terrasynth.TerrasynthError, match="window"):
        terrasynth.synthesize(db, (100, 100), (90, 0, 20, 20))
    with pytest.raises(ValueError, match="empty"):
        terrasynth.synthesize(db, (100, 100), (0, 0, 0, 5))
    with pytest.raises(terrasynth.TerrasynthError):
        terrasynth.synthesize(db, (100, 100), start_exemplar=99)
    with pytest.raises(terrasynth.TerrasynthError):
        terrasynth.Database.open(tmp_path / "missing.tsdb")
    (tmp_path / "junk.tsdb").write_bytes(b"not a database")
    with pytest.raises(terrasynth.TerrasynthError):
        terrasynth.Database.open(tmp_path / "junk.tsdb")
    with pytest.raises(terrasynth.TerrasynthError, match="missing.tif"):
        terrasynth.read_heightfield(tmp_path / "missing.tif")
    with pytest.raises(TypeError, match="2-D"):
        terrasynth.write_heightfield(tmp_path / "x.tif", np.zeros(5, np.float32), 1.0)
    with pytest.raises(TypeError):
        terrasynth.write_heightfield(tmp_path / "x.tif", np.zeros((4, 4), np.int32), 1.0)
    with pytest.raises(ValueError, match="infinite|∞|inf"):
        terrasynth.write_heightfield(tmp_path / "x.tif", np.full((4, 4), np.inf, np.float32), 1.0)
    with pytest.raises(terrasynth.TerrasynthError):
        terrasynth.synthesize_scene(tmp_path / "missing.json")
    with pytest.raises(OverflowError):
        terrasynth.synthesize(db, (-1, 10))
    assert issubclass(terrasynth.TerrasynthError, Exception)


def test_database_describes_itself(db, root):
    assert db.path is None and len(db.exemplars) == 4 and db.levels >= 2
    assert db.type_names == ["sea", "flat", "hills", "mountains"]
    assert db.cell_size() > 0 and "Database(default" in repr(db)
