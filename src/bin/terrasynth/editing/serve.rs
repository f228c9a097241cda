//! `terrasynth serve`: the interactive editor in a browser (see
//! `terrasynth::server`).

use crate::CliResult;
use crate::args::{BackendArg, parse_size};
use std::net::SocketAddr;
use std::path::PathBuf;
use terrasynth::backend::engine::Engine;
use terrasynth::server::{self, Config, DbSource};

#[derive(clap::Args)]
pub struct Args {
    /// Exemplar database (default: the scene's, else the embedded one).
    #[arg(long)]
    db: Option<PathBuf>,
    /// Scene file: loaded at start when it exists, written by Save; unsaved
    /// work is autosaved beside it (SCENE.autosave.json) and offered back at
    /// the next start. Without it, designs are downloaded and unsaved work
    /// is autosaved to the cache dir (TERRASYNTH_CACHE_DIR).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Address to listen on: a loopback address (127.0.0.1 or [::1]) and a
    /// port. Others are refused: the editor has no login, so other machines
    /// must not reach it (forward a port with ssh instead).
    #[arg(long, default_value = "127.0.0.1:8080")]
    bind: SocketAddr,
    /// Size of a new design, WxH (a scene file's own size wins).
    #[arg(long, value_parser = parse_size, default_value = "1024x1024")]
    size: (usize, usize),
    /// Seed of a new design.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Most editor sessions (browser tabs) at once.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u16).range(1..=64))]
    max_sessions: u16,
    /// Largest request body, MiB (scene documents).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=1024))]
    max_request_mib: u16,
    /// Where sessions synthesize and previews are shaded: cpu, gpu
    /// (`--features gpu` builds) or auto. The same terrain and pictures,
    /// byte for byte, on each.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
}

pub fn run(a: Args) -> CliResult {
    // Without a scene file, unsaved work is autosaved to the user cache
    // dir (one file, shared by every scene-less server of this user).
    let unsaved_autosave = match &a.scene {
        None => {
            Some(terrasynth::database::default::cache_dir().join("unsaved-scene.autosave.json"))
        }
        Some(_) => None,
    };
    let (engine, notice) = Engine::choose(a.backend.into())?;
    if let Some(n) = notice {
        eprintln!("note: {n}");
    }
    let config = Config {
        bind: a.bind,
        database: a.db.map(DbSource::File),
        scene: a.scene,
        unsaved_autosave,
        size: a.size,
        seed: a.seed,
        max_sessions: a.max_sessions as usize,
        max_request_bytes: (a.max_request_mib as usize) << 20,
        engine,
        ..Config::default()
    };
    server::run(config, |s| {
        eprintln!(
            "terrasynth editor: open {} in a browser (Ctrl-C stops it)",
            s.url()
        );
    })?;
    Ok(())
}
