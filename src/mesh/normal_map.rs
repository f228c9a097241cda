//! Tangent-space normal maps for a mesh of the heightfield (its UVs: u
//! east, v south, 0..1 over the samples, see [`super`]): the normal of the
//! heightfield itself ([`super::normal`]), so a coarse LOD lit with it
//! shades like the full-resolution terrain.
//!
//! Encoding: each component c in −1..1 as round((c + 1) / 2 × 255); R is
//! the tangent (east, +u), B the up component; G depends on the engine:
//! - **OpenGL** (Y+: Blender, Unity, Godot, glTF): G = the north component
//!   (up in the image);
//! - **DirectX** (Y−: Unreal, 3ds Max): G = the south component.
//!
//! The two differ only in G (g ↦ 255 − g, up to rounding of the 127.5
//! midpoint), and a flat surface is (128, 128, 255) in both.

use super::{MeshError, check_heights, normal};
use crate::heightfield::Heightfield;
use crate::io::check_memory;
use crate::resample::bilinear;
use rayon::prelude::*;

/// The sign of G: which way the map's Y points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Convention {
    /// Y+ (G = north, up in the image).
    OpenGl,
    /// Y− (G = south, down in the image).
    DirectX,
}

fn encode(c: f32) -> u8 {
    ((c.clamp(-1.0, 1.0) + 1.0) * 127.5).round() as u8
}

/// The `size × size` RGB map of `hf` (no nodata, at least 2×2), texel
/// (i, j) at u = (i + ½) / size, v = (j + ½) / size: the normals of the
/// samples interpolated bilinearly there and renormalised.
pub fn normal_map(
    hf: &Heightfield,
    size: usize,
    convention: Convention,
) -> Result<Vec<[u8; 3]>, MeshError> {
    check_heights(hf)?;
    crate::size::check_dims(size, size)?;
    let (w, h) = (hf.width(), hf.height());
    check_memory(
        &format!("a {size}x{size} normal map"),
        (w * h * 24 + size * size * 6) as u64,
    )?;
    // (east, up, south) per sample.
    let n: Vec<[f32; 3]> = (0..w * h)
        .into_par_iter()
        .map(|i| normal(hf, (i % w) as u32, (i / w) as u32))
        .collect();
    let comp: [Vec<f32>; 3] = std::array::from_fn(|k| n.iter().map(|v| v[k]).collect());
    let mut out = vec![[0u8; 3]; size * size];
    out.par_chunks_mut(size).enumerate().for_each(|(j, row)| {
        for (i, o) in row.iter_mut().enumerate() {
            // Sample coordinates, +½ for `bilinear`'s pixel centres.
            let p = [
                (i as f32 + 0.5) / size as f32 * (w - 1) as f32 + 0.5,
                (j as f32 + 0.5) / size as f32 * (h - 1) as f32 + 0.5,
            ];
            let v = glam::Vec3::from(comp.each_ref().map(|c| bilinear(c, w, h, p))).normalize();
            let g = match convention {
                Convention::OpenGl => -v.z,
                Convention::DirectX => v.z,
            };
            *o = [encode(v.x), encode(g), encode(v.y)];
        }
    });
    Ok(out)
}
