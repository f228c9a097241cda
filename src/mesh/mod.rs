//! Triangle meshes of a heightfield for engines and DCC tools (issue 44):
//! a regular grid ([`grid`]) or an error-bounded adaptive triangulation
//! ([`rtin`]), with level-of-detail copies, per-tile pieces whose borders
//! share their vertices exactly, optional skirts, normals and UVs; written
//! as glTF 2.0 ([`gltf`]: `.glb`, or `.gltf` + `.bin`) or OBJ ([`obj`]).
//!
//! Coordinates are glTF's (and OBJ's usual) Y-up, right-handed frame, in
//! metres: X east = column × cell size, Z south = row × cell size (row 0 is
//! north, so seen from above the mesh looks like the heightfield's image),
//! Y = the height in metres as read (the sidecar's height mapping already
//! applied). Triangles wind counter-clockwise seen from above, so their
//! normals point up. Positions are absolute (not per tile), so the tiles of
//! one mesh line up with no node transforms and their shared border
//! vertices are the same bytes on both sides.
//!
//! Both triangulations work on the grid's own samples (no resampling), so
//! the vertical error is measured exactly at every sample by
//! [`measure::max_vertical_error`].

pub mod gltf;
pub mod grid;
pub mod measure;
pub mod normal_map;
pub mod obj;
pub mod rtin;

use crate::heightfield::{FirstNodata, Heightfield};
use crate::io::{IoError, check_memory};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Most level-of-detail copies (each ¼ of the previous one's triangles or
/// fewer: 8 levels go from a full grid to ~1/16000 of it).
pub const MAX_LODS: usize = 8;

/// A mesh that cannot be made.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum MeshError {
    #[error(
        "{count} nodata samples (the first at pixel ({x}, {y})): a mesh needs every height; fill them first (terrasynth convert --fill-nodata IN OUT)"
    )]
    Nodata { count: usize, x: usize, y: usize },
    #[error(
        "a {width}x{height} grid has no cell to triangulate: a mesh needs at least 2x2 samples"
    )]
    TooSmall { width: usize, height: usize },
    #[error("{name} {value} is invalid: expected {expected}")]
    Param {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error(
        "the mesh needs {bytes} bytes of buffers but {format} holds at most {limit}; use --max-error, --triangles or --tile to make it smaller"
    )]
    TooLarge {
        bytes: u64,
        format: &'static str,
        limit: u64,
    },
    #[error("{path}: cannot tell the mesh format from the name; use .glb, .gltf or .obj")]
    Format { path: PathBuf },
    #[error(transparent)]
    Size(#[from] crate::size::SizeError),
    #[error(transparent)]
    Io(#[from] IoError),
}

/// How the surface is triangulated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Detail {
    /// Every sample a vertex, two triangles a cell.
    Regular,
    /// As few triangles as keep every sample within this many metres of
    /// the surface.
    MaxError(f32),
    /// The smallest error bound that needs at most this many triangles
    /// (over all tiles of the finest level).
    Triangles(usize),
}

/// What to build.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub detail: Detail,
    /// Level-of-detail copies, 1 (just the mesh) ..= [`MAX_LODS`]. Level
    /// `i` of a regular mesh keeps every 2^i-th sample; of an adaptive one,
    /// allows 2^i times the error (or ¼^i of the triangles).
    pub lods: usize,
    pub normals: bool,
    pub uvs: bool,
    /// Depth in metres of the skirt hung below every tile's outer edge
    /// (hides cracks between tiles of different LODs); `None`, no skirt.
    pub skirt: Option<f32>,
    /// Cells per tile side (tiles share their border samples); `None`,
    /// one piece. Adaptive tiles need a power of two (see [`rtin`]).
    pub tile: Option<usize>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            detail: Detail::Regular,
            lods: 1,
            normals: false,
            uvs: false,
            skirt: None,
            tile: None,
        }
    }
}

impl Options {
    /// Refuses values no mesh can be made with, naming the option.
    pub fn check(&self) -> Result<(), MeshError> {
        let bad = |name, value: f64, expected| MeshError::Param {
            name,
            value,
            expected,
        };
        match self.detail {
            Detail::MaxError(e) if !(e.is_finite() && e >= 0.0) => {
                return Err(bad("--max-error", e as f64, "a finite value >= 0 m"));
            }
            Detail::Triangles(n) if n < 2 => {
                return Err(bad("--triangles", n as f64, "at least 2"));
            }
            _ => {}
        }
        if !(1..=MAX_LODS).contains(&self.lods) {
            return Err(bad("--lods", self.lods as f64, "1..=8"));
        }
        if let Some(s) = self.skirt
            && !(s.is_finite() && s > 0.0)
        {
            return Err(bad("--skirt", s as f64, "a finite depth > 0 m"));
        }
        match (self.tile, self.detail) {
            (Some(0), _) => Err(bad("--tile", 0.0, "at least 1 cell")),
            (Some(t), Detail::MaxError(_) | Detail::Triangles(_)) if !t.is_power_of_two() => Err(
                bad("--tile", t as f64, "a power of two for an adaptive mesh"),
            ),
            _ => Ok(()),
        }
    }
}

