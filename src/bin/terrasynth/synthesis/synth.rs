//! `terrasynth synth`: synthesize a terrain from an exemplar database.

use crate::CliResult;
use crate::args::{
    BackendArg, EngineArg, SynthesisArgs, load_database, parse_window, parse_world_size,
    select_backend, write_output,
};
use std::path::{Path, PathBuf};
use terrasynth::Heightfield;
use terrasynth::database::Database;
use terrasynth::io::{self, CoordsMap};
use terrasynth::render::{self, RenderOptions};
use terrasynth::scene::{CurveItem, Scene, SceneEdits};
use terrasynth::synth::cone::Rect;
use terrasynth::synth::session::Session;
use terrasynth::synth::source_map::source_map;
use terrasynth::synth::{Params, Synthesizer};
use terrasynth::water::valleys;

#[derive(clap::Args)]
pub struct Args {
    /// Exemplar database (.tsdb, from `db build`); default: the embedded one.
    #[arg(long)]
    db: Option<PathBuf>,
    /// Output size WxH (any size, e.g. 1024x1024 or 777x333); with
    /// --window, the size of the world the window is cut from (each side up
    /// to 1048576, e.g. 65536x65536).
    #[arg(long, value_parser = parse_world_size, default_value = "1024x1024")]
    size: (usize, usize),
    /// Synthesize only this window X,Y,W,H of the world (output pixels):
    /// the same heights as the same crop of the whole world, computed in
    /// memory and time proportional to the window. The output is placed in
    /// the world's grid (GeoTIFF, sidecars), so windows tile seamlessly.
    #[arg(long, value_parser = parse_window, conflicts_with_all = ["coords", "coords_preview"])]
    window: Option<terrasynth::synth::cone::Rect>,
    /// Random seed: the same seed and inputs give the same bytes.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Output heightfield (format from the extension: .exr, .png, .tif, .r16, .ter, .asc…).
    #[arg(short, long)]
    output: PathBuf,
    /// Also write a shaded-relief preview PNG.
    #[arg(long)]
    preview: Option<PathBuf>,
    /// Also write where every output pixel was drawn from, exactly: a 16-bit
    /// RGB PNG, R = x and G = y of the source texel within its exemplar,
    /// B = the exemplar's index (`db info` order). `eval --coords` reads it.
    #[arg(long)]
    coords: Option<PathBuf>,
    /// Also write a picture of the coordinates for a person (8-bit: red = x,
    /// green = y within the exemplar, blue = which exemplar; paper Fig. 3).
    #[arg(long)]
    coords_preview: Option<PathBuf>,
    #[command(flatten)]
    synthesis: SynthesisArgs,
    /// Where the stages run: cpu, gpu (WGSL on Vulkan; `--features gpu`
    /// builds) or auto (the GPU if there is one). Same output bytes on each.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
    /// A scene file (see data/scenes/): its database, size, seed and
    /// controls replace --db, --size, --seed, --jitter, --passes and
    /// --start-exemplar; the preview shows the controls (not with
    /// --window, whose preview is plain).
    #[arg(long, conflicts_with = "db")]
    scene: Option<PathBuf>,
    /// With --scene: a preview without the controls drawn on it.
    #[arg(long, requires = "scene")]
    no_overlay: bool,
    /// Lay the output out for a game engine and print its import settings
    /// (see `convert --for`).
    #[arg(long = "for", value_enum)]
    engine: Option<EngineArg>,
    /// Erode the result with this strength (0-10, as `terrasynth erode
    /// --strength`); a --window erodes to the same bytes as the same crop
    /// of the whole world eroded.
    #[arg(long, value_name = "S", value_parser = crate::terrain::erode::parse_strength, conflicts_with = "scene")]
    erode: Option<f32>,
    /// Give the terrain a valley network: synthesize, find where its water
    /// would run with every closed basin breached, and synthesize again
    /// with those valleys as curve constraints (about twice the time; see
    /// README, "Valleys"). Whole maps only: where water runs depends on
    /// the whole terrain.
    #[arg(long, conflicts_with_all = ["scene", "window", "coords", "coords_preview"])]
    valleys: bool,
}

/// Refuses outputs that would replace an input, before any work is done.
pub fn check_outputs(outputs: &[Option<&Path>], inputs: &[&Path]) -> Result<(), io::IoError> {
    for out in outputs.iter().flatten() {
        let mut files = vec![out.to_path_buf()];
        // Data files may bring a sidecar or a .prj with them.
        match io::Format::from_path(out) {
            Some(f) if f.uses_sidecar() => files.push(io::sidecar_path(out)),
            Some(io::Format::Asc) => files.push(io::prj_path(out)),
            _ => {}
        }
        for f in files {
            if let Some(input) = inputs.iter().find(|i| io::same_file(i, &f)) {
                return Err(io::IoError::WouldOverwrite {
                    path: f,
                    input: input.to_path_buf(),
                });
            }
        }
    }
    Ok(())
}

