//! `terrasynth convert`: heightfield format conversion.

use crate::{
    CliResult,
    args::{Input, parse_format},
};
use std::path::PathBuf;
use terrasynth::io::{self, Format, WriteOptions};

#[derive(clap::Args)]
pub struct Args {
    /// Input heightfield.
    input: PathBuf,
    /// Output heightfield; the format follows the extension.
    output: PathBuf,
    /// Output format, when the extension does not say it.
    #[arg(long = "out-format", value_parser = parse_format)]
    out_format: Option<Format>,
    #[command(flatten)]
    read: Input,
}

pub fn run(a: Args) -> CliResult {
    let hf = a.read.read(&a.input)?;
    io::write(
        &hf,
        &a.output,
        &WriteOptions {
            format: a.out_format,
            ..Default::default()
        },
    )?;
    eprintln!(
        "wrote {} ({} x {})",
        a.output.display(),
        hf.width(),
        hf.height()
    );
    Ok(())
}