/// A triangulation in grid coordinates: vertices are samples (column,
/// row), triangles index them counter-clockwise seen from above.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Triangulation {
    pub vertices: Vec<[u32; 2]>,
    pub triangles: Vec<[u32; 3]>,
}

impl Triangulation {
    /// Splits a triangulation given by sample index (`y × width + x`)
    /// triangles into one per tile (by the triangle's first vertex's tile
    /// of `tile` cells: every triangle lies in one tile), each with its
    /// own vertex list, tiles in row-major order.
    fn from_triangles(
        tris: &[[u32; 3]],
        width: usize,
        tiles: (usize, usize),
        tile: usize,
    ) -> Vec<Triangulation> {
        let mut out = vec![Triangulation::default(); tiles.0 * tiles.1];
        let mut maps: Vec<HashMap<u32, u32>> = vec![HashMap::new(); out.len()];
        for t in tris {
            let at = |i: u32| ((i as usize) % width, (i as usize) / width);
            // The centroid's tile: border vertices belong to two tiles.
            let c = t.map(at);
            let cx = (c[0].0 + c[1].0 + c[2].0) / 3;
            let cy = (c[0].1 + c[1].1 + c[2].1) / 3;
            let k = (cy / tile).min(tiles.1 - 1) * tiles.0 + (cx / tile).min(tiles.0 - 1);
            let (piece, map) = (&mut out[k], &mut maps[k]);
            let tri = t.map(|i| {
                *map.entry(i).or_insert_with(|| {
                    let (x, y) = at(i);
                    piece.vertices.push([x as u32, y as u32]);
                    (piece.vertices.len() - 1) as u32
                })
            });
            piece.triangles.push(tri);
        }
        out
    }
}

/// One mesh, ready for a writer: positions in metres (see the module
/// comment for the frame), optional normals and UVs per vertex, and
/// triangles.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Unique within its [`Meshes`]: `terrain`, `terrain_x1_y0`, with
    /// `_LOD2` appended for level 2 when there are LODs (the suffix
    /// Unity's and Unreal's importers group by).
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub triangles: Vec<[u32; 3]>,
}

/// What [`build`] made.
#[derive(Debug, Clone, Default)]
pub struct Meshes {
    /// Level by level, tiles in row-major order within a level.
    pub meshes: Vec<Mesh>,
    /// The triangulations the meshes were made from (before skirts), in
    /// the same order, for measuring.
    pub triangulations: Vec<Triangulation>,
    /// Per level: the error bound used; 0 for a regular mesh, whose level
    /// 0 is exact and coarser levels are not error-bounded.
    pub bounds: Vec<f32>,
    /// Tiles per row and column.
    pub tiles: (usize, usize),
}

/// The metre position of sample (x, y): computed the same way wherever
/// the sample appears, so shared vertices are bit-identical.
pub fn position(hf: &Heightfield, x: u32, y: u32) -> [f32; 3] {
    let c = hf.cell_size();
    [
        (x as f64 * c) as f32,
        hf.get(x as usize, y as usize),
        (y as f64 * c) as f32,
    ]
}

/// The unit surface normal at sample (x, y) from central differences of
/// the heightfield (one-sided at its edges), not from the triangles: a
/// coarse LOD then still shades like the terrain, and a border vertex gets
/// the same normal in both tiles.
pub fn normal(hf: &Heightfield, x: u32, y: u32) -> [f32; 3] {
    let (w, h) = (hf.width() as i64, hf.height() as i64);
    let (x, y) = (x as i64, y as i64);
    let (x0, x1) = ((x - 1).max(0), (x + 1).min(w - 1));
    let (y0, y1) = ((y - 1).max(0), (y + 1).min(h - 1));
    let at = |x: i64, y: i64| hf.get(x as usize, y as usize) as f64;
    let c = hf.cell_size();
    let gx = (at(x1, y) - at(x0, y)) / (c * (x1 - x0).max(1) as f64);
    let gz = (at(x, y1) - at(x, y0)) / (c * (y1 - y0).max(1) as f64);
    let len = (gx * gx + 1.0 + gz * gz).sqrt();
    [(-gx / len) as f32, (1.0 / len) as f32, (-gz / len) as f32]
}

/// Refuses a grid with no cell or with nodata.
fn check_heights(hf: &Heightfield) -> Result<(), MeshError> {
    let (w, h) = (hf.width(), hf.height());
    if w < 2 || h < 2 {
        return Err(MeshError::TooSmall {
            width: w,
            height: h,
        });
    }
    match hf.first_nodata() {
        Some(FirstNodata { count, x, y }) => Err(MeshError::Nodata { count, x, y }),
        None => Ok(()),
    }
}

