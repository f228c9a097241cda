//! Scenes → session edits: the first scene of a session becomes the edits
//! that set everything up; each later scene becomes only the edits that
//! differ from the one before (so coherence keeps the rest of the terrain).
//!
//! Identity across scenes is the item's `id` (or its default
//! `points[i]` / `curves[i]` / `pastes[i]`). A point is re-set when any of
//! its values changed; a curve when its spec changed or a junction on it
//! moved or changed height (curves are rebuilt together because junctions
//! couple them, but distance fields come from a shared cache, so a curve
//! whose shape is unchanged is not re-rasterized). Pastes are permanent in
//! a session (paper §5.3: the pasted region stays frozen): a later scene
//! may add pastes but not change or remove earlier ones.

use super::*;
use crate::database::Database;
use crate::synth::Params;
use crate::synth::control::curve::{self, Curve, FieldCache, Junction};
use crate::synth::control::{self, Constraint, ConstraintId, PointConstraint};
use crate::synth::session::{Edit, Session, SessionError};
use std::collections::BTreeMap;
use std::sync::Arc;

/// A curve's identity for change detection: its spec and the junctions on it.
#[derive(Debug, Clone, PartialEq)]
struct CurveKey {
    spec: CurveSpec,
    junctions: Vec<(DVec2, f64)>,
}

/// What the previous scene set up.
#[derive(Debug, Clone, Default)]
struct Applied {
    points: BTreeMap<String, PointSpec>,
    curves: BTreeMap<String, CurveKey>,
    types: Option<Vec<u8>>,
    freeze: Option<Vec<bool>>,
    pastes: Vec<PasteSpec>,
    /// The stroke forms the rasters came from: an editor sends a scene per
    /// mouse move, and repainting every stroke of a large terrain each time
    /// would cost more than the edit. (Image forms are always read again:
    /// the file may have changed.)
    type_strokes: Option<TypePaint>,
    freeze_strokes: Option<Freeze>,
    sculpt: Vec<SculptSpec>,
}

/// A stroke form (not an image), which fully determines its raster.
fn strokes<T: Clone>(v: &Option<T>, is_strokes: impl Fn(&T) -> bool) -> Option<T> {
    v.as_ref().filter(|t| is_strokes(t)).cloned()
}

/// Turns a sequence of scenes into session edits.
///
/// Cloned (the distance fields' cache shared) beside a session's
/// [`Snapshot`](crate::synth::session::Snapshot): the two together are
/// what an editor keeps to step back.
#[derive(Debug, Default, Clone)]
pub struct SceneEdits {
    cache: Arc<FieldCache>,
    ids: BTreeMap<String, u64>,
    first: Option<Scene>,
    applied: Applied,
    curves: Vec<(String, Arc<Curve>)>,
    junctions: Vec<Junction>,
    /// The last curves built and what they were built from.
    built: Option<BuiltCurves>,
}

/// Curve specs and junction heights, and the curves and junctions built
/// from them.
type BuiltCurves = (
    (Vec<CurveSpec>, Vec<JunctionHeight>),
    Vec<Arc<Curve>>,
    Vec<Junction>,
);

impl SceneEdits {
    pub fn new() -> SceneEdits {
        SceneEdits::default()
    }

    /// The synthesis parameters a scene asks for.
    pub fn params(scene: &Scene) -> Params {
        Params {
            jitter: scene.jitter,
            passes: scene.passes,
            start_exemplar: scene.start_exemplar,
            ..Params::default()
        }
    }

