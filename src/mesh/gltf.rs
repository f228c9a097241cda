//! glTF 2.0 out: binary `.glb` (JSON and buffer in one file) or `.gltf`
//! with its buffer beside it in `NAME.bin` (text JSON a person can read;
//! base64-embedded buffers would be a third larger). One node and one
//! mesh per [`Mesh`] (levels of detail and tiles are separate nodes, named
//! like the meshes); every attribute and the indices in their own tightly
//! packed buffer view, so every accessor is 4-byte aligned. POSITION
//! accessors carry their exact min/max, as the specification requires.
//! Checked by the Khronos glTF-Validator in `tests/terrain/mesh_clients.rs`.

use super::{Mesh, MeshError, bounds};
use crate::io::write_atomic;
use serde_json::{Value, json};
use std::path::Path;

/// GLB stores its lengths in 32 bits.
pub const GLB_LIMIT: u64 = u32::MAX as u64;

const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The JSON document and its binary buffer; `uri` names the buffer's file
/// (`.gltf`), none for a GLB's own chunk.
pub fn encode(meshes: &[Mesh], uri: Option<&str>) -> (Value, Vec<u8>) {
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut gmeshes, mut nodes) = (vec![], vec![], vec![], vec![]);
    // One tightly packed view of `bytes`, and an accessor over it.
    let mut add = |bytes: &[u8], target: u32, accessor: Value| -> usize {
        views.push(json!({
            "buffer": 0,
            "byteOffset": bin.len(),
            "byteLength": bytes.len(),
            "target": target,
        }));
        bin.extend_from_slice(bytes);
        let mut a = accessor;
        a["bufferView"] = json!(views.len() - 1);
        accessors.push(a);
        accessors.len() - 1
    };
    for (i, m) in meshes.iter().enumerate() {
        let n = m.positions.len();
        let (lo, hi) = bounds(&m.positions);
        // As f64, the JSON numbers are the f32 values exactly.
        let f64s = |v: [f32; 3]| v.map(|x| x as f64);
        let mut attributes = serde_json::Map::new();
        let pos = add(
            bytemuck::cast_slice(&m.positions),
            ARRAY_BUFFER,
            json!({"componentType": FLOAT, "count": n, "type": "VEC3", "min": f64s(lo), "max": f64s(hi)}),
        );
        attributes.insert("POSITION".into(), json!(pos));
        let extra: [(&str, &[u8], &str); 2] = [
            ("NORMAL", bytemuck::cast_slice(&m.normals), "VEC3"),
            ("TEXCOORD_0", bytemuck::cast_slice(&m.uvs), "VEC2"),
        ];
        for (name, bytes, kind) in extra.into_iter().filter(|e| !e.1.is_empty()) {
            let a = add(
                bytes,
                ARRAY_BUFFER,
                json!({"componentType": FLOAT, "count": n, "type": kind}),
            );
            attributes.insert(name.into(), json!(a));
        }
        let indices = add(
            bytemuck::cast_slice(&m.triangles),
            ELEMENT_ARRAY_BUFFER,
            json!({"componentType": UNSIGNED_INT, "count": 3 * m.triangles.len(), "type": "SCALAR"}),
        );
        gmeshes.push(json!({
            "name": m.name,
            "primitives": [{"attributes": attributes, "indices": indices, "mode": 4}],
        }));
        nodes.push(json!({"name": m.name, "mesh": i}));
    }
    let mut buffer = json!({"byteLength": bin.len()});
    if let Some(uri) = uri {
        buffer["uri"] = json!(uri);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": concat!("terrasynth ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": (0..meshes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": gmeshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [buffer],
    });
    (doc, bin)
}

/// A GLB file: header, JSON chunk padded with spaces, BIN chunk padded
/// with zeros, each to 4 bytes.
pub fn encode_glb(meshes: &[Mesh]) -> Result<Vec<u8>, MeshError> {
    let (doc, mut bin) = encode(meshes, None);
    let mut json = serde_json::to_vec(&doc).expect("a JSON value serialises");
    json.resize(json.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() as u64 + 8 + bin.len() as u64;
    if total > GLB_LIMIT {
        return Err(MeshError::TooLarge {
            bytes: total,
            format: "GLB",
            limit: GLB_LIMIT,
        });
    }
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(b"glTF");
    for v in [2, total as u32, json.len() as u32, 0x4E4F_534A] {
        out.extend_from_slice(&u32::to_le_bytes(v));
    }
    out.extend_from_slice(&json);
    for v in [bin.len() as u32, 0x004E_4942] {
        out.extend_from_slice(&u32::to_le_bytes(v));
    }
    out.extend_from_slice(&bin);
    Ok(out)
}

/// Percent-encodes a file name for a glTF URI (RFC 3986 unreserved
/// characters kept).
fn uri_escape(name: &str) -> String {
    name.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' => {
                (b as char).to_string()
            }
            _ => format!("%{b:02X}"),
        })
        .collect()
}

/// Writes `path` (`.glb`, or `.gltf` with `NAME.bin` beside it; the
/// buffer first, so a `.gltf` never points at a missing one), each file
/// atomically.
pub fn write(path: &Path, meshes: &[Mesh], binary: bool) -> Result<(), MeshError> {
    if binary {
        return Ok(write_atomic(path, &encode_glb(meshes)?)?);
    }
    let bin_path = path.with_extension("bin");
    let name = bin_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (doc, bin) = encode(meshes, Some(&uri_escape(&name)));
    write_atomic(&bin_path, &bin)?;
    let mut text = serde_json::to_vec_pretty(&doc).expect("a JSON value serialises");
    text.push(b'\n');
    Ok(write_atomic(path, &text)?)
}
