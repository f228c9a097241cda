//! Type usage: which kinds of exemplar terrain a synthesis draws from,
//! against how much of the exemplars each kind covers. An unconstrained
//! synthesis that reproduces its exemplars' character should use each type
//! about as often as it occurs; one that avoids steep sources shows
//! "mountains" far below their share.

use super::EvalError;
use crate::database::Database;
use crate::io::CoordsMap;
use serde::Serialize;

/// One type's (or exemplar's) share of the output against its share of the
/// exemplar texels (fractions in 0..=1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Share {
    pub name: String,
    /// Fraction of the output's pixels drawn from it.
    pub used: f64,
    /// Fraction of the database's level-0 texels that are it.
    pub exemplars: f64,
}

impl Share {
    /// used − exemplars, in percentage points.
    pub fn points(&self) -> f64 {
        (self.used - self.exemplars) * 100.0
    }
}

/// Shares per type and per exemplar.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TypeUsage {
    pub pixels: u64,
    /// In the database's type order.
    pub types: Vec<Share>,
    /// In the database's exemplar order.
    pub exemplars: Vec<Share>,
}

/// Type usage of the output whose sources `map` gives, drawn from `db`.
/// Every source must lie inside an exemplar of `db` (a map made with
/// another database is refused, naming the first bad pixel).
pub fn type_usage(map: &CoordsMap, db: &Database) -> Result<TypeUsage, EvalError> {
    let level = db.level(0);
    let rects = &level.layout.rects;
    let ntypes = db.type_names().len();
    let mut used_types = vec![0u64; ntypes];
    let mut used_exemplars = vec![0u64; rects.len()];
    for (i, s) in map.sources.iter().enumerate() {
        let (x, y) = (i % map.width, i / map.width);
        let Some(r) = rects.get(s.exemplar as usize) else {
            return Err(EvalError::NoSuchExemplar {
                x,
                y,
                exemplar: s.exemplar,
                count: rects.len(),
            });
        };
        if s.x as u32 >= r.width || s.y as u32 >= r.height {
            return Err(EvalError::OutsideExemplar {
                x,
                y,
                sx: s.x,
                sy: s.y,
                exemplar: s.exemplar,
                width: r.width,
                height: r.height,
            });
        }
        let t = level.types[r.index(r.x0 + s.x as u32, s.y as u32)];
        used_types[t as usize] += 1;
        used_exemplars[s.exemplar as usize] += 1;
    }
    let mut texel_types = vec![0u64; ntypes];
    for &t in level.types {
        texel_types[t as usize] += 1;
    }
    let pixels = map.sources.len() as u64;
    let texels = level.types.len() as f64;
    let types = db
        .type_names()
        .iter()
        .enumerate()
        .map(|(t, name)| Share {
            name: name.clone(),
            used: used_types[t] as f64 / pixels as f64,
            exemplars: texel_types[t] as f64 / texels,
        })
        .collect();
    let exemplars = db
        .meta()
        .exemplars
        .iter()
        .zip(rects)
        .enumerate()
        .map(|(e, (m, r))| Share {
            name: m.name.clone(),
            used: used_exemplars[e] as f64 / pixels as f64,
            exemplars: r.texels() as f64 / texels,
        })
        .collect();
    Ok(TypeUsage {
        pixels,
        types,
        exemplars,
    })
}