/// Triangulates `hf` as `opts` asks and turns every piece into a [`Mesh`].
/// Sizes are checked against the available memory before the large
/// allocations.
pub fn build(hf: &Heightfield, opts: &Options) -> Result<Meshes, MeshError> {
    opts.check()?;
    check_heights(hf)?;
    let (w, h) = (hf.width(), hf.height());
    let tile = opts.tile.unwrap_or(usize::MAX).min((w - 1).max(h - 1));
    let tiles = ((w - 1).div_ceil(tile), (h - 1).div_ceil(tile));
    let mut levels: Vec<(f32, Vec<Triangulation>)> = Vec::with_capacity(opts.lods);
    match opts.detail {
        Detail::Regular => {
            // Vertices (with normals, UVs and output bytes) and triangles of
            // the finest level; the coarser ones add at most a third.
            let cells = ((w - 1) * (h - 1)) as u64;
            check_memory(
                &format!("a {w}x{h} grid mesh"),
                (w * h) as u64 * 64 + cells * 48,
            )?;
            for l in 0..opts.lods {
                levels.push((0.0, grid::triangulate(w, h, tile, 1 << l)));
            }
        }
        Detail::MaxError(_) | Detail::Triangles(_) => {
            let errors = rtin::Errors::compute(hf, tile)?;
            for l in 0..opts.lods {
                let bound = match opts.detail {
                    Detail::Triangles(n) => errors.bound_for((n >> (2 * l)).max(2)),
                    Detail::MaxError(e) => e * (1u32 << l) as f32,
                    Detail::Regular => 0.0,
                };
                check_memory(
                    &format!("an adaptive {w}x{h} mesh"),
                    errors.count(bound) as u64 * 96,
                )?;
                let tris = errors.extract(bound);
                levels.push((bound, Triangulation::from_triangles(&tris, w, tiles, tile)));
            }
        }
    }
    let mut out = Meshes {
        tiles,
        ..Default::default()
    };
    for (l, (bound, pieces)) in levels.into_iter().enumerate() {
        out.bounds.push(bound);
        for (k, t) in pieces.into_iter().enumerate() {
            let mut name = String::from("terrain");
            if tiles != (1, 1) {
                name += &format!("_x{}_y{}", k % tiles.0, k / tiles.0);
            }
            if opts.lods > 1 {
                name += &format!("_LOD{l}");
            }
            out.meshes.push(to_mesh(hf, &t, name, opts));
            out.triangulations.push(t);
        }
    }
    Ok(out)
}

/// Positions, attributes and triangles of one piece, with its skirt.
fn to_mesh(hf: &Heightfield, t: &Triangulation, name: String, opts: &Options) -> Mesh {
    let (w, h) = ((hf.width() - 1) as f32, (hf.height() - 1) as f32);
    let mut m = Mesh {
        name,
        positions: t
            .vertices
            .iter()
            .map(|&[x, y]| position(hf, x, y))
            .collect(),
        triangles: t.triangles.clone(),
        ..Default::default()
    };
    if opts.normals {
        m.normals = t.vertices.iter().map(|&[x, y]| normal(hf, x, y)).collect();
    }
    if opts.uvs {
        // Over the whole grid (one texture for all tiles), v down as glTF's.
        m.uvs = t
            .vertices
            .iter()
            .map(|&[x, y]| [x as f32 / w, y as f32 / h])
            .collect();
    }
    if let Some(depth) = opts.skirt {
        add_skirt(&mut m, depth);
    }
    m
}

/// Hangs a vertical strip `depth` metres deep below every boundary edge
/// (an edge of one triangle only), facing outwards; its bottom vertices
/// copy the top ones' normals and UVs.
fn add_skirt(m: &mut Mesh, depth: f32) {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut bottom: HashMap<u32, u32> = HashMap::new();
    let mut skirt = Vec::new();
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if edges[&(a.min(b), a.max(b))] != 1 {
                continue;
            }
            let mut low = |v: u32| {
                *bottom.entry(v).or_insert_with(|| {
                    let [x, y, z] = m.positions[v as usize];
                    m.positions.push([x, y - depth, z]);
                    if !m.normals.is_empty() {
                        m.normals.push(m.normals[v as usize]);
                    }
                    if !m.uvs.is_empty() {
                        m.uvs.push(m.uvs[v as usize]);
                    }
                    (m.positions.len() - 1) as u32
                })
            };
            let (a2, b2) = (low(a), low(b));
            skirt.push([a, a2, b]);
            skirt.push([b, a2, b2]);
        }
    }
    m.triangles.extend(skirt);
}

/// The smallest and largest of each coordinate (glTF's accessor bounds).
pub fn bounds(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Writes `meshes` in the format the extension of `path` names: `.glb`,
/// `.gltf` (+ `.bin`) or `.obj`.
pub fn write(path: &Path, meshes: &[Mesh]) -> Result<(), MeshError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    match ext.to_ascii_lowercase().as_str() {
        "glb" => gltf::write(path, meshes, true),
        "gltf" => gltf::write(path, meshes, false),
        "obj" => obj::write(path, meshes),
        _ => Err(MeshError::Format {
            path: path.to_path_buf(),
        }),
    }
}
