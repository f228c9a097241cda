"""Type stubs of the extension module (python/src/lib.rs)."""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, "os.PathLike[str]"]
_Window = Tuple[int, int, int, int]
Heights = npt.NDArray[np.float32]
Georef = Dict[str, Any]

class TerrasynthError(Exception):
    """An error of the terrasynth engine; the message is the engine's."""

class Database:
    """An exemplar database: the analysed real terrains syntheses draw from."""

    @staticmethod
    def default() -> "Database":
        """The embedded exemplars' database (cached in ~/.cache/terrasynth)."""
    @staticmethod
    def open(path: _Path) -> "Database":
        """Opens a .tsdb file (from `terrasynth db build`)."""
    @property
    def path(self) -> Optional["os.PathLike[str]"]:
        """The file it was opened from (a pathlib.Path); None for default()."""
    @property
    def exemplars(self) -> List[str]: ...
    @property
    def type_names(self) -> List[str]: ...
    @property
    def levels(self) -> int: ...
    def cell_size(self, start_exemplar: Optional[int] = None) -> float:
        """Cell size in metres of a synthesis from `start_exemplar`."""

def synthesize(
    db: Database,
    world: Tuple[int, int],
    window: Optional[_Window] = None,
    *,
    seed: int = 1,
    jitter: float = 0.4,
    passes: int = 2,
    start_exemplar: Optional[int] = None,
    height_prior: Optional[int] = None,
) -> Heights:
    """A world (width, height), or its window (x, y, w, h): float32 (h, w)."""

def synthesize_scene(
    scene_path: _Path,
    window: Optional[_Window] = None,
    db: Optional[Database] = None,
) -> Heights:
    """A scene file's terrain, or its window (x, y, w, h): float32 (h, w)."""

def read_heightfield(path: _Path) -> Tuple[Heights, float, Optional[Georef]]:
    """(heights, cell size in metres, georeference dict or None)."""

def write_heightfield(
    path: _Path,
    heights: Union[npt.NDArray[np.float32], npt.NDArray[np.float64]],
    cell_size: float,
    georef: Optional[Georef] = None,
) -> None:
    """Writes heights (metres, NaN = nodata); format from the extension."""

def eval(
    synth: Union[npt.NDArray[np.float32], npt.NDArray[np.float64]],
    reference: Union[npt.NDArray[np.float32], npt.NDArray[np.float64]],
    cell_size: float,
    reference_cell_size: Optional[float] = None,
) -> Dict[str, Any]:
    """`terrasynth eval --json`'s comparison: ratio, descriptors, ..."""

def novelty(
    synth: Union[npt.NDArray[np.float32], npt.NDArray[np.float64]],
    exemplars: Sequence[Union[npt.NDArray[np.float32], npt.NDArray[np.float64]]],
    *,
    window: int = 64,
    downsample: int = 2,
    threshold: float = 0.95,
    flat: float = 0.25,
    max_windows: int = 150,
) -> Dict[str, Any]:
    """Copy share against the exemplars, their halves' baseline, self-repetition."""

def water(
    heights: Union[npt.NDArray[np.float32], npt.NDArray[np.float64]],
    cell_size: float,
    *,
    sea_level: Optional[float] = None,
    river_area_km2: float = 5.0,
    lake_min_depth: float = 2.0,
    lake_min_area_km2: float = 0.1,
    routing: str = "d8",
) -> Dict[str, Any]:
    """`terrasynth water`: filled, depth, accumulation, flow (routed by `routing`: "d8" or "mfd"), receivers, rivers (arrays) and summary."""

def erode(
    heights: Union[npt.NDArray[np.float32], npt.NDArray[np.float64]],
    cell_size: float,
    *,
    strength: float = 1.0,
) -> npt.NDArray[np.float32]:
    """`terrasynth erode`: the heights after the local erosion filter."""

def mesh(
    heights: Union[npt.NDArray[np.float32], npt.NDArray[np.float64]],
    cell_size: float,
    *,
    max_error: Optional[float] = None,
    triangles: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.uint32]]:
    """`terrasynth mesh`: vertices (n, 3; Y up, X east, Z south, metres) and triangles (m, 3)."""