/// Refuses a synthesis whose state would not fit in memory. `factor`: how
/// many copies of the finest levels' state the caller keeps (an editing
/// session keeps every pass of every level).
pub fn check_synthesis_memory(width: usize, height: usize, factor: f64) -> Result<(), io::IoError> {
    let bytes = (width * height) as f64 * Synthesizer::bytes_per_pixel(width, height) * factor;
    io::check_memory(&format!("a {width}x{height} synthesis"), bytes as u64)
}

pub fn run(a: Args) -> CliResult {
    if let (Some(scene), Some(win)) = (&a.scene, a.window) {
        return scene_window(&a, scene, win);
    }
    if let Some(scene) = &a.scene {
        return crate::editing::edit::synth_scene(
            scene,
            &a.output,
            a.preview.as_deref(),
            !a.no_overlay,
            a.backend,
            a.engine,
            (a.coords.as_deref(), a.coords_preview.as_deref()),
        );
    }
    let inputs: Vec<&Path> = a.db.as_deref().into_iter().collect();
    check_outputs(
        &[
            Some(&a.output),
            a.preview.as_deref(),
            a.coords.as_deref(),
            a.coords_preview.as_deref(),
        ],
        &inputs,
    )?;
    let (w, h) = a.size;
    if a.window.is_none() {
        check_synthesis_memory(w, h, 1.0)?;
    }
    let db = load_database(a.db.as_deref())?;
    let params = a
        .synthesis
        .params(a.coords.is_some() || a.coords_preview.is_some());
    if a.valleys {
        check_synthesis_memory(w, h, 3.0)?;
        return with_valleys(&a, &db, params, &inputs);
    }
    let mut synth = Synthesizer::new(&db, params)?;
    select_backend(&mut synth, a.backend)?;
    // With erosion, a window is synthesized with the halo its erosion reads.
    let extent = a.window.map(|win| match a.erode {
        Some(_) => terrasynth::erode::extent((w, h), win),
        None => win,
    });
    let (mut result, what) = match (a.window, extent) {
        (Some(win), Some(ext)) => {
            let cone = synth.window_cone((w, h), ext).map_err(window_error(win))?;
            let what = format!(
                "a {}x{} window of a {w}x{h} world",
                win.width(),
                win.height()
            );
            io::check_memory(&what, cone.bytes())?;
            let what = format!(
                "{} x {} at ({}, {}) of {w} x {h}",
                win.width(),
                win.height(),
                win.x0,
                win.y0
            );
            (synth.run_window((w, h), ext, a.seed)?, what)
        }
        _ => (synth.run(w, h, a.seed)?, format!("{w} x {h}")),
    };
    let win = a.window.zip(extent);
    let ms = result.timings.total.as_secs_f64() * 1e3;
    finish(
        &a,
        &synth,
        &mut result.heightfield,
        win,
        (&what, ms),
        &inputs,
    )?;
    if let Some(l0) = result.levels.first() {
        let paths = (a.coords.as_deref(), a.coords_preview.as_deref());
        write_coords(&source_map(&l0.coords, l0.width, w, h, &db), &db, paths)?;
    }
    Ok(())
}

/// `synth --valleys`: the terrain, its valley network
/// ([`terrasynth::water::valleys`]), and the terrain again with those
/// valleys as curve constraints — the second frame of an editing session
/// on the first, as if an artist had drawn them, so that away from the
/// valleys the terrain stays the first frame's (coherence).
fn with_valleys(a: &Args, db: &Database, params: Params, inputs: &[&Path]) -> CliResult {
    let (w, h) = a.size;
    let mut session = Session::new(db, params.clone(), w, h, a.seed)?;
    select_backend(session.synthesizer_mut(), a.backend)?;
    let first = session.apply(Vec::new())?;
    let t = std::time::Instant::now();
    let network = valleys::network(&first.heightfield);
    let found = t.elapsed();
    let scene = Scene {
        file: PathBuf::from("synth --valleys"),
        database: a.db.clone(),
        width: w,
        height: h,
        seed: a.seed,
        jitter: params.jitter,
        passes: params.passes,
        start_exemplar: params.start_exemplar,
        points: Vec::new(),
        curves: (network.into_iter().enumerate())
            .map(|(i, spec)| CurveItem {
                id: format!("valley{i}"),
                spec,
            })
            .collect(),
        junctions: Vec::new(),
        types: None,
        freeze: None,
        pastes: Vec::new(),
        sculpt: Vec::new(),
    };
    let count = scene.curves.len();
    let mut second = session.apply(SceneEdits::new().edits(&scene, db)?)?;
    let ms = (first.time + found + second.time).as_secs_f64() * 1e3;
    let what = format!("{w} x {h}, {count} valley curves");
    finish(
        a,
        session.synthesizer(),
        &mut second.heightfield,
        None,
        (&what, ms),
        inputs,
    )
}

