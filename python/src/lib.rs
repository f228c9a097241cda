//! Python bindings of terrasynth (issue 17): the extension module
//! `terrasynth._native`, re-exported by the `terrasynth` package
//! (`python/terrasynth/__init__.py`, stubs in `_native.pyi`).
//!
//! Heightfields cross as numpy `float32` arrays of shape (rows, columns),
//! row 0 north, NaN = nodata. Every engine error becomes a
//! `terrasynth.TerrasynthError` carrying the Rust error's message; the GIL
//! is released while the engine works, so threads (and Dask's threaded
//! workers) run syntheses side by side.

mod terrain;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::{PyException, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Arc;
use terrasynth::database::{self, default};
use terrasynth::georef::{Crs, PixelIs, Units};
use terrasynth::io::{self, ReadOptions, WriteOptions};
use terrasynth::progress::Silent;
use terrasynth::scene::{Scene, WindowedScene};
use terrasynth::synth::cone::Rect;
use terrasynth::synth::{Params, Synthesizer};
use terrasynth::{Georef, Heightfield};

pyo3::create_exception!(
    terrasynth,
    TerrasynthError,
    PyException,
    "An error of the terrasynth engine (bad database, window outside the \
     world, unreadable file, ...); the message is the engine's."
);

/// The engine's error as a Python exception, with its message.
fn err(e: impl std::fmt::Display) -> PyErr {
    TerrasynthError::new_err(e.to_string())
}

/// An exemplar database: the analysed real terrains syntheses draw from.
///
/// Open one with ``Database.default()`` (the embedded exemplars, built once
/// and cached) or ``Database.open(path)`` (a ``.tsdb`` from
/// ``terrasynth db build``). A database is immutable and can be shared by
/// any number of threads.
#[pyclass(module = "terrasynth", name = "Database", frozen)]
struct PyDatabase {
    db: Arc<database::Database>,
    /// Where it came from: a path, or None for the embedded database.
    path: Option<PathBuf>,
}

#[pymethods]
impl PyDatabase {
    /// The database of the embedded exemplars (four real SRTM DEMs: a
    /// coast, a plain, mountains, hills): loaded from the cache (``$TERRASYNTH_CACHE_DIR``, else
    /// ``~/.cache/terrasynth``) or built there on first use (a few
    /// seconds), exactly as the ``terrasynth`` CLI does without ``--db``.
    #[staticmethod]
    fn default(py: Python<'_>) -> PyResult<Self> {
        let db = py
            .allow_threads(|| default::load_or_build(&default::cache_dir(), &Silent))
            .map_err(err)?
            .0;
        Ok(PyDatabase {
            db: Arc::new(db),
            path: None,
        })
    }

    /// Opens a database file (``.tsdb``, from ``terrasynth db build``).
    #[staticmethod]
    fn open(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let db = py
            .allow_threads(|| database::Database::load(&path))
            .map_err(err)?;
        Ok(PyDatabase {
            db: Arc::new(db),
            path: Some(path),
        })
    }

    /// The file this database was opened from; None for ``Database.default()``.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    /// The exemplars' names, in the database's order (``start_exemplar``
    /// indices).
    #[getter]
    fn exemplars(&self) -> Vec<String> {
        self.db
            .meta()
            .exemplars
            .iter()
            .map(|e| e.name.clone())
            .collect()
    }

    /// The terrain type names the database knows (for scenes' type strokes).
    #[getter]
    fn type_names(&self) -> Vec<String> {
        self.db.type_names().to_vec()
    }

    /// The number of pyramid levels.
    #[getter]
    fn levels(&self) -> usize {
        self.db.level_count()
    }

    /// The cell size in metres of a synthesis starting from
    /// ``start_exemplar`` (None: exemplar 0's, as ``synthesize``).
    #[pyo3(signature = (start_exemplar=None))]
    fn cell_size(&self, start_exemplar: Option<usize>) -> PyResult<f64> {
        let params = Params {
            start_exemplar,
            ..Params::default()
        };
        Ok(Synthesizer::new(&self.db, params)
            .map_err(err)?
            .cell_size_m())
    }

