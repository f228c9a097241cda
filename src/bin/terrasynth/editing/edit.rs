//! `terrasynth synth --scene` and `terrasynth edit`: scene files through an
//! editing session (coherent re-synthesis between frames).

use crate::CliResult;
use crate::args::{BackendArg, EngineArg, load_database, select_backend, write_output};
use std::path::{Path, PathBuf};
use terrasynth::database::Database;
use terrasynth::io::{self, WriteOptions};
use terrasynth::scene::{Scene, SceneEdits, overlay};
use terrasynth::synth::session::Session;
use terrasynth::synth::source_map::source_map;

#[derive(clap::Args)]
pub struct Args {
    /// The first scene (database, size, seed and initial controls).
    base: PathBuf,
    /// Later scenes, applied in order as edits of the one before (same
    /// database, size and seed; only what differs is re-synthesized).
    edits: Vec<PathBuf>,
    /// Folder for the frames: frame_NNN.<ext>, frame_NNN.preview.png and
    /// report.json (what changed where, per frame).
    #[arg(long)]
    out_dir: PathBuf,
    /// Heightfield format of the frames, by extension.
    #[arg(long, default_value = "exr")]
    ext: String,
    /// Previews without the controls drawn on them.
    #[arg(long)]
    no_overlay: bool,
    /// Re-synthesize every frame from scratch (no coherence), for comparison.
    #[arg(long)]
    no_coherence: bool,
    /// Where the stages run: cpu, gpu (`--features gpu` builds) or auto.
    /// Same frames, byte for byte, on each.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
}

/// `synth --scene`: one scene, one output.
pub fn synth_scene(
    scene: &Path,
    output: &Path,
    preview: Option<&Path>,
    overlay: bool,
    backend: BackendArg,
    engine: Option<EngineArg>,
    coords: (Option<&Path>, Option<&Path>),
) -> CliResult {
    let scene_path = scene;
    let scene = Scene::read(scene_path)?;
    let mut inputs = vec![scene_path];
    inputs.extend(scene.database.as_deref());
    // The output's sidecar (X.json) must never replace the scene (X.json).
    crate::synthesis::synth::check_outputs(&[Some(output), preview, coords.0, coords.1], &inputs)?;
    // An editing session keeps every pass of every level (about three
    // times the state of one synthesis).
    crate::synthesis::synth::check_synthesis_memory(scene.width, scene.height, 3.0)?;
    let db = load_database(scene.database.as_deref())?;
    let mut edits = SceneEdits::new();
    let first = edits.edits(&scene, &db)?;
    let mut session = scene_session(&db, &scene, backend)?;
    let frame = session.apply(first)?;
    // The heightfield's encoder runs on one core: the preview is drawn
    // meanwhile (and written only once the heightfield is).
    let (written, drawn) = rayon::join(
        || write_output(&frame.heightfield, output, None, engine, &inputs),
        || {
            preview.map(|_| {
                overlay::preview(&frame.heightfield, &scene, &edits, db.type_names(), overlay)
            })
        },
    );
    written?;
    let (lo, hi) = frame
        .heightfield
        .extent()
        .range
        .expect("synthesis has no nodata");
    eprintln!(
        "wrote {} ({} x {}, seed {}, {} points, {} curves, {} junctions): heights {:.1} .. {:.1} m in {:.0} ms",
        output.display(),
        scene.width,
        scene.height,
        scene.seed,
        scene.points.len(),
        scene.curves.len(),
        edits.junctions().len(),
        lo,
        hi,
        frame.time.as_secs_f64() * 1e3
    );
    if let (Some(p), Some(drawn)) = (preview, drawn) {
        terrasynth::render::write_png(p, &drawn?)?;
        eprintln!("wrote {}", p.display());
    }
    if coords.0.is_some() || coords.1.is_some() {
        // The last pass of level 0 is what reconstruction read.
        let l0 = session
            .frames()
            .and_then(|f| f.levels().first())
            .and_then(|l| l.last())
            .ok_or("no level-0 coordinates: the scene runs 0 correction passes")?;
        let stride = terrasynth::level::state::level_size(scene.width, scene.height, 0).0;
        let map = source_map(&l0.coords, stride, scene.width, scene.height, &db);
        crate::synthesis::synth::write_coords(&map, &db, coords)?;
    }
    Ok(())
}

/// An editing session at `scene`'s size, seed and parameters on `backend`,
/// before any of its edits.
fn scene_session<'db>(
    db: &'db Database,
    scene: &Scene,
    backend: BackendArg,
) -> Result<Session<'db>, Box<dyn std::error::Error + Send + Sync>> {
    let mut session = SceneEdits::session(db, scene)?;
    select_backend(session.synthesizer_mut(), backend)?;
    Ok(session)
}

