//! Water, erosion and meshes of heightfields: `terrasynth.water`,
//! `terrasynth.erode`, `terrasynth.mesh`.

use super::{err, heightfield};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Water on a heightfield (``terrasynth water``): depressions filled by
/// priority-flood, flats resolved (Barnes et al. 2014), D8 flow on the
/// filled surface, lakes, the sea and rivers.
///
/// ``heights``: float32/float64 (rows, columns), metres, no NaN;
/// ``cell_size`` in metres. ``sea_level``: cells joined to the border at or
/// below it are sea. A filled depression is a lake when at least
/// ``lake_min_depth`` metres deep and ``lake_min_area_km2`` large; rivers
/// drain at least ``river_area_km2``. ``routing``: ``"d8"`` or ``"mfd"``
/// (flow shared among lower neighbours by slope), for ``flow``; rivers
/// follow D8 either way.
///
/// Returns a dict of (rows, columns) arrays — ``filled`` (float32: the
/// water surface), ``depth`` (float32: lake and sea water depth),
/// ``accumulation`` (uint32: D8 upstream area in cells), ``flow``
/// (float32: upstream area in cells routed by ``routing``, what
/// ``flow.tif`` holds), ``receivers``
/// (int64: the flat index each cell drains to, -1 at outlets), ``rivers``
/// (uint8: Strahler order of river cells) — and ``summary`` (the dict
/// ``terrasynth water --json`` prints).
#[pyfunction]
#[pyo3(signature = (heights, cell_size, *, sea_level=None, river_area_km2=5.0, lake_min_depth=2.0, lake_min_area_km2=0.1, routing="d8"))]
#[allow(clippy::too_many_arguments)] // one Rust argument per Python keyword
pub fn water<'py>(
    py: Python<'py>,
    heights: &Bound<'py, PyAny>,
    cell_size: f64,
    sea_level: Option<f32>,
    river_area_km2: f64,
    lake_min_depth: f64,
    lake_min_area_km2: f64,
    routing: &str,
) -> PyResult<Bound<'py, PyDict>> {
    use terrasynth::water::{self, Params, Routing, Thresholds};
    let routing = match routing {
        "d8" => Routing::D8,
        "mfd" => Routing::Mfd,
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "routing {other:?} is invalid: expected \"d8\" or \"mfd\""
            )));
        }
    };
    let hf = heightfield(heights, cell_size, "heights")?;
    let params = Params {
        sea_level,
        lakes: Thresholds {
            min_depth_m: lake_min_depth,
            min_area_km2: lake_min_area_km2,
        },
        river_area_km2,
    };
    let (w, summary) = py
        .allow_threads(|| -> Result<_, String> {
            let w = water::compute_with(&hf, &params, routing).map_err(|e| e.to_string())?;
            let s = serde_json::to_string(&w.summary()).map_err(|e| e.to_string())?;
            Ok((w, s))
        })
        .map_err(err)?;
    let shape = (w.height, w.width);
    let flow = w.flow();
    let out = PyDict::new(py);
    fn grid<T>(shape: (usize, usize), v: Vec<T>) -> Array2<T> {
        Array2::from_shape_vec(shape, v).expect("one value per cell")
    }
    out.set_item("filled", grid(shape, w.filled).into_pyarray(py))?;
    out.set_item("depth", grid(shape, w.bodies.depth).into_pyarray(py))?;
    out.set_item("flow", grid(shape, flow).into_pyarray(py))?;
    out.set_item("accumulation", grid(shape, w.accumulation).into_pyarray(py))?;
    let receivers: Vec<i64> = w
        .receivers
        .iter()
        .map(|&r| if r == water::d8::OUTLET { -1 } else { r as i64 })
        .collect();
    out.set_item("receivers", grid(shape, receivers).into_pyarray(py))?;
    out.set_item("rivers", grid(shape, w.rivers.order).into_pyarray(py))?;
    out.set_item(
        "summary",
        py.import("json")?.call_method1("loads", (summary,))?,
    )?;
    Ok(out)
}

/// The local erosion filter (``terrasynth erode``): a few steps of
/// stream-power incision and hillslope creep, each local, so a window of a
/// world erodes like the same crop of the whole world eroded (with
/// ``terrasynth synth --erode``).
///
/// ``heights``: float32/float64 (rows, columns), metres, no NaN;
/// ``cell_size`` in metres; ``strength`` 0 (unchanged) to 10. Returns the
/// eroded heights, float32, of the same shape.
#[pyfunction]
#[pyo3(signature = (heights, cell_size, *, strength=terrasynth::erode::DEFAULT_STRENGTH))]
pub fn erode<'py>(
    py: Python<'py>,
    heights: &Bound<'py, PyAny>,
    cell_size: f64,
    strength: f32,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let hf = heightfield(heights, cell_size, "heights")?;
    let out = py
        .allow_threads(|| terrasynth::erode::erode(&hf, strength))
        .map_err(err)?;
    let shape = (out.height(), out.width());
    Ok(Array2::from_shape_vec(shape, out.into_vec())
        .expect("one value per cell")
        .into_pyarray(py))
}

/// `mesh`'s vertices (n × 3) and triangles (m × 3).
type MeshArrays<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<u32>>);

/// A triangle mesh of a heightfield (``terrasynth mesh``): regular (every
/// sample a vertex) or, with ``max_error`` (metres) or ``triangles``,
/// adaptive (RTIN, every sample within the bound). Y up, X east, Z south,
/// metres; triangles counter-clockwise seen from above.
///
/// ``heights``: float32/float64 (rows, columns), metres, no NaN;
/// ``cell_size`` in metres. Returns ``(vertices, indices)``: float32
/// (n, 3) positions and uint32 (m, 3) triangles.
#[pyfunction]
#[pyo3(signature = (heights, cell_size, *, max_error=None, triangles=None))]
pub fn mesh<'py>(
    py: Python<'py>,
    heights: &Bound<'py, PyAny>,
    cell_size: f64,
    max_error: Option<f32>,
    triangles: Option<usize>,
) -> PyResult<MeshArrays<'py>> {
    use terrasynth::mesh::{self, Detail, Options};
    let hf = heightfield(heights, cell_size, "heights")?;
    let detail = match (max_error, triangles) {
        (Some(_), Some(_)) => return Err(err("give max_error or triangles, not both")),
        (Some(e), None) => Detail::MaxError(e),
        (None, Some(n)) => Detail::Triangles(n),
        (None, None) => Detail::Regular,
    };
    let opts = Options {
        detail,
        ..Options::default()
    };
    let mut built = py.allow_threads(|| mesh::build(&hf, &opts)).map_err(err)?;
    let m = built.meshes.swap_remove(0);
    let (n, t) = (m.positions.len(), m.triangles.len());
    let v = Array2::from_shape_vec((n, 3), m.positions.into_flattened()).expect("3 per vertex");
    let i = Array2::from_shape_vec((t, 3), m.triangles.into_flattened()).expect("3 per triangle");
    Ok((v.into_pyarray(py), i.into_pyarray(py)))
}