/// Erodes (`--erode`; `win` is the window and the extent synthesized for
/// it), writes the heightfield and its preview, and reports `what` took
/// `ms`.
fn finish(
    a: &Args,
    synth: &Synthesizer<'_>,
    hf: &mut Heightfield,
    win: Option<(Rect, Rect)>,
    (what, ms): (&str, f64),
    inputs: &[&Path],
) -> CliResult {
    if let Some(strength) = a.erode {
        let t = std::time::Instant::now();
        *hf = match win {
            Some((win, ext)) => terrasynth::erode::window(hf, ext, win, strength)?,
            None => terrasynth::erode::erode(hf, strength)?,
        };
        eprintln!(
            "eroded (strength {strength}) in {:.0} ms",
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    // The heightfield's encoder runs on one core: the preview is drawn
    // meanwhile.
    let (written, drawn) = rayon::join(
        || write_output(hf, &a.output, None, a.engine, inputs),
        || a.preview.as_ref().map(|_| preview(synth, hf)),
    );
    written?;
    let (lo, hi) = hf.extent().range.expect("synthesis has no nodata");
    eprintln!(
        "wrote {} ({what}, seed {}): heights {:.1} .. {:.1} m in {ms:.0} ms",
        a.output.display(),
        a.seed,
        lo,
        hi,
    );
    if let (Some(p), Some(drawn)) = (&a.preview, drawn) {
        render::write_png(p, &drawn?.image)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// `synth --scene S --window X,Y,W,H`: a window of the scene's terrain
/// (its size is the world's).
fn scene_window(a: &Args, scene_path: &Path, win: terrasynth::synth::cone::Rect) -> CliResult {
    use terrasynth::scene::{Scene, WindowedScene};
    let scene = Scene::read(scene_path)?;
    let mut inputs = vec![scene_path];
    inputs.extend(scene.database.as_deref());
    check_outputs(&[Some(&a.output), a.preview.as_deref()], &inputs)?;
    let db = load_database(scene.database.as_deref())?;
    let ws = WindowedScene::new(&scene, &db)?;
    let mut synth = Synthesizer::new(&db, ws.params())?;
    select_backend(&mut synth, a.backend)?;
    let world = (scene.width, scene.height);
    let cone = synth.window_cone(world, win).map_err(window_error(win))?;
    // A scene's first frame is recorded for its pastes (every pass of
    // every level): about three times one synthesis, as `synth --scene`.
    let what = format!("a {}x{} window of the scene", win.width(), win.height());
    io::check_memory(&what, cone.bytes() * 3)?;
    let t = std::time::Instant::now();
    let hf = ws.synthesize_window(&synth, win)?;
    write_output(&hf, &a.output, None, a.engine, &inputs)?;
    let (lo, hi) = hf.extent().range.expect("synthesis has no nodata");
    eprintln!(
        "wrote {} ({} x {} at ({}, {}) of the {} x {} scene, seed {}): heights {:.1} .. {:.1} m in {:.0} ms",
        a.output.display(),
        win.width(),
        win.height(),
        win.x0,
        win.y0,
        scene.width,
        scene.height,
        scene.seed,
        lo,
        hi,
        t.elapsed().as_secs_f64() * 1e3
    );
    if let Some(p) = &a.preview {
        render::write_png(p, &preview(&synth, &hf)?.image)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// Names `--window` (and `--size`) in a window the world cannot hold.
pub fn window_error(
    win: terrasynth::synth::cone::Rect,
) -> impl Fn(terrasynth::synth::SynthError) -> Box<dyn std::error::Error + Send + Sync> {
    move |e| match e {
        terrasynth::synth::SynthError::Window(e) => format!(
            "--window {},{},{},{}: {e} (--size)",
            win.x0,
            win.y0,
            win.width(),
            win.height()
        )
        .into(),
        e => e.into(),
    }
}

/// Writes where every pixel of a synthesis was drawn from: the exact map
/// and/or its picture.
pub fn write_coords(
    map: &CoordsMap,
    db: &Database,
    (exact, picture): (Option<&Path>, Option<&Path>),
) -> CliResult {
    if let Some(p) = exact {
        map.write(p)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = picture {
        let sizes: Vec<(u32, u32)> = db
            .meta()
            .exemplars
            .iter()
            .map(|e| (e.width, e.height))
            .collect();
        render::write_png(p, &render::coords_preview(map, &sizes))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// The preview, shaded where the synthesis ran (same bytes either way).
fn preview(
    synth: &Synthesizer<'_>,
    hf: &Heightfield,
) -> Result<render::Preview, Box<dyn std::error::Error + Send + Sync>> {
    Ok(render::render_on(
        &synth.engine(),
        hf,
        &RenderOptions::default(),
    )?)
}