pub fn run(a: Args) -> CliResult {
    let base = Scene::read(&a.base)?;
    let db = load_database(base.database.as_deref())?;
    let ext = a.ext.trim_start_matches('.');
    if io::Format::from_path(Path::new(&format!("x.{ext}"))).is_none_or(|f| !f.can_write()) {
        return Err(format!(
            "--ext {ext:?} is not a writable heightfield format: expected one of {}",
            io::Format::list()
        )
        .into());
    }
    std::fs::create_dir_all(&a.out_dir)
        .map_err(|e| format!("cannot create {}: {e}", a.out_dir.display()))?;
    let mut edits = SceneEdits::new();
    let mut session = scene_session(&db, &base, a.backend)?;
    session.coherence = !a.no_coherence;
    let mut report = Vec::new();
    let files: Vec<PathBuf> = std::iter::once(a.base.clone())
        .chain(a.edits.iter().cloned())
        .collect();
    let mut prev: Option<terrasynth::Heightfield> = None;
    let mut prev_scene: Option<Scene> = None;
    for (k, file) in files.iter().enumerate() {
        let mut scene = if k == 0 {
            base.clone()
        } else {
            Scene::read(file)?
        };
        // Sculpt strokes written without targets are baked on the frame
        // before, as the editor bakes them on the terrain shown.
        if let (Some(p), Some(hf)) = (&prev_scene, session.heightfield()) {
            scene.bake_sculpt_over(p, hf);
        }
        let list = edits.edits(&scene, &db)?;
        let n_edits = list.len();
        let frame = session.apply(list)?;
        let hf = &frame.heightfield;
        let out = a.out_dir.join(format!("frame_{k:03}.{ext}"));
        // The frame is encoded while its preview is drawn.
        let (written, drawn) = rayon::join(
            || io::write(hf, &out, &WriteOptions::default()),
            || overlay::preview(hf, &scene, &edits, db.type_names(), !a.no_overlay),
        );
        written?;
        let img = drawn?;
        let pv = a.out_dir.join(format!("frame_{k:03}.preview.png"));
        terrasynth::render::write_png(&pv, &img)?;
        // Where the terrain changed, and by how much.
        let (mut max_abs, mut over_1m) = (0f64, 0usize);
        if let Some(p) = &prev {
            for (a, b) in p.data().iter().zip(hf.data()) {
                let d = (*a as f64 - *b as f64).abs();
                max_abs = max_abs.max(d);
                over_1m += (d > 1.0) as usize;
            }
        }
        let total = hf.width() * hf.height();
        let entry = match &frame.change {
            None => serde_json::json!({
                "frame": k, "scene": file.display().to_string(), "heightfield": out.display().to_string(),
                "preview": pv.display().to_string(), "edits": n_edits, "time_ms": frame.time.as_secs_f64() * 1e3,
            }),
            Some(c) => serde_json::json!({
                "frame": k, "scene": file.display().to_string(), "heightfield": out.display().to_string(),
                "preview": pv.display().to_string(), "edits": n_edits, "time_ms": frame.time.as_secs_f64() * 1e3,
                "changed_pixels": c.pixels, "changed_fraction": c.pixels as f64 / total as f64,
                "changed_bounds": c.bounds, "changed_more_than_1m": over_1m, "max_abs_change_m": max_abs,
            }),
        };
        match &frame.change {
            None => eprintln!(
                "frame {k}: {} ({n_edits} edits) in {:.0} ms",
                file.display(),
                frame.time.as_secs_f64() * 1e3
            ),
            Some(c) => eprintln!(
                "frame {k}: {} ({n_edits} edits) in {:.0} ms: {} pixels changed ({:.2} %) within {:?}, {} by > 1 m, at most {:.1} m",
                file.display(),
                frame.time.as_secs_f64() * 1e3,
                c.pixels,
                100.0 * c.pixels as f64 / total as f64,
                c.bounds,
                over_1m,
                max_abs
            ),
        }
        report.push(entry);
        prev = Some(frame.heightfield);
        prev_scene = Some(scene);
    }
    let path = a.out_dir.join("report.json");
    let text = serde_json::to_string_pretty(&serde_json::json!({ "frames": report }))?;
    io::write_atomic(&path, text.as_bytes())?;
    eprintln!("wrote {} frames and {}", files.len(), path.display());
    Ok(())
}