    fn __repr__(&self) -> String {
        let from = match &self.path {
            Some(p) => format!("{:?}", p.display().to_string()),
            None => "default".into(),
        };
        format!(
            "Database({from}, exemplars={:?}, levels={})",
            self.exemplars(),
            self.db.level_count()
        )
    }
}

/// A heightfield's heights as a (rows, columns) float32 array.
fn to_numpy(py: Python<'_>, hf: Heightfield) -> Bound<'_, PyArray2<f32>> {
    let (w, h) = (hf.width(), hf.height());
    Array2::from_shape_vec((h, w), hf.into_vec())
        .expect("a heightfield holds width × height samples")
        .into_pyarray(py)
}

/// A 2-D float32 or float64 array (any layout) as (width, height, samples).
fn from_numpy(a: &Bound<'_, PyAny>, what: &str) -> PyResult<(usize, usize, Vec<f32>)> {
    if let Ok(a) = a.extract::<PyReadonlyArray2<'_, f32>>() {
        let v = a.as_array();
        return Ok((v.ncols(), v.nrows(), v.iter().copied().collect()));
    }
    if let Ok(a) = a.extract::<PyReadonlyArray2<'_, f64>>() {
        let v = a.as_array();
        return Ok((v.ncols(), v.nrows(), v.iter().map(|&x| x as f32).collect()));
    }
    Err(PyTypeError::new_err(format!(
        "{what}: expected a 2-D numpy array of float32 or float64 (rows, columns)"
    )))
}

fn heightfield(a: &Bound<'_, PyAny>, cell_size: f64, what: &str) -> PyResult<Heightfield> {
    let (w, h, v) = from_numpy(a, what)?;
    Heightfield::from_vec(w, h, cell_size, v)
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))
}

/// `(x, y, w, h)` as a rectangle, refusing empty windows here (the
/// engine checks that the window lies in the world).
fn rect((x, y, w, h): (usize, usize, usize, usize)) -> PyResult<Rect> {
    if w == 0 || h == 0 {
        return Err(PyValueError::new_err(format!(
            "window ({x}, {y}, {w}, {h}) is empty"
        )));
    }
    Ok(Rect::new(x, y, w, h))
}

/// Synthesizes a terrain, or one window of it, as a float32 array.
///
/// ``world`` is the terrain's (width, height) in pixels; ``window``
/// (x, y, w, h) cuts a window out of it: the result is byte for byte the
/// same crop of the whole synthesis, computed in time and memory
/// proportional to the window (worlds up to 1048576 pixels a side), so
/// windows computed anywhere (threads, processes, machines) assemble into
/// one seamless terrain. None synthesizes the whole world.
///
/// ``seed``, ``jitter`` (texels; 0 reproduces the exemplar), ``passes``
/// (correction passes per level; the start level takes more for exemplars
/// smooth at the pixel scale), ``start_exemplar`` and ``height_prior`` are
/// those of ``terrasynth synth``. Returns an array of shape (h, w)
/// (rows north to south) of heights in metres; the cell size is
/// ``db.cell_size(start_exemplar)``.
#[pyfunction]
#[pyo3(signature = (db, world, window=None, *, seed=1, jitter=0.4, passes=2, start_exemplar=None, height_prior=None))]
#[allow(clippy::too_many_arguments)]
fn synthesize<'py>(
    py: Python<'py>,
    db: &PyDatabase,
    world: (usize, usize),
    window: Option<(usize, usize, usize, usize)>,
    seed: u32,
    jitter: f64,
    passes: u32,
    start_exemplar: Option<usize>,
    height_prior: Option<u32>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let window = window.map(rect).transpose()?;
    let params = Params {
        jitter,
        passes,
        start_exemplar,
        prior: height_prior.unwrap_or(Params::default().prior),
        ..Params::default()
    };
    let db = db.db.clone();
    let hf = py
        .allow_threads(move || -> Result<Heightfield, String> {
            let synth = Synthesizer::new(&db, params).map_err(|e| e.to_string())?;
            let (w, h) = world;
            match window {
                Some(win) => {
                    let cone = synth.window_cone(world, win).map_err(|e| e.to_string())?;
                    let what = format!(
                        "a {}x{} window of a {w}x{h} world",
                        win.width(),
                        win.height()
                    );
                    io::check_memory(&what, cone.bytes()).map_err(|e| e.to_string())?;
                    synth
                        .synthesize_window(world, win, seed)
                        .map_err(|e| e.to_string())
                }
                None => {
                    terrasynth::size::check_dims(w, h).map_err(|e| e.to_string())?;
                    let bytes = (w * h) as f64 * Synthesizer::bytes_per_pixel(w, h);
                    io::check_memory(&format!("a {w}x{h} synthesis"), bytes as u64)
                        .map_err(|e| e.to_string())?;
                    synth.synthesize(w, h, seed).map_err(|e| e.to_string())
                }
            }
        })
        .map_err(err)?;
    Ok(to_numpy(py, hf))
}