    /// An editing session at the scene's size and seed with the parameters
    /// it asks for, before any of its edits.
    pub fn session<'db>(db: &'db Database, scene: &Scene) -> Result<Session<'db>, SessionError> {
        Session::new(
            db,
            SceneEdits::params(scene),
            scene.width,
            scene.height,
            scene.seed,
        )
    }

    /// The curves of the last scene (with their ids), for overlays.
    pub fn curves(&self) -> &[(String, Arc<Curve>)] {
        &self.curves
    }

    /// The painted type raster of the last scene (database indices, 255 =
    /// unconstrained), if it paints any.
    pub fn type_raster(&self) -> Option<&[u8]> {
        self.applied.types.as_deref()
    }

    /// The junctions of the last scene.
    pub fn junctions(&self) -> &[Junction] {
        &self.junctions
    }

    /// Distance fields computed so far (the rest came from the cache).
    pub fn fields_computed(&self) -> usize {
        self.cache.computed()
    }

    fn id(&mut self, name: &str) -> ConstraintId {
        let next = self.ids.len() as u64;
        ConstraintId(*self.ids.entry(name.to_string()).or_insert(next))
    }

    /// The edits that take the session from the previous scene (or from
    /// nothing) to `scene`. Nothing is remembered when this fails.
    pub fn edits(&mut self, scene: &Scene, db: &Database) -> Result<Vec<Edit>, SceneError> {
        let err = |path: &str, kind| SceneError::new(&scene.file, path, kind);
        let invalid = |path: &str, found: String, expected: String| {
            err(path, SceneErrorKind::Invalid { found, expected })
        };
        if let Some(first) = &self.first {
            let same = [
                ("database", first.database == scene.database),
                (
                    "size",
                    (first.width, first.height) == (scene.width, scene.height),
                ),
                ("seed", first.seed == scene.seed),
                ("jitter", first.jitter == scene.jitter),
                ("passes", first.passes == scene.passes),
                (
                    "start_exemplar",
                    first.start_exemplar == scene.start_exemplar,
                ),
            ];
            if let Some((field, _)) = same.iter().find(|(_, ok)| !ok) {
                return Err(invalid(
                    field,
                    "a different value".into(),
                    format!(
                        "the same {field} as the session's first scene, {}",
                        first.file.display()
                    ),
                ));
            }
        }
        let count = db.meta().exemplars.len();
        if let Some(e) = scene.start_exemplar.filter(|&e| e >= count) {
            return Err(invalid(
                "start_exemplar",
                e.to_string(),
                format!("an exemplar index in 0..={}", count - 1),
            ));
        }
        let cell = db.meta().exemplars[scene.start_exemplar.unwrap_or(0)].cell_size_m;
        let mut edits = Vec::new();
        let mut next = Applied::default();

        // Points.
        for (i, p) in scene.points.iter().enumerate() {
            next.points.insert(p.id.clone(), p.clone());
            if self.applied.points.get(&p.id) == Some(p) {
                continue;
            }
            let c = PointConstraint::new(
                (p.at.x, p.at.y),
                p.height_m,
                p.slope_direction_deg.to_radians(),
                p.slope_deg.to_radians(),
                p.radius_px,
                cell,
            )
            .map_err(|e| err(&format!("points[{i}]"), e.into()))?;
            let id = self.id(&p.id);
            edits.push(Edit::SetConstraint(id, Arc::new(c)));
        }

        // Curves, built together for their junctions (again only when a
        // curve or junction changed: building smooths every envelope).
        let input = (scene.curve_specs(), scene.junctions.clone());
        let (built, junctions) = if self.built.as_ref().is_some_and(|b| b.0 == input) {
            let b = self.built.as_ref().expect("checked");
            (b.1.clone(), b.2.clone())
        } else {
            let (c, j) = curve::build(&input.0, &input.1, cell, &self.cache).map_err(|e| {
                let path = match &e {
                    curve::CurveError::TooFewPoints { curve, .. }
                    | curve::CurveError::ZeroLength { curve }
                    | curve::CurveError::NoWidget { curve }
                    | curve::CurveError::Value { curve, .. }
                    | curve::CurveError::TooLarge { curve, .. }
                    | curve::CurveError::TooLong { curve, .. } => format!("curves[{curve}]"),
                    _ => "junctions".to_string(),
                };
                err(&path, e.into())
            })?;
            (c.into_iter().map(Arc::new).collect::<Vec<_>>(), j)
        };
        let mut curves = Vec::with_capacity(built.len());
        for (k, (item, c)) in scene.curves.iter().zip(built.iter().cloned()).enumerate() {
            let key = CurveKey {
                spec: item.spec.clone(),
                junctions: junctions
                    .iter()
                    .filter(|j| j.members.iter().any(|m| m.0 == k))
                    .map(|j| (j.at, j.height_m))
                    .collect(),
            };
            if self.applied.curves.get(&item.id) != Some(&key) {
                let id = self.id(&item.id);
                edits.push(Edit::SetConstraint(id, c.clone() as Arc<dyn Constraint>));
            }
            next.curves.insert(item.id.clone(), key);
            curves.push((item.id.clone(), c));
        }

        // Removed constraints.
        let gone: Vec<&String> = self
            .applied
            .points
            .keys()
            .chain(self.applied.curves.keys())
            .filter(|id| !next.points.contains_key(*id) && !next.curves.contains_key(*id))
            .collect();
        let mut removals = Vec::new();
        for id in gone {
            removals.push(ConstraintId(self.ids[id]));
        }
        edits.extend(removals.into_iter().map(Edit::RemoveConstraint));

        // Type paint and freezing.
        next.type_strokes = strokes(&scene.types, |t| matches!(t, TypePaint::Strokes(_)));
        next.types = match &next.type_strokes {
            Some(t) if self.applied.type_strokes.as_ref() == Some(t) => self.applied.types.clone(),
            _ => scene.type_raster(db.type_names())?,
        };
        if next.types != self.applied.types {
            edits.push(Edit::PaintTypes(next.types.clone()));
        }
        next.freeze_strokes = strokes(&scene.freeze, |f| matches!(f, Freeze::Strokes(_)));
        next.freeze = match &next.freeze_strokes {
            Some(f) if self.applied.freeze_strokes.as_ref() == Some(f) => {
                self.applied.freeze.clone()
            }
            _ => scene.freeze_raster()?,
        };
        if next.freeze != self.applied.freeze {
            edits.push(Edit::Freeze(next.freeze.clone()));
        }

        // Sculpt strokes: one layer, swapped where its strokes changed.
        if scene.sculpt != self.applied.sculpt {
            edits.push(Edit::Sculpt(scene.sculpt_layer()?));
        }
        next.sculpt = scene.sculpt.clone();

        // Pastes: earlier ones must stay as they were.
        for (i, old) in self.applied.pastes.iter().enumerate() {
            if scene.pastes.get(i) != Some(old) {
                return Err(invalid(
                    &format!("pastes[{i}]"),
                    "a changed or removed paste".into(),
                    format!(
                        "paste {:?} as the previous scene had it: pastes are permanent; add new ones after it",
                        old.id
                    ),
                ));
            }
        }
        for (i, p) in scene
            .pastes
            .iter()
            .enumerate()
            .skip(self.applied.pastes.len())
        {
            edits.push(Edit::Paste(self.paste(p, i, scene, db)?));
        }
        next.pastes = scene.pastes.clone();

        self.first.get_or_insert_with(|| scene.clone());
        self.applied = next;
        self.curves = curves;
        self.junctions = junctions.clone();
        self.built = Some((input, built, junctions));
        Ok(edits)
    }

    /// A scene paste as a session paste: the lasso's centroid moves to `to`.
    fn paste(
        &self,
        p: &PasteSpec,
        i: usize,
        scene: &Scene,
        db: &Database,
    ) -> Result<control::Paste, SceneError> {
        let path = format!("pastes[{i}]");
        let source = match p.source {
            PasteSource::Terrain => control::PasteSource::Terrain,
            PasteSource::Exemplar(e) => {
                let count = db.meta().exemplars.len();
                if e >= count {
                    return Err(SceneError::new(
                        &scene.file,
                        format!("{path}.exemplar"),
                        SceneErrorKind::Invalid {
                            found: e.to_string(),
                            expected: format!("an exemplar index in 0..={}", count - 1),
                        },
                    ));
                }
                let r = db.level(0).layout.rects[e];
                if let Some((k, q)) = p
                    .lasso
                    .iter()
                    .enumerate()
                    .find(|(_, q)| q.x > r.width as f64 || q.y > r.height as f64)
                {
                    return Err(SceneError::new(
                        &scene.file,
                        format!("{path}.lasso[{k}]"),
                        SceneErrorKind::Invalid {
                            found: format!("[{}, {}]", q.x, q.y),
                            expected: format!(
                                "a point inside exemplar {e}: x in 0..={}, y in 0..={}",
                                r.width, r.height
                            ),
                        },
                    ));
                }
                control::PasteSource::Exemplar(e)
            }
        };
        let centroid = polygon_centroid(&p.lasso);
        let offset = p.to - centroid;
        Ok(control::Paste {
            source,
            lasso: p.lasso.iter().map(|q| (q.x, q.y)).collect(),
            offset: (offset.x.round() as i64, offset.y.round() as i64),
            delta_m: p.delta_m,
            lift: p.lift,
        })
    }
}

/// Area centroid of a polygon (vertex mean when it has no area).
pub fn polygon_centroid(pts: &[DVec2]) -> DVec2 {
    let n = pts.len();
    let (mut a, mut c) = (0.0, DVec2::ZERO);
    for k in 0..n {
        let (p, q) = (pts[k], pts[(k + 1) % n]);
        let cross = p.perp_dot(q);
        a += cross;
        c += (p + q) * cross;
    }
    if a.abs() < 1e-9 {
        return pts.iter().copied().sum::<DVec2>() / n as f64;
    }
    c / (3.0 * a)
}
