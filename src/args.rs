//! The render command's groups of options: how a frame is split into
//! parts, checkpointed and resumed (docs/farm.md), how its EXR is stored
//! (docs/output.md), and, with `merge`, how it is denoised.

use std::path::PathBuf;

use clap::ValueEnum;

use lucent::denoise::DenoiseOptions;
use lucent::film::cryptomatte;
use lucent::film::exr_layers::{ExrCompression, Precision};
use lucent::film::region::Region;
use lucent::scene;
use lucent::session;
use lucent::Error;

use crate::values::{parse_checkpoint, parse_crop, parse_samples, parse_tile};

/// Splitting a frame into parts, checkpoints and resuming (docs/farm.md).
#[derive(clap::Args)]
pub(crate) struct SplitArgs {
    /// Render only the pixels X0 ≤ x < X1, Y0 ≤ y < Y1; the output is a
    /// part for `lucent merge`.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop, conflicts_with = "tile")]
    crop: Option<Region>,
    /// Render only the pixels X0 ≤ x < X1, Y0 ≤ y < Y1 as a viewable EXR
    /// (its data window; beauty and passes as a frame's), to view or to
    /// `lucent paste` into a frame.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop,
          conflicts_with_all = ["crop", "tile", "samples"])]
    region: Option<Region>,
    /// Render band I (0-based) of N balanced horizontal bands; the output
    /// is a part for `lucent merge`.
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    tile: Option<(u32, u32)>,
    /// Render only the sample indices A ≤ s < B of each pixel; the output
    /// is a part for `lucent merge`.
    #[arg(long, value_name = "A..B", value_parser = parse_samples)]
    samples: Option<std::ops::Range<u32>>,
    /// Every SECONDS (at the end of a pass), save the finished samples to
    /// OUT.partial.exr, atomically, for --resume.
    #[arg(long, value_name = "SECONDS", value_parser = parse_checkpoint)]
    checkpoint: Option<f64>,
    /// Continue from a part this same render left (at a signal or a
    /// checkpoint): the result is bitwise the uninterrupted render's.
    #[arg(long, value_name = "PART.exr")]
    resume: Option<PathBuf>,
}

impl From<SplitArgs> for session::Split {
    fn from(a: SplitArgs) -> session::Split {
        session::Split {
            crop: a.crop,
            region: a.region,
            tile: a.tile,
            samples: a.samples,
            checkpoint: a.checkpoint,
            resume: a.resume,
        }
    }
}

/// How the EXR is stored (docs/output.md); each overrides the scene's
/// `[output]` key of the same name.
#[derive(clap::Args)]
pub(crate) struct FileArgs {
    /// Precision of light passes: half | float (data passes, IDs and beauty
    /// are always float).
    #[arg(long, value_enum)]
    aov_precision: Option<PrecisionArg>,
    /// Lossless EXR compression: none | rle | zips | zip (default) | piz.
    #[arg(long, value_enum)]
    exr_compression: Option<CompressionArg>,
    /// One file per pass (OUT.PASS.exr beside OUT.exr) instead of one
    /// multi-layer file.
    #[arg(long, num_args = 0..=1, default_missing_value = "true")]
    aov_split: Option<bool>,
    /// Cryptomatte ranks per pixel, 1 to 64 (default 6).
    #[arg(long)]
    cryptomatte_ranks: Option<usize>,
    /// A transparent film: the environment seen directly is left out of
    /// the beauty, and A is the fraction of camera rays that hit
    /// (premultiplied; docs/output.md, "Transparent film").
    #[arg(long, num_args = 0..=1, default_missing_value = "true")]
    transparent: Option<bool>,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum PrecisionArg {
    Half,
    Float,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum CompressionArg {
    None,
    Rle,
    Zips,
    Zip,
    Piz,
}

impl FileArgs {
    /// The command line's settings, in the scene's form (they override it).
    pub(crate) fn settings(&self) -> Result<scene::OutputSettings, Error> {
        if let Some(n) = self
            .cryptomatte_ranks
            .filter(|n| !(1..=cryptomatte::MAX_RANKS).contains(n))
        {
            return Err(Error::Argument {
                argument: "--cryptomatte-ranks".into(),
                problem: format!("{n} is not in 1 to {}", cryptomatte::MAX_RANKS),
            });
        }
        Ok(scene::OutputSettings {
            precision: self.aov_precision.map(|p| match p {
                PrecisionArg::Half => Precision::Half,
                PrecisionArg::Float => Precision::Float,
            }),
            compression: self.exr_compression.map(|c| match c {
                CompressionArg::None => ExrCompression::None,
                CompressionArg::Rle => ExrCompression::Rle,
                CompressionArg::Zips => ExrCompression::Zips,
                CompressionArg::Zip => ExrCompression::Zip,
                CompressionArg::Piz => ExrCompression::Piz,
            }),
            split: self.aov_split,
            cryptomatte_ranks: self.cryptomatte_ranks,
            transparent: self.transparent,
        })
    }
}

/// Denoising the frame `render` or `merge` writes (docs/output.md,
/// "Denoising").
#[derive(clap::Args)]
pub(crate) struct FrameDenoiseArgs {
    /// Also write the frame's beauty denoised by Open Image Denoise (the
    /// layer `denoised`, which the PNG preview shows), guided by its albedo
    /// and N passes (`render` adds them if not asked for). Frames only:
    /// a split render is denoised after the merge (docs/output.md,
    /// "Denoising").
    #[arg(long)]
    denoise: bool,
    /// With --denoise, also each light path and light group layer, as
    /// `denoised_<layer>`, with the beauty's guides.
    #[arg(long, requires = "denoise")]
    denoise_layers: bool,
    /// With --denoise, OIDN's scratch memory cap in MB (it then
    /// denoises in overlapping tiles; default: OIDN's own).
    #[arg(long, requires = "denoise", value_name = "MB")]
    denoise_memory: Option<u32>,
}

impl FrameDenoiseArgs {
    /// What the flags ask of the denoiser on `threads`, or None without
    /// --denoise.
    pub(crate) fn options(&self, threads: Option<usize>) -> Option<DenoiseOptions> {
        self.denoise.then(|| DenoiseOptions {
            layers: self.denoise_layers,
            max_memory_mb: self.denoise_memory,
            ..DenoiseOptions::with_threads(threads)
        })
    }
}