/// Synthesizes a scene file (``data/scenes/*.json``: size, seed, database
/// and controls), or one window (x, y, w, h) of it: every constraint,
/// type, freeze and paste that reaches the window acts on it as in the
/// whole scene (``terrasynth synth --scene``).
///
/// ``db`` replaces the scene's database (default: the one the scene names,
/// else the embedded one). Returns a float32 array of shape (h, w).
#[pyfunction]
#[pyo3(signature = (scene_path, window=None, db=None))]
fn synthesize_scene<'py>(
    py: Python<'py>,
    scene_path: PathBuf,
    window: Option<(usize, usize, usize, usize)>,
    db: Option<&PyDatabase>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let window = window.map(rect).transpose()?;
    let given = db.map(|d| d.db.clone());
    let hf = py
        .allow_threads(move || -> Result<Heightfield, String> {
            let scene = Scene::read(&scene_path).map_err(|e| e.to_string())?;
            let db = match given {
                Some(db) => db,
                None => Arc::new(match &scene.database {
                    Some(p) => database::Database::load(p).map_err(|e| e.to_string())?,
                    None => {
                        default::load_or_build(&default::cache_dir(), &Silent)
                            .map_err(|e| e.to_string())?
                            .0
                    }
                }),
            };
            let ws = WindowedScene::new(&scene, &db).map_err(|e| e.to_string())?;
            let synth = Synthesizer::new(&db, ws.params()).map_err(|e| e.to_string())?;
            let world = (scene.width, scene.height);
            let win = window.unwrap_or(Rect::new(0, 0, scene.width, scene.height));
            let cone = synth.window_cone(world, win).map_err(|e| e.to_string())?;
            // A scene's first frame is recorded for its pastes (as the CLI).
            let what = format!("a {}x{} window of the scene", win.width(), win.height());
            io::check_memory(&what, cone.bytes() * 3).map_err(|e| e.to_string())?;
            ws.synthesize_window(&synth, win)
                .map_err(|e| format!("{}: {e}", scene_path.display()))
        })
        .map_err(err)?;
    Ok(to_numpy(py, hf))
}

/// A georeference as a dict (see `read_heightfield`).
fn georef_dict<'py>(py: Python<'py>, g: &Georef) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("origin_x", g.origin_x)?;
    d.set_item("origin_y", g.origin_y)?;
    d.set_item("pixel_x", g.pixel_x)?;
    d.set_item("pixel_y", g.pixel_y)?;
    let pixel_is = match g.pixel_is {
        PixelIs::Area => "area",
        PixelIs::Point => "point",
    };
    d.set_item("pixel_is", pixel_is)?;
    match &g.crs {
        None => d.set_item("crs", py.None())?,
        Some(c) => {
            let crs = PyDict::new(py);
            crs.set_item("epsg", c.epsg)?;
            crs.set_item("wkt", &c.wkt)?;
            crs.set_item("name", &c.name)?;
            match c.units {
                Units::Degrees => crs.set_item("units", "degrees")?,
                Units::Linear { metres_per_unit } => {
                    crs.set_item("units", "linear")?;
                    crs.set_item("metres_per_unit", metres_per_unit)?;
                }
            }
            crs.set_item("vertical_epsg", c.vertical_epsg)?;
            d.set_item("crs", crs)?;
        }
    }
    Ok(d)
}

