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
    let metas = &db.meta().exemplars;
    let ntypes = db.type_names().len();
    let mut used_types = vec![0u64; ntypes];
    let mut used_exemplars = vec![0u64; rects.len()];
    for (i, s) in map.sources.iter().enumerate() {
        let (x, y) = (i % map.width, i / map.width);
        let (Some(r), Some(m)) = (
            rects.get(s.exemplar as usize),
            metas.get(s.exemplar as usize),
        ) else {
            return Err(EvalError::NoSuchExemplar {
                x,
                y,
                exemplar: s.exemplar,
                count: rects.len(),
            });
        };
        if s.x as u32 >= m.width || s.y as u32 >= m.height {
            return Err(EvalError::OutsideExemplar {
                x,
                y,
                sx: s.x,
                sy: s.y,
                exemplar: s.exemplar,
                width: m.width,
                height: m.height,
            });
        }
        let t = level.types[r.index(r.x0 + m.pad + s.x as u32, m.pad + s.y as u32)];
        used_types[t as usize] += 1;
        used_exemplars[s.exemplar as usize] += 1;
    }
    // Shares of the exemplars' own texels: their pads repeat their rims.
    let mut texel_types = vec![0u64; ntypes];
    for (r, m) in rects.iter().zip(metas) {
        for k in r.offset..r.offset + r.texels() {
            let (x, y) = r.coords(k);
            if m.is_real(x - r.x0, y) {
                texel_types[level.types[k as usize] as usize] += 1;
            }
        }
    }
    let real = |m: &crate::database::ExemplarMeta| u64::from(m.width) * u64::from(m.height);
    let pixels = map.sources.len() as u64;
    let texels = metas.iter().map(real).sum::<u64>() as f64;
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
        .enumerate()
        .map(|(e, m)| Share {
            name: m.name.clone(),
            used: used_exemplars[e] as f64 / pixels as f64,
            exemplars: real(m) as f64 / texels,
        })
        .collect();
    Ok(TypeUsage {
        pixels,
        types,
        exemplars,
    })
}
