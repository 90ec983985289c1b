//! What a render is asked to do: the scene, where the output goes, and the
//! options that override the scene's.

use std::ops::Range;
use std::path::PathBuf;

use super::Overrides;
use crate::accel::Backend;
use crate::denoise::DenoiseOptions;
use crate::film::exr_layers::Preview;
use crate::film::passes::PassSet;
use crate::film::region::Region;
use crate::render::RenderOptions;
use crate::scene::OutputSettings;

/// One render of a scene file.
#[derive(Clone, Debug)]
pub struct Request {
    pub scene: PathBuf,
    /// The OpenEXR written (a frame, or a part with [`Split::is_part`]).
    pub output: PathBuf,
    pub backend: Backend,
    pub opts: RenderOptions,
    /// The passes besides the beauty (None: the scene's `[output] aovs`).
    pub aov: Option<PassSet>,
    /// Sampling options that replace every subsurface material's own.
    pub overrides: Overrides,
    /// File options over the scene's `[output]`.
    pub file: OutputSettings,
    pub split: Split,
    pub preview: Preview,
    /// Also write the beauty denoised (`--denoise`), run so.
    pub denoise: Option<DenoiseOptions>,
}

/// Splitting a frame into parts, checkpoints and resuming (docs/farm.md).
#[derive(Clone, Debug, Default)]
pub struct Split {
    /// Only these pixels, as a part.
    pub crop: Option<Region>,
    /// Only these pixels, as a frame: a viewable EXR whose data window is
    /// the region (docs/output.md, "Region renders").
    pub region: Option<Region>,
    /// Only band I of N balanced horizontal bands.
    pub tile: Option<(u32, u32)>,
    /// Only these sample indices of each pixel.
    pub samples: Option<Range<u32>>,
    /// Save the finished samples every this many seconds.
    pub checkpoint: Option<f64>,
    /// The part of this same render to continue.
    pub resume: Option<PathBuf>,
}

impl Split {
    /// Whether the output is a part rather than a frame.
    pub fn is_part(&self) -> bool {
        self.crop.is_some() || self.tile.is_some() || self.samples.is_some()
    }
}