/// The inverse of `georef_dict`.
fn georef_from(d: &Bound<'_, PyDict>) -> PyResult<Georef> {
    fn get<'py, T: FromPyObject<'py>>(d: &Bound<'py, PyDict>, k: &str) -> PyResult<Option<T>> {
        match d.get_item(k)? {
            Some(v) if !v.is_none() => Ok(Some(v.extract()?)),
            _ => Ok(None),
        }
    }
    fn need<'py, T: FromPyObject<'py>>(d: &Bound<'py, PyDict>, k: &str) -> PyResult<T> {
        get(d, k)?.ok_or_else(|| PyValueError::new_err(format!("georef: missing {k:?}")))
    }
    let pixel_is = match get::<String>(d, "pixel_is")?.as_deref() {
        None | Some("area") => PixelIs::Area,
        Some("point") => PixelIs::Point,
        Some(o) => {
            return Err(PyValueError::new_err(format!(
                "georef: pixel_is {o:?} is neither \"area\" nor \"point\""
            )));
        }
    };
    let crs = match d.get_item("crs")? {
        Some(c) if !c.is_none() => {
            let c = c.downcast::<PyDict>()?;
            let units = match get::<String>(c, "units")?.as_deref() {
                Some("degrees") => Units::Degrees,
                None | Some("linear") => Units::Linear {
                    metres_per_unit: get(c, "metres_per_unit")?.unwrap_or(1.0),
                },
                Some(o) => {
                    return Err(PyValueError::new_err(format!(
                        "georef: crs units {o:?} are neither \"degrees\" nor \"linear\""
                    )));
                }
            };
            Some(Crs {
                epsg: get(c, "epsg")?,
                wkt: get(c, "wkt")?,
                name: get(c, "name")?,
                units,
                vertical_epsg: get(c, "vertical_epsg")?,
            })
        }
        _ => None,
    };
    Ok(Georef {
        crs,
        origin_x: need(d, "origin_x")?,
        origin_y: need(d, "origin_y")?,
        pixel_x: need(d, "pixel_x")?,
        pixel_y: need(d, "pixel_y")?,
        pixel_is,
    })
}

/// `read_heightfield`'s (heights, cell size, georeference).
type ReadResult<'py> = (Bound<'py, PyArray2<f32>>, f64, Option<Bound<'py, PyDict>>);

/// Reads a heightfield file (GeoTIFF, EXR, PNG16, R16/RAW with sidecar,
/// ESRI ASCII, SRTM .hgt, Terragen .ter; the format from the extension).
///
/// Returns ``(heights, cell_size, georef)``: a float32 array of shape
/// (rows, columns) in metres (NaN = nodata), the cell size in metres, and
/// the file's georeference as a dict (``origin_x``, ``origin_y``: map
/// coordinates of the top-left cell's outer corner; ``pixel_x``,
/// ``pixel_y``; ``pixel_is``; ``crs``: None or a dict with ``epsg``,
/// ``wkt``, ``name``, ``units``, ``metres_per_unit``, ``vertical_epsg``),
/// or None when the file places the grid nowhere.
#[pyfunction]
fn read_heightfield<'py>(py: Python<'py>, path: PathBuf) -> PyResult<ReadResult<'py>> {
    let hf = py
        .allow_threads(|| io::read(&path, &ReadOptions::default()))
        .map_err(err)?;
    let cell = hf.cell_size();
    let georef = hf.georef().map(|g| georef_dict(py, g)).transpose()?;
    Ok((to_numpy(py, hf), cell, georef))
}

/// Writes a heightfield (float32 or float64 array of shape (rows, columns),
/// metres, NaN = nodata) with its cell size in metres; the format comes
/// from the extension (``.tif``, ``.exr``, ``.png``, ``.r16``, ``.asc``,
/// ``.ter``, ...). ``georef`` (a dict as ``read_heightfield`` returns) places
/// it on a map; formats that cannot hold it keep it in a sidecar where the
/// CLI would.
#[pyfunction]
#[pyo3(signature = (path, heights, cell_size, georef=None))]
fn write_heightfield(
    py: Python<'_>,
    path: PathBuf,
    heights: &Bound<'_, PyAny>,
    cell_size: f64,
    georef: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let mut hf = heightfield(heights, cell_size, "heights")?;
    hf.set_georef(georef.map(georef_from).transpose()?);
    py.allow_threads(|| io::write(&hf, &path, &WriteOptions::default()))
        .map_err(|e| err(format!("{}: {e}", path.display())))
}

