"""terrasynth.mesh (issue 44): numpy vertices and triangles of a heightfield."""

import numpy as np
import pytest

import terrasynth


def surface(rows: int, cols: int) -> np.ndarray:
    y, x = np.mgrid[0:rows, 0:cols].astype(np.float64)
    return (300.0 + 2.0 * x + 25.0 * np.sin(y / 7.0) * np.cos(x / 9.0)).astype(np.float32)


def test_regular_mesh_has_every_sample_in_metres():
    z = surface(20, 30)
    v, t = terrasynth.mesh(z, 10.0)
    assert v.dtype == np.float32 and v.shape == (600, 3)
    assert t.dtype == np.uint32 and t.shape == (2 * 29 * 19, 3)
    # Y up, X east, Z south: the rows of the array run south.
    assert np.array_equal(v.min(axis=0), [0.0, z.min(), 0.0])
    assert np.array_equal(v.max(axis=0), [290.0, z.max(), 190.0])
    assert {tuple(r) for r in v.tolist()} >= {(50.0, float(z[3, 5]), 30.0)}
    # Counter-clockwise seen from above: every face normal points up.
    a, b, c = (v[t[:, k]] for k in range(3))
    assert (np.cross(b - a, c - a)[:, 1] > 0).all()


def test_adaptive_mesh_is_smaller_and_refuses_bad_input():
    z = surface(65, 65)
    _, regular = terrasynth.mesh(z, 10.0)
    v, t = terrasynth.mesh(z, 10.0, max_error=1.0)
    assert 0 < len(t) < len(regular) / 2 and t.max() < len(v)
    _, few = terrasynth.mesh(z, 10.0, triangles=200)
    assert len(few) <= 200
    with pytest.raises(terrasynth.TerrasynthError):
        terrasynth.mesh(z, 10.0, max_error=1.0, triangles=10)
    z[3, 4] = np.nan
    with pytest.raises(terrasynth.TerrasynthError, match="nodata"):
        terrasynth.mesh(z, 10.0)
