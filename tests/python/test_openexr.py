"""What we write as EXR, read by the reference OpenEXR library (its
official Python bindings, PyPI `OpenEXR`): every block kind our writer
makes (level-4 ZIP, quick ZIP, raw), bit for bit, and the cell size."""

import numpy as np
import OpenEXR
import pytest

import terrasynth


def _kinds(rows: int, cols: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:rows, 0:cols].astype(np.float32)
    # Interpolated heights: a smooth surface with noisy low mantissa bits.
    smooth = 800 + 0.31 * x + 0.17 * y + rng.random((rows, cols), dtype=np.float32)
    # Whole metres with nodata: compresses well.
    whole = np.round(smooth / 7).astype(np.float32)
    whole[::37, ::11] = np.nan
    # Random bits: incompressible, stored raw.
    bits = rng.integers(0, 2**31, (rows, cols), dtype=np.uint32)
    noise = bits.view(np.float32).copy()
    noise[~np.isfinite(noise)] = 1.0
    # One file with all three, block by block (16 lines each).
    mixed = np.concatenate([noise[:16], smooth[16:32], whole[32:]])
    return {"smooth": smooth, "whole": whole, "noise": noise, "mixed": mixed}


@pytest.mark.parametrize("kind", ["smooth", "whole", "noise", "mixed"])
def test_openexr_reads_what_we_write(tmp_path, kind):
    # 70 blocks: past the bindings' and the crate's parallel thresholds,
    # with a partial last block.
    a = _kinds(1110, 130)[kind]
    p = tmp_path / f"{kind}.exr"
    terrasynth.write_heightfield(p, a, 12.5)
    f = OpenEXR.File(str(p))
    header = f.header()
    assert header["compression"] == OpenEXR.ZIP_COMPRESSION
    assert float(header["cellSizeMetres"][0]) == 12.5
    y = f.channels()["Y"].pixels
    assert y.dtype == np.float32 and y.shape == a.shape
    assert y.tobytes() == a.tobytes()
    ours, cell, _ = terrasynth.read_heightfield(p)
    assert cell == 12.5 and ours.tobytes() == a.tobytes()