/// Compares a synthesis with a reference terrain by the realism
/// descriptors of ``terrasynth eval`` (slope, curvature, roughness,
/// drainage, spectrum, ...).
///
/// ``synth`` and ``reference`` are height arrays in metres with cell sizes
/// ``cell_size`` and ``reference_cell_size`` (default: the same). Returns
/// ``terrasynth eval --json``'s dict: ``ratio`` (the realism ratio: mean of
/// the descriptors' distances to the reference in units of the distance
/// between the reference's two halves; about 1 is as real as the
/// reference), ``descriptors`` (per descriptor: ``id``, ``unit``,
/// ``synth``, ``reference``, ``distance``, ``halves``, ``ratio``, ...),
/// ``median_slope``, ``relief``, ``pits`` and ``closed`` (the share of
/// the area in closed depressions: water with no valley out).
#[pyfunction]
#[pyo3(signature = (synth, reference, cell_size, reference_cell_size=None))]
fn eval<'py>(
    py: Python<'py>,
    synth: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    cell_size: f64,
    reference_cell_size: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let s = heightfield(synth, cell_size, "synth")?;
    let r = heightfield(
        reference,
        reference_cell_size.unwrap_or(cell_size),
        "reference",
    )?;
    let json = py
        .allow_threads(|| -> Result<String, String> {
            let c = terrasynth::eval::compare(&s, &r).map_err(|e| e.to_string())?;
            serde_json::to_string(&c).map_err(|e| e.to_string())
        })
        .map_err(err)?;
    py.import("json")?.call_method1("loads", (json,))
}

/// How much of a synthesis is a recognisable copy of its exemplars
/// (``terrasynth eval``'s novelty): 64-cell windows of ``synth`` (heights
/// averaged 2×2) whose best normalised cross-correlation with any window
/// of any of ``exemplars``, in any of the 8 orientations, is at least
/// ``threshold``; windows flatter than ``flat`` × the exemplars' median
/// window standard deviation are skipped; at most ``max_windows`` windows,
/// evenly spread.
///
/// Returns a dict: ``copies`` (``share``, ``median_ncc``, ``scored``,
/// ``flat``, ``windows``: each scored window's corner, best NCC and where
/// it matched), ``baselines`` and ``baseline`` (each exemplar's top half
/// against its bottom half: what real terrain scores against itself) and
/// ``repetition`` (windows with a near-duplicate elsewhere in ``synth``).
#[pyfunction]
#[pyo3(signature = (synth, exemplars, *, window=64, downsample=2, threshold=0.95, flat=0.25, max_windows=150))]
#[allow(clippy::too_many_arguments)]
fn novelty<'py>(
    py: Python<'py>,
    synth: &Bound<'py, PyAny>,
    exemplars: Vec<Bound<'py, PyAny>>,
    window: usize,
    downsample: usize,
    threshold: f64,
    flat: f64,
    max_windows: usize,
) -> PyResult<Bound<'py, PyAny>> {
    // NCC ignores the cell size.
    let s = heightfield(synth, 1.0, "synth")?;
    let ex = exemplars
        .iter()
        .map(|e| heightfield(e, 1.0, "exemplars"))
        .collect::<PyResult<Vec<_>>>()?;
    let p = terrasynth::eval::novelty::Params {
        window,
        downsample,
        threshold,
        flat,
        max_windows,
    };
    let json = py
        .allow_threads(|| -> Result<String, String> {
            let refs: Vec<&terrasynth::Heightfield> = ex.iter().collect();
            let r = terrasynth::eval::novelty::measure(&s, &refs, &p).map_err(|e| e.to_string())?;
            serde_json::to_string(&r).map_err(|e| e.to_string())
        })
        .map_err(err)?;
    py.import("json")?.call_method1("loads", (json,))
}

/// terrasynth's engine: example-based terrain synthesis (Gain, Merry &
/// Marais 2015) with windows of unbounded worlds.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyDatabase>()?;
    m.add("TerrasynthError", m.py().get_type::<TerrasynthError>())?;
    m.add_function(wrap_pyfunction!(synthesize, m)?)?;
    m.add_function(wrap_pyfunction!(synthesize_scene, m)?)?;
    m.add_function(wrap_pyfunction!(read_heightfield, m)?)?;
    m.add_function(wrap_pyfunction!(write_heightfield, m)?)?;
    m.add_function(wrap_pyfunction!(eval, m)?)?;
    m.add_function(wrap_pyfunction!(novelty, m)?)?;
    m.add_function(wrap_pyfunction!(terrain::water, m)?)?;
    m.add_function(wrap_pyfunction!(terrain::erode, m)?)?;
    m.add_function(wrap_pyfunction!(terrain::mesh, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
