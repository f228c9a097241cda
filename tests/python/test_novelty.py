"""terrasynth.novelty against the reference script of the novelty rule
(../shared/tools/novelty.py: numpy + scikit-image's match_template), on a
real DEM and a synthesis from it: the same windows, the same copies."""

import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import terrasynth

SHARED = pathlib.Path(__file__).resolve().parents[3] / "shared"
SCRIPT = SHARED / "tools" / "novelty.py"
DEM = SHARED / "dem" / "pyrenees_andorra.png"


def needs_shared():
    missing = [p for p in (SCRIPT, DEM) if not p.exists()]
    if missing:
        if os.environ.get("TERRASYNTH_REQUIRE_DEM"):
            pytest.fail(f"TERRASYNTH_REQUIRE_DEM is set but {missing} is absent")
        pytest.skip(f"{missing} absent")
    pytest.importorskip("skimage")
    pytest.importorskip("PIL")


def reference(synth_png, exemplar_png, *args):
    """The script's (copy share %, median best NCC, windows)."""
    out = subprocess.run(
        [sys.executable, str(SCRIPT), str(synth_png), str(exemplar_png), *args],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    # "copy share 62.0 % (NCC >= 0.95); median best NCC 0.988; 150 windows of 64 px"
    words = out.split()
    share = float(words[2])
    median = float(words[words.index("NCC", 6) + 1].rstrip(";"))
    windows = int(words[words.index("windows") - 1])
    return share, median, windows


def test_novelty_agrees_with_the_reference_script(tmp_path):
    needs_shared()
    dem, cell, _ = terrasynth.read_heightfield(DEM)
    exemplar = dem[100:484, 150:534]  # 384²: the script's ~2 s per window batch
    ex_png = tmp_path / "exemplar.png"
    terrasynth.write_heightfield(ex_png, exemplar, cell)
    # A synthesis that partly copies (the jitter-free one is all copy) and
    # an unrelated real terrain (the DEM's other corner).
    db_path = tmp_path / "ex.tsdb"
    subprocess.run(
        [str(cli()), "db", "build", "--no-types", str(ex_png), "-o", str(db_path)],
        check=True,
        capture_output=True,
    )
    db = terrasynth.Database.open(db_path)
    cases = {
        "synthesis": terrasynth.synthesize(db, (320, 320), seed=11),
        "copy": terrasynth.synthesize(db, (320, 320), seed=11, jitter=0.0),
        "other": dem[500:820, 560:880],
    }
    for name, synth in cases.items():
        png = tmp_path / f"{name}.png"
        terrasynth.write_heightfield(png, synth, cell)
        # Both read the same 16-bit file (quantised heights).
        heights, _, _ = terrasynth.read_heightfield(png)
        ex_heights, _, _ = terrasynth.read_heightfield(ex_png)
        ours = terrasynth.novelty(heights, [ex_heights])["copies"]
        share, median, windows = reference(png, ex_png)
        assert ours["scored"] == windows, name
        # One window may fall on the other side of the threshold by rounding.
        assert abs(ours["share"] * 100 - share) <= 100 / windows + 0.05, (name, ours["share"], share)
        assert abs(ours["median_ncc"] - median) <= 0.0015, (name, ours["median_ncc"], median)
    # The rule's ends: a jitter-free synthesis is a copy, other terrain is not.
    copy = terrasynth.novelty(cases["copy"].astype(np.float32), [exemplar])["copies"]
    other = terrasynth.novelty(cases["other"].astype(np.float32), [exemplar])["copies"]
    assert copy["share"] >= 0.8, copy["share"]
    assert other["share"] <= 0.1, other["share"]


def cli():
    root = pathlib.Path(__file__).resolve().parents[2]
    path = root / "target" / "release" / "terrasynth"
    if not path.exists():
        pytest.fail("the terrasynth CLI is not built (cargo build --release)")
    return path
