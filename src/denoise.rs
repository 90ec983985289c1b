//! `lucent denoise`: a finished frame denoised from its own layers
//! (docs/output.md, "Denoising").

use std::io::Write as _;
use std::path::PathBuf;

use lucent::denoise::DenoiseOptions;
use lucent::film::exr_layers::Preview;
use lucent::session;
use lucent::Error;

use crate::{exposure_stops, ToneMapArg};

/// The arguments of `lucent denoise`.
#[derive(clap::Args)]
pub(crate) struct DenoiseArgs {
    /// The frame.
    frame: PathBuf,
    /// Output OpenEXR path (default: the frame itself, replaced
    /// atomically); the preview goes to the same path with `.png`.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The denoiser's threads, 1 to 1024 (default: all cores).
    #[arg(long, value_parser = lucent_tools::bench::parse_threads)]
    threads: Option<usize>,
    /// Tone map of the PNG preview (the EXR is always linear).
    #[arg(long, value_enum, default_value = "filmic")]
    tonemap: ToneMapArg,
    /// Exposure of the PNG preview in stops.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = exposure_stops)]
    exposure: f32,
    /// Also denoise each light path and light group layer, as
    /// `denoised_<layer>`, with the beauty's guides.
    #[arg(long)]
    layers: bool,
    /// OIDN's scratch memory cap in MB (it then denoises in overlapping
    /// tiles; default: OIDN's own).
    #[arg(long, value_name = "MB")]
    max_memory: Option<u32>,
    /// No summary line.
    #[arg(short, long)]
    quiet: bool,
}

/// Denoises the frame as `a` says and says how it went (unless quiet).
pub(crate) fn run(a: DenoiseArgs) -> Result<(), Error> {
    let preview = Preview {
        tonemap: a.tonemap.into(),
        exposure: a.exposure,
    };
    let output = a.output.unwrap_or_else(|| a.frame.clone());
    let opts = DenoiseOptions {
        layers: a.layers,
        max_memory_mb: a.max_memory,
        ..DenoiseOptions::with_threads(a.threads)
    };
    let d = session::denoise_file(&a.frame, &output, preview, &opts)?;
    if !a.quiet {
        // a closed stderr drops the line; the exit status still tells
        let _ = writeln!(std::io::stderr(), "{}", d.summary(&output));
    }
    Ok(())
}
