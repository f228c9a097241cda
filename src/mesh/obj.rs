//! Wavefront OBJ out: one `o` object per [`Mesh`], vertices numbered
//! across the file (OBJ indices are global and 1-based), with `vt` and
//! `vn` sharing the vertex's number. Numbers are written in Rust's
//! shortest round-trip form, so a reader gets the same f32 bits. OBJ's
//! texture origin is the bottom-left corner: `vt` is (u, 1 − v).
//! Checked by trimesh in `tests/terrain/mesh_clients.rs`.

use super::{Mesh, MeshError};
use crate::io::write_atomic;
use std::fmt::Write as _;
use std::path::Path;

/// The OBJ text of `meshes`.
pub fn encode(meshes: &[Mesh]) -> String {
    let mut s = String::from("# terrasynth mesh: Y up, X east, Z south, metres\n");
    let mut base = 1u64;
    // `write!` into a String cannot fail.
    for m in meshes {
        let _ = writeln!(s, "o {}", m.name);
        for [x, y, z] in &m.positions {
            let _ = writeln!(s, "v {x} {y} {z}");
        }
        for [u, v] in &m.uvs {
            let _ = writeln!(s, "vt {u} {}", 1.0 - v);
        }
        for [x, y, z] in &m.normals {
            let _ = writeln!(s, "vn {x} {y} {z}");
        }
        let (uv, n) = (!m.uvs.is_empty(), !m.normals.is_empty());
        for t in &m.triangles {
            s.push('f');
            for &i in t {
                let i = base + i as u64;
                let _ = match (uv, n) {
                    (false, false) => write!(s, " {i}"),
                    (true, false) => write!(s, " {i}/{i}"),
                    (false, true) => write!(s, " {i}//{i}"),
                    (true, true) => write!(s, " {i}/{i}/{i}"),
                };
            }
            s.push('\n');
        }
        base += m.positions.len() as u64;
    }
    s
}

/// Writes `path` atomically.
pub fn write(path: &Path, meshes: &[Mesh]) -> Result<(), MeshError> {
    Ok(write_atomic(path, encode(meshes).as_bytes())?)
}
